#pragma once
// Several solutions of one run scored against one truth, side by side (`canyon evaluate`): the number of rover
// epochs they share, each solution's rates and its absolute position errors (APE) overall and by status, as a text
// table (columns joined by " : ", as in the paper's tables), Markdown and JSON.
//
// Definitions (per solution; "epochs" are all rover epochs, see EpochCount):
//   availability    solved epochs (any status) / epochs
//   fixed rate      Q 1 epochs / epochs; float (Q 2), single (Q 5), fill-in (Q 7, VIO) and other (Q 3, 4, 6) alike
//   wrong fix       a fixed epoch whose 3D error is above the threshold (0.10 m by default)
//   wrong-fix rate  wrong fixes / fixed epochs that have truth
//   APE             |d_N| (3D) and hypot(e, n) (horizontal) of d_N = R_NE (p_E - p_E_truth), ENU at the truth point,
//                   truth interpolated to the epoch (Truth::position_at); statistics as in ErrorDistribution
//   without truth   solved epochs at times the truth does not cover (outside its span, inside its gaps): counted in
//                   the rates, not in the APE
//
// JSON (format_json), stable keys; rates are fractions in [0, 1]; null where there is nothing to compute:
//   { "format": "canyon-evaluate/1",
//     "truth": { "source": SPEC, "kind": "trajectory" | "static", "samples": N },
//     "epochs": { "count": N, "source": "given" | "rover-file" | "truth+solutions" | "solutions" },
//     "wrong_fix_threshold_m": M,
//     "solutions": [ { "label": L, "file": PATH, "epochs": N, "solved": N, "availability": F,
//                      "status": { "fixed" | "float" | "single" | "fill_in" | "other": { "epochs": N, "rate": F } },
//                      "wrong_fixes": N, "wrong_fix_rate": F | null, "correct_fixes": N, "correct_fix_rate": F,
//                      "beyond_3_sigma_horizontal": N, "epochs_with_covariance": N, "beyond_protection_level": N,
//                      "epochs_with_truth": N, "epochs_without_truth": N, "time_to_first_fix_s": F | null,
//                      "ape": { "all" | "fixed" | "float" | "single" | "fill_in" | "other":
//                               { "epochs": N, "3d": D | null, "horizontal": D | null, "vertical_rmse_m": F | null } }
//                    } ],
//     "warnings": [ TEXT ] }
//   with D = { "rmse_m", "mean_m", "median_m", "std_m", "max_m", "p95_m" }.

#include <optional>
#include <string>
#include <vector>

#include "canyon/core/result.hpp"
#include "canyon/core/solution.hpp"
#include "canyon/eval/metrics.hpp"
#include "canyon/eval/truth.hpp"

namespace canyon::eval {

/// Where the number of rover epochs comes from.
enum class EpochSource {
  Given,           ///< by the caller (`--epochs N`)
  RoverFile,       ///< the epochs of the rover observation file (`--rover OBS`)
  TruthEpochs,     ///< a trajectory truth's epochs within the solutions' time span, joined with the solutions' epochs
  SolutionEpochs,  ///< the union of all solutions' epochs (a static truth has no epochs)
};
[[nodiscard]] const char* epoch_source_name(EpochSource source);

struct EpochCount {
  int epochs = 0;
  EpochSource source = EpochSource::SolutionEpochs;
  std::optional<core::GpsTime> first;  ///< first epoch: the time to first fix counts from here (nullopt: each
                                       ///< solution's first record)
};

/// The default rule: for a trajectory truth, its samples from the first to the last epoch of any solution joined
/// with every solution's epochs (so epochs inside truth gaps count too); for a static truth, the union of the
/// solutions' epochs. Epochs closer than `time_tolerance_s` are one.
[[nodiscard]] EpochCount count_epochs(const Truth& truth, const std::vector<std::vector<core::Solution>>& solution_sets,
                                      double time_tolerance_s);

/// One solution file to score.
struct SolutionInput {
  std::string label;
  std::string path;
  std::vector<core::Solution> solutions;
};

struct SolutionReport {
  std::string label;
  std::string path;
  std::vector<core::Solution> solutions;  ///< sorted by time, records without a solution (Q 0) dropped
  SolutionStats stats;
  std::optional<double> wrong_fix_rate;  ///< wrong fixes / fixed epochs with truth (nullopt: none)
};

struct ReportOptions {
  /// Fixed epochs with a 3D error above this are wrong fixes (m).
  double wrong_fix_threshold_m = 0.10;
  /// Two epochs are the same when their times differ by at most this (s).
  double time_tolerance_s = 0.005;
  /// Rover epochs; nullopt: count_epochs().
  std::optional<EpochCount> epochs;
};

struct EvaluationReport {
  std::string truth_source;  ///< as given (a file or "ecef:..." / "llh:...")
  bool truth_is_trajectory = false;
  int truth_samples = 0;
  EpochCount epochs;
  double wrong_fix_threshold_m = 0.0;
  std::vector<SolutionReport> solutions;
  std::vector<std::string> warnings;  ///< e.g. solved epochs without truth, a truth denser than the solutions
};

/// Scores every input against `truth`. Errors: a solution with solved epochs none of which the truth covers (names
/// the file and both time spans), more solved epochs than rover epochs, two records of one file at one epoch, no
/// input, invalid options.
Result<EvaluationReport> evaluate_report(std::vector<SolutionInput> inputs, const Truth& truth,
                                         const std::string& truth_source, const ReportOptions& options = {});

/// The side-by-side table: a few lines naming the truth and the epoch count, then one row per figure and one
/// column per solution (" : " between columns).
[[nodiscard]] std::string format_text_table(const EvaluationReport& report);
/// The same table in Markdown.
[[nodiscard]] std::string format_markdown(const EvaluationReport& report);
/// The figures as JSON (keys above).
[[nodiscard]] std::string format_json(const EvaluationReport& report);

}  // namespace canyon::eval
