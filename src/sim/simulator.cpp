// The scenario generator (see simulator.hpp).

#include "canyon/sim/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/io/rinex_nav.hpp"
#include "canyon/sim/atmosphere.hpp"
#include "canyon/sim/constellation.hpp"
#include "canyon/sim/random.hpp"
#include "canyon/sim/signal_model.hpp"
#include "canyon/sim/tracking.hpp"

namespace canyon::sim {
namespace {

using core::GpsTime;
using core::kSpeedOfLightMps;

constexpr std::uint64_t kOrbitStream = 0x0E7B, kClockStream = 0xC10C, kChannelStream = 0xC4A7;
constexpr std::uint64_t kNlosLossStream = 0x2105;
constexpr double kL1Hz = 1575.42e6;
constexpr double kSkipBelowHorizonRad = -2.0 * core::kDegToRad;

// ------------------------------------------------------------------------------------------------------------------
// Satellite truth: broadcast state plus orbit and clock errors.

/// Slowly varying broadcast orbit and clock error of one satellite: a constant plus a once-per-orbit term.
struct OrbitError {
  Eigen::Vector3d constant_rtn = Eigen::Vector3d::Zero();
  Eigen::Vector3d periodic_rtn = Eigen::Vector3d::Zero();
  double clock_constant_m = 0.0;
  double clock_periodic_m = 0.0;
  double phase_rad = 0.0;
  static constexpr double kPeriodS = 43082.0;  // about one GPS orbit

  [[nodiscard]] Eigen::Vector3d rtn_m(double t_s) const {
    return constant_rtn + periodic_rtn * std::sin(2.0 * core::kPi * t_s / kPeriodS + phase_rad);
  }
  [[nodiscard]] double clock_m(double t_s) const {
    return clock_constant_m + clock_periodic_m * std::sin(2.0 * core::kPi * t_s / kPeriodS + phase_rad);
  }
};

OrbitError draw_orbit_error(const OrbitErrorOptions& o, std::uint64_t seed, core::SatelliteId sat) {
  Rng rng = Rng::stream(seed, kOrbitStream, static_cast<std::uint64_t>(sat.index()));
  const Eigen::Vector3d sigma(o.radial_m, o.along_m, o.cross_m);
  const double half = std::sqrt(0.5);  // constant and periodic parts share the variance
  OrbitError e;
  e.constant_rtn = half * sigma.cwiseProduct(Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal()));
  e.periodic_rtn = half * sigma.cwiseProduct(Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal()));
  e.clock_constant_m = half * o.clock_m * rng.normal();
  e.clock_periodic_m = half * o.clock_m * rng.normal();
  e.phase_rad = rng.uniform(0.0, 2.0 * core::kPi);
  return e;
}

/// A satellite as a receiver sees it at one reception time.
struct SatelliteView {
  Eigen::Vector3d p_E_m;    ///< satellite at transmission, in the ECEF frame of the reception time
  Eigen::Vector3d v_E_mps;  ///< satellite velocity in that frame
  double range_m = 0.0;     ///< geometric range with Earth rotation during the flight
  double clock_s = 0.0;     ///< true satellite clock (broadcast + error)
  double clock_drift_sps = 0.0;
  Eigen::Vector3d u_E = Eigen::Vector3d::UnitZ();  ///< receiver -> satellite
  GpsTime t_tx;
};

/// Rotation of ECEF coordinates by the Earth's rotation during `tau_s` (coordinates at transmission -> reception).
Eigen::Vector3d rotate_earth(const Eigen::Vector3d& p, double tau_s) {
  const double a = core::kEarthRotationRateRadps * tau_s;
  const double c = std::cos(a), s = std::sin(a);
  return {c * p.x() + s * p.y(), -s * p.x() + c * p.y(), p.z()};
}

class SatelliteTruth {
 public:
  SatelliteTruth(const gnss::EphemerisStore& store, const OrbitErrorOptions& errors, std::uint64_t seed,
                 const std::vector<core::SatelliteId>& sats, GpsTime start)
      : store_(store), start_(start) {
    for (const core::SatelliteId sat : sats) errors_[sat.index()] = draw_orbit_error(errors, seed, sat);
  }

