// The leave-out check of fixes (see check_fixes.hpp).

#include "canyon/commands/check_fixes.hpp"

#include <utility>

#include "canyon/io/pos_file.hpp"

namespace canyon::commands {

std::string CheckFixesOptions::validate() const {
  if (max_left_out < 1) return "the number of runs leaving satellites out must be >= 1";
  if (!(tolerance_m > 0.0)) return "the agreement tolerance must be > 0 m";
  if (!(min_agreement >= 0.0 && min_agreement <= 1.0)) return "the agreement share must be in [0, 1]";
  return {};
}

bool CheckFixesResult::consistent(double min_agreement) const {
  for (const eval::LeaveOutAgreement& r : runs) {
    if (r.agreement() < min_agreement) return false;
  }
  return true;
}

std::string leave_out_path(const std::string& out, int left_out) {
  const bool pos = out.size() > 4 && out.compare(out.size() - 4, 4, ".pos") == 0;
  return (pos ? out.substr(0, out.size() - 4) : out) + ".leave-out-" + std::to_string(left_out) + ".pos";
}

Result<CheckFixesResult> check_fixes(const config::ProcessConfig& config, const CheckFixesOptions& options,
                                     const std::function<void(const std::string&)>& progress) {
  if (const std::string e = options.validate(); !e.empty()) return Error{"check-fixes: " + e};
  if (config.mode == config::ProcessMode::Spp) return Error{"check-fixes: mode spp has no fixes (use rtk or fusion)"};
  if (const std::string e = config.validate(); !e.empty()) return Error{"check-fixes: " + e};
  CheckFixesResult result;
  if (progress) progress("full solution");
  auto full = run_process(config);
  if (!full) return full.error();
  result.full = std::move(*full);
  result.outputs.push_back(config.out);
  auto full_solutions = io::read_pos_file(config.out);
  if (!full_solutions) return full_solutions.error();
  for (int n = 1; n <= options.max_left_out; ++n) {
    config::ProcessConfig left_out = config;
    left_out.exclude_most_observed = config.exclude_most_observed + n;
    left_out.out = leave_out_path(config.out, n);
    left_out.nmea_out.clear();
    if (progress) progress("leave out " + std::to_string(n));
    auto run = run_process(left_out);
    if (!run) return run.error();
    auto solutions = io::read_pos_file(left_out.out);
    if (!solutions) return solutions.error();
    eval::LeaveOutAgreement agreement = eval::leave_out_agreement(*full_solutions, *solutions, options.tolerance_m);
    agreement.left_out = n;
    agreement.satellites = run->excluded_most_observed;
    result.runs.push_back(std::move(agreement));
    result.outputs.push_back(left_out.out);
  }
  return result;
}

}  // namespace canyon::commands
