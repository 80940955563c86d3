// Scenario files: their keys described once (config/scenarios/*.yaml show each with its unit and default), parsed,
// validated with line numbers, printed and compared from that description (see scenario_config.hpp).

#include "canyon/config/scenario_config.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <stdexcept>

#include "canyon/config/shipped_config.hpp"
#include "canyon/core/constants.hpp"

namespace canyon::config {
namespace {

namespace fs = std::filesystem;
using sim::Scenario;

// ---------------------------------------------------------------------------------------------------------------
// Codecs of the scenario's own forms.

struct QuotedText : Same<std::string> {
  static constexpr bool kQuoted = true;
};

struct QuotedPath : Path {
  static constexpr bool kQuoted = true;
};

/// seed: a whole number >= 0 (std::uint64_t, beyond what YAML integers hold).
struct Seed {
  using Yaml = std::string;
  [[nodiscard]] std::string to(std::uint64_t seed) const { return std::to_string(seed); }
  void from(const std::string& text, std::uint64_t& seed, Reading& reading) const {
    try {
      std::size_t used = 0;
      seed = std::stoull(text, &used);
      if (used != text.size() || text.front() == '-') throw std::invalid_argument("seed");
    } catch (const std::exception&) {
      reading.fail("must be a whole number >= 0, not '" + text + "'");
    }
  }
};

/// start: a GPST calendar time "YYYY-MM-DD hh:mm:ss", printed in quotes.
struct StartTime {
  using Yaml = std::string;
  [[nodiscard]] std::string to(const core::GpsTime& start) const {
    const core::CalendarTime c = core::gps_to_calendar(start);
    char text[32];
    std::snprintf(text, sizeof text, "%04d-%02d-%02d %02d:%02d:%02d", c.year, c.month, c.day, c.hour, c.minute,
                  static_cast<int>(c.second));
    return text;
  }
  void print(const core::GpsTime& start, Printer& printer) const {
    const core::CalendarTime c = core::gps_to_calendar(start);
    char text[40];
    std::snprintf(text, sizeof text, "%04d-%02d-%02d %02d:%02d:%02d", c.year, c.month, c.day, c.hour, c.minute,
                  static_cast<int>(std::lround(c.second)));
    printer.value(std::string(text), true);
  }
  void from(const std::string& value, core::GpsTime& start, Reading& reading) const {
    core::CalendarTime c;
    char tail = 0;
    if (std::sscanf(value.c_str(), "%d-%d-%d %d:%d:%lf%c", &c.year, &c.month, &c.day, &c.hour, &c.minute, &c.second,
                    &tail) != 6 ||
        !core::is_valid(c) || c.year < 1990 || c.year > 2100) {
      reading.fail("must be a GPST calendar time \"YYYY-MM-DD hh:mm:ss\", not '" + value + "'");
      return;
    }
    start = core::calendar_to_gps(c);
  }
};

/// origin.lat_deg, lon_deg: radians in the struct, degrees in YAML, within +-limit.
struct DegreesWithin {
  using Yaml = double;
  double limit = 90.0;
  std::string rule;
  [[nodiscard]] double to(double rad) const { return rad * core::kRadToDeg; }
  void from(double deg, double& rad, Reading& reading) const {
    if (!(std::abs(deg) <= limit)) reading.fail(rule);
    rad = deg * core::kDegToRad;
  }
};

/// RINEX band and attribute of each signal ([1C, 2L]).
struct Signals {
  using Yaml = std::vector<std::string>;
  [[nodiscard]] Yaml to(const std::vector<core::SignalCode>& signals) const {
    Yaml texts;
    texts.reserve(signals.size());
    for (const core::SignalCode s : signals) texts.push_back(s.to_string());
    return texts;
  }
  void from(const Yaml& texts, std::vector<core::SignalCode>& out, Reading& reading) const {
    std::vector<core::SignalCode> signals;
    for (const std::string& t : texts) {
      const auto s = core::parse_signal(t);
      if (!s) {
        reading.fail("has '" + t + "', not a RINEX band and attribute (e.g. 1C, 2L, 7Q)");
        return;
      }
      signals.push_back(*s);
    }
    out = signals;
  }
};

/// city.blocks: [nx, ny], whole numbers.
struct Blocks {
  using Yaml = std::vector<double>;
  [[nodiscard]] Yaml to(const std::vector<int>& blocks) const { return {blocks.begin(), blocks.end()}; }
  void from(const Yaml& numbers, std::vector<int>& blocks, Reading& reading) const {
    blocks.clear();
    for (const double b : numbers) {
      if (b != std::floor(b) || std::abs(b) > 1e6) {
        reading.fail("must be [nx, ny], whole numbers of blocks");
        break;
      }
      blocks.push_back(static_cast<int>(b));
    }
  }
};

/// route.waypoints_m: [[east, north], ...].
struct Waypoints {
  using Yaml = std::vector<std::vector<double>>;
  [[nodiscard]] Yaml to(const std::vector<Eigen::Vector2d>& points) const {
    Yaml rows;
    for (const Eigen::Vector2d& w : points) rows.push_back({w.x(), w.y()});
    return rows;
  }
  void from(const Yaml& rows, std::vector<Eigen::Vector2d>& points, Reading& reading) const {
    points.clear();
    for (const auto& p : rows) {
      if (p.size() != 2) {
        reading.fail("must be a list of [east, north] pairs (m)");
        break;
      }
      points.emplace_back(p[0], p[1]);
    }
  }
};

/// atmosphere.gradient_tecu_per_100km: [east, north].
struct EastNorth {
  using Yaml = std::vector<double>;
  [[nodiscard]] Yaml to(const Eigen::Vector2d& v) const { return {v.x(), v.y()}; }
  void from(const Yaml& value, Eigen::Vector2d& v, Reading& reading) const {
    if (value.size() == 2) {
      v = Eigen::Vector2d(value[0], value[1]);
    } else {
      reading.fail("must be [east, north] (TECU per 100 km)");
    }
  }
};

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

std::vector<fs::path> scenario_folders() {
  std::vector<fs::path> folders;
  for (const std::string& config : shipped_config_folders()) folders.push_back(fs::path(config) / "scenarios");
  return folders;
}

// ---------------------------------------------------------------------------------------------------------------
// The keys, section by section.

const Table<core::Geodetic>& origin_table() {
  using G = core::Geodetic;
  static const Table<G> table{
      {"lat_deg", "deg", "latitude", at(&G::lat_rad), DegreesWithin{80.0, "must be within [-80, 80]"}},
      {"lon_deg", "deg", "longitude", at(&G::lon_rad), DegreesWithin{180.0, "must be within [-180, 180]"}},
      {"height_m", "m", "ground ellipsoidal height", at(&G::height_m)},
  };
  return table;
}

const Table<sim::ConstellationOptions>& constellation_table() {
  using C = sim::ConstellationOptions;
  static const Table<C> table{
      {"systems", "", "G GPS, R GLONASS, E Galileo, C BeiDou (MEO)", whole, Systems{"G, R, E, C"}},
      {"nav_file", "", "RINEX navigation file to take the orbits from; empty: the built-in constellation",
       at(&C::nav_file), QuotedPath{}},
      {"gps_satellites", "", "built-in: 24 nominal slots + spares, 24..32", at(&C::gps_satellites)},
      {"glonass_satellites", "", "built-in, 1..24", at(&C::glonass_satellites)},
      {"galileo_satellites", "", "built-in, 1..24", at(&C::galileo_satellites)},
      {"beidou_satellites", "", "built-in MEO, 1..24", at(&C::beidou_satellites)},
      {"gps_signals", "", "RINEX band+attribute tracked, first the L1-band one", at(&C::gps_signals), Signals{}},
      {"glonass_signals", "", "RINEX band+attribute tracked", at(&C::glonass_signals), Signals{}},
      {"galileo_signals", "", "RINEX band+attribute tracked", at(&C::galileo_signals), Signals{}},
      {"beidou_signals", "", "RINEX band+attribute tracked", at(&C::beidou_signals), Signals{}},
  };
  return table;
}

const Table<sim::CityOptions>& city_table() {
  using C = sim::CityOptions;
  static const Table<C> table{
      {"buildings", "", "false: open area, the grid only guides the walk", at(&C::buildings)},
      {"grid_azimuth_deg", "deg", "azimuth of the avenues, clockwise from north", at(&C::grid_azimuth_deg)},
      {"street_width_m", "m", "facade to facade, > 0", at(&C::street_width_m)},
      {"block_length_m", "m", "block size along the avenues, > 0", at(&C::block_length_m)},
      {"block_width_m", "m", "block size across the avenues, > 0", at(&C::block_width_m)},
      {"lot_width_min_m", "m", "narrowest building frontage", at(&C::lot_width_min_m)},
      {"lot_width_max_m", "m", "widest building frontage", at(&C::lot_width_max_m)},
      {"height_mean_m", "m", "mean building height before clipping", at(&C::height_mean_m)},
      {"height_sigma_m", "m", "standard deviation of building heights, >= 0", at(&C::height_sigma_m)},
      {"height_min_m", "m", "lowest building, >= 0", at(&C::height_min_m)},
      {"height_max_m", "m", "tallest building, >= height_min_m", at(&C::height_max_m)},
      {"gap_probability", "", "probability that a lot is empty (plaza, parking), 0..1", at(&C::gap_probability)},
      {"margin_m", "m", "buildings at least this far around the route", at(&C::margin_m)},
      {"start_square_m", "m", "side of an open square at the origin, where a generated walk starts; 0: none",
       at(&C::start_square_m)},
      {"blocks", "", "[nx, ny]: a city of nx by ny blocks centred on the origin; []: sized to the route",
       at(&C::blocks), Blocks{}},
  };
  return table;
}

const Table<sim::TreeOptions>& trees_table() {
  using T = sim::TreeOptions;
  static const Table<T> table{
      {"spacing_m", "m", "distance between trees along a street; 0: no trees", at(&T::spacing_m)},
      {"presence_probability", "", "probability that a tree stands at each spot, 0..1", at(&T::presence_probability)},
      {"crown_radius_m", "m", "crown radius", at(&T::crown_radius_m)},
      {"crown_bottom_m", "m", "height of the lowest leaves", at(&T::crown_bottom_m)},
      {"crown_top_m", "m", "tree height", at(&T::crown_top_m)},
      {"attenuation_db_per_m", "dB/m", "signal loss per metre of crown crossed", at(&T::attenuation_db_per_m)},
      {"facade_offset_m", "m", "tree line distance from the facades", at(&T::facade_offset_m)},
  };
  return table;
}

const Table<sim::RouteOptions>& route_table() {
  using R = sim::RouteOptions;
  static const Table<R> table{
      {"speed_mps", "m/s", "walking speed", at(&R::speed_mps)},
      {"antenna_height_m", "m", "antenna above the ground", at(&R::antenna_height_m)},
      {"sidewalk_offset_m", "m", "walking line distance from the facades, < street_width_m / 2",
       at(&R::sidewalk_offset_m)},
      {"turn_probability", "", "probability of turning at an intersection, 0..1", at(&R::turn_probability)},
      {"turn_radius_m", "m", "radius of the walk at corners", at(&R::turn_radius_m)},
      {"head_bob_m", "m", "vertical head motion amplitude", at(&R::head_bob_m)},
      {"step_frequency_hz", "Hz", "step frequency", at(&R::step_frequency_hz)},
      {"waypoints_m", "m",
       "explicit route [[east, north], ...] from the origin, walked back and forth; []: a random walk",
       at(&R::waypoints_N_m), Waypoints{}},
  };
  return table;
}

const Table<sim::BaseOptions>& base_station_table() {
  using B = sim::BaseOptions;
  static const Table<B> table{
      {"distance_m", "m", "from the city origin", at(&B::distance_m)},
      {"azimuth_deg", "deg", "direction from the origin, clockwise from north", at(&B::azimuth_deg)},
      {"height_m", "m", "antenna ellipsoidal height", at(&B::height_m)},
      {"rate_hz", "Hz", "observation rate", at(&B::rate_hz)},
  };
  return table;
}

const Table<sim::ReceiverOptions>& receiver_table() {
  using R = sim::ReceiverOptions;
  static const Table<R> table{
      {"cn0_zenith_dbhz", "dB-Hz", "line-of-sight C/N0 at 90 deg elevation, first band", at(&R::cn0_zenith_dbhz)},
      {"cn0_horizon_dbhz", "dB-Hz", "... at 0 deg; in between (1 - sin el)^2", at(&R::cn0_horizon_dbhz)},
      {"band2_cn0_offset_db", "dB", "second band relative to the first", at(&R::band2_cn0_offset_db)},
      {"cn0_noise_db", "dB", "noise of the reported C/N0", at(&R::cn0_noise_db)},
      {"cn0_reference_dbhz", "dB-Hz", "C/N0 at which the three sigmas below hold", at(&R::cn0_reference_dbhz)},
      {"code_sigma_m", "m", "pseudorange noise at the reference C/N0, x 10^((ref - C/N0) / 20)", at(&R::code_sigma_m)},
      {"phase_sigma_m", "m", "carrier-phase noise at the reference C/N0, same scaling", at(&R::phase_sigma_m)},
      {"doppler_sigma_hz", "Hz", "Doppler noise at the reference C/N0, same scaling", at(&R::doppler_sigma_hz)},
      {"track_threshold_dbhz", "dB-Hz", "weaker signals lose lock", at(&R::track_threshold_dbhz)},
      {"acquire_threshold_dbhz", "dB-Hz", "a lost signal must be this strong to be reacquired",
       at(&R::acquire_threshold_dbhz)},
      {"reacquisition_s", "s", "time a lost signal must be receivable before it is output again",
       at(&R::reacquisition_s)},
      {"slip_rate_hz", "1/s", "cycle slips at the tracking threshold, 10x fewer per 10 dB above", at(&R::slip_rate_hz)},
      {"path_change_slip_probability", "", "lock lost when the received path changes (direct <-> reflected)",
       at(&R::path_change_slip_probability)},
      {"correlator_spacing_chips", "chips", "early-late spacing of the code loop", at(&R::correlator_spacing_chips)},
      {"clock_offset_max_s", "s", "initial clock offset drawn in +-this", at(&R::clock_offset_max_s)},
      {"clock_drift_max_sps", "s/s", "initial clock drift drawn in +-this", at(&R::clock_drift_max_sps)},
      {"clock_drift_noise", "s/s per sqrt(s)", "clock drift random walk", at(&R::clock_drift_noise)},
      {"elevation_cutoff_deg", "deg", "no signal tracked below", at(&R::elevation_cutoff_deg)},
  };
  return table;
}

const Table<sim::ReflectionOptions>& reflections_table() {
  using R = sim::ReflectionOptions;
  static const Table<R> table{
      {"multipath", "", "line-of-sight signals also get wall and ground reflections", at(&R::multipath)},
      {"nlos", "", "a signal a building blocks is received by a wall reflection; false: not at all", at(&R::nlos)},
      {"wall_loss_db", "dB", "wall reflection power below the direct signal", at(&R::wall_loss_db)},
      {"nlos_extra_loss_db", "dB", "extra loss of a reflection received without the direct signal",
       at(&R::nlos_extra_loss_db)},
      {"nlos_loss_spread_db", "dB",
       "1-sigma spread of an NLOS signal's loss, drawn per satellite and wall (0: every NLOS signal exactly "
       "wall_loss_db + nlos_extra_loss_db down)",
       at(&R::nlos_loss_spread_db)},
      {"ground_loss_db", "dB", "ground reflection power below the direct signal", at(&R::ground_loss_db)},
      {"max_wall_distance_m", "m", "walls further from the antenna reflect nothing", at(&R::max_wall_distance_m)},
  };
  return table;
}

const Table<sim::AtmosphereOptions>& atmosphere_table() {
  using A = sim::AtmosphereOptions;
  static const Table<A> table{
      {"vtec_tecu", "TECU", "mean vertical TEC (1 TECU = 0.162 m on L1)", at(&A::vtec_tecu)},
      {"gradient_tecu_per_100km", "TECU per 100 km", "VTEC gradient [east, north]", at(&A::gradient_tecu_per_100km),
       EastNorth{}},
      {"wave_amplitude_tecu", "TECU", "travelling ionospheric disturbances: amplitude of each",
       at(&A::wave_amplitude_tecu)},
      {"wave_count", "", "number of disturbances", at(&A::wave_count)},
      {"wave_length_km", "km", "their mean wavelength", at(&A::wave_length_km)},
      {"wave_period_s", "s", "their mean period", at(&A::wave_period_s)},
      {"shell_height_km", "km", "thin ionospheric shell", at(&A::shell_height_km)},
      {"zwd_residual_m", "m", "rover zenith wet delay not in Saastamoinen's model", at(&A::zwd_residual_m)},
      {"zwd_difference_m", "m", "base minus rover residual zenith wet delay", at(&A::zwd_difference_m)},
      {"zwd_variation_m", "m", "slow variation of each residual", at(&A::zwd_variation_m)},
  };
  return table;
}

const Table<sim::OrbitErrorOptions>& orbit_errors_table() {
  using O = sim::OrbitErrorOptions;
  static const Table<O> table{
      {"radial_m", "m", "radial orbit error, 1 sigma", at(&O::radial_m)},
      {"along_m", "m", "along-track orbit error, 1 sigma", at(&O::along_m)},
      {"cross_m", "m", "cross-track orbit error, 1 sigma", at(&O::cross_m)},
      {"clock_m", "m", "c x satellite clock error, 1 sigma", at(&O::clock_m)},
  };
  return table;
}

const Table<sim::VioOptions>& vio_table() {
  using V = sim::VioOptions;
  static const Table<V> table{
      {"enabled", "", "write vio.csv and timesync.csv", at(&V::enabled)},
      {"t_IA_m", "m", "antenna position in the IMU frame (lever arm)", at(&V::t_IA_m), Vector3{}},
      {"odometry_yaw_deg", "deg", "yaw of the odometry frame from east, counter-clockwise", at(&V::odometry_yaw_deg)},
      {"rate_hz", "Hz", "VIO pose rate, device clock", at(&V::rate_hz)},
      {"position_drift_fraction", "", "1-sigma 3-D translation random walk after 1 km, per distance",
       at(&V::position_drift_fraction)},
      {"yaw_drift_deg_per_km", "deg", "1-sigma heading random walk after 1 km walked", at(&V::yaw_drift_deg_per_km)},
      {"tilt_drift_deg_per_km", "deg", "1-sigma roll/pitch random walk after 1 km walked",
       at(&V::tilt_drift_deg_per_km)},
      {"device_clock_offset_s", "s", "device clock reading at the start", at(&V::device_clock_offset_s)},
      {"device_clock_drift_ppm", "ppm", "device clock rate error", at(&V::device_clock_drift_ppm)},
      {"timesync_jitter_s", "s", "jitter of the built-in GPS time-sync pairs, 1 sigma", at(&V::timesync_jitter_s)},
      {"scale_error", "", "VIO translation scale error (0.005: every increment 0.5 % long), not in its covariance",
       at(&V::scale_error)},
      {"covariance_optimism", "",
       "the reported covariance is the drift model's over this squared (2: sigmas half the true ones)",
       at(&V::covariance_optimism)},
  };
  return table;
}

}  // namespace

const Table<sim::Scenario>& scenario_table() {
  static const Table<Scenario> table{
      {"name", "", "the scenario's name", at(&Scenario::name), QuotedText{}},
      {"seed", "", "random seed (integer >= 0); --seed overrides", at(&Scenario::seed), Seed{}},
      {"start", "", "first epoch, GPST calendar time \"YYYY-MM-DD hh:mm:ss\"", at(&Scenario::start), StartTime{}},
      {"duration_s", "s", "scenario length, 1..86400", at(&Scenario::duration_s)},
      {"rover_rate_hz", "Hz", "rover observation rate", at(&Scenario::rover_rate_hz)},
      {"origin", "city origin (the local ENU frame's)", at(&Scenario::origin), origin_table()},
      {"constellation", "satellites and signals", at(&Scenario::constellation), constellation_table()},
      {"city", "2.5-D street grid city generated around the route", at(&Scenario::city), city_table()},
      {"trees", "street trees: crowns as vertical cylinders along the sidewalks", at(&Scenario::trees), trees_table()},
      {"route", "the pedestrian with a head-worn antenna", at(&Scenario::route), route_table()},
      {"base", "static base station under open sky", at(&Scenario::base), base_station_table()},
      {"rover_receiver", "the rover's receiver", at(&Scenario::rover_receiver), receiver_table()},
      {"base_receiver", "the base's receiver (keys as rover_receiver)", at(&Scenario::base_receiver), receiver_table()},
      {"reflections", "at the rover (the base has none)", at(&Scenario::reflections), reflections_table()},
      {"atmosphere", "true delays; the base-rover differences grow with the baseline", at(&Scenario::atmosphere),
       atmosphere_table()},
      {"orbit_errors", "broadcast orbit and clock errors", at(&Scenario::orbit_errors), orbit_errors_table()},
      {"vio", "the device's visual-inertial odometry and clock", at(&Scenario::vio), vio_table()},
      ignored_section<Scenario>("truth"),
  };
  return table;
}

std::vector<KeyDescription> describe_scenario() {
  return describe_keys(scenario_table(), Scenario{}, Numbers::Shortest);
}

bool same_scenario(const sim::Scenario& a, const sim::Scenario& b) {
  return equal_keys(scenario_table(), a, b);
}

Result<Scenario> parse_scenario(const YAML::Node& node, const std::string& file) {
  Scenario s;
  s.source_file = file;
  YamlMap top(node, file);
  read_keys(scenario_table(), top, s);
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
  std::string text = yaml_text(scenario_table(), scenario, Numbers::Shortest);
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
