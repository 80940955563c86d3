#pragma once
// `canyon check-fixes`: the leave-out check of fixes on data without ground truth (eval/leave_out.hpp). Solves the
// input as configured, then again with the 1, 2, ... N most-observed satellites left out, and compares each left-out
// solution's fixes with the full solution's at the epochs fixed in both.

#include <functional>
#include <string>
#include <vector>

#include "canyon/commands/process.hpp"
#include "canyon/config/process_config.hpp"
#include "canyon/core/result.hpp"
#include "canyon/eval/leave_out.hpp"

namespace canyon::commands {

struct CheckFixesOptions {
  int max_left_out = 3;         ///< runs with 1 .. max_left_out most-observed satellites left out
  double tolerance_m = 0.05;    ///< a fix agrees when within this of the full solution's (3-D, m)
  double min_agreement = 0.95;  ///< a run is consistent when at least this share of its epochs agree

  [[nodiscard]] std::string validate() const;
};

struct CheckFixesResult {
  ProcessSummary full;                        ///< the full solution's run
  std::vector<std::string> outputs;           ///< the .pos files: full, then one per left-out run
  std::vector<eval::LeaveOutAgreement> runs;  ///< one per left-out run
  [[nodiscard]] bool consistent(double min_agreement) const;
};

/// The left-out solution files of `out`: "<out without .pos>.leave-out-N.pos".
[[nodiscard]] std::string leave_out_path(const std::string& out, int left_out);

/// Runs the check (config.mode rtk or fusion; config.out is the full solution's file, the others beside it).
/// `progress` is called before each run with its label ("full solution", "leave out 1", ...).
Result<CheckFixesResult> check_fixes(const config::ProcessConfig& config, const CheckFixesOptions& options,
                                     const std::function<void(const std::string&)>& progress = {});

}  // namespace canyon::commands
