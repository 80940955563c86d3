// Satellite position, velocity and clock from broadcast ephemerides, and ephemeris selection.
//
// Kepler orbits: IS-GPS-200 table 20-IV (GPS, and QZSS per IS-QZSS-PNT), Galileo OS SIS ICD 5.1.1, BDS-SIS-ICD-B1I
// 5.2.4.12 (MEO/IGSO as GPS with CGCS2000 constants; GEO computed in an inertial-like frame, then rotated by
// R_Z(omega_e tk) R_X(-5 deg)). Clock: IS-GPS-200 20.3.3.3.3.1 polynomial plus the relativistic term
// F e sqrt(A) sin(E), F = -2 sqrt(mu) / c^2. Velocity and clock drift are central differences over +-1 ms of the
// analytic position and clock (truncation error < 1e-9 m/s, rounding < 1e-5 m/s), one code path for every orbit type.
// GLONASS: GLONASS ICD 5.1 (2008) appendix A.3.1.2, 4th-order Runge-Kutta integration of the PZ-90 equations of
// motion in the rotating frame (central term, J2, centrifugal and Coriolis terms, broadcast lunisolar acceleration
// held constant) in steps of at most 60 s from tb to t; clock = -tau_n + gamma_n (t - tb).

#include "canyon/gnss/ephemeris.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>

#include "canyon/core/constants.hpp"

