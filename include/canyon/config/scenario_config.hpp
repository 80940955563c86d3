#pragma once
// Scenario files of `canyon simulate`: strict YAML (an unknown key, a value of the wrong type or out of range is an
// error naming the file, the line and the key) into sim::Scenario, and back, from its keys described once
// (scenario_table()). The shipped scenarios in
// config/scenarios/ document every key with its unit and default; keys are the sim::Scenario field names (see
// canyon/sim/scenario.hpp), except:
//   start: "2023-06-14 18:00:00"        GPST calendar time of the first epoch
//   origin: {lat_deg, lon_deg, height_m} city origin (degrees, ellipsoidal metres)
//   constellation.systems: [G, R, E]    constellations simulated (C: BeiDou MEO)
//   constellation.*_signals: [1C, 2L]   RINEX band+attribute of each tracked signal
//   route.waypoints_m: [[e, n], ...]    explicit route, metres east/north of the origin
//   vio.t_IA_m: [x, y, z]
//   truth: {...}                        written by `canyon simulate` into DIR/scenario.yaml; ignored on input
// Relative paths (constellation.nav_file) are relative to the scenario file's folder.

#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "canyon/config/options_table.hpp"
#include "canyon/core/result.hpp"
#include "canyon/sim/scenario.hpp"

namespace canyon::config {

/// Parses a scenario; `file` names the source in errors and anchors relative paths. The scenario is validated
/// (sim::Scenario::validate()); a broken rule is reported at the line of the key it names.
Result<sim::Scenario> parse_scenario(const YAML::Node& node, const std::string& file);
Result<sim::Scenario> load_scenario(const std::string& path);

/// The scenario as YAML that parse_scenario() reads back to the same scenario (every key written). `truth_yaml`, if
/// not empty, is appended as the `truth:` section (already indented by two spaces per line, without the key).
[[nodiscard]] std::string scenario_to_yaml(const sim::Scenario& scenario, const std::string& truth_yaml = {});

/// The scenario's keys (options_table.hpp): each with its unit, default (of sim::Scenario{}) and doc.
[[nodiscard]] const Table<sim::Scenario>& scenario_table();
[[nodiscard]] std::vector<KeyDescription> describe_scenario();
/// Whether two scenarios have every key of scenario_table() equal (source_file aside).
[[nodiscard]] bool same_scenario(const sim::Scenario& a, const sim::Scenario& b);

/// The path of a scenario given as NAME (a file NAME.yaml in a scenario folder) or as a file path. Scenario folders:
/// `scenarios/` in each shipped configuration folder (canyon/config/shipped_config.hpp). Error naming the shipped
/// scenarios if nothing matches.
Result<std::string> find_scenario_file(const std::string& name_or_file);

/// Names of the shipped scenarios found in the scenario folders.
[[nodiscard]] std::vector<std::string> shipped_scenarios();

}  // namespace canyon::config
