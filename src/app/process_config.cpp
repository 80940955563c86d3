// `canyon process` configuration: strict YAML parsing, printing and validation.

#include "canyon/app/process_config.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "canyon/app/yaml_reader.hpp"
#include "canyon/core/constants.hpp"

namespace canyon::app {
namespace {

std::string resolve(const std::string& path, const std::string& file) {
  if (path.empty() || file.empty() || std::filesystem::path(path).is_absolute()) return path;
  return (std::filesystem::path(file).parent_path() / path).lexically_normal().string();
}

std::vector<std::string> system_letters(const gnss::SppOptions& o) {
  std::vector<std::string> out;
  if (o.use_gps) out.emplace_back("G");
  if (o.use_glonass) out.emplace_back("R");
  if (o.use_galileo) out.emplace_back("E");
  if (o.use_beidou) out.emplace_back("C");
  if (o.use_qzss) out.emplace_back("J");
  return out;
}

void parse_spp(YamlMap map, gnss::SppOptions& o) {
  double mask_deg = o.elevation_mask_rad * core::kRadToDeg;
  map.get("elevation_mask_deg", mask_deg);
  o.elevation_mask_rad = mask_deg * core::kDegToRad;
  std::vector<std::string> systems = system_letters(o);
  map.get("systems", systems);
  o.use_gps = o.use_glonass = o.use_galileo = o.use_beidou = o.use_qzss = false;
  for (const std::string& s : systems) {
    if (s == "G") {
      o.use_gps = true;
    } else if (s == "R") {
      o.use_glonass = true;
    } else if (s == "E") {
      o.use_galileo = true;
    } else if (s == "C") {
      o.use_beidou = true;
    } else if (s == "J") {
      o.use_qzss = true;
    } else {
      map.fail("systems", "has '" + s + "'; allowed: G, R, E, C, J");
    }
  }
  std::string iono = o.ionosphere_klobuchar ? "klobuchar" : "off";
  map.get("ionosphere", iono);
  if (iono != "klobuchar" && iono != "off") map.fail("ionosphere", "must be klobuchar or off, not '" + iono + "'");
  o.ionosphere_klobuchar = iono == "klobuchar";
  std::string tropo = o.troposphere_saastamoinen ? "saastamoinen" : "off";
  map.get("troposphere", tropo);
  if (tropo != "saastamoinen" && tropo != "off") {
    map.fail("troposphere", "must be saastamoinen or off, not '" + tropo + "'");
  }
  o.troposphere_saastamoinen = tropo == "saastamoinen";
  map.get("code_sigma_m", o.code_sigma_m);
  map.get("raim_fde", o.raim_fde);
  map.get("max_gdop", o.max_gdop);
  map.get("qzss_own_clock", o.qzss_own_clock);
  std::vector<std::string> excluded;
  for (const auto& sat : o.excluded) excluded.push_back(sat.to_string());
  map.get("exclude", excluded);
  o.excluded.clear();
  for (const std::string& text : excluded) {
    const auto sat = core::parse_satellite(text);
    if (!sat) {
      map.fail("exclude", "has '" + text + "', not a satellite (e.g. G05, R12, E30, C20, J02)");
    } else {
      o.excluded.push_back(*sat);
    }
  }
  map.reject_unknown_keys();
}

}  // namespace

std::string mode_name(ProcessMode mode) {
  switch (mode) {
    case ProcessMode::Spp: return "spp";
  }
  return "?";
}

std::string ProcessConfig::validate() const {
  if (rover_obs.empty()) return "a rover observation file is required (--rover or 'rover:')";
  if (nav.empty()) return "at least one navigation file is required (--nav or 'nav:')";
  if (out.empty()) return "a solution file is required (--out or 'out:')";
  if (const std::string e = spp.validate(); !e.empty()) return "spp: " + e;
  return {};
}

bool operator==(const ProcessConfig& a, const ProcessConfig& b) {
  return to_yaml(a) == to_yaml(b);
}

Result<ProcessConfig> parse_process_config(const YAML::Node& node, const std::string& file, ProcessConfig defaults) {
  ProcessConfig c = std::move(defaults);
  YamlMap top(node, file);
  std::string mode = mode_name(c.mode);
  top.get("mode", mode);
  if (mode != "spp") top.fail("mode", "must be spp (rtk and fusion are not available yet), not '" + mode + "'");
  top.get("rover", c.rover_obs);
  c.rover_obs = resolve(c.rover_obs, file);
  top.get("nav", c.nav);
  for (std::string& n : c.nav) n = resolve(n, file);
  top.get("out", c.out);
  c.out = resolve(c.out, file);
  {
    YamlMap output = top.sub("output");
    std::string coordinates = c.coordinates == io::PosCoordinates::Llh ? "llh" : "ecef";
    output.get("coordinates", coordinates);
    if (coordinates != "llh" && coordinates != "ecef") {
      output.fail("coordinates", "must be llh or ecef, not '" + coordinates + "'");
    }
    c.coordinates = coordinates == "ecef" ? io::PosCoordinates::Ecef : io::PosCoordinates::Llh;
    std::string time_format = c.time_format == io::PosTimeFormat::WeekTow ? "tow" : "calendar";
    output.get("time_format", time_format);
    if (time_format != "tow" && time_format != "calendar") {
      output.fail("time_format", "must be tow or calendar, not '" + time_format + "'");
    }
    c.time_format = time_format == "calendar" ? io::PosTimeFormat::Calendar : io::PosTimeFormat::WeekTow;
    output.reject_unknown_keys();
  }
  parse_spp(top.sub("spp"), c.spp);
  top.reject_unknown_keys();
  if (Status s = top.status(); !s) return s.error();
  if (const std::string e = c.spp.validate(); !e.empty()) return Error{"spp: " + e, file, 0};
  return c;
}

Result<ProcessConfig> load_process_config(const std::string& path, ProcessConfig defaults) {
  auto node = load_yaml_file(path);
  if (!node) return node.error();
  return parse_process_config(*node, path, std::move(defaults));
}

std::string to_yaml(const ProcessConfig& c) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "mode" << YAML::Value << mode_name(c.mode);
  out << YAML::Key << "rover" << YAML::Value << c.rover_obs;
  out << YAML::Key << "nav" << YAML::Value << YAML::Flow << c.nav;
  out << YAML::Key << "out" << YAML::Value << c.out;
  out << YAML::Key << "output" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "coordinates" << YAML::Value << (c.coordinates == io::PosCoordinates::Llh ? "llh" : "ecef");
  out << YAML::Key << "time_format" << YAML::Value
      << (c.time_format == io::PosTimeFormat::WeekTow ? "tow" : "calendar");
  out << YAML::EndMap;
  const gnss::SppOptions& s = c.spp;
  out << YAML::Key << "spp" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "elevation_mask_deg" << YAML::Value << s.elevation_mask_rad * core::kRadToDeg;
  out << YAML::Key << "systems" << YAML::Value << YAML::Flow << system_letters(s);
  out << YAML::Key << "ionosphere" << YAML::Value << (s.ionosphere_klobuchar ? "klobuchar" : "off");
  out << YAML::Key << "troposphere" << YAML::Value << (s.troposphere_saastamoinen ? "saastamoinen" : "off");
  out << YAML::Key << "code_sigma_m" << YAML::Value << s.code_sigma_m;
  out << YAML::Key << "raim_fde" << YAML::Value << s.raim_fde;
  out << YAML::Key << "max_gdop" << YAML::Value << s.max_gdop;
  out << YAML::Key << "qzss_own_clock" << YAML::Value << s.qzss_own_clock;
  std::vector<std::string> excluded;
  for (const auto& sat : s.excluded) excluded.push_back(sat.to_string());
  out << YAML::Key << "exclude" << YAML::Value << YAML::Flow << excluded;
  out << YAML::EndMap;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace canyon::app