  /// The satellite seen from p_E_rcv at true reception time t_rx; nullopt without an ephemeris or when it is below
  /// the horizon by more than 2 deg (`up_E`: local vertical).
  [[nodiscard]] std::optional<SatelliteView> view(core::SatelliteId sat, const GpsTime& t_rx,
                                                  const Eigen::Vector3d& p_E_rcv, const Eigen::Vector3d& up_E) const {
    const OrbitError& error = errors_.at(sat.index());
    double tau_s = 0.075;
    SatelliteView v;
    for (int iteration = 0; iteration < 3; ++iteration) {
      const bool last = iteration == 2;
      v.t_tx = t_rx - tau_s;
      const auto state = store_.state(sat, v.t_tx, last);
      if (!state) return std::nullopt;
      const Eigen::Vector3d p_true = state->p_E_m + error_E(error, *state, v.t_tx - start_);
      v.p_E_m = rotate_earth(p_true, tau_s);
      const Eigen::Vector3d d = v.p_E_m - p_E_rcv;
      v.range_m = d.norm();
      v.u_E = d / v.range_m;
      tau_s = v.range_m / kSpeedOfLightMps;
      if (iteration == 0 && v.u_E.dot(up_E) < std::sin(kSkipBelowHorizonRad)) return std::nullopt;
      if (last) {
        v.v_E_mps = rotate_earth(state->v_E_mps, tau_s);
        v.clock_s = state->clock_bias_s + error.clock_m(v.t_tx - start_) / kSpeedOfLightMps;
        v.clock_drift_sps = state->clock_drift_sps;
      }
    }
    return v;
  }

 private:
  /// Orbit error in ECEF from its radial, along-track, cross-track components (t_s since the start).
  static Eigen::Vector3d error_E(const OrbitError& e, const gnss::SatelliteState& s, double t_s) {
    const Eigen::Vector3d r = s.p_E_m.normalized();
    const Eigen::Vector3d c = s.p_E_m.cross(s.v_E_mps).normalized();
    const Eigen::Vector3d a = c.cross(r);
    const Eigen::Vector3d rtn = e.rtn_m(t_s);
    return rtn.x() * r + rtn.y() * a + rtn.z() * c;
  }

  const gnss::EphemerisStore& store_;
  GpsTime start_;
  std::map<int, OrbitError> errors_;
};

// ------------------------------------------------------------------------------------------------------------------
// One receiver.

/// Where the antenna is, for a receiver: a moving rover in the city, or a static base.
struct Antenna {
  const Trajectory* trajectory = nullptr;  ///< nullptr: static at p_E_static
  Eigen::Vector3d p_E_static = Eigen::Vector3d::Zero();
  const City* city = nullptr;  ///< nullptr: open sky
};

struct ReceiverSetup {
  const Scenario* scenario = nullptr;
  const ReceiverOptions* rx = nullptr;
  Antenna antenna;
  double rate_hz = 1.0;
  bool is_base = false;
  std::uint64_t seed = 0;
  std::uint64_t receiver_id = 0;
  bool keep_truth = false;
};

/// How one satellite's signal reaches the antenna at an epoch (common to its signals).
struct Propagation {
  bool direct = true;
  std::optional<WallReflection> nlos;  ///< set when not direct and a reflection exists
  double foliage_m = 0.0;
  std::optional<WallReflection> wall_multipath;  ///< reflection accompanying a direct signal
  double ground_excess_m = 0.0;                  ///< ground reflection excess path (0: none)
};

struct ChannelState {
  explicit ChannelState(Rng rng) : channel(rng) {}
  Channel channel;
  int nlos_wall = -1;                ///< the wall whose NLOS loss is drawn below (-1: none yet)
  double nlos_loss_spread_db = 0.0;  ///< that wall's loss about the mean (dB)
  bool has_last = false;
  double last_t_s = 0.0;
  double last_phase_extra_m = 0.0;
};

class ReceiverSimulator {
 public:
  ReceiverSimulator(const ReceiverSetup& setup, const gnss::EphemerisStore& store, const SatelliteTruth& satellites,
                    const std::vector<core::SatelliteId>& sats, const Ionosphere& iono, const Troposphere& tropo)
      : setup_(setup),
        store_(store),
        satellites_(satellites),
        sats_(sats),
        iono_(iono),
        tropo_(tropo),
        clock_(*setup.rx, Rng::stream(setup.seed, kClockStream, setup.receiver_id)),
        origin_E_(core::geodetic_to_ecef(setup.scenario->origin)),
        R_NE_(core::rotation_enu_from_ecef(setup.scenario->origin)) {}

