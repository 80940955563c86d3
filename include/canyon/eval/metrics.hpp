#pragma once
// Solution-quality metrics in the paper's terms (fix rate, errors by status), the same for canyon's and RTKLIB's
// .pos solutions.
//
// Errors are taken in local ENU at the truth point: d_N = R_NE (p_E_solution - p_E_truth); horizontal =
// hypot(e, n), vertical = |u|, 3D = |d_N|. RMSE = sqrt(mean of squares). The 95th percentile is of the 3D error,
// linearly interpolated between order statistics at rank 0.95 (n - 1) (as numpy.percentile's default).
// Epochs of two solution sets are the same epoch when their GPST tags differ by at most `time_tolerance_s`.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "canyon/core/result.hpp"
#include "canyon/core/solution.hpp"
#include "canyon/eval/truth.hpp"

namespace canyon::eval {

struct EvalOptions {
  /// Fixed epochs with a 3D error above this are wrong fixes (m).
  double wrong_fix_threshold_m = 0.10;
  /// Number of input epochs (rover observation epochs); nullopt: the number of solution records.
  std::optional<int> epochs_in;
  /// Time from which the time to first fix counts; nullopt: the first solution record.
  std::optional<core::GpsTime> first_epoch;
  /// Two epochs are the same when their times differ by at most this (s): compare() and epoch counting.
  double time_tolerance_s = 0.005;

  /// Empty if valid, else the broken rule.
  [[nodiscard]] std::string validate() const;
};

/// Distribution of one error magnitude over a set of epochs (absolute position error, APE): all zero when empty.
/// Median and p95 interpolate linearly between order statistics (as the 95th percentile above); std is the
/// population standard deviation (divided by n), so that rmse^2 = mean^2 + std^2.
struct ErrorDistribution {
  double rmse_m = 0.0;
  double mean_m = 0.0;
  double median_m = 0.0;
  double std_m = 0.0;
  double max_m = 0.0;
  double p95_m = 0.0;
};

/// Position error statistics over a set of epochs (all zero when count == 0).
struct ErrorStats {
  int count = 0;                   ///< epochs with a truth position
  double horizontal_rmse_m = 0.0;  ///< RMS of hypot(e, n)
  double horizontal_max_m = 0.0;
  double vertical_rmse_m = 0.0;  ///< RMS of u
  double rmse_3d_m = 0.0;
  double max_3d_m = 0.0;
  double p95_3d_m = 0.0;             ///< 95th percentile of the 3D error
  ErrorDistribution ape_3d;          ///< of |d_N|
  ErrorDistribution ape_horizontal;  ///< of hypot(e, n)
};

/// Status classes counted separately: canyon's four (RTKLIB's Q 1, 2, 5, 7) and everything else RTKLIB writes
/// (SBAS 3, DGPS 4, PPP 6).
enum class StatusClass { Fixed = 0, Float = 1, Single = 2, VioFillIn = 3, Other = 4 };
inline constexpr std::size_t kNumStatusClasses = 5;
[[nodiscard]] StatusClass status_class(core::SolutionStatus status);
[[nodiscard]] const char* status_class_name(StatusClass c);

struct StatusStats {
  int epochs = 0;                      ///< solutions of this class
  double fraction_of_solved = 0.0;     ///< epochs / epochs with a solution
  double fraction_of_epochs_in = 0.0;  ///< epochs / epochs in
  ErrorStats error;                    ///< against the truth, if one was given
};

struct SolutionStats {
  int epochs_in = 0;             ///< input epochs (EvalOptions::epochs_in, else solution records)
  int epochs_with_solution = 0;  ///< records with a status other than None
  int epochs_with_truth = 0;     ///< solutions for which the truth has a position
  int epochs_without_truth = 0;  ///< solutions at times the truth does not cover (outside its span, in its gaps)
  std::array<StatusStats, kNumStatusClasses> by_class{};
  ErrorStats overall;   ///< all solutions with truth, every status
  int wrong_fixes = 0;  ///< fixed epochs with 3D error > wrong_fix_threshold_m
  /// Covariance honesty: of the solutions with truth and a positive definite horizontal covariance C (east, north),
  /// those whose horizontal error e lies beyond 3 sigma, e^T C^-1 e > 9 (a Gaussian error: 1.1 % of epochs).
  int epochs_with_covariance = 0;
  int beyond_3_sigma_horizontal = 0;
  /// Integrity: of those, the solutions whose horizontal error exceeds their horizontal protection level
  /// HPL = core::horizontal_protection_level_m(C), the level output with the solution but in the frame at the truth
  /// (misleading information).
  int beyond_protection_level = 0;
  double wrong_fix_threshold_m = 0.0;
  std::optional<double> time_to_first_fix_s;  ///< from the first epoch to the first fixed solution
  bool has_truth = false;

