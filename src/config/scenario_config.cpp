// Scenario files: strict YAML parsing, validation with line numbers, printing (see scenario_config.hpp).

#include "canyon/config/scenario_config.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>

#include "canyon/config/shipped_config.hpp"
#include "canyon/config/yaml_reader.hpp"
#include "canyon/core/constants.hpp"

namespace canyon::config {
namespace {

namespace fs = std::filesystem;
using sim::Scenario;

std::string resolve(const std::string& path, const std::string& file) {
  if (path.empty() || file.empty() || fs::path(path).is_absolute()) return path;
  return (fs::path(file).parent_path() / path).lexically_normal().string();
}

// ---------------------------------------------------------------------------------------------------------------
// Parsing helpers.

void parse_signals(YamlMap& map, const std::string& key, std::vector<core::SignalCode>& out) {
  std::vector<std::string> texts;
  texts.reserve(out.size());
  for (const core::SignalCode s : out) texts.push_back(s.to_string());
  map.get(key, texts);
  std::vector<core::SignalCode> signals;
  for (const std::string& t : texts) {
    const auto s = core::parse_signal(t);
    if (!s) {
      map.fail(key, "has '" + t + "', not a RINEX band and attribute (e.g. 1C, 2L, 7Q)");
      return;
    }
    signals.push_back(*s);
  }
  out = signals;
}

void parse_vector3(YamlMap& map, const std::string& key, Eigen::Vector3d& out) {
  std::vector<double> v = {out.x(), out.y(), out.z()};
  map.get(key, v);
  if (v.size() != 3) {
    map.fail(key, "must be [x, y, z]");
    return;
  }
  out = Eigen::Vector3d(v[0], v[1], v[2]);
}

void parse_start(YamlMap& map, core::GpsTime& start) {
  const core::CalendarTime c0 = core::gps_to_calendar(start);
  char text[32];
  std::snprintf(text, sizeof text, "%04d-%02d-%02d %02d:%02d:%02d", c0.year, c0.month, c0.day, c0.hour, c0.minute,
                static_cast<int>(c0.second));
  std::string value = text;
  map.get("start", value);
  core::CalendarTime c;
  char tail = 0;
  if (std::sscanf(value.c_str(), "%d-%d-%d %d:%d:%lf%c", &c.year, &c.month, &c.day, &c.hour, &c.minute, &c.second,
                  &tail) != 6 ||
      !core::is_valid(c) || c.year < 1990 || c.year > 2100) {
    map.fail("start", "must be a GPST calendar time \"YYYY-MM-DD hh:mm:ss\", not '" + value + "'");
    return;
  }
  start = core::calendar_to_gps(c);
}

void parse_origin(YamlMap map, core::Geodetic& origin) {
  double lat_deg = origin.lat_rad * core::kRadToDeg, lon_deg = origin.lon_rad * core::kRadToDeg;
  map.get("lat_deg", lat_deg);
  map.get("lon_deg", lon_deg);
  map.get("height_m", origin.height_m);
  if (!(std::abs(lat_deg) <= 80.0)) map.fail("lat_deg", "must be within [-80, 80]");
  if (!(std::abs(lon_deg) <= 180.0)) map.fail("lon_deg", "must be within [-180, 180]");
  origin.lat_rad = lat_deg * core::kDegToRad;
  origin.lon_rad = lon_deg * core::kDegToRad;
  map.reject_unknown_keys();
}

void parse_constellation(YamlMap map, sim::ConstellationOptions& o, const std::string& file) {
  std::vector<std::string> systems = o.letters();
  map.get("systems", systems);
  std::string bad;
  if (!o.set_from_letters(systems, &bad)) map.fail("systems", "has '" + bad + "'; allowed: G, R, E, C");
  map.get("nav_file", o.nav_file);
  o.nav_file = resolve(o.nav_file, file);
  map.get("gps_satellites", o.gps_satellites);
  map.get("glonass_satellites", o.glonass_satellites);
  map.get("galileo_satellites", o.galileo_satellites);
  map.get("beidou_satellites", o.beidou_satellites);
  parse_signals(map, "gps_signals", o.gps_signals);
  parse_signals(map, "glonass_signals", o.glonass_signals);
  parse_signals(map, "galileo_signals", o.galileo_signals);
  parse_signals(map, "beidou_signals", o.beidou_signals);
  map.reject_unknown_keys();
}

void parse_city(YamlMap map, sim::CityOptions& o) {
  map.get("buildings", o.buildings);
  map.get("grid_azimuth_deg", o.grid_azimuth_deg);
  map.get("street_width_m", o.street_width_m);
  map.get("block_length_m", o.block_length_m);
  map.get("block_width_m", o.block_width_m);
  map.get("lot_width_min_m", o.lot_width_min_m);
  map.get("lot_width_max_m", o.lot_width_max_m);
  map.get("height_mean_m", o.height_mean_m);
  map.get("height_sigma_m", o.height_sigma_m);
  map.get("height_min_m", o.height_min_m);
  map.get("height_max_m", o.height_max_m);
  map.get("gap_probability", o.gap_probability);
  map.get("margin_m", o.margin_m);
  std::vector<double> blocks(o.blocks.begin(), o.blocks.end());
  map.get("blocks", blocks);
  o.blocks.clear();
  for (const double b : blocks) {
    if (b != std::floor(b) || std::abs(b) > 1e6) {
      map.fail("blocks", "must be [nx, ny], whole numbers of blocks");
      break;
    }
    o.blocks.push_back(static_cast<int>(b));
  }
  map.reject_unknown_keys();
}

void parse_trees(YamlMap map, sim::TreeOptions& o) {
  map.get("spacing_m", o.spacing_m);
  map.get("presence_probability", o.presence_probability);
  map.get("crown_radius_m", o.crown_radius_m);
  map.get("crown_bottom_m", o.crown_bottom_m);
  map.get("crown_top_m", o.crown_top_m);
  map.get("attenuation_db_per_m", o.attenuation_db_per_m);
  map.get("facade_offset_m", o.facade_offset_m);
  map.reject_unknown_keys();
}

void parse_route(YamlMap map, sim::RouteOptions& o) {
  map.get("speed_mps", o.speed_mps);
  map.get("antenna_height_m", o.antenna_height_m);
  map.get("sidewalk_offset_m", o.sidewalk_offset_m);
  map.get("turn_probability", o.turn_probability);
  map.get("turn_radius_m", o.turn_radius_m);
  map.get("head_bob_m", o.head_bob_m);
  map.get("step_frequency_hz", o.step_frequency_hz);
  std::vector<std::vector<double>> points;
  for (const Eigen::Vector2d& w : o.waypoints_N_m) points.push_back({w.x(), w.y()});
  map.get("waypoints_m", points);
  o.waypoints_N_m.clear();
  for (const auto& p : points) {
    if (p.size() != 2) {
      map.fail("waypoints_m", "must be a list of [east, north] pairs (m)");
      break;
    }
    o.waypoints_N_m.emplace_back(p[0], p[1]);
  }
  map.reject_unknown_keys();
}

void parse_base(YamlMap map, sim::BaseOptions& o) {
  map.get("distance_m", o.distance_m);
  map.get("azimuth_deg", o.azimuth_deg);
  map.get("height_m", o.height_m);
  map.get("rate_hz", o.rate_hz);
  map.reject_unknown_keys();
}

void parse_receiver(YamlMap map, sim::ReceiverOptions& o) {
  map.get("cn0_zenith_dbhz", o.cn0_zenith_dbhz);
  map.get("cn0_horizon_dbhz", o.cn0_horizon_dbhz);
  map.get("band2_cn0_offset_db", o.band2_cn0_offset_db);
  map.get("cn0_noise_db", o.cn0_noise_db);
  map.get("cn0_reference_dbhz", o.cn0_reference_dbhz);
  map.get("code_sigma_m", o.code_sigma_m);
  map.get("phase_sigma_m", o.phase_sigma_m);
  map.get("doppler_sigma_hz", o.doppler_sigma_hz);
  map.get("track_threshold_dbhz", o.track_threshold_dbhz);
  map.get("acquire_threshold_dbhz", o.acquire_threshold_dbhz);
  map.get("reacquisition_s", o.reacquisition_s);
  map.get("slip_rate_hz", o.slip_rate_hz);
  map.get("path_change_slip_probability", o.path_change_slip_probability);
  map.get("correlator_spacing_chips", o.correlator_spacing_chips);
  map.get("clock_offset_max_s", o.clock_offset_max_s);
  map.get("clock_drift_max_sps", o.clock_drift_max_sps);
  map.get("clock_drift_noise", o.clock_drift_noise);
  map.get("elevation_cutoff_deg", o.elevation_cutoff_deg);
  map.reject_unknown_keys();
}

void parse_reflections(YamlMap map, sim::ReflectionOptions& o) {
  map.get("multipath", o.multipath);
  map.get("nlos", o.nlos);
  map.get("wall_loss_db", o.wall_loss_db);
  map.get("nlos_extra_loss_db", o.nlos_extra_loss_db);
  map.get("ground_loss_db", o.ground_loss_db);
  map.get("max_wall_distance_m", o.max_wall_distance_m);
  map.reject_unknown_keys();
}

void parse_atmosphere(YamlMap map, sim::AtmosphereOptions& o) {
  map.get("vtec_tecu", o.vtec_tecu);
  std::vector<double> g = {o.gradient_tecu_per_100km.x(), o.gradient_tecu_per_100km.y()};
  map.get("gradient_tecu_per_100km", g);
  if (g.size() == 2) {
    o.gradient_tecu_per_100km = Eigen::Vector2d(g[0], g[1]);
  } else {
    map.fail("gradient_tecu_per_100km", "must be [east, north] (TECU per 100 km)");
  }
  map.get("wave_amplitude_tecu", o.wave_amplitude_tecu);
  map.get("wave_count", o.wave_count);
  map.get("wave_length_km", o.wave_length_km);
  map.get("wave_period_s", o.wave_period_s);
  map.get("shell_height_km", o.shell_height_km);
  map.get("zwd_residual_m", o.zwd_residual_m);
  map.get("zwd_difference_m", o.zwd_difference_m);
  map.get("zwd_variation_m", o.zwd_variation_m);
  map.reject_unknown_keys();
}

void parse_orbit_errors(YamlMap map, sim::OrbitErrorOptions& o) {
  map.get("radial_m", o.radial_m);
  map.get("along_m", o.along_m);
  map.get("cross_m", o.cross_m);
  map.get("clock_m", o.clock_m);
  map.reject_unknown_keys();
}

void parse_vio(YamlMap map, sim::VioOptions& o) {
  map.get("enabled", o.enabled);
  parse_vector3(map, "t_IA_m", o.t_IA_m);
  map.get("odometry_yaw_deg", o.odometry_yaw_deg);
  map.get("rate_hz", o.rate_hz);
  map.get("position_drift_fraction", o.position_drift_fraction);
  map.get("yaw_drift_deg_per_km", o.yaw_drift_deg_per_km);
  map.get("tilt_drift_deg_per_km", o.tilt_drift_deg_per_km);
  map.get("device_clock_offset_s", o.device_clock_offset_s);
  map.get("device_clock_drift_ppm", o.device_clock_drift_ppm);
  map.get("timesync_jitter_s", o.timesync_jitter_s);
  map.reject_unknown_keys();
}

/// Line of the key at a dotted path ("city.street_width_m") in `root`: the deepest key present, 0 if none.
int line_of_path(const YAML::Node& root, const std::string& path) {
  YAML::Node node = root;
  int line = 0;
  std::string rest = path;
  while (!rest.empty() && node && node.IsMap()) {
    const std::size_t dot = rest.find('.');
    std::string key = rest.substr(0, dot);
    const std::size_t bracket = key.find('[');
    if (bracket != std::string::npos) key.resize(bracket);
    rest = dot == std::string::npos ? "" : rest.substr(dot + 1);
    bool found = false;
    for (const auto& item : node) {
      if (item.first.Scalar() == key) {
        line = item.first.Mark().line + 1;
        node = item.second;
        found = true;
        break;
      }
    }
    if (!found) break;
  }
  return line;
}

// ---------------------------------------------------------------------------------------------------------------
// Printing.

/// Shortest decimal text that reads back as the same double.
std::string number(double v) {
  char buffer[40];
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(buffer, sizeof buffer, "%.*g", precision, v);
    if (std::strtod(buffer, nullptr) == v) break;
  }
  std::string s = buffer;
  return s;
}

class Writer {
 public:
  void section(const std::string& name) { out_ << name << ":\n"; }
  void key(const std::string& name, const std::string& value, int indent = 2) {
    out_ << std::string(static_cast<std::size_t>(indent), ' ') << name << ": " << value << "\n";
  }
  void key(const std::string& name, double value, int indent = 2) { key(name, number(value), indent); }
  void key(const std::string& name, int value, int indent = 2) { key(name, std::to_string(value), indent); }
  void flag(const std::string& name, bool value, int indent = 2) { key(name, value ? "true" : "false", indent); }
  [[nodiscard]] std::string text() const { return out_.str(); }

