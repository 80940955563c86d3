#pragma once
// `canyon process`: batch processing of recorded observations into a solution file.

#include <functional>
#include <string>
#include <vector>

#include "canyon/config/process_config.hpp"
#include "canyon/core/ephemeris.hpp"
#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/core/satellite.hpp"
#include "canyon/fusion/vio_track.hpp"
#include "canyon/io/rinex_obs.hpp"
#include "canyon/pipeline/epoch_pipeline.hpp"

namespace canyon::commands {

struct ProcessSummary {
  int epochs = 0;                     ///< rover epochs read
  int solved = 0;                     ///< epochs with a solution written
  int fixed = 0;                      ///< epochs with a fixed (RTK) solution
  int partial_fixed = 0;              ///< float epochs conditioned on fixed integer combinations (partial fixes)
  double wall_s = 0.0;                ///< wall-clock time of the whole run
  std::vector<std::string> warnings;  ///< recovered input defects, "file:line: what"
  /// Satellites left out by `exclude_most_observed`, most observed first.
  std::vector<core::SatelliteId> excluded_most_observed;
  /// Why epochs got no solution or one below the mode's best (first 100): "week tow: no solution: reason" or, in
  /// rtk mode, "week tow: float: ratio test failed" (status, then why it is not fixed).
  std::vector<std::string> epoch_notes;
  /// Fusion: the time bridge, VIO segments, alignments, lever-arm calibration and its observability, float
  /// validation and false-fix guard counts (one line each).
  std::vector<std::string> report;
};

/// The `n` satellites of the constellations in `systems` tracked (any code or phase) in the most epochs, most
/// observed first; ties go to the lower satellite id. Fewer when fewer were tracked.
[[nodiscard]] std::vector<core::SatelliteId> most_observed_satellites(const std::vector<core::ObsEpoch>& epochs, int n,
                                                                      const core::ConstellationFlags& systems);

/// Called after each epoch with (rover epochs done, fraction of the rover file read 0..1). Observation files are
/// read epoch by epoch, so the number of epochs is not known before the end.
using ProgressFn = std::function<void(int, double)>;

/// Runs the configured mode over the whole input. Error (file and line) if an input cannot be read or the output
/// cannot be written; an epoch that cannot be solved is counted and skipped.
/// rtk and fusion modes run the staged pipeline (epoch_pipeline.hpp), sequentially unless `pipeline` says threaded;
/// both give the same output.
Result<ProcessSummary> run_process(const config::ProcessConfig& input_config, const ProgressFn& progress = {},
                                   const pipeline::PipelineOptions& pipeline = {});

// Building blocks of run_process() that canyon rover shares.
/// The ephemerides of RINEX navigation files (warnings appended).
Result<core::NavigationData> load_navigation(const std::vector<std::string>& paths, std::vector<std::string>& warnings);
/// What observation files are read for (constellations, frequencies) in the configured mode.
[[nodiscard]] io::ObsFilter process_observation_filter(const config::ProcessConfig& config);
/// The VIO track on GPST (vio.csv through the time bridge); notes go to the summary's report and warnings.
Result<fusion::VioTrack> load_vio_track(const config::ProcessConfig& config, ProcessSummary& summary);
/// The .pos header lines of the configuration.
[[nodiscard]] std::vector<std::string> pos_header_lines(const config::ProcessConfig& config);

}  // namespace canyon::commands