  ReceiverRun run() {
    ReceiverRun out;
    const Scenario& sc = *setup_.scenario;
    out.clock_offset_s = clock_.initial_offset_s();
    out.clock_drift_sps = clock_.initial_drift_sps();
    const int epochs = static_cast<int>(std::floor(sc.duration_s * setup_.rate_hz + 1e-9)) + 1;
    out.epochs.reserve(static_cast<std::size_t>(epochs));
    for (int k = 0; k < epochs; ++k) {
      const double tag_s = k / setup_.rate_hz;
      out.epochs.push_back(epoch(sc.start + tag_s, tag_s, out));
    }
    for (const auto& [key, state] : channels_) {
      out.losses += state.channel.losses();
      out.slips += state.channel.slips();
    }
    return out;
  }

 private:
  core::ObsEpoch epoch(const GpsTime& tag, double tag_s, ReceiverRun& out) {
    clock_.advance(tag_s);
    const double dt_r = clock_.offset_s();
    const double t_s = tag_s - dt_r;  // true reception time since the start
    const GpsTime t_rx = tag - dt_r;
    Eigen::Vector3d p_N = Eigen::Vector3d::Zero(), v_N = Eigen::Vector3d::Zero();
    Eigen::Vector3d p_E = setup_.antenna.p_E_static, v_E = Eigen::Vector3d::Zero();
    if (setup_.antenna.trajectory != nullptr) {
      p_N = setup_.antenna.trajectory->antenna_N(t_s);
      v_N = setup_.antenna.trajectory->velocity_N(t_s);
      p_E = origin_E_ + R_NE_.transpose() * p_N;
      v_E = R_NE_.transpose() * v_N;
    }
    const core::Geodetic rcv = core::ecef_to_geodetic(p_E);
    const Eigen::Matrix3d R_NE_local = core::rotation_enu_from_ecef(rcv);
    const Eigen::Vector3d up_E = R_NE_local.row(2).transpose();
    std::vector<int> walls;
    if (setup_.antenna.city != nullptr) {
      walls = setup_.antenna.city->walls_facing(p_N, setup_.scenario->reflections.max_wall_distance_m);
    }
    core::ObsEpoch epoch;
    epoch.time = tag;
    EpochTruth truth;
    truth.tag = tag;
    truth.t_s = t_s;
    truth.p_E_m = p_E;
    truth.p_N_m = p_N;
    int line_of_sight = 0;  // satellites output with phase on the direct path
    for (const core::SatelliteId sat : sats_) {
      const auto view = satellites_.view(sat, t_rx, p_E, up_E);
      core::SatelliteObs obs;
      obs.sat = sat;
      bool direct = false;
      if (view) {
        Context ctx{sat, *view, t_s, dt_r, p_N, v_E, rcv, R_NE_local, walls};
        ctx.propagation = propagate(ctx);
        observe(ctx, obs, truth, out);
        direct = ctx.propagation.direct;
      } else {
        step_unseen(sat, t_s);
      }
      if (obs.signals.empty()) continue;
      if (direct) ++line_of_sight;
      epoch.sats.push_back(std::move(obs));
    }
    if (line_of_sight >= kLineOfSightCeilingSatellites) ++out.line_of_sight_epochs;
    if (setup_.keep_truth) out.truth.push_back(std::move(truth));
    return epoch;
  }

  struct Context {
    core::SatelliteId sat;
    SatelliteView view;
    double t_s;
    double dt_r;
    Eigen::Vector3d p_N;
    Eigen::Vector3d v_E;
    core::Geodetic rcv;
    Eigen::Matrix3d R_NE_local;
    const std::vector<int>& walls;
    Propagation propagation{};
    Eigen::Vector3d u_N = Eigen::Vector3d::UnitZ();
    double elevation_rad = 0.0;
  };

