// Built-in constellation (see constellation.hpp).

#include "canyon/sim/constellation.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Geometry>

#include "canyon/core/constants.hpp"
#include "canyon/sim/random.hpp"

namespace canyon::sim {
namespace {

using core::Constellation;
using core::GpsTime;
using core::kDegToRad;
using core::kPi;
using State = Eigen::Matrix<double, 6, 1>;

constexpr double kTwoPi = 2.0 * kPi;
constexpr double kEarthJ2 = 1.08262668e-3;                      // WGS84 J2, for the secular rates of the Kepler orbits
constexpr std::uint64_t kElementsSeed = 0x5EED0F5A7E111735ULL;  // fixed: the same sky in every scenario
constexpr double kGloIntegrationStepS = 10.0;

/// Mean orbital elements of one satellite at the reference epoch.
struct Elements {
  core::SatelliteId sat;
  double a_m = 0.0;
  double e = 0.0;
  double i_rad = 0.0;
  double raan_rad = 0.0;  ///< right ascension of the node in the quasi-inertial frame at the reference epoch
  double omega_rad = 0.0;
  double m_rad = 0.0;  ///< mean anomaly at the reference epoch
  double clock_s = 0.0;
  double clock_rate_sps = 0.0;
  double group_delay_s = 0.0;
  double group_delay2_s = 0.0;
  int glonass_channel = 0;
};

double wrap_two_pi(double a) {
  a = std::fmod(a, kTwoPi);
  return a < 0.0 ? a + kTwoPi : a;
}

double wrap_pi(double a) {
  a = wrap_two_pi(a);
  return a > kPi ? a - kTwoPi : a;
}

/// Fills eccentricity, perigee, clock and group delays with small fixed-seed values.
void perturb(Elements& el, Rng& rng, double base_inclination_rad) {
  el.e = rng.uniform(0.0005, 0.015);
  el.i_rad = base_inclination_rad + rng.uniform(-1.0, 1.0) * kDegToRad;
  el.omega_rad = rng.uniform(0.0, kTwoPi);
  el.clock_s = rng.uniform(-5e-4, 5e-4);
  el.clock_rate_sps = rng.uniform(-5e-12, 5e-12);
  el.group_delay_s = rng.uniform(-8e-9, 8e-9);
  el.group_delay2_s = rng.uniform(-8e-9, 8e-9);
}

/// Mean anomaly for argument of latitude u (near-circular: M ~ u - omega).
double mean_anomaly_for_latitude(double u_rad, double omega_rad) {
  return wrap_two_pi(u_rad - omega_rad);
}

std::vector<Elements> gps_elements(int count, Rng& rng) {
  // Argument of latitude (deg) of the four nominal slots of planes A..F: uneven phasing so that the 24 satellites
  // cover the sky evenly (canyon's own values in the manner of the SPS 24-slot baseline).
  constexpr std::array<std::array<double, 4>, 6> kSlotsDeg = {{{11.7, 41.8, 161.8, 268.1},
                                                               {81.0, 173.3, 204.4, 310.0},
                                                               {11.8, 111.9, 241.6, 339.7},
                                                               {35.2, 135.2, 167.4, 265.4},
                                                               {66.1, 197.0, 302.6, 333.7},
                                                               {105.2, 135.3, 238.9, 345.2}}};
  std::vector<std::pair<int, double>> slots;  // (plane, u deg)
  for (int p = 0; p < 6; ++p) {
    for (const double u : kSlotsDeg[static_cast<std::size_t>(p)]) slots.emplace_back(p, u);
  }
  // Spares: into the largest remaining gap of planes A, B, C, ... in turn.
  for (int k = 0; static_cast<int>(slots.size()) < count; ++k) {
    const int plane = k % 6;
    std::vector<double> us;
    for (const auto& [p, u] : slots) {
      if (p == plane) us.push_back(u);
    }
    std::sort(us.begin(), us.end());
    double best_gap = 0.0, best_u = 0.0;
    for (std::size_t j = 0; j < us.size(); ++j) {
      const double next = j + 1 < us.size() ? us[j + 1] : us.front() + 360.0;
      if (next - us[j] > best_gap) {
        best_gap = next - us[j];
        best_u = std::fmod(us[j] + best_gap / 2.0, 360.0);
      }
    }
    slots.emplace_back(plane, best_u);
  }
  // PRNs are assigned to slots in a fixed shuffled order, as in the real constellation.
  std::vector<int> prns(slots.size());
  for (std::size_t k = 0; k < prns.size(); ++k) prns[k] = static_cast<int>(k) + 1;
  for (std::size_t k = prns.size() - 1; k > 0; --k) {
    std::swap(prns[k], prns[static_cast<std::size_t>(rng.integer(0, static_cast<std::int64_t>(k)))]);
  }
  std::vector<Elements> out;
  for (std::size_t k = 0; k < slots.size(); ++k) {
    Elements el;
    el.sat = {Constellation::Gps, static_cast<std::uint8_t>(prns[k])};
    el.a_m = 26559.7e3 + rng.uniform(-5e3, 5e3);
    perturb(el, rng, 55.0 * kDegToRad);
    el.raan_rad = (272.8 + 60.0 * slots[k].first) * kDegToRad;
    el.m_rad = mean_anomaly_for_latitude(slots[k].second * kDegToRad, el.omega_rad);
    out.push_back(el);
  }
  return out;
}

/// Walker constellation t/p/f: `planes` planes of `per_plane` satellites, phasing f * 360 / t between planes.
std::vector<Elements> walker_elements(Constellation system, int count, int first_prn, double a_m, double i_deg,
                                      double raan0_deg, double phasing_deg, Rng& rng) {
  constexpr int kPlanes = 3, kPerPlane = 8;
  std::vector<Elements> out;
  for (int p = 0; p < kPlanes; ++p) {
    for (int s = 0; s < kPerPlane; ++s) {
      Elements el;
      el.sat = {system, static_cast<std::uint8_t>(first_prn + p * kPerPlane + s)};
      el.a_m = a_m + rng.uniform(-2e3, 2e3);
      perturb(el, rng, i_deg * kDegToRad);
      if (system == Constellation::Glonass) el.e = rng.uniform(0.0002, 0.002);
      el.raan_rad = (raan0_deg + 120.0 * p) * kDegToRad;
      el.m_rad = mean_anomaly_for_latitude((45.0 * s + phasing_deg * p) * kDegToRad, el.omega_rad);
      out.push_back(el);
    }
  }
  out.resize(static_cast<std::size_t>(std::min<int>(count, kPlanes * kPerPlane)));
  return out;
}

int glonass_channel_of_slot(int slot) {
  constexpr std::array<int, 24> kChannels = {1,  -4, 5, 6,  1, -4, 5, 6, -2, -7, 0, -1,
                                             -2, -7, 0, -1, 4, -3, 3, 2, 4,  -3, 3, 2};
  return kChannels[static_cast<std::size_t>(slot - 1)];
}

// ------------------------------------------------------------------------------------------------------------------
// Kepler records.

struct SystemConstants {
  double mu_m3ps2;
  double omega_e_radps;
};

SystemConstants constants_of(Constellation system) {
  switch (system) {
    case Constellation::Galileo: return {core::kGalMuM3ps2, core::kEarthRotationRateRadps};
    case Constellation::BeiDou: return {core::kBdsMuM3ps2, core::kBdsEarthRotationRateRadps};
    case Constellation::Glonass: return {core::kGloMuM3ps2, core::kGloEarthRotationRateRadps};
    default: return {core::kGpsMuM3ps2, core::kEarthRotationRateRadps};
  }
}

/// J2 secular rates: node (rad/s) and mean-motion correction (rad/s).
std::pair<double, double> j2_rates(const Elements& el, double mu) {
  const double n = std::sqrt(mu / (el.a_m * el.a_m * el.a_m));
  const double p = el.a_m * (1.0 - el.e * el.e);
  const double k = kEarthJ2 * (core::kWgs84SemiMajorM / p) * (core::kWgs84SemiMajorM / p);
  const double ci = std::cos(el.i_rad);
  const double node_rate = -1.5 * n * k * ci;
  const double dn = 0.75 * n * k * std::sqrt(1.0 - el.e * el.e) * (3.0 * ci * ci - 1.0);
  return {node_rate, dn};
}

/// Start (GPST) of the system week containing t: GPS/Galileo weeks start at GPST week starts, BDT weeks 14 s later.
GpsTime system_week_start(Constellation system, const GpsTime& t) {
  if (system == Constellation::BeiDou) {
    const core::WeekTow bdt = core::gps_to_bdt(t);
    return core::bdt_to_gps(bdt.week, 0.0);
  }
  return GpsTime{t.normalized().week, 0.0};
}

core::KeplerEphemeris kepler_record(const Elements& el, const GpsTime& t_ref, const GpsTime& toe, int index) {
  const Constellation system = el.sat.system;
  const SystemConstants k = constants_of(system);
  const auto [node_rate, dn] = j2_rates(el, k.mu_m3ps2);
  const double n = std::sqrt(k.mu_m3ps2 / (el.a_m * el.a_m * el.a_m)) + dn;
  const double dt_s = toe - t_ref;
  const GpsTime week_start = system_week_start(system, toe);
  core::KeplerEphemeris e;
  e.sat = el.sat;
  e.toe = toe;
  e.toc = toe;
  e.toe_sow_s = toe - week_start;
  e.sqrt_a_sqrtm = std::sqrt(el.a_m);
  e.e = el.e;
  e.i0_rad = el.i_rad;
  e.omega_rad = wrap_pi(el.omega_rad);
  e.m0_rad = wrap_pi(el.m_rad + n * dt_s);
  e.delta_n_radps = dn;
  e.omega_dot_radps = node_rate;
  // Node longitude lambda(t) = raan + node_rate (t - t_ref) - omega_e (t - week start at t_ref), written as the
  // broadcast OMEGA0 of this record's week (see the Kepler model in gnss/ephemeris.cpp).
  const double week_shift_s = week_start - system_week_start(system, t_ref);
  e.omega0_rad = wrap_pi(el.raan_rad + node_rate * dt_s - k.omega_e_radps * week_shift_s);
  e.af0_s = el.clock_s + el.clock_rate_sps * dt_s;
  e.af1_sps = el.clock_rate_sps;
  e.health = 0;
  e.fit_interval_h = system == Constellation::Gps ? 4.0 : 0.0;
  switch (system) {
    case Constellation::Galileo:
      e.iode = index % 1024;
      e.data_source = 0x205;  // I/NAV E1-B and E5b-I, clock for E5b/E1
      e.accuracy_m = 3.12;
      e.tgd_s = {el.group_delay_s, el.group_delay2_s};
      e.transmission_time = toe;
      break;
    case Constellation::BeiDou:
      e.iode = index % 256;
      e.iodc = index % 256;
      e.accuracy_m = 2.0;
      e.tgd_s = {el.group_delay_s, el.group_delay2_s};
      e.transmission_time = toe - 1800.0;
      break;
    default:
      e.iode = index % 256;
      e.iodc = e.iode;
      e.accuracy_m = 2.0;
      e.tgd_s = {el.group_delay_s, 0.0};
      e.transmission_time = toe - 3600.0;
      break;
  }
  return e;
}

/// toe values: multiples of `period_s` of the system time from before t_begin - margin to after t_end + margin.
std::vector<GpsTime> record_times(Constellation system, const GpsTime& t_begin, const GpsTime& t_end, double period_s,
                                  double margin_s) {
  const GpsTime ws = system_week_start(system, t_begin - margin_s);
  const double first_s = std::floor(((t_begin - margin_s) - ws) / period_s) * period_s;
  std::vector<GpsTime> times;
  for (double s = first_s; ws + s < t_end + margin_s + period_s; s += period_s) times.push_back(ws + s);
  return times;
}

// ------------------------------------------------------------------------------------------------------------------
// GLONASS records.

/// Position and velocity in the quasi-inertial frame at t (two-body, J2 node regression).
State inertial_state(const Elements& el, double dt_s, double mu) {
  const auto [node_rate, dn] = j2_rates(el, mu);
  const double n = std::sqrt(mu / (el.a_m * el.a_m * el.a_m)) + dn;
  const double m = el.m_rad + n * dt_s;
  double ecc_anomaly = m;
  for (int i = 0; i < 30; ++i)
    ecc_anomaly -= (ecc_anomaly - el.e * std::sin(ecc_anomaly) - m) / (1.0 - el.e * std::cos(ecc_anomaly));
  const double r = el.a_m * (1.0 - el.e * std::cos(ecc_anomaly));
  const double nu = std::atan2(std::sqrt(1.0 - el.e * el.e) * std::sin(ecc_anomaly), std::cos(ecc_anomaly) - el.e);
  const double u = nu + el.omega_rad;
  const double p = el.a_m * (1.0 - el.e * el.e);
  const double h = std::sqrt(mu * p);
  const double vr = mu / h * el.e * std::sin(nu), vt = h / r;
  const Eigen::Vector3d p_orb(r * std::cos(u), r * std::sin(u), 0.0);
  const Eigen::Vector3d v_orb(vr * std::cos(u) - vt * std::sin(u), vr * std::sin(u) + vt * std::cos(u), 0.0);
  const Eigen::Matrix3d rot = (Eigen::AngleAxisd(el.raan_rad + node_rate * dt_s, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(el.i_rad, Eigen::Vector3d::UnitX()))
                                  .toRotationMatrix();
  State x;
  x << rot * p_orb, rot * v_orb;
  return x;
}

/// PZ-90 equations of motion in the rotating frame, no lunisolar term (GLONASS ICD A.3.1.2).
State glonass_rate(const State& x) {
  const double mu = core::kGloMuM3ps2, ae = core::kGloSemiMajorM, we = core::kGloEarthRotationRateRadps;
  const Eigen::Vector3d p = x.head<3>();
  const double r2 = p.squaredNorm(), r = std::sqrt(r2);
  const double c = mu / (r2 * r);
  const double j = 1.5 * core::kGloJ2 * mu * ae * ae / (r2 * r2 * r);
  const double z2 = p.z() * p.z() / r2;
  State d;
  d.head<3>() = x.tail<3>();
  d(3) = -c * p.x() - j * p.x() * (1.0 - 5.0 * z2) + we * we * p.x() + 2.0 * we * x(4);
  d(4) = -c * p.y() - j * p.y() * (1.0 - 5.0 * z2) + we * we * p.y() - 2.0 * we * x(3);
  d(5) = -c * p.z() - j * p.z() * (3.0 - 5.0 * z2);
  return d;
}

State rk4(State x, double dt_s) {
  const int steps = std::max(1, static_cast<int>(std::ceil(std::abs(dt_s) / kGloIntegrationStepS)));
  const double h = dt_s / steps;
  for (int i = 0; i < steps; ++i) {
    const State k1 = glonass_rate(x);
    const State k2 = glonass_rate(x + 0.5 * h * k1);
    const State k3 = glonass_rate(x + 0.5 * h * k2);
    const State k4 = glonass_rate(x + h * k3);
    x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  return x;
}

std::vector<core::GlonassEphemeris> glonass_records(const Elements& el, const GpsTime& t_ref,
                                                    const std::vector<GpsTime>& tbs) {
  // Reference state: inertial elements at t_ref rotated into the Earth-fixed frame (Earth rotation angle measured
  // from t_ref: the absolute sidereal angle only shifts all planes together).
  const State xi = inertial_state(el, 0.0, core::kGloMuM3ps2);
  State x_ref;
  const Eigen::Vector3d w(0.0, 0.0, core::kGloEarthRotationRateRadps);
  x_ref << xi.head<3>(), xi.tail<3>() - w.cross(xi.head<3>());
  std::vector<core::GlonassEphemeris> out;
  // Integrate from t_ref to each tb in order, continuing from the previous tb (the same trajectory throughout).
  State x = x_ref;
  GpsTime t = t_ref;
  for (const GpsTime& tb : tbs) {
    x = rk4(x, tb - t);
    t = tb;
    core::GlonassEphemeris g;
    g.sat = el.sat;
    g.toe = tb;
    g.frame_time = tb - 900.0;
    g.frequency_channel = el.glonass_channel;
    g.p_E_m = x.head<3>();
    g.v_E_mps = x.tail<3>();
    g.tau_n_s = el.clock_s + el.clock_rate_sps * (tb - t_ref);
    g.gamma_n = el.clock_rate_sps;
    out.push_back(g);
  }
  return out;
}

/// tb values (GPST) at hh:15 and hh:45 UTC covering [t_begin - margin, t_end + margin].
std::vector<GpsTime> glonass_times(const GpsTime& t_begin, const GpsTime& t_end, double margin_s) {
  const int leap_s = core::builtin_leap_seconds().gps_minus_utc_at_gps(t_begin);
  // UTC instants k * 1800 + 900 s of the UTC week, expressed in GPST.
  const GpsTime week_start{(t_begin - margin_s).normalized().week, 0.0};
  const double first_utc_s = (t_begin - margin_s) - week_start - leap_s;
  double s = std::floor((first_utc_s - 900.0) / 1800.0) * 1800.0 + 900.0;
  std::vector<GpsTime> times;
  for (; week_start + (s + leap_s) < t_end + margin_s + 1800.0; s += 1800.0) times.push_back(week_start + (s + leap_s));
  return times;
}

std::vector<Elements> all_elements(const ConstellationOptions& options) {
  Rng rng(kElementsSeed);
  // Always drawn in the same order so that a system's elements do not depend on which others are enabled.
  std::vector<Elements> gps = gps_elements(options.gps_satellites, rng);
  std::vector<Elements> glo =
      walker_elements(Constellation::Glonass, options.glonass_satellites, 1, 25508.0e3, 64.8, 251.0, 15.0, rng);
  for (Elements& el : glo) el.glonass_channel = glonass_channel_of_slot(el.sat.prn);
  std::vector<Elements> gal =
      walker_elements(Constellation::Galileo, options.galileo_satellites, 1, 29599.8e3, 56.0, 37.0, 15.0, rng);
  std::vector<Elements> bds =
      walker_elements(Constellation::BeiDou, options.beidou_satellites, 19, 27906.1e3, 55.0, 163.0, 15.0, rng);
  std::vector<Elements> out;
  if (options.use_gps) out.insert(out.end(), gps.begin(), gps.end());
  if (options.use_glonass) out.insert(out.end(), glo.begin(), glo.end());
  if (options.use_galileo) out.insert(out.end(), gal.begin(), gal.end());
  if (options.use_beidou) out.insert(out.end(), bds.begin(), bds.end());
  std::sort(out.begin(), out.end(), [](const Elements& a, const Elements& b) { return a.sat < b.sat; });
  return out;
}

}  // namespace

std::vector<core::SatelliteId> builtin_satellites(const ConstellationOptions& options) {
  std::vector<core::SatelliteId> sats;
  for (const Elements& el : all_elements(options)) sats.push_back(el.sat);
  return sats;
}

core::NavigationData builtin_navigation(const ConstellationOptions& options, core::GpsTime t_begin,
                                        core::GpsTime t_end) {
  // Reference epoch of the elements: the start of the GPS week of t_begin (the same sky for any scenario start).
  const GpsTime t_ref{t_begin.normalized().week, 0.0};
  core::NavigationData nav;
  nav.leap_seconds = core::builtin_leap_seconds().gps_minus_utc_at_gps(t_begin);
  // Klobuchar parameters as broadcast on a quiet mid-latitude day (readers use them for single point positioning).
  nav.gps_klobuchar = core::KlobucharParams{{1.1176e-08, 7.4506e-09, -5.9605e-08, -5.9605e-08},
                                            {9.0112e+04, 4.9152e+04, -1.3107e+05, -3.2768e+05}};
  for (const Elements& el : all_elements(options)) {
    const Constellation system = el.sat.system;
    if (system == Constellation::Glonass) {
      const auto records = glonass_records(el, t_ref, glonass_times(t_begin, t_end, 3600.0));
      nav.glonass.insert(nav.glonass.end(), records.begin(), records.end());
      continue;
    }
    const double period_s = system == Constellation::Gps ? 7200.0 : system == Constellation::Galileo ? 600.0 : 3600.0;
    const double margin_s = system == Constellation::Galileo ? 3600.0 : 7200.0;
    for (const GpsTime& toe : record_times(system, t_begin, t_end, period_s, margin_s)) {
      // Issue of data: the record's number within its week (unique over the records a scenario spans).
      const auto index = static_cast<int>(std::lround((toe - system_week_start(system, toe)) / period_s));
      nav.kepler.push_back(kepler_record(el, t_ref, toe, index));
    }
  }
  return nav;
}

}  // namespace canyon::sim
