// Scenario parameters: ranges (see scenario.hpp).

#include "canyon/sim/scenario.hpp"

#include <cmath>
#include <sstream>

#include "canyon/sim/city.hpp"

namespace canyon::sim {
namespace {

bool finite(double v) {
  return std::isfinite(v);
}

/// Collects the first broken rule.
class Rules {
 public:
  /// `key` must satisfy `ok`; otherwise "<key> <rule>" (e.g. "city.street_width_m must be > 0, not -3").
  void require(bool ok, const std::string& key, const std::string& rule, double value) {
    if (!message_.empty() || ok) return;
    std::ostringstream os;
    os << key << " " << rule << ", not " << value;
    message_ = os.str();
  }
  void positive(double v, const std::string& key) { require(finite(v) && v > 0.0, key, "must be > 0", v); }
  void non_negative(double v, const std::string& key) { require(finite(v) && v >= 0.0, key, "must be >= 0", v); }
  void range(double v, double lo, double hi, const std::string& key) {
    std::ostringstream rule;
    rule << "must be in [" << lo << ", " << hi << "]";
    require(finite(v) && v >= lo && v <= hi, key, rule.str(), v);
  }
  void fail(const std::string& message) {
    if (message_.empty()) message_ = message;
  }
  [[nodiscard]] const std::string& message() const { return message_; }