  Propagation propagate(Context& ctx) const {
    // Direction in the city frame (the origin's ENU; the rover stays within a few km of it).
    ctx.u_N = R_NE_ * ctx.view.u_E;
    const Eigen::Vector3d u_local = ctx.R_NE_local * ctx.view.u_E;
    ctx.elevation_rad = std::asin(std::clamp(u_local.z(), -1.0, 1.0));
    Propagation p;
    const City* city = setup_.antenna.city;
    if (city == nullptr || ctx.elevation_rad <= 0.0) return p;
    const ReflectionOptions& refl = setup_.scenario->reflections;
    if (city->direct_blocked(ctx.p_N, ctx.u_N)) {
      p.direct = false;
      if (refl.nlos) p.nlos = city->wall_reflection(ctx.p_N, ctx.u_N, ctx.walls);
      return p;
    }
    p.foliage_m = city->foliage_m(ctx.p_N, ctx.u_N);
    if (refl.multipath) {
      p.wall_multipath = city->wall_reflection(ctx.p_N, ctx.u_N, ctx.walls);
      p.ground_excess_m = 2.0 * ctx.p_N.z() * std::sin(ctx.elevation_rad);
    }
    return p;
  }

  /// An NLOS signal's loss off `wall` (dB): the scenario's mean, plus the spread drawn once per satellite and wall
  /// (the same for every band of the satellite), at least 0.
  double nlos_loss_db(ChannelState& state, core::SatelliteId sat, int wall) const {
    const ReflectionOptions& refl = setup_.scenario->reflections;
    const double mean_db = refl.wall_loss_db + refl.nlos_extra_loss_db;
    if (refl.nlos_loss_spread_db <= 0.0) return mean_db;
    if (state.nlos_wall != wall) {
      Rng rng = Rng::stream(setup_.seed, kNlosLossStream, static_cast<std::uint64_t>(sat.index()),
                            static_cast<std::uint64_t>(wall));
      state.nlos_wall = wall;
      state.nlos_loss_spread_db = refl.nlos_loss_spread_db * rng.normal();
    }
    return std::max(0.0, mean_db + state.nlos_loss_spread_db);
  }

  ChannelState& channel(core::SatelliteId sat, int signal_index) {
    const int key = sat.index() * 4 + signal_index;
    auto it = channels_.find(key);
    if (it == channels_.end()) {
      Rng rng =
          Rng::stream(setup_.seed, kChannelStream, setup_.receiver_id * 1000003ULL + static_cast<std::uint64_t>(key));
      it = channels_.emplace(key, ChannelState(rng)).first;
    }
    return it->second;
  }

  /// Steps the channels of a satellite that is not in view (no ephemeris or below the horizon).
  void step_unseen(core::SatelliteId sat, double t_s) {
    const auto& signals = setup_.scenario->constellation.signals(sat.system);
    for (int i = 0; i < static_cast<int>(signals.size()); ++i) {
      const int key = sat.index() * 4 + i;
      auto it = channels_.find(key);
      if (it == channels_.end()) continue;
      it->second.channel.step(t_s, SignalPath{}, *setup_.rx);
      it->second.has_last = false;
    }
  }