 private:
  std::ostringstream out_;
};

std::string list(const std::vector<std::string>& items) {
  std::string s = "[";
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) s += ", ";
    s += items[i];
  }
  return s + "]";
}

std::string signal_list(const std::vector<core::SignalCode>& signals) {
  std::vector<std::string> items;
  items.reserve(signals.size());
  for (const core::SignalCode s : signals) items.push_back(s.to_string());
  return list(items);
}

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

void write_receiver(Writer& w, const std::string& name, const sim::ReceiverOptions& o) {
  w.section(name);
  w.key("cn0_zenith_dbhz", o.cn0_zenith_dbhz);
  w.key("cn0_horizon_dbhz", o.cn0_horizon_dbhz);
  w.key("band2_cn0_offset_db", o.band2_cn0_offset_db);
  w.key("cn0_noise_db", o.cn0_noise_db);
  w.key("cn0_reference_dbhz", o.cn0_reference_dbhz);
  w.key("code_sigma_m", o.code_sigma_m);
  w.key("phase_sigma_m", o.phase_sigma_m);
  w.key("doppler_sigma_hz", o.doppler_sigma_hz);
  w.key("track_threshold_dbhz", o.track_threshold_dbhz);
  w.key("acquire_threshold_dbhz", o.acquire_threshold_dbhz);
  w.key("reacquisition_s", o.reacquisition_s);
  w.key("slip_rate_hz", o.slip_rate_hz);
  w.key("path_change_slip_probability", o.path_change_slip_probability);
  w.key("correlator_spacing_chips", o.correlator_spacing_chips);
  w.key("clock_offset_max_s", o.clock_offset_max_s);
  w.key("clock_drift_max_sps", o.clock_drift_max_sps);
  w.key("clock_drift_noise", o.clock_drift_noise);
  w.key("elevation_cutoff_deg", o.elevation_cutoff_deg);
}

