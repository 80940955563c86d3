#pragma once
// Helpers for end-to-end tests: shared datasets, running RTKLIB and canyon as real processes, comparing solutions.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <sys/wait.h>

#include "canyon/core/solution.hpp"
#include "canyon/io/pos_file.hpp"

namespace canyon::test {

inline std::filesystem::path shared_data() {
  return CANYON_SHARED_DATA_DIR;
}

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

inline bool have_rtklib() {
  return run_command("command -v rnx2rtkp").exit_code == 0;
}

/// RTKLIB navsys bit mask of systems given as "G,R,E,C,J".
inline int rtklib_navsys(const std::string& systems) {
  int mask = 0;
  if (systems.find('G') != std::string::npos) mask |= 1;
  if (systems.find('R') != std::string::npos) mask |= 4;
  if (systems.find('E') != std::string::npos) mask |= 8;
  if (systems.find('J') != std::string::npos) mask |= 16;
  if (systems.find('C') != std::string::npos) mask |= 32;
  return mask;
}

/// Writes an rnx2rtkp option file for single-point positioning with the same models as canyon's defaults
/// (rnx2rtkp's built-in defaults apply no ionosphere or troposphere model).
inline std::filesystem::path write_rtklib_spp_conf(const std::filesystem::path& dir, const std::string& systems,
                                                   double elevation_mask_deg = 15.0) {
  const auto path = dir / "rtklib_spp.conf";
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return path;
  std::fprintf(f,
               "pos1-posmode=single\npos1-elmask=%g\npos1-ionoopt=brdc\npos1-tropopt=saas\npos1-sateph=brdc\n"
               "pos1-navsys=%d\nout-solformat=xyz\nout-timeform=tow\nout-timendec=3\n",
               elevation_mask_deg, rtklib_navsys(systems));
  std::fclose(f);
  return path;
}

inline std::filesystem::path temp_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("canyon_test_" + name);
  std::filesystem::create_directories(dir);
  return dir;
}

/// Solution nearest in time to t within max_dt_s.
inline const core::Solution* nearest(const std::vector<core::Solution>& sols, const core::GpsTime& t, double max_dt_s) {
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