  void observe(Context& ctx, core::SatelliteObs& obs, EpochTruth& truth, ReceiverRun& out) {
    const Scenario& sc = *setup_.scenario;
    const ReceiverOptions& rx = *setup_.rx;
    const Propagation& prop = ctx.propagation;
    const auto& signals = sc.constellation.signals(ctx.sat.system);
    const int glonass_channel =
        ctx.sat.system == core::Constellation::Glonass ? store_.glonass_channel(ctx.sat.prn) : core::kNoGlonassChannel;
    const bool above_cutoff = ctx.elevation_rad >= std::max(0.0, rx.elevation_cutoff_deg * core::kDegToRad);
    const core::AzEl azel = core::azimuth_elevation_from_enu(ctx.R_NE_local * ctx.view.u_E);
    const double iono_l1_m = iono_.slant_delay_l1_m(ctx.t_s, ctx.rcv, azel);
    const double tropo_m = tropo_.slant_delay_m(ctx.t_s, ctx.rcv, ctx.elevation_rad, setup_.is_base);
    const double range_rate_mps = ctx.view.u_E.dot(ctx.view.v_E_mps - ctx.v_E);
    const double clock_m = kSpeedOfLightMps * (ctx.dt_r - ctx.view.clock_s);
    const double clock_rate_mps = kSpeedOfLightMps * (clock_.drift_sps() - ctx.view.clock_drift_sps);
    for (int i = 0; i < static_cast<int>(signals.size()); ++i) {
      const core::SignalCode code = signals[static_cast<std::size_t>(i)];
      const auto f_hz = core::carrier_frequency_hz(ctx.sat.system, code, glonass_channel);
      ChannelState& state = channel(ctx.sat, i);
      if (!f_hz) {
        state.channel.step(ctx.t_s, SignalPath{}, rx);
        continue;
      }
      const double lambda_m = kSpeedOfLightMps / *f_hz;
      const double chip_m = chip_length_m(ctx.sat.system, code);
      // Path, errors from reflections and C/N0.
      SignalPath path;
      double code_extra_m = 0.0, phase_extra_m = 0.0;
      double cn0 = line_of_sight_cn0_dbhz(rx, ctx.elevation_rad, i);
      if (prop.direct) {
        std::vector<Reflection> reflections;
        if (prop.wall_multipath) {
          reflections.push_back({std::pow(10.0, -sc.reflections.wall_loss_db / 20.0), prop.wall_multipath->excess_m});
        }
        if (prop.ground_excess_m > 0.0) {
          reflections.push_back({std::pow(10.0, -sc.reflections.ground_loss_db / 20.0), prop.ground_excess_m});
        }
        const MultipathError mp = line_of_sight_multipath(reflections, lambda_m, chip_m, rx.correlator_spacing_chips);
        code_extra_m = mp.code_m;
        phase_extra_m = mp.phase_m;
        cn0 += mp.cn0_change_db - sc.trees.attenuation_db_per_m * prop.foliage_m;
        path.receivable = above_cutoff;
        path.direct = true;
      } else if (prop.nlos) {
        code_extra_m = prop.nlos->excess_m;
        phase_extra_m = prop.nlos->excess_m + 0.5 * lambda_m;
        cn0 -= nlos_loss_db(state, ctx.sat, prop.nlos->wall);
        path.receivable = above_cutoff;
        path.direct = false;
        path.wall = prop.nlos->wall;
      }
      path.cn0_dbhz = cn0;
      const ChannelOutput ch = state.channel.step(ctx.t_s, path, rx);
      if (!ch.output) {
        state.has_last = false;
        continue;
      }
      Rng& rng = state.channel.rng();
      const double code_sigma_m = scaled_sigma(rx, rx.code_sigma_m, cn0);
      const double phase_sigma_m = scaled_sigma(rx, rx.phase_sigma_m, cn0);
      const double doppler_sigma_hz = scaled_sigma(rx, rx.doppler_sigma_hz, cn0);
      const double code_noise_m = code_sigma_m * rng.normal();
      const double phase_noise_m = phase_sigma_m * rng.normal();
      const double iono_m = iono_l1_m * (kL1Hz / *f_hz) * (kL1Hz / *f_hz);
      const double group_delay_m = kSpeedOfLightMps * store_.group_delay_s(ctx.sat, code, ctx.view.t_tx);
      const double extra_rate_mps = state.has_last && ctx.t_s > state.last_t_s
                                        ? (phase_extra_m - state.last_phase_extra_m) / (ctx.t_s - state.last_t_s)
                                        : 0.0;
      state.has_last = true;
      state.last_t_s = ctx.t_s;
      state.last_phase_extra_m = phase_extra_m;

      core::SignalObs s;
      s.code = code;
      s.pseudorange_m = ctx.view.range_m + clock_m + tropo_m + iono_m + group_delay_m + code_extra_m + code_noise_m;
      s.carrier_phase_cyc = (ctx.view.range_m + clock_m + tropo_m - iono_m + phase_extra_m + phase_noise_m) / lambda_m +
                            static_cast<double>(ch.ambiguity_cyc);
      s.doppler_hz = -(range_rate_mps + clock_rate_mps + extra_rate_mps) / lambda_m + doppler_sigma_hz * rng.normal();
      s.snr_dbhz = std::round((cn0 + rx.cn0_noise_db * rng.normal()) * 4.0) / 4.0;
      s.lli = ch.loss_of_lock ? core::kLliLossOfLock : 0;
      obs.signals.push_back(s);
      ++out.signal_epochs;
      if (!prop.direct) ++out.nlos_signal_epochs;
      if (setup_.keep_truth) {
        SignalTruth t;
        t.sat = ctx.sat;
        t.code = code;
        t.wavelength_m = lambda_m;
        t.direct = prop.direct;
        t.nlos_excess_m = prop.direct ? 0.0 : prop.nlos->excess_m;
        t.code_multipath_m = prop.direct ? code_extra_m : 0.0;
        t.phase_multipath_m = prop.direct ? phase_extra_m : 0.0;
        t.range_m = ctx.view.range_m;
        t.satellite_clock_m = kSpeedOfLightMps * ctx.view.clock_s;
        t.receiver_clock_m = kSpeedOfLightMps * ctx.dt_r;
        t.troposphere_m = tropo_m;
        t.ionosphere_m = iono_m;
        t.group_delay_m = group_delay_m;
        t.ambiguity_cyc = ch.ambiguity_cyc;
        t.code_noise_m = code_noise_m;
        t.phase_noise_m = phase_noise_m;
        t.code_sigma_m = code_sigma_m;
        t.phase_sigma_m = phase_sigma_m;
        t.cn0_dbhz = cn0;
        t.loss_of_lock = ch.loss_of_lock;
        t.elevation_rad = ctx.elevation_rad;
        t.u_N = ctx.u_N;
        truth.signals.push_back(t);
      }
    }
  }