void write_scenario_body(Writer& w, const Scenario& s) {
  w.key("name", quoted(s.name), 0);
  w.key("seed", std::to_string(s.seed), 0);
  const core::CalendarTime c = core::gps_to_calendar(s.start);
  char start[40];
  std::snprintf(start, sizeof start, "\"%04d-%02d-%02d %02d:%02d:%02d\"", c.year, c.month, c.day, c.hour, c.minute,
                static_cast<int>(std::lround(c.second)));
  w.key("start", start, 0);
  w.key("duration_s", s.duration_s, 0);
  w.key("rover_rate_hz", s.rover_rate_hz, 0);
  w.section("origin");
  w.key("lat_deg", s.origin.lat_rad * core::kRadToDeg);
  w.key("lon_deg", s.origin.lon_rad * core::kRadToDeg);
  w.key("height_m", s.origin.height_m);
  const sim::ConstellationOptions& k = s.constellation;
  w.section("constellation");
  w.key("systems", list(k.letters()));
  w.key("nav_file", quoted(k.nav_file));
  w.key("gps_satellites", k.gps_satellites);
  w.key("glonass_satellites", k.glonass_satellites);
  w.key("galileo_satellites", k.galileo_satellites);
  w.key("beidou_satellites", k.beidou_satellites);
  w.key("gps_signals", signal_list(k.gps_signals));
  w.key("glonass_signals", signal_list(k.glonass_signals));
  w.key("galileo_signals", signal_list(k.galileo_signals));
  w.key("beidou_signals", signal_list(k.beidou_signals));
  const sim::CityOptions& city = s.city;
  w.section("city");
  w.flag("buildings", city.buildings);
  w.key("grid_azimuth_deg", city.grid_azimuth_deg);
  w.key("street_width_m", city.street_width_m);
  w.key("block_length_m", city.block_length_m);
  w.key("block_width_m", city.block_width_m);
  w.key("lot_width_min_m", city.lot_width_min_m);
  w.key("lot_width_max_m", city.lot_width_max_m);
  w.key("height_mean_m", city.height_mean_m);
  w.key("height_sigma_m", city.height_sigma_m);
  w.key("height_min_m", city.height_min_m);
  w.key("height_max_m", city.height_max_m);
  w.key("gap_probability", city.gap_probability);
  w.key("margin_m", city.margin_m);
  std::vector<std::string> blocks;
  for (const int b : city.blocks) blocks.push_back(std::to_string(b));
  w.key("blocks", list(blocks));
  const sim::TreeOptions& t = s.trees;
  w.section("trees");
  w.key("spacing_m", t.spacing_m);
  w.key("presence_probability", t.presence_probability);
  w.key("crown_radius_m", t.crown_radius_m);
  w.key("crown_bottom_m", t.crown_bottom_m);
  w.key("crown_top_m", t.crown_top_m);
  w.key("attenuation_db_per_m", t.attenuation_db_per_m);
  w.key("facade_offset_m", t.facade_offset_m);
  const sim::RouteOptions& r = s.route;
  w.section("route");
  w.key("speed_mps", r.speed_mps);
  w.key("antenna_height_m", r.antenna_height_m);
  w.key("sidewalk_offset_m", r.sidewalk_offset_m);
  w.key("turn_probability", r.turn_probability);
  w.key("turn_radius_m", r.turn_radius_m);
  w.key("head_bob_m", r.head_bob_m);
  w.key("step_frequency_hz", r.step_frequency_hz);
  std::vector<std::string> points;
  for (const Eigen::Vector2d& p : r.waypoints_N_m)
    points.push_back(std::string("[") + number(p.x()) + ", " + number(p.y()) + "]");
  w.key("waypoints_m", list(points));
  w.section("base");
  w.key("distance_m", s.base.distance_m);
  w.key("azimuth_deg", s.base.azimuth_deg);
  w.key("height_m", s.base.height_m);
  w.key("rate_hz", s.base.rate_hz);
  write_receiver(w, "rover_receiver", s.rover_receiver);
  write_receiver(w, "base_receiver", s.base_receiver);
  w.section("reflections");
  w.flag("multipath", s.reflections.multipath);
  w.flag("nlos", s.reflections.nlos);
  w.key("wall_loss_db", s.reflections.wall_loss_db);
  w.key("nlos_extra_loss_db", s.reflections.nlos_extra_loss_db);
  w.key("ground_loss_db", s.reflections.ground_loss_db);
  w.key("max_wall_distance_m", s.reflections.max_wall_distance_m);
  const sim::AtmosphereOptions& a = s.atmosphere;
  w.section("atmosphere");
  w.key("vtec_tecu", a.vtec_tecu);
  w.key("gradient_tecu_per_100km",
        std::string("[") + number(a.gradient_tecu_per_100km.x()) + ", " + number(a.gradient_tecu_per_100km.y()) + "]");
  w.key("wave_amplitude_tecu", a.wave_amplitude_tecu);
  w.key("wave_count", a.wave_count);
  w.key("wave_length_km", a.wave_length_km);
  w.key("wave_period_s", a.wave_period_s);
  w.key("shell_height_km", a.shell_height_km);
  w.key("zwd_residual_m", a.zwd_residual_m);
  w.key("zwd_difference_m", a.zwd_difference_m);
  w.key("zwd_variation_m", a.zwd_variation_m);
  w.section("orbit_errors");
  w.key("radial_m", s.orbit_errors.radial_m);
  w.key("along_m", s.orbit_errors.along_m);
  w.key("cross_m", s.orbit_errors.cross_m);
  w.key("clock_m", s.orbit_errors.clock_m);
  w.section("vio");
  w.flag("enabled", s.vio.enabled);
  const Eigen::Vector3d& l = s.vio.t_IA_m;
  w.key("t_IA_m", std::string("[") + number(l.x()) + ", " + number(l.y()) + ", " + number(l.z()) + "]");
  w.key("odometry_yaw_deg", s.vio.odometry_yaw_deg);
  w.key("rate_hz", s.vio.rate_hz);
  w.key("position_drift_fraction", s.vio.position_drift_fraction);
  w.key("yaw_drift_deg_per_km", s.vio.yaw_drift_deg_per_km);
  w.key("tilt_drift_deg_per_km", s.vio.tilt_drift_deg_per_km);
  w.key("device_clock_offset_s", s.vio.device_clock_offset_s);
  w.key("device_clock_drift_ppm", s.vio.device_clock_drift_ppm);
  w.key("timesync_jitter_s", s.vio.timesync_jitter_s);
}

