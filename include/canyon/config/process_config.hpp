#pragma once
// Configuration of `canyon process`: inputs, mode, output format and the estimator options, from a strict YAML
// file and/or the command line. Relative paths in a YAML file are relative to that file's folder. Every key is
// described once, in the tables below (process_config.cpp, estimator_tables.cpp): they parse, print and compare the
// configuration, and `canyon process --describe-config` lists every key with its unit, default and doc.
//
// The keys (all optional; the command line overrides them): mode, the inputs (rover, base, vio, timesync,
// base_position, nav), the outputs (out, nmea, output: coordinates and time_format), exclude_most_observed, and the
// sections spp:, rtk: and fusion:. config/spp.yaml, rtk.yaml and fusion.yaml show each key with its unit and default.

#include <optional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "canyon/config/options_table.hpp"
#include "canyon/core/result.hpp"
#include "canyon/fusion/fusion_options.hpp"
#include "canyon/gnss/spp.hpp"
#include "canyon/io/pos_file.hpp"
#include "canyon/rtk/engine.hpp"

namespace canyon::config {

enum class ProcessMode { Spp, Rtk, Fusion };

struct ProcessConfig {
  ProcessMode mode = ProcessMode::Spp;
  std::string rover_obs;                             ///< rover observation file
  std::string base_obs;                              ///< base observation file (rtk, fusion)
  std::string vio;                                   ///< VIO pose file (fusion)
  std::string timesync;                              ///< time-sync file (fusion with a device clock)
  std::optional<Eigen::Vector3d> base_position_E_m;  ///< base antenna position (ECEF, m); header position if unset
  std::vector<std::string> nav;                      ///< navigation files
  std::string out;                                   ///< solution file
  std::string nmea_out;                              ///< NMEA GGA file written beside the .pos when set
  int exclude_most_observed = 0;                     ///< leave out the N most observed satellites (>= 0)
  io::PosCoordinates coordinates = io::PosCoordinates::Llh;
  io::PosTimeFormat time_format = io::PosTimeFormat::WeekTow;
  gnss::SppOptions spp;
  rtk::RtkOptions rtk;
  fusion::FusionOptions fusion;

  /// Empty if complete and consistent, else the first violated rule ("rover observation file is required").
  [[nodiscard]] std::string validate() const;

  /// The RTK engine's options (rtk and fusion modes): `rtk` with its single-point solution (the prior, the fallback,
  /// fusion's integrity reference) configured by `spp`, and a satellite excluded in either section left out of both.
  [[nodiscard]] rtk::RtkOptions rtk_engine_options() const;
};

/// Equal when every key of the tables is (the member itself where it can be compared, else its YAML form).
[[nodiscard]] bool operator==(const ProcessConfig& a, const ProcessConfig& b);

/// The recommended set-up of each mode, the one source of `canyon process`'s defaults: ProcessConfig{} with `mode`,
/// and for fusion the RTK engine as the paper's fusion runs it (fix-and-hold, estimated ionosphere, C/N0 weights, the
/// float's consistency test, an ambiguity random walk of 0.01 cycles per sqrt(s)). config/spp.yaml, rtk.yaml and
/// fusion.yaml are these, key for key (tests/config/process_config_test.cpp).
[[nodiscard]] ProcessConfig process_defaults(ProcessMode mode);

/// Parses a YAML node over process_defaults() of its mode: `mode` when given (the command line's --mode), else the
/// node's `mode:` key, else spp. `file` names the source in errors and anchors relative paths.
Result<ProcessConfig> parse_process_config(const YAML::Node& node, const std::string& file,
                                           std::optional<ProcessMode> mode = std::nullopt);
Result<ProcessConfig> load_process_config(const std::string& path, std::optional<ProcessMode> mode = std::nullopt);
/// The configuration as YAML that parse_process_config() reads back to an equal configuration.
[[nodiscard]] std::string to_yaml(const ProcessConfig& config);

[[nodiscard]] std::string mode_name(ProcessMode mode);
/// The mode named `name` (spp, rtk, fusion), nullopt for any other.
[[nodiscard]] std::optional<ProcessMode> mode_from_name(const std::string& name);

/// The keys of each section (options_table.hpp): spp:, rtk:, fusion: (flat keys over the per-piece structs), and the
/// whole configuration with those as sections.
[[nodiscard]] const Table<gnss::SppOptions>& spp_table();
[[nodiscard]] const Table<rtk::RtkOptions>& rtk_table();
[[nodiscard]] const Table<fusion::FusionOptions>& fusion_table();
[[nodiscard]] const Table<ProcessConfig>& process_table();
/// Every key with its unit, default (of process_defaults(mode)) and doc.
[[nodiscard]] std::vector<KeyDescription> describe_process_config(ProcessMode mode = ProcessMode::Spp);

}  // namespace canyon::config