  ReceiverSetup setup_;
  const gnss::EphemerisStore& store_;
  const SatelliteTruth& satellites_;
  const std::vector<core::SatelliteId>& sats_;
  const Ionosphere& iono_;
  const Troposphere& tropo_;
  ReceiverClock clock_;
  Eigen::Vector3d origin_E_;
  Eigen::Matrix3d R_NE_;
  std::map<int, ChannelState> channels_;
};

// ------------------------------------------------------------------------------------------------------------------
// Scenario set-up: navigation data, base, route and city.

Result<core::NavigationData> navigation(const Scenario& sc, const std::string& nav_path) {
  core::NavigationData nav;
  if (sc.constellation.nav_file.empty()) {
    nav = builtin_navigation(sc.constellation, sc.start, sc.start + sc.duration_s);
  } else {
    auto read = io::read_rinex_nav(sc.constellation.nav_file);
    if (!read) return read.error();
    nav = std::move(read->nav);
  }
  if (Status s = io::write_rinex_nav(nav_path, nav); !s) return s.error();
  auto back = io::read_rinex_nav(nav_path);
  if (!back) return back.error();
  return std::move(back->nav);
}

std::vector<core::SatelliteId> satellites_of(const core::NavigationData& nav, const ConstellationOptions& options) {
  std::vector<core::SatelliteId> sats;
  for (const auto& e : nav.kepler) sats.push_back(e.sat);
  for (const auto& g : nav.glonass) sats.push_back(g.sat);
  std::sort(sats.begin(), sats.end());
  sats.erase(std::unique(sats.begin(), sats.end()), sats.end());
  sats.erase(std::remove_if(sats.begin(), sats.end(),
                            [&](core::SatelliteId s) { return !s.valid() || !options.uses(s.system); }),
             sats.end());
  return sats;
}

Eigen::Vector3d base_position_E(const Scenario& sc) {
  const double az = sc.base.azimuth_deg * core::kDegToRad;
  const Eigen::Vector3d d_N(sc.base.distance_m * std::sin(az), sc.base.distance_m * std::cos(az), 0.0);
  core::Geodetic g = core::ecef_to_geodetic(core::geodetic_to_ecef(sc.origin) + core::enu_to_ecef(d_N, sc.origin));
  g.height_m = sc.base.height_m;
  return core::geodetic_to_ecef(g);
}