namespace canyon::gnss {
namespace {

using core::Constellation;
using core::GpsTime;
using core::kSpeedOfLightMps;

constexpr double kGloStepS = 60.0;
constexpr double kDiffStepS = 1e-3;
constexpr double kBdsGeoInclinationRad = -5.0 * core::kDegToRad;
constexpr double kMaxAccuracyM = 6144.0;  // largest URA of IS-GPS-200; used when the accuracy is unknown
constexpr double kUraIndexZeroM = 2.4;    // upper bound of URA index 0 (IS-GPS-200 20.3.3.3.1.3)
constexpr double kGloErrorM = 5.0;        // GLONASS broadcast orbit/clock error assumed (1 sigma)

struct KeplerParams {
  double mu_m3ps2;
  double omega_e_radps;
};

KeplerParams kepler_params(Constellation system) {
  switch (system) {
    case Constellation::Galileo: return {core::kGalMuM3ps2, core::kEarthRotationRateRadps};
    case Constellation::BeiDou: return {core::kBdsMuM3ps2, core::kBdsEarthRotationRateRadps};
    default: return {core::kGpsMuM3ps2, core::kEarthRotationRateRadps};
  }
}

bool is_bds_geo(core::SatelliteId sat) {
  return sat.system == Constellation::BeiDou && (sat.prn <= 5 || sat.prn >= 59);
}

struct PositionClock {
  Eigen::Vector3d p_E_m;
  double clock_s;
};

/// Position (ECEF) and clock bias (with relativity) of a Kepler ephemeris at GPST t.
PositionClock kepler_position_clock(const core::KeplerEphemeris& eph, const GpsTime& t) {
  const KeplerParams k = kepler_params(eph.sat.system);
  const double a_m = eph.sqrt_a_sqrtm * eph.sqrt_a_sqrtm;
  const double tk_s = t - eph.toe;
  const double n_radps = std::sqrt(k.mu_m3ps2 / (a_m * a_m * a_m)) + eph.delta_n_radps;
  const double m_rad = eph.m0_rad + n_radps * tk_s;
  // Kepler's equation M = E - e sin E by Newton iteration.
  double e_rad = m_rad;
  for (int i = 0; i < 30; ++i) {
    const double step = (e_rad - eph.e * std::sin(e_rad) - m_rad) / (1.0 - eph.e * std::cos(e_rad));
    e_rad -= step;
    if (std::abs(step) < 1e-14) break;
  }
  const double sin_e = std::sin(e_rad), cos_e = std::cos(e_rad);
  const double nu_rad = std::atan2(std::sqrt(1.0 - eph.e * eph.e) * sin_e, cos_e - eph.e);
  const double phi_rad = nu_rad + eph.omega_rad;
  const double sin2p = std::sin(2.0 * phi_rad), cos2p = std::cos(2.0 * phi_rad);
  const double u_rad = phi_rad + eph.cus_rad * sin2p + eph.cuc_rad * cos2p;
  const double r_m = a_m * (1.0 - eph.e * cos_e) + eph.crs_m * sin2p + eph.crc_m * cos2p;
  const double i_rad = eph.i0_rad + eph.idot_radps * tk_s + eph.cis_rad * sin2p + eph.cic_rad * cos2p;
  const double x_orb_m = r_m * std::cos(u_rad), y_orb_m = r_m * std::sin(u_rad);
  const double cos_i = std::cos(i_rad), sin_i = std::sin(i_rad);

  Eigen::Vector3d p_E_m;
  if (is_bds_geo(eph.sat)) {
    // BDS-SIS-ICD 5.2.4.12: node in the inertial-like frame, then R_Z(omega_e tk) R_X(-5 deg).
    const double node_rad = eph.omega0_rad + eph.omega_dot_radps * tk_s - k.omega_e_radps * eph.toe_sow_s;
    const double cn = std::cos(node_rad), sn = std::sin(node_rad);
    const Eigen::Vector3d p_gk(x_orb_m * cn - y_orb_m * cos_i * sn, x_orb_m * sn + y_orb_m * cos_i * cn,
                               y_orb_m * sin_i);
    const double cx = std::cos(kBdsGeoInclinationRad), sx = std::sin(kBdsGeoInclinationRad);
    const double z_rad = k.omega_e_radps * tk_s;
    const double cz = std::cos(z_rad), sz = std::sin(z_rad);
    Eigen::Matrix3d r_x, r_z;
    r_x << 1, 0, 0, 0, cx, sx, 0, -sx, cx;
    r_z << cz, sz, 0, -sz, cz, 0, 0, 0, 1;
    p_E_m = r_z * r_x * p_gk;
  } else {
    const double node_rad =
        eph.omega0_rad + (eph.omega_dot_radps - k.omega_e_radps) * tk_s - k.omega_e_radps * eph.toe_sow_s;
    const double cn = std::cos(node_rad), sn = std::sin(node_rad);
    p_E_m = Eigen::Vector3d(x_orb_m * cn - y_orb_m * cos_i * sn, x_orb_m * sn + y_orb_m * cos_i * cn, y_orb_m * sin_i);
  }
  const double tc_s = t - eph.toc;
  const double relativity_s =
      -2.0 * std::sqrt(k.mu_m3ps2 * a_m) * eph.e * sin_e / (kSpeedOfLightMps * kSpeedOfLightMps);
  const double clock_s = eph.af0_s + eph.af1_sps * tc_s + eph.af2_sps2 * tc_s * tc_s + relativity_s;
  return {p_E_m, clock_s};
}

/// Variance of the broadcast orbit and clock from the accuracy field. 0 is what receivers that store the URA
/// *index* write for index 0 (the best class, <= 2.4 m; 125 of 162 records of rtklib-test-gsi-2005 carry it), so it
/// means 2.4 m, not "unknown"; a negative, absurd or beyond-the-table value means no prediction (6144 m).
double kepler_variance_m2(const core::KeplerEphemeris& eph) {
  double acc_m = kMaxAccuracyM;
  if (eph.accuracy_m == 0.0) {
    acc_m = kUraIndexZeroM;
  } else if (eph.accuracy_m > 0.0 && eph.accuracy_m <= kMaxAccuracyM) {
    acc_m = eph.accuracy_m;
  }
  return acc_m * acc_m;
}

/// Time derivative of the GLONASS state (p, v) in PZ-90 (GLONASS ICD A.3.1.2).
Eigen::Matrix<double, 6, 1> glonass_derivative(const Eigen::Matrix<double, 6, 1>& x, const Eigen::Vector3d& a_ls) {
  const double mu = core::kGloMuM3ps2, ae = core::kGloSemiMajorM, j2 = core::kGloJ2;
  const double we = core::kGloEarthRotationRateRadps;
  const double r2 = x.head<3>().squaredNorm();
  const double r = std::sqrt(r2);
  const double mu_r3 = mu / (r2 * r);
  const double j2_term = 1.5 * j2 * mu * ae * ae / (r2 * r2 * r);
  const double z2_r2 = x(2) * x(2) / r2;
  Eigen::Matrix<double, 6, 1> dx;
  dx.head<3>() = x.tail<3>();
  dx(3) = -mu_r3 * x(0) - j2_term * x(0) * (1.0 - 5.0 * z2_r2) + we * we * x(0) + 2.0 * we * x(4) + a_ls(0);
  dx(4) = -mu_r3 * x(1) - j2_term * x(1) * (1.0 - 5.0 * z2_r2) + we * we * x(1) - 2.0 * we * x(3) + a_ls(1);
  dx(5) = -mu_r3 * x(2) - j2_term * x(2) * (3.0 - 5.0 * z2_r2) + a_ls(2);
  return dx;
}

/// The state after whole integration steps from a record's toe, kept per satellite and thread: a record is
/// integrated over up to 15 minutes (15 steps of 4 derivatives) for every state, while consecutive calls share all
/// but the last, partial step. Identified by the record's contents, so a hit is the same arithmetic by construction.
struct GlonassSteps {
  Eigen::Matrix<double, 9, 1> record = Eigen::Matrix<double, 9, 1>::Constant(std::numeric_limits<double>::quiet_NaN());
  double direction = 0.0;  // +1 forward, -1 backward from toe
  int steps = 0;           // whole steps taken
  Eigen::Matrix<double, 6, 1> x = Eigen::Matrix<double, 6, 1>::Zero();
};

Eigen::Matrix<double, 6, 1> rk4_step(const Eigen::Matrix<double, 6, 1>& x, double h, const Eigen::Vector3d& a_ls) {
  const auto k1 = glonass_derivative(x, a_ls);
  const auto k2 = glonass_derivative(x + 0.5 * h * k1, a_ls);
  const auto k3 = glonass_derivative(x + 0.5 * h * k2, a_ls);
  const auto k4 = glonass_derivative(x + h * k3, a_ls);
  return x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
}

/// Runge-Kutta 4 from the record's toe over dt_s: whole steps of kGloStepS, then the remainder (none below a
/// nanosecond). The whole steps already taken for the same record and direction on this thread are reused (`cache`):
/// dt_s - k kGloStepS is exact, so the result is that of integrating from the toe every time.
Eigen::Matrix<double, 6, 1> glonass_integrate(const core::GlonassEphemeris& eph, double dt_s, GlonassSteps& cache) {
  Eigen::Matrix<double, 9, 1> record;
  record << eph.p_E_m, eph.v_E_mps, eph.a_E_mps2;
  const double direction = dt_s < 0.0 ? -1.0 : 1.0;
  auto whole_steps = static_cast<int>(std::floor(std::abs(dt_s) / kGloStepS));
  if (std::abs(dt_s) - kGloStepS * whole_steps < 0.0) --whole_steps;  // the division rounded up to a whole number
  if (std::abs(dt_s) - kGloStepS * whole_steps >= kGloStepS) ++whole_steps;
  if (!(cache.record == record) || cache.direction != direction || cache.steps > whole_steps) {
    cache.record = record;
    cache.direction = direction;
    cache.steps = 0;
    cache.x << eph.p_E_m, eph.v_E_mps;
  }
  for (; cache.steps < whole_steps; ++cache.steps) cache.x = rk4_step(cache.x, direction * kGloStepS, eph.a_E_mps2);
  const double remaining_s = dt_s - direction * kGloStepS * whole_steps;
  return std::abs(remaining_s) > 1e-9 ? rk4_step(cache.x, remaining_s, eph.a_E_mps2) : cache.x;
}

/// Galileo I/NAV record (data source bit 0 E1-B or bit 9 clock for E5b,E1).
bool is_galileo_inav(const core::KeplerEphemeris& eph) {
  return (eph.data_source & 0x201) != 0;
}

double band_frequency_hz(Constellation system, char band) {
  const std::optional<double> f = core::carrier_frequency_hz(system, core::SignalCode{band, 'C'});
  return f.value_or(0.0);
}

/// One T per satellite for the calling thread, made on the thread's first call: on the heap, so that the threads
/// that never compute a satellite state (readers, DDS) do not carry it in their thread-local storage.
template <typename T>
std::array<T, core::kMaxSatellites>& per_thread() {
  thread_local std::unique_ptr<std::array<T, core::kMaxSatellites>> entries;
  if (!entries) entries = std::make_unique<std::array<T, core::kMaxSatellites>>();
  return *entries;
}

std::uint64_t next_selection_stamp() {
  static std::atomic<std::uint64_t> counter{0};
  return counter.fetch_add(1, std::memory_order_relaxed) + 1;
}

/// A satellite's last Kepler selection on this thread, reused while the query time t stays inside the open interval
/// t_ref + (lo_s, hi_s) in which the selection cannot change. A selection is asked for three or four times per
/// satellite and epoch (transmission time, state, group delay; rover and base) and changes every few minutes at most.
struct KeplerSelectionMemo {
  std::uint64_t stamp = 0;  // the store's selection_stamp_ when made; 0: empty
  core::GpsTime t_ref;
  double lo_s = 0.0;
  double hi_s = 0.0;
  int index = -1;  // into the store's nav().kepler, -1: none usable
};

/// Margin kept from the ends of a memo's interval, where the rounding of time differences could decide.
constexpr double kSelectionMemoMarginS = 1e-6;

/// Health as it concerns canyon's signals. QZSS LNAV's health word has the L1C/B (formerly LEX) signal in its least
/// significant bit (IS-QZSS-PNT), set on satellites that do not transmit it: it says nothing about L1 C/A, L2C or
/// L5, so it is ignored.
bool kepler_healthy(const core::KeplerEphemeris& e) {
  const int relevant = e.sat.system == Constellation::Qzss ? (e.health & ~0x01) : e.health;
  return relevant == 0;
}

}  // namespace

EphemerisStore::EphemerisStore(core::NavigationData nav, EphemerisOptions options)
    : nav_(std::move(nav)), options_(options), selection_stamp_(next_selection_stamp()) {
  kepler_by_sat_.resize(core::kMaxSatellites);
  glonass_by_sat_.resize(core::kMaxSatellites);
  for (int i = 0; i < static_cast<int>(nav_.kepler.size()); ++i) index_kepler(i);
  for (int i = 0; i < static_cast<int>(nav_.glonass.size()); ++i) index_glonass(i);
}

void EphemerisStore::index_kepler(int i) {
  const core::KeplerEphemeris& e = nav_.kepler[static_cast<std::size_t>(i)];
  if (!e.sat.valid() || (!kepler_healthy(e) && !options_.use_unhealthy)) return;
  const double fit_s = e.fit_interval_h > 0.0 ? e.fit_interval_h * 3600.0 / 2.0 : 0.0;
  kepler_by_sat_[e.sat.index()].push_back(
      KeplerCandidate{e.toe, e.transmission_time, std::max(options_.max_age_kepler_s, fit_s), i, is_galileo_inav(e)});
}

void EphemerisStore::index_glonass(int i) {
  const core::GlonassEphemeris& e = nav_.glonass[static_cast<std::size_t>(i)];
  if (e.sat.valid()) glonass_by_sat_[e.sat.index()].push_back(i);
}

int EphemerisStore::add(const core::NavigationData& fresh) {
  int added = 0;
  for (const core::KeplerEphemeris& e : fresh.kepler) {
    const bool held = std::any_of(nav_.kepler.begin(), nav_.kepler.end(), [&e](const core::KeplerEphemeris& h) {
      return h.sat == e.sat && h.toe == e.toe && h.iode == e.iode && is_galileo_inav(h) == is_galileo_inav(e);
    });
    if (held) continue;
    nav_.kepler.push_back(e);
    index_kepler(static_cast<int>(nav_.kepler.size()) - 1);
    ++added;
  }
  for (const core::GlonassEphemeris& e : fresh.glonass) {
    const bool held = std::any_of(nav_.glonass.begin(), nav_.glonass.end(),
                                  [&e](const core::GlonassEphemeris& h) { return h.sat == e.sat && h.toe == e.toe; });
    if (held) continue;
    nav_.glonass.push_back(e);
    index_glonass(static_cast<int>(nav_.glonass.size()) - 1);
    ++added;
  }
  if (added > 0) selection_stamp_ = next_selection_stamp();
  if (!nav_.gps_klobuchar) nav_.gps_klobuchar = fresh.gps_klobuchar;
  if (!nav_.bds_klobuchar) nav_.bds_klobuchar = fresh.bds_klobuchar;
  return added;
}

const core::KeplerEphemeris* EphemerisStore::select_kepler(core::SatelliteId sat, core::GpsTime t) const {
  if (!sat.valid() || sat.system == Constellation::Glonass) return nullptr;
  KeplerSelectionMemo& memo = per_thread<KeplerSelectionMemo>()[sat.index()];
  const double since_ref_s = t - memo.t_ref;
  if (memo.stamp != selection_stamp_ || !(since_ref_s > memo.lo_s && since_ref_s < memo.hi_s)) {
    const int index = scan_kepler(sat, t);
    const auto [lo_s, hi_s] = kepler_selection_interval(sat, t, index);
    memo = {selection_stamp_, t, lo_s + kSelectionMemoMarginS, hi_s - kSelectionMemoMarginS, index};
  }
  return memo.index >= 0 ? &nav_.kepler[static_cast<std::size_t>(memo.index)] : nullptr;
}

int EphemerisStore::scan_kepler(core::SatelliteId sat, core::GpsTime t) const {
  const bool galileo = sat.system == Constellation::Galileo;
  const KeplerCandidate* best = nullptr;
  double best_age_s = 0.0;
  for (const KeplerCandidate& c : kepler_by_sat_[sat.index()]) {  // usable health only
    // Galileo: only an ephemeris whose toe has passed (age of data > 0), the rule RTKLIB 2.4.3 applies; Galileo
    // toe is at the start of the record's validity, so a future toe means a record not broadcast yet.
    if (galileo && !(c.toe < t)) continue;
    const double age_s = std::abs(t - c.toe);
    if (age_s > c.max_age_s) continue;
    if (best != nullptr) {
      // Galileo: I/NAV is preferred to F/NAV whatever their ages (the I/NAV clock is referenced to E1/E5b, the
      // signals canyon pairs first).
      if (galileo && best->galileo_inav != c.galileo_inav) {
        if (!c.galileo_inav) continue;
      } else if (age_s > best_age_s || (age_s == best_age_s && c.transmission_time < best->transmission_time)) {
        // Nearest toe; on equal distance, the most recently transmitted message.
        continue;
      }
    }
    best = &c;
    best_age_s = age_s;
  }
  return best != nullptr ? best->index : -1;
}

/// The scan's outcome is a function of which candidates are eligible and of how each compares with the chosen one.
/// Eligibility changes only where t crosses a candidate's toe +- its maximum age (Galileo: also its toe); the
/// comparison of two records of different toes only where their ages are equal, at the midpoint of the toes (the
/// I/NAV preference and the tie on equal toes do not depend on t). So the outcome is constant between the nearest
/// such times on either side of t; the interval is empty when t is one of them.
std::pair<double, double> EphemerisStore::kepler_selection_interval(core::SatelliteId sat, core::GpsTime t,
                                                                    int index) const {
  const bool galileo = sat.system == Constellation::Galileo;
  double lo_s = -std::numeric_limits<double>::infinity();
  double hi_s = std::numeric_limits<double>::infinity();
  const auto limit = [&](double offset_s) {
    if (offset_s >= 0.0) hi_s = std::min(hi_s, offset_s);
    if (offset_s <= 0.0) lo_s = std::max(lo_s, offset_s);
  };
  const bool chosen = index >= 0;
  const double chosen_toe_s = chosen ? nav_.kepler[static_cast<std::size_t>(index)].toe - t : 0.0;
  for (const KeplerCandidate& c : kepler_by_sat_[sat.index()]) {
    const double toe_s = c.toe - t;
    if (galileo) limit(toe_s);
    limit(toe_s - c.max_age_s);
    limit(toe_s + c.max_age_s);
    if (chosen && toe_s != chosen_toe_s) limit(0.5 * (toe_s + chosen_toe_s));
  }
  return {lo_s, hi_s};
}

const core::GlonassEphemeris* EphemerisStore::select_glonass(core::SatelliteId sat, core::GpsTime t) const {
  if (!sat.valid() || sat.system != Constellation::Glonass) return nullptr;
  const core::GlonassEphemeris* best = nullptr;
  double best_age_s = 0.0;
  for (const int i : glonass_by_sat_[sat.index()]) {
    const core::GlonassEphemeris& g = nav_.glonass[i];
    if (g.health != 0 && !options_.use_unhealthy) continue;
    const double age_s = std::abs(t - g.toe);
    if (age_s > options_.max_age_glonass_s) continue;
    if (best != nullptr && (age_s > best_age_s || (age_s == best_age_s && g.frame_time < best->frame_time))) continue;
    best = &g;
    best_age_s = age_s;
  }
  return best;
}

std::optional<SatelliteState> EphemerisStore::state(core::SatelliteId sat, core::GpsTime t_tx,
                                                    bool with_velocity) const {
  SatelliteState s;
  s.sat = sat;
  if (sat.system == Constellation::Glonass) {
    const core::GlonassEphemeris* g = select_glonass(sat, t_tx);
    if (g == nullptr) return std::nullopt;
    const double dt_s = t_tx - g->toe;
    const Eigen::Matrix<double, 6, 1> x = glonass_integrate(*g, dt_s, per_thread<GlonassSteps>()[sat.index()]);
    s.p_E_m = x.head<3>();
    s.v_E_mps = x.tail<3>();
    s.clock_bias_s = g->tau_n_s + g->gamma_n * dt_s;
    s.clock_drift_sps = g->gamma_n;
    s.variance_m2 = kGloErrorM * kGloErrorM;
    s.glonass_channel = g->frequency_channel;
    return s;
  }
  const core::KeplerEphemeris* e = select_kepler(sat, t_tx);
  if (e == nullptr) return std::nullopt;
  // Velocity and clock drift by a forward difference over 1 ms: the truncation error (acceleration x step / 2,
  // about 0.3 mm/s) is far below what Doppler can use, and it costs one orbit evaluation instead of two.
  const PositionClock now = kepler_position_clock(*e, t_tx);
  s.p_E_m = now.p_E_m;
  s.clock_bias_s = now.clock_s;
  if (with_velocity) {
    const PositionClock after = kepler_position_clock(*e, t_tx + kDiffStepS);
    s.v_E_mps = (after.p_E_m - now.p_E_m) / kDiffStepS;
    s.clock_drift_sps = (after.clock_s - now.clock_s) / kDiffStepS;
  }
  s.variance_m2 = kepler_variance_m2(*e);
  s.iode = e->iode;
  return s;
}

std::optional<double> EphemerisStore::clock_polynomial_s(core::SatelliteId sat, core::GpsTime t) const {
  if (sat.system == Constellation::Glonass) {
    const core::GlonassEphemeris* g = select_glonass(sat, t);
    if (g == nullptr) return std::nullopt;
    return g->tau_n_s + g->gamma_n * (t - g->toe);
  }
  const core::KeplerEphemeris* e = select_kepler(sat, t);
  if (e == nullptr) return std::nullopt;
  const double tc_s = t - e->toc;
  return e->af0_s + e->af1_sps * tc_s + e->af2_sps2 * tc_s * tc_s;
}

std::optional<SatelliteState> EphemerisStore::state_at_reception(core::SatelliteId sat, core::GpsTime t_rx,
                                                                 double pseudorange_m, core::GpsTime* t_tx,
                                                                 bool with_velocity) const {
  // The transmission time needs the satellite clock to ~1e-7 s (3 cm of orbit motion at most); the clock
  // polynomial without the relativistic term (< 5e-8 s) gives that, in two fixed-point steps, without any orbit
  // evaluation. The full state is then computed once.
  const GpsTime t_signal = t_rx - pseudorange_m / kSpeedOfLightMps;
  GpsTime t = t_signal;
  for (int i = 0; i < 2; ++i) {
    const auto clock_s = clock_polynomial_s(sat, t);
    if (!clock_s) return std::nullopt;
    t = t_signal - *clock_s;
  }
  auto s = state(sat, t, with_velocity);
  if (s && t_tx != nullptr) *t_tx = t;
  return s;
}

double EphemerisStore::group_delay_s(core::SatelliteId sat, core::SignalCode signal, core::GpsTime t) const {
  if (sat.system == Constellation::Glonass) return 0.0;
  const core::KeplerEphemeris* e = select_kepler(sat, t);
  if (e == nullptr) return 0.0;
  const double f_hz = band_frequency_hz(sat.system, signal.band);
  if (f_hz <= 0.0) return 0.0;
  switch (sat.system) {
    case Constellation::Gps:
    case Constellation::Qzss: {
      const double ratio = band_frequency_hz(sat.system, '1') / f_hz;
      return e->tgd_s[0] * ratio * ratio;
    }
    case Constellation::Galileo: {
      const double ratio = band_frequency_hz(sat.system, '1') / f_hz;
      const double bgd_s = is_galileo_inav(*e) ? e->tgd_s[1] : e->tgd_s[0];
      return bgd_s * ratio * ratio;
    }
    case Constellation::BeiDou:
      if (signal.band == '2') return e->tgd_s[0];
      if (signal.band == '7') return e->tgd_s[1];
      return 0.0;
    default: return 0.0;
  }
}

int EphemerisStore::glonass_channel(int slot) const {
  return nav_.glonass_channel(slot);
}

double geometric_range_m(const Eigen::Vector3d& p_E_sat, const Eigen::Vector3d& p_E_rcv, Eigen::Vector3d* los_E) {
  const Eigen::Vector3d d = p_E_sat - p_E_rcv;
  const double norm_m = d.norm();
  if (los_E != nullptr) *los_E = norm_m > 0.0 ? Eigen::Vector3d(d / norm_m) : Eigen::Vector3d::Zero();
  // Sagnac: first-order term of rotating p_E_sat by omega_e * range / c about Z (IS-GPS-200 20.3.3.4.3.4 note;
  // the second-order remainder is below 1 mm).
  const double sagnac_m =
      core::kEarthRotationRateRadps * (p_E_sat.x() * p_E_rcv.y() - p_E_sat.y() * p_E_rcv.x()) / kSpeedOfLightMps;
  return norm_m + sagnac_m;
}

}  // namespace canyon::gnss