std::vector<fs::path> scenario_folders() {
  std::vector<fs::path> folders;
  for (const std::string& config : shipped_config_folders()) folders.push_back(fs::path(config) / "scenarios");
  return folders;
}

}  // namespace

Result<Scenario> parse_scenario(const YAML::Node& node, const std::string& file) {
  Scenario s;
  s.source_file = file;
  YamlMap top(node, file);
  top.get("name", s.name);
  std::string seed = std::to_string(s.seed);
  top.get("seed", seed);
  try {
    std::size_t used = 0;
    s.seed = std::stoull(seed, &used);
    if (used != seed.size() || seed.front() == '-') throw std::invalid_argument("seed");
  } catch (const std::exception&) {
    top.fail("seed", "must be a whole number >= 0, not '" + seed + "'");
  }
  parse_start(top, s.start);
  top.get("duration_s", s.duration_s);
  top.get("rover_rate_hz", s.rover_rate_hz);
  parse_origin(top.sub("origin"), s.origin);
  parse_constellation(top.sub("constellation"), s.constellation, file);
  parse_city(top.sub("city"), s.city);
  parse_trees(top.sub("trees"), s.trees);
  parse_route(top.sub("route"), s.route);
  parse_base(top.sub("base"), s.base);
  parse_receiver(top.sub("rover_receiver"), s.rover_receiver);
  parse_receiver(top.sub("base_receiver"), s.base_receiver);
  parse_reflections(top.sub("reflections"), s.reflections);
  parse_atmosphere(top.sub("atmosphere"), s.atmosphere);
  parse_orbit_errors(top.sub("orbit_errors"), s.orbit_errors);
  parse_vio(top.sub("vio"), s.vio);
  (void)top.sub("truth");  // written by canyon simulate; ignored
  top.reject_unknown_keys();
  if (Status st = top.status(); !st) return st.error();
  if (const std::string e = s.validate(); !e.empty()) {
    std::string key = e.substr(0, e.find(' '));
    if (!key.empty() && key.back() == ':') key.pop_back();
    return Error{e, file, line_of_path(node, key)};
  }
  return s;
}