CityExtent extent_around(const std::vector<Eigen::Vector2d>& points_G, const StreetGrid& grid, double margin_m) {
  Eigen::Vector2d lo = points_G.front(), hi = points_G.front();
  for (const Eigen::Vector2d& p : points_G) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector2d pitch(grid.pitch_x_m, grid.pitch_y_m);
  CityExtent e;
  e.min_G = ((lo.array() - margin_m) / pitch.array()).floor() * pitch.array();
  e.max_G = ((hi.array() + margin_m) / pitch.array()).ceil() * pitch.array();
  // At least one block beyond the outermost street walked.
  const Eigen::Vector2d one_block_lo = ((lo.array() / pitch.array()).floor() - 1.0) * pitch.array();
  const Eigen::Vector2d one_block_hi = ((hi.array() / pitch.array()).ceil() + 1.0) * pitch.array();
  e.min_G = e.min_G.cwiseMin(one_block_lo);
  e.max_G = e.max_G.cwiseMax(one_block_hi);
  return e;
}

struct Ground {
  City city;
  Trajectory trajectory;
};

Error scenario_error(const Scenario& sc, const std::string& message) {
  return Error{message, sc.source_file, 0};
}

Result<Ground> build_ground(const Scenario& sc) {
  const StreetGrid grid = StreetGrid::from(sc.city);
  const double length_m = sc.route.speed_mps * sc.duration_s + 10.0;
  const bool fixed_extent = !sc.city.blocks.empty();
  const CityExtent fixed = fixed_extent ? blocks_extent(sc.city.blocks, grid) : CityExtent{};
  std::vector<Eigen::Vector2d> points_G;
  if (sc.route.waypoints_N_m.empty()) {
    points_G = random_walk_G(sc.route, grid, length_m, fixed_extent ? &fixed : nullptr, sc.seed);
  } else {
    for (const Eigen::Vector2d& w : sc.route.waypoints_N_m) points_G.push_back(grid.to_G(w));
  }
  const CityExtent extent = fixed_extent ? fixed : extent_around(points_G, grid, sc.city.margin_m);
  for (std::size_t k = 0; k < points_G.size(); ++k) {
    if (!extent.contains_G(points_G[k])) {
      return scenario_error(sc, "route.waypoints_m[" + std::to_string(k) + "] is outside the city (city.blocks)");
    }
  }
  City city = generate_city(sc.city, sc.trees, extent, sc.seed);
  std::vector<Eigen::Vector2d> points_N;
  points_N.reserve(points_G.size());
  for (const Eigen::Vector2d& p : points_G) points_N.push_back(grid.to_N(p));
  for (std::size_t k = 1; k < points_N.size(); ++k) {
    if ((points_N[k] - points_N[k - 1]).norm() < 1e-3) {
      return scenario_error(sc, "route.waypoints_m[" + std::to_string(k) + "] repeats the previous waypoint");
    }
  }
  Path path = Path::through(points_N, sc.route.turn_radius_m);
  // The walk must stay in the streets: sample it every 0.5 m.
  constexpr double kRouteCheckStepM = 0.5;
  for (int k = 0; k * kRouteCheckStepM <= path.length_m(); ++k) {
    const Eigen::Vector2d p = path.position_N(k * kRouteCheckStepM);
    if (city.inside_building(p)) {
      return scenario_error(sc, "the route enters a building at (east " + std::to_string(std::lround(p.x())) +
                                    " m, north " + std::to_string(std::lround(p.y())) +
                                    " m): route.waypoints_m must follow the streets");
    }
  }
  return Ground{std::move(city), Trajectory(std::move(path), sc.route)};
}

// ------------------------------------------------------------------------------------------------------------------
// RINEX headers and truth.

io::RinexObsHeader obs_header(const Scenario& sc, bool base, const Eigen::Vector3d& p_E,
                              const core::NavigationData& nav, double rate_hz) {
  io::RinexObsHeader h;
  h.version = 3.04;
  h.receiver.marker_name = base ? "BASE" : "ROVER";
  h.receiver.receiver_type = "CANYON SIMULATED";
  h.receiver.antenna_type = base ? "CANYON SIM GEODETIC" : "CANYON SIM HEAD-WORN";
  h.receiver.approx_position_E_m = p_E;
  for (const core::Constellation system : {core::Constellation::Gps, core::Constellation::Glonass,
                                           core::Constellation::Galileo, core::Constellation::BeiDou}) {
    if (!sc.constellation.uses(system)) continue;
    std::vector<std::string>& types = h.obs_types[system];
    for (const core::SignalCode s : sc.constellation.signals(system)) {
      for (const char kind : {'C', 'L', 'D', 'S'}) types.push_back(std::string{kind, s.band, s.attribute});
      h.receiver.phase_shifts.push_back({system, s, 0.0});
    }
  }
  if (sc.constellation.use_glonass) {
    std::map<int, int> slots;
    for (const auto& g : nav.glonass) slots[g.sat.prn] = g.frequency_channel;
    for (const auto& [slot, channel] : slots) h.receiver.glonass_slot_channels.emplace_back(slot, channel);
  }
  h.interval_s = 1.0 / rate_hz;
  h.first_obs = sc.start;
  h.leap_seconds = core::builtin_leap_seconds().gps_minus_utc_at_gps(sc.start);
  const core::CalendarTime c = core::gps_to_calendar(sc.start);
  char date[32];
  std::snprintf(date, sizeof date, "%04d%02d%02d %02d%02d%02d GPS", c.year, c.month, c.day, c.hour, c.minute,
                static_cast<int>(c.second));
  h.program_date = date;
  return h;
}