 private:
  std::string message_;
};

void check_city(const CityOptions& c, Rules& r) {
  r.range(c.grid_azimuth_deg, -360.0, 360.0, "city.grid_azimuth_deg");
  r.positive(c.street_width_m, "city.street_width_m");
  r.positive(c.block_length_m, "city.block_length_m");
  r.positive(c.block_width_m, "city.block_width_m");
  r.positive(c.lot_width_min_m, "city.lot_width_min_m");
  r.require(finite(c.lot_width_max_m) && c.lot_width_max_m >= c.lot_width_min_m, "city.lot_width_max_m",
            "must be >= city.lot_width_min_m", c.lot_width_max_m);
  r.non_negative(c.height_min_m, "city.height_min_m");
  r.positive(c.height_max_m, "city.height_max_m");
  r.require(finite(c.height_max_m) && c.height_max_m >= c.height_min_m, "city.height_max_m",
            "must be >= city.height_min_m", c.height_max_m);
  r.range(c.height_mean_m, c.height_min_m, c.height_max_m, "city.height_mean_m");
  r.non_negative(c.height_sigma_m, "city.height_sigma_m");
  r.range(c.gap_probability, 0.0, 1.0, "city.gap_probability");
  r.non_negative(c.margin_m, "city.margin_m");
  r.non_negative(c.start_square_m, "city.start_square_m");
  r.require(c.blocks.empty() || c.blocks.size() == 2, "city.blocks", "must be [nx, ny]",
            static_cast<double>(c.blocks.size()));
  for (const int n : c.blocks) r.require(n >= 1 && n <= 1000, "city.blocks", "must be between 1 and 1000", n);
}

void check_trees(const TreeOptions& t, const CityOptions& c, Rules& r) {
  r.non_negative(t.spacing_m, "trees.spacing_m");
  r.range(t.presence_probability, 0.0, 1.0, "trees.presence_probability");
  r.positive(t.crown_radius_m, "trees.crown_radius_m");
  r.non_negative(t.crown_bottom_m, "trees.crown_bottom_m");
  r.require(finite(t.crown_top_m) && t.crown_top_m > t.crown_bottom_m, "trees.crown_top_m",
            "must be > trees.crown_bottom_m", t.crown_top_m);
  r.non_negative(t.attenuation_db_per_m, "trees.attenuation_db_per_m");
  r.range(t.facade_offset_m, 0.0, c.street_width_m / 2.0, "trees.facade_offset_m");
}

void check_route(const RouteOptions& o, const CityOptions& c, Rules& r) {
  r.range(o.speed_mps, 0.0, 50.0, "route.speed_mps");
  r.range(o.antenna_height_m, 0.0, 100.0, "route.antenna_height_m");
  r.require(finite(o.sidewalk_offset_m) && o.sidewalk_offset_m > 0.0 && o.sidewalk_offset_m < c.street_width_m / 2.0,
            "route.sidewalk_offset_m", "must be > 0 and less than half the street width", o.sidewalk_offset_m);
  r.range(o.turn_probability, 0.0, 1.0, "route.turn_probability");
  r.require(finite(o.turn_radius_m) && o.turn_radius_m >= 0.0 && o.turn_radius_m < c.block_width_m / 2.0,
            "route.turn_radius_m", "must be >= 0 and less than half a block", o.turn_radius_m);
  r.non_negative(o.head_bob_m, "route.head_bob_m");
  r.positive(o.step_frequency_hz, "route.step_frequency_hz");
  r.require(o.waypoints_N_m.empty() || o.waypoints_N_m.size() >= 2, "route.waypoints_m", "needs at least 2 points",
            static_cast<double>(o.waypoints_N_m.size()));
  for (const Eigen::Vector2d& w : o.waypoints_N_m) {
    r.require(w.allFinite(), "route.waypoints_m", "must be finite numbers", w.x());
  }
  if (c.blocks.size() != 2 || !r.message().empty()) return;
  // An explicit route must stay inside a city of explicit size.
  const StreetGrid grid = StreetGrid::from(c);
  const CityExtent extent = blocks_extent(c.blocks, grid);
  for (std::size_t k = 0; k < o.waypoints_N_m.size(); ++k) {
    const Eigen::Vector2d& w = o.waypoints_N_m[k];
    if (extent.contains_G(grid.to_G(w))) continue;
    std::ostringstream os;
    os << "route.waypoints_m[" << k << "] (east " << w.x() << " m, north " << w.y()
       << " m) is outside the city: city.blocks " << c.blocks[0] << " x " << c.blocks[1] << " of " << grid.pitch_x_m
       << " m x " << grid.pitch_y_m << " m (block and street) centred on the origin";
    r.fail(os.str());
    return;
  }
}

void check_receiver(const ReceiverOptions& o, const std::string& p, Rules& r) {
  r.range(o.cn0_zenith_dbhz, 0.0, 70.0, p + ".cn0_zenith_dbhz");
  r.range(o.cn0_horizon_dbhz, 0.0, o.cn0_zenith_dbhz, p + ".cn0_horizon_dbhz");
  r.range(o.band2_cn0_offset_db, -30.0, 30.0, p + ".band2_cn0_offset_db");
  r.non_negative(o.cn0_noise_db, p + ".cn0_noise_db");
  r.range(o.cn0_reference_dbhz, 10.0, 70.0, p + ".cn0_reference_dbhz");
  r.non_negative(o.code_sigma_m, p + ".code_sigma_m");
  r.non_negative(o.phase_sigma_m, p + ".phase_sigma_m");
  r.non_negative(o.doppler_sigma_hz, p + ".doppler_sigma_hz");
  r.range(o.track_threshold_dbhz, 0.0, 70.0, p + ".track_threshold_dbhz");
  r.range(o.acquire_threshold_dbhz, o.track_threshold_dbhz, 70.0, p + ".acquire_threshold_dbhz");
  r.non_negative(o.reacquisition_s, p + ".reacquisition_s");
  r.non_negative(o.slip_rate_hz, p + ".slip_rate_hz");
  r.range(o.path_change_slip_probability, 0.0, 1.0, p + ".path_change_slip_probability");
  r.range(o.correlator_spacing_chips, 0.01, 1.0, p + ".correlator_spacing_chips");
  r.range(o.clock_offset_max_s, 0.0, 5e-4, p + ".clock_offset_max_s");
  r.range(o.clock_drift_max_sps, 0.0, 1e-6, p + ".clock_drift_max_sps");
  r.range(o.clock_drift_noise, 0.0, 1e-8, p + ".clock_drift_noise");
  r.range(o.elevation_cutoff_deg, 0.0, 90.0, p + ".elevation_cutoff_deg");
}

void check_constellation(const ConstellationOptions& o, Rules& r) {
  if (!o.any()) r.fail("constellation.systems must name at least one of G, R, E, C");
  if (o.use_qzss) r.fail("constellation.systems: QZSS (J) is not simulated");
  r.range(o.gps_satellites, 24, 32, "constellation.gps_satellites");
  r.range(o.glonass_satellites, 1, 24, "constellation.glonass_satellites");
  r.range(o.galileo_satellites, 1, 24, "constellation.galileo_satellites");
  r.range(o.beidou_satellites, 1, 24, "constellation.beidou_satellites");
  const struct {
    core::Constellation system;
    const char* key;
  } lists[] = {{core::Constellation::Gps, "constellation.gps_signals"},
               {core::Constellation::Glonass, "constellation.glonass_signals"},
               {core::Constellation::Galileo, "constellation.galileo_signals"},
               {core::Constellation::BeiDou, "constellation.beidou_signals"}};
  for (const auto& list : lists) {
    const auto& signals = o.signals(list.system);
    r.require(!signals.empty() && signals.size() <= 3, list.key, "must list 1 to 3 signals",
              static_cast<double>(signals.size()));
    for (std::size_t i = 0; i < signals.size(); ++i) {
      const core::SignalCode s = signals[i];
      if (!core::carrier_frequency_hz(list.system, s, 0)) {
        r.fail(std::string(list.key) + ": signal " + s.to_string() + " does not exist for this system");
      }
      for (std::size_t j = 0; j < i; ++j) {
        if (signals[j].band == s.band) r.fail(std::string(list.key) + ": two signals on band " + s.band);
      }
    }
  }
}

void check_atmosphere(const AtmosphereOptions& a, Rules& r) {
  r.range(a.vtec_tecu, 0.0, 300.0, "atmosphere.vtec_tecu");
  r.require(a.gradient_tecu_per_100km.allFinite() && a.gradient_tecu_per_100km.norm() <= 50.0,
            "atmosphere.gradient_tecu_per_100km", "must be finite and at most 50 TECU per 100 km",
            a.gradient_tecu_per_100km.norm());
  r.range(a.wave_amplitude_tecu, 0.0, 20.0, "atmosphere.wave_amplitude_tecu");
  r.range(a.wave_count, 0, 20, "atmosphere.wave_count");
  r.positive(a.wave_length_km, "atmosphere.wave_length_km");
  r.positive(a.wave_period_s, "atmosphere.wave_period_s");
  r.range(a.shell_height_km, 100.0, 2000.0, "atmosphere.shell_height_km");
  r.range(a.zwd_residual_m, -0.5, 0.5, "atmosphere.zwd_residual_m");
  r.range(a.zwd_difference_m, -0.5, 0.5, "atmosphere.zwd_difference_m");
  r.range(a.zwd_variation_m, 0.0, 0.5, "atmosphere.zwd_variation_m");
}

}  // namespace

const std::vector<core::SignalCode>& ConstellationOptions::signals(core::Constellation system) const {
  switch (system) {
    case core::Constellation::Glonass: return glonass_signals;
    case core::Constellation::Galileo: return galileo_signals;
    case core::Constellation::BeiDou: return beidou_signals;
    default: return gps_signals;
  }
}

ReceiverOptions geodetic_receiver() {
  ReceiverOptions r;
  r.cn0_zenith_dbhz = 50.0;
  r.cn0_horizon_dbhz = 35.0;
  r.band2_cn0_offset_db = -2.0;
  r.code_sigma_m = 0.2;
  r.phase_sigma_m = 0.0015;
  r.doppler_sigma_hz = 0.03;
  r.correlator_spacing_chips = 0.1;
  r.elevation_cutoff_deg = 5.0;
  return r;
}

std::string Scenario::validate() const {
  Rules r;
  r.require(seed <= (std::uint64_t(1) << 53U), "seed", "must be at most 2^53", static_cast<double>(seed));
  r.range(duration_s, 1.0, 86400.0, "duration_s");
  r.range(rover_rate_hz, 0.1, 100.0, "rover_rate_hz");
  r.range(origin.lat_rad, -1.4, 1.4, "origin latitude (rad)");
  r.range(origin.height_m, -500.0, 5000.0, "origin.height_m");
  check_constellation(constellation, r);
  check_city(city, r);
  check_trees(trees, city, r);
  check_route(route, city, r);
  r.range(base.distance_m, 0.0, 200000.0, "base.distance_m");
  r.range(base.azimuth_deg, -360.0, 360.0, "base.azimuth_deg");
  r.range(base.height_m, -500.0, 5000.0, "base.height_m");
  r.range(base.rate_hz, 0.1, 100.0, "base.rate_hz");
  check_receiver(rover_receiver, "rover_receiver", r);
  check_receiver(base_receiver, "base_receiver", r);
  r.non_negative(reflections.wall_loss_db, "reflections.wall_loss_db");
  r.non_negative(reflections.nlos_extra_loss_db, "reflections.nlos_extra_loss_db");
  r.range(reflections.nlos_loss_spread_db, 0.0, 20.0, "reflections.nlos_loss_spread_db");
  r.non_negative(reflections.ground_loss_db, "reflections.ground_loss_db");
  r.non_negative(reflections.max_wall_distance_m, "reflections.max_wall_distance_m");
  check_atmosphere(atmosphere, r);
  r.non_negative(orbit_errors.radial_m, "orbit_errors.radial_m");
  r.non_negative(orbit_errors.along_m, "orbit_errors.along_m");
  r.non_negative(orbit_errors.cross_m, "orbit_errors.cross_m");
  r.non_negative(orbit_errors.clock_m, "orbit_errors.clock_m");
  r.require(vio.t_IA_m.allFinite() && vio.t_IA_m.norm() < 10.0, "vio.t_IA_m", "must be finite and shorter than 10 m",
            vio.t_IA_m.norm());
  r.range(vio.odometry_yaw_deg, -360.0, 360.0, "vio.odometry_yaw_deg");
  r.range(vio.rate_hz, 1.0, 200.0, "vio.rate_hz");
  r.range(vio.position_drift_fraction, 0.0, 0.2, "vio.position_drift_fraction");
  r.range(vio.yaw_drift_deg_per_km, 0.0, 90.0, "vio.yaw_drift_deg_per_km");
  r.range(vio.tilt_drift_deg_per_km, 0.0, 90.0, "vio.tilt_drift_deg_per_km");
  r.range(vio.device_clock_offset_s, 0.0, 1e8, "vio.device_clock_offset_s");
  r.range(vio.device_clock_drift_ppm, -1000.0, 1000.0, "vio.device_clock_drift_ppm");
  r.range(vio.timesync_jitter_s, 0.0, 1.0, "vio.timesync_jitter_s");
  r.range(vio.scale_error, -0.1, 0.1, "vio.scale_error");
  r.range(vio.covariance_optimism, 0.1, 10.0, "vio.covariance_optimism");
  return r.message();
}

int Scenario::rover_epochs() const {
  return static_cast<int>(std::floor(duration_s * rover_rate_hz + 1e-9)) + 1;
}

}  // namespace canyon::sim
