#pragma once
// `canyon demo`: canyon's main job on a built-in default, with no external data. Generates a scenario
// (downtown unless told otherwise: the walk calibrated to the paper's UC2 by RTKLIB), processes it with every mode
// canyon has (SPP, RTK, fusion), runs RTKLIB's `rnx2rtkp` on the same files as the baseline when it is installed, and
// scores everything against the scenario's truth: the side-by-side table (RTKLIB : canyon) and the plots of `canyon
// evaluate`.
//
// Files (DIR):
//   scenario/        the generated scenario (canyon simulate's files)
//   spp.pos rtk.pos fusion.pos  canyon's solutions (configurations: the shipped spp defaults, config/<rtk_config>,
//                    config/<fusion_config> with the scenario's vio.csv and timesync.csv)
//   rtklib.pos       RTKLIB's solution (config/<rtklib_config>), rtklib.log its messages
//   evaluation.md evaluation.json trajectory.svg ape.svg   canyon evaluate's outputs

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "canyon/commands/simulate.hpp"
#include "canyon/core/result.hpp"

namespace canyon::commands {

struct DemoConfig {
  std::string scenario = "downtown";              ///< shipped scenario name or a scenario file
  std::optional<std::uint64_t> seed;              ///< default: the scenario's
  std::optional<double> duration_s;               ///< default: the scenario's
  std::string out_dir = "out/demo";               ///< created if needed
  std::string rtk_config = "rtk-urban.yaml";      ///< canyon's RTK configuration, a file in the shipped config/
  std::string fusion_config = "fusion.yaml";      ///< canyon's fusion configuration, a file in the shipped config/
  std::string rtklib_config = "rtklib/sim.conf";  ///< RTKLIB's option file, in the shipped config/
  bool run_rtklib = true;                         ///< run `rnx2rtkp` (skipped with a note when not installed)
  std::string rtklib_program = "rnx2rtkp";        ///< found on PATH
};

struct DemoSummary {
  SimulateSummary simulation;
  std::string table;                 ///< canyon evaluate's side-by-side table
  std::vector<std::string> notes;    ///< e.g. RTKLIB not installed
  std::vector<std::string> written;  ///< result files (the scenario's files are in DIR/scenario)
};

/// Called with one line per stage ("simulate downtown (seed 1, 600 s)").
using DemoLog = std::function<void(const std::string&)>;

/// Runs the demo. Error if a stage fails (a shipped configuration is missing, RTKLIB fails, a file cannot be
/// written): it names the stage and the file.
Result<DemoSummary> run_demo(const DemoConfig& config, const DemoLog& log = {});

}  // namespace canyon::commands