Result<Scenario> load_scenario(const std::string& path) {
  auto node = load_yaml_file(path);
  if (!node) return node.error();
  return parse_scenario(*node, path);
}

std::string scenario_to_yaml(const Scenario& scenario, const std::string& truth_yaml) {
  Writer w;
  write_scenario_body(w, scenario);
  std::string text = w.text();
  if (!truth_yaml.empty()) text += "truth:\n" + truth_yaml;
  return text;
}

Result<std::string> find_scenario_file(const std::string& name_or_file) {
  const fs::path given(name_or_file);
  const std::string ext = given.extension().string();
  if (ext == ".yaml" || ext == ".yml" || name_or_file.find('/') != std::string::npos) {
    if (!fs::exists(given)) return Error{"scenario file not found", name_or_file, 0};
    return name_or_file;
  }
  for (const fs::path& folder : scenario_folders()) {
    const fs::path candidate = folder / (name_or_file + ".yaml");
    if (fs::exists(candidate)) return candidate.lexically_normal().string();
  }
  std::string names;
  for (const std::string& n : shipped_scenarios()) {
    if (!names.empty()) names += ", ";
    names += n;
  }
  return Error{"no scenario named '" + name_or_file + "' (shipped: " + (names.empty() ? "none found" : names) +
               "; or give a FILE.yaml)"};
}

std::vector<std::string> shipped_scenarios() {
  std::set<std::string> names;
  for (const fs::path& folder : scenario_folders()) {
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(folder, ec)) {
      if (entry.path().extension() == ".yaml") names.insert(entry.path().stem().string());
    }
  }
  return {names.begin(), names.end()};
}

}  // namespace canyon::config
