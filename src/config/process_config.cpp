// `canyon process` configuration: its keys described once (the estimator's sections in estimator_tables.cpp),
// parsed, printed and compared from that description; validation.

#include "canyon/config/process_config.hpp"

#include <algorithm>
#include <cstdio>
#include <exception>

namespace canyon::config {
namespace {

using P = ProcessConfig;

/// base_position: [X, Y, Z] read as text (std::stod: "1e6", "-2297445.2680"), printed as numbers.
struct EcefText {
  using Yaml = std::vector<std::string>;
  [[nodiscard]] Yaml to(const Eigen::Vector3d& v) const {
    Yaml texts;
    for (const double x : {v.x(), v.y(), v.z()}) {
      char text[32];
      std::snprintf(text, sizeof text, "%.17g", x);
      texts.emplace_back(text);
    }
    return texts;
  }
  void print(const Eigen::Vector3d& v, Printer& printer) const {
    printer.value(std::vector<double>{v.x(), v.y(), v.z()});
  }
  void from(const Yaml& xyz, Eigen::Vector3d& v, Reading& reading) const {
    std::vector<double> values;
    for (const std::string& text : xyz) {
      try {
        values.push_back(std::stod(text));
      } catch (const std::exception&) {
        values.clear();
        break;
      }
    }
    if (values.size() != 3) {
      reading.fail("must be [X, Y, Z], ECEF metres");
      return;
    }
    v = Eigen::Vector3d(values[0], values[1], values[2]);
  }
};

/// A path that is left out of the printed YAML while empty (nmea).
struct PathIfSet : Path {
  [[nodiscard]] bool omitted(const std::string& path) const { return path.empty(); }
};

struct NotNegative {
  using Yaml = int;
  [[nodiscard]] int to(int v) const { return v; }
  void from(int value, int& v, Reading& reading) const {
    v = value;
    if (v < 0) reading.fail("must be >= 0");
  }
};

const Table<P>& output_table() {
  static const Table<P> table{
      {"coordinates", "", "llh | ecef", at(&P::coordinates),
       Names<io::PosCoordinates>{{{io::PosCoordinates::Llh, "llh"}, {io::PosCoordinates::Ecef, "ecef"}}}},
      {"time_format", "", "tow (GPST week and seconds of week) | calendar", at(&P::time_format),
       Names<io::PosTimeFormat>{{{io::PosTimeFormat::WeekTow, "tow"}, {io::PosTimeFormat::Calendar, "calendar"}}}},
  };
  return table;
}

}  // namespace

const Table<ProcessConfig>& process_table() {
  static const Table<P> table{
      {"mode", "", "processing mode: spp | rtk | fusion (RTK aided by VIO)", at(&P::mode),
       names_of({ProcessMode::Spp, ProcessMode::Rtk, ProcessMode::Fusion}, mode_name)},
      {"rover", "", "rover RINEX observations (2.x/3.x, may be .gz); also --rover", at(&P::rover_obs), Path{}},
      {"base", "", "base RINEX observations (rtk, fusion); also --base", at(&P::base_obs), Path{}},
      {"vio", "", "VIO poses T_OI with covariances (fusion; DESIGN.md contract); also --vio", at(&P::vio), Path{}},
      {"timesync", "", "the device's GPS time-sync pairs (fusion); also --timesync", at(&P::timesync), Path{}},
      {"base_position", "m", "base antenna ECEF [X, Y, Z]; default: the base file's APPROX POSITION XYZ",
       at(&P::base_position_E_m), Optional<EcefText>{}},
      {"nav", "", "RINEX navigation files (one or a list); also --nav", at(&P::nav), Paths{}},
      {"out", "", "solution file (RTKLIB .pos format); also --out", at(&P::out), Path{}},
      {"nmea", "", "also write NMEA GGA sentences to this file; also --nmea", at(&P::nmea_out), PathIfSet{}},
      {"exclude_most_observed", "", "leave out the N satellites tracked in the most rover epochs (the paper's test)",
       at(&P::exclude_most_observed), NotNegative{}},
      {"output", "the .pos file's format", whole, output_table()},
      {"spp", "the single point: spp mode's solution, the RTK engine's prior and fallback", at(&P::spp), spp_table()},
      {"rtk", "the RTK engine (rtk and fusion modes)", at(&P::rtk), rtk_table()},
      {"fusion", "RTK aided by VIO, the paper's method (fusion mode)", at(&P::fusion), fusion_table()},
  };
  return table;
}

std::vector<KeyDescription> describe_process_config(ProcessMode mode) {
  return describe_keys(process_table(), process_defaults(mode), Numbers::Digits12);
}

ProcessConfig process_defaults(ProcessMode mode) {
  ProcessConfig c;
  c.mode = mode;
  if (mode == ProcessMode::Fusion) {
    c.rtk.ar_mode = rtk::ArMode::FixAndHold;
    c.rtk.ionosphere = rtk::IonosphereModel::Estimate;
    c.rtk.float_consistency_level = 0.001;
    c.rtk.snr_weighting = true;
    c.rtk.ambiguity_noise_cyc = 0.01;
    c.rtk.iono_noise_m = 3e-5;
  }
  return c;
}

std::optional<ProcessMode> mode_from_name(const std::string& name) {
  for (const ProcessMode mode : {ProcessMode::Spp, ProcessMode::Rtk, ProcessMode::Fusion}) {
    if (name == mode_name(mode)) return mode;
  }
  return std::nullopt;
}

std::string mode_name(ProcessMode mode) {
  switch (mode) {
    case ProcessMode::Spp: return "spp";
    case ProcessMode::Rtk: return "rtk";
    case ProcessMode::Fusion: return "fusion";
  }
  return "?";
}

std::string ProcessConfig::validate() const {
  if (rover_obs.empty()) return "a rover observation file is required (--rover or 'rover:')";
  if (nav.empty()) return "at least one navigation file is required (--nav or 'nav:')";
  if (out.empty()) return "a solution file is required (--out or 'out:')";
  if (exclude_most_observed < 0) return "exclude_most_observed must be >= 0";
  if (const std::string e = spp.validate(); !e.empty()) return "spp: " + e;
  if (mode == ProcessMode::Rtk || mode == ProcessMode::Fusion) {
    if (base_obs.empty()) return mode_name(mode) + " needs a base observation file (--base or 'base:')";
    if (const std::string e = rtk.validate(); !e.empty()) return "rtk: " + e;
  }
  if (mode == ProcessMode::Fusion) {
    if (vio.empty()) return "fusion needs a VIO file (--vio or 'vio:')";
    if (timesync.empty() && !fusion.vio_on_gps_time) {
      return "fusion needs a time-sync file (--timesync or 'timesync:'), or fusion.vio_clock: gps for VIO stamped "
             "with GPST";
    }
    if (const std::string e = fusion.validate(); !e.empty()) return "fusion: " + e;
  }
  return {};
}

rtk::RtkOptions ProcessConfig::rtk_engine_options() const {
  rtk::RtkOptions o = rtk;
  o.spp = spp;
  for (const core::SatelliteId& sat : rtk.observables.excluded) {
    if (std::find(o.spp.excluded.begin(), o.spp.excluded.end(), sat) == o.spp.excluded.end()) {
      o.spp.excluded.push_back(sat);
    }
  }
  for (const core::SatelliteId& sat : spp.excluded) {
    std::vector<core::SatelliteId>& excluded = o.observables.excluded;
    if (std::find(excluded.begin(), excluded.end(), sat) == excluded.end()) excluded.push_back(sat);
  }
  return o;
}

bool operator==(const ProcessConfig& a, const ProcessConfig& b) {
  return equal_keys(process_table(), a, b);
}

namespace {

/// The node's `mode:` when it names one (a bad value is reported by the table's codec), else spp.
ProcessMode mode_of(const YAML::Node& node) {
  if (!node.IsMap() || !node["mode"] || !node["mode"].IsScalar()) return ProcessMode::Spp;
  return mode_from_name(node["mode"].Scalar()).value_or(ProcessMode::Spp);
}

}  // namespace

Result<ProcessConfig> parse_process_config(const YAML::Node& node, const std::string& file,
                                           std::optional<ProcessMode> mode) {
  ProcessConfig c = process_defaults(mode.value_or(mode_of(node)));
  YamlMap top(node, file);
  read_keys(process_table(), top, c);
  if (Status s = top.status(); !s) return s.error();
  if (mode) c.mode = *mode;
  if (const std::string e = c.spp.validate(); !e.empty()) return Error{"spp: " + e, file, 0};
  if (const std::string e = c.rtk.validate(); !e.empty()) return Error{"rtk: " + e, file, 0};
  if (const std::string e = c.fusion.validate(); !e.empty()) return Error{"fusion: " + e, file, 0};
  return c;
}

Result<ProcessConfig> load_process_config(const std::string& path, std::optional<ProcessMode> mode) {
  auto node = load_yaml_file(path);
  if (!node) return node.error();
  return parse_process_config(*node, path, mode);
}

std::string to_yaml(const ProcessConfig& c) {
  return yaml_text(process_table(), c, Numbers::Digits12);
}

}  // namespace canyon::config
