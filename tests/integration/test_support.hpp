#pragma once
// Helpers for end-to-end tests: shared datasets, running RTKLIB and canyon as real processes, comparing solutions.

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/solution.hpp"
#include "canyon/io/pos_file.hpp"

namespace canyon::test {

inline std::filesystem::path shared_data() { return CANYON_SHARED_DATA_DIR; }

/// Output and exit status of a shell command.
struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

inline CommandResult run_command(const std::string& command) {
  CommandResult r;
  std::FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return r;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) r.output += buffer;
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline bool have_rtklib() { return run_command("command -v rnx2rtkp").exit_code == 0; }

inline std::filesystem::path temp_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("canyon_test_" + name);
  std::filesystem::create_directories(dir);
  return dir;
}

/// Solution nearest in time to t within max_dt_s.
inline const core::Solution* nearest(const std::vector<core::Solution>& sols, const core::GpsTime& t,
                                     double max_dt_s) {
  const core::Solution* best = nullptr;
  for (const auto& s : sols) {
    const double dt = std::abs(s.time - t);
    if (dt <= max_dt_s && (best == nullptr || dt < std::abs(best->time - t))) best = &s;
  }
  return best;
}

inline double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

inline double rms(const std::vector<double>& v) {
  double sum = 0.0;
  for (const double x : v) sum += x * x;
  return v.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(v.size()));
}

}  // namespace canyon::test