  [[nodiscard]] const StatusStats& of(StatusClass c) const { return by_class[static_cast<std::size_t>(c)]; }
  [[nodiscard]] const StatusStats& fixed() const { return of(StatusClass::Fixed); }
  [[nodiscard]] const StatusStats& floating() const { return of(StatusClass::Float); }
};

/// Scores `solutions` against `truth` (nullptr: counts, rates and time to first fix only). Solutions need not be
/// sorted; records of status None count as input epochs without a solution. Duplicated times (within
/// time_tolerance_s) are an Error, as are invalid options.
Result<SolutionStats> evaluate(const std::vector<core::Solution>& solutions, const Truth* truth,
                               const EvalOptions& options = {});
inline Result<SolutionStats> evaluate(const std::vector<core::Solution>& solutions, const Truth& truth,
                                      const EvalOptions& options = {}) {
  return evaluate(solutions, &truth, options);
}

/// Agreement of two solution sets on the epochs both solved (e.g. canyon against RTKLIB).
struct Agreement {
  int epochs_a = 0;                     ///< solutions (status other than None) in a
  int epochs_b = 0;                     ///< solutions in b
  int matched = 0;                      ///< epochs solved by both
  int both_fixed = 0;                   ///< epochs fixed in both
  int only_a_fixed = 0;                 ///< matched epochs fixed in a, not in b
  int only_b_fixed = 0;                 ///< matched epochs fixed in b, not in a
  double max_distance_fixed_m = 0.0;    ///< max |p_a - p_b| over epochs both fixed
  double rms_distance_fixed_m = 0.0;    ///< RMS of |p_a - p_b| over epochs both fixed
  double max_distance_matched_m = 0.0;  ///< max |p_a - p_b| over all matched epochs
};
/// Epochs matched by time within `time_tolerance_s` (nearest). Error if the tolerance is not positive or one set
/// has two solutions within the tolerance of each other.
Result<Agreement> compare(const std::vector<core::Solution>& a, const std::vector<core::Solution>& b,
                          double time_tolerance_s = 0.005);

/// Text table: one row per status class present and one overall row, with counts, rates and errors (m, 3
/// decimals), then wrong fixes and time to first fix.
[[nodiscard]] std::string format_stats(const SolutionStats& stats, const std::string& title = {});
/// Text lines: matched, both fixed, only-one fixed, max and RMS distance on epochs both fixed.
[[nodiscard]] std::string format_agreement(const Agreement& agreement, const std::string& name_a = "a",
                                           const std::string& name_b = "b");

/// One file's text report (bench_eval_pos; `canyon evaluate` uses report.hpp): reads `solution_path` (.pos), scores
/// it against the truth given by `truth_spec` (see parse_truth_spec; empty: no truth), and, if `reference_path` is
/// not empty, compares it with that second .pos file. Errors name the file and line.
Result<std::string> evaluate_files(const std::string& solution_path, const std::string& truth_spec,
                                   const EvalOptions& options = {}, const std::string& reference_path = {});

/// One line of `key=value` pairs for scripts (tests/bench/rtk_vs_rtklib.sh): epochs_in, solved, fixed, float,
/// fixed_pct, float_pct, rmse_3d_m (or "-" without truth), wrong_fixes (or "-"), ttff_s (or "-"), and with an
/// agreement: both_fixed, max_fixed_dist_m, rms_fixed_dist_m.
[[nodiscard]] std::string format_key_values(const SolutionStats& stats, const std::optional<Agreement>& agreement);

}  // namespace canyon::eval