std::vector<TruthSample> rover_truth(const Scenario& sc, const Trajectory& trajectory) {
  const Eigen::Vector3d origin_E = core::geodetic_to_ecef(sc.origin);
  const Eigen::Matrix3d R_EN = core::rotation_enu_from_ecef(sc.origin).transpose();
  std::vector<TruthSample> out;
  const int epochs = sc.rover_epochs();
  for (int k = 0; k < epochs; ++k) {
    const double t_s = k / sc.rover_rate_hz;
    TruthSample s;
    s.time = sc.start + t_s;
    s.p_E_m = origin_E + R_EN * trajectory.antenna_N(t_s);
    s.q_EI = Eigen::Quaterniond(R_EN * body_attitude_N(trajectory, t_s)).normalized();
    out.push_back(s);
  }
  return out;
}

}  // namespace

Result<Simulation> simulate(const Scenario& scenario, const std::string& nav_path, const SimulationOptions& options) {
  if (const std::string e = scenario.validate(); !e.empty()) return scenario_error(scenario, e);
  Simulation sim;
  sim.scenario = scenario;
  auto nav = navigation(scenario, nav_path);
  if (!nav) return nav.error();
  sim.nav = std::move(*nav);
  auto ground = build_ground(scenario);
  if (!ground) return ground.error();
  sim.city = std::move(ground->city);
  sim.trajectory = std::move(ground->trajectory);
  sim.base_p_E_m = base_position_E(scenario);

  const gnss::EphemerisStore store(sim.nav);
  const std::vector<core::SatelliteId> sats = satellites_of(sim.nav, scenario.constellation);
  if (sats.empty()) return scenario_error(scenario, "no satellite of the selected systems in the navigation data");
  const SatelliteTruth satellites(store, scenario.orbit_errors, scenario.seed, sats, scenario.start);
  const Ionosphere iono(scenario.atmosphere, scenario.origin, scenario.seed);
  const Troposphere tropo(scenario.atmosphere, scenario.seed);

  ReceiverSetup rover;
  rover.scenario = &scenario;
  rover.rx = &scenario.rover_receiver;
  rover.antenna.trajectory = &sim.trajectory;
  rover.antenna.city = &sim.city;
  rover.rate_hz = scenario.rover_rate_hz;
  rover.seed = scenario.seed;
  rover.receiver_id = 1;
  rover.keep_truth = options.keep_signal_truth;
  sim.truth = rover_truth(scenario, sim.trajectory);
  sim.rover = ReceiverSimulator(rover, store, satellites, sats, iono, tropo).run();
  sim.rover.header = obs_header(scenario, false, sim.truth.front().p_E_m, sim.nav, scenario.rover_rate_hz);

  ReceiverSetup base = rover;
  base.rx = &scenario.base_receiver;
  base.antenna = Antenna{nullptr, sim.base_p_E_m, nullptr};
  base.rate_hz = scenario.base.rate_hz;
  base.is_base = true;
  base.receiver_id = 2;
  sim.base = ReceiverSimulator(base, store, satellites, sats, iono, tropo).run();
  sim.base.header = obs_header(scenario, true, sim.base_p_E_m, sim.nav, scenario.base.rate_hz);
  if (scenario.vio.enabled) sim.vio = simulate_vio(scenario, sim.trajectory, scenario.seed);
  return sim;
}

}  // namespace canyon::sim
