#pragma once
// `canyon evaluate`: several .pos solutions (canyon's, RTKLIB's in any of its output forms) scored against one
// truth, side by side: a text table, Markdown, JSON and two SVG plots (see canyon/eval/report.hpp, plots.hpp).
//
// Rover epochs (the denominator of every rate): `epochs` if given, else the epochs of `rover_obs` if given, else
// eval::count_epochs() (a trajectory truth's epochs within the solutions' span joined with the solutions' epochs;
// a static truth: the union of the solutions' epochs).
//
// Output files: with out_dir, DIR/evaluation.md, DIR/evaluation.json, DIR/trajectory.svg and DIR/ape.svg, each
// replaced by its own option (markdown, json, trajectory_svg, ape_svg) when that is given. Without out_dir, only
// the files given by their own options are written; with none of the five, out_dir is `evaluation/` in the folder
// of the first solution.

#include <optional>
#include <string>
#include <vector>

#include "canyon/core/result.hpp"

namespace canyon::commands {

struct EvaluateConfig {
  std::string truth;                   ///< truth file (.csv, .pos) or "ecef:X,Y,Z" / "llh:LAT,LON,H"
  std::vector<std::string> solutions;  ///< .pos files
  std::vector<std::string> labels;     ///< one per solution, or none: each file's name without its extension
  std::optional<int> epochs;           ///< rover epochs, if known
  std::string rover_obs;               ///< rover RINEX observation file whose epochs are counted (if no `epochs`)
  std::string city;                    ///< city GeoJSON (canyon simulate's city.geojson) under the trajectories
  std::string out_dir;                 ///< see above
  std::string markdown;
  std::string json;
  std::string trajectory_svg;
  std::string ape_svg;
  std::string kml;  ///< KML 2.2 track of every solution by status, the truth beside them (eval/map_tracks.hpp)
  std::string gpx;  ///< GPX 1.1 tracks, the same
  double wrong_fix_threshold_m = 0.10;  ///< fixed epochs with a larger 3D error are wrong fixes (m)
  double time_tolerance_s = 0.005;      ///< epochs closer than this are one (s)

  /// Empty if the configuration is usable, else the broken rule (a command-line error).
  [[nodiscard]] std::string validate() const;
};

struct EvaluateSummary {
  std::string table;                  ///< the side-by-side text table
  std::vector<std::string> warnings;  ///< e.g. solved epochs without truth
  std::vector<std::string> written;   ///< files written
};

/// Reads every input, scores the solutions and writes the outputs. Errors (bad input) name the file, and the line
/// where there is one. The map tracks are written last: when one cannot be written the error says so and lists the
/// files already written (they stay).
Result<EvaluateSummary> run_evaluate(const EvaluateConfig& config);

/// Labels for `config`: the given ones, or each solution's file name without its extension (the whole path where
/// two names are alike).
[[nodiscard]] std::vector<std::string> solution_labels(const EvaluateConfig& config);

}  // namespace canyon::commands
