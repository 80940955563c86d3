// Single-point positioning: weighted least squares on pseudoranges with one receiver clock per constellation,
// RAIM fault detection and exclusion, DOP, and velocity from Doppler. The model is stated in spp.hpp.

#include "canyon/gnss/spp.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <string_view>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/gnss/atmosphere.hpp"

namespace canyon::gnss {
namespace {

using core::Constellation;
using core::SatelliteId;

constexpr int kNumClocks = core::kNumConstellations;
constexpr double kMinSinElevation = 0.05;  // floor for the elevation weighting near the horizon

/// One pseudorange measurement prepared for the least squares.
struct Measurement {
  SatelliteId sat;
  int clock = 0;  // index of the receiver clock this measurement depends on
  double pseudorange_m = 0.0;
  double doppler_hz = core::kNoValue;
  double wavelength_m = 0.0;
  double group_delay_m = 0.0;
  double iono_scale = 1.0;  // (f_L1 / f)^2: Klobuchar is an L1 delay
  SatelliteState state;
  // Atmosphere delays and the position they were computed at: they change by millimetres over 100 m, so they are
  // refreshed only when the position estimate moves further (a large saving in the iterations).
  mutable Eigen::Vector3d atmosphere_p_E_m = Eigen::Vector3d::Zero();
  mutable double iono_m = 0.0;
  mutable double tropo_m = 0.0;
};

constexpr double kAtmosphereRefreshM = 100.0;
/// Position steps below this may converge without another linearisation (see iterate()).
constexpr double kShortcutStepM = 100.0;

/// RAIM solves exactly only the exclusions whose first-order weighted residual sum is within this fraction of
/// (1 + the least such sum): the others cannot be the best (see leave_one_out_sums()).
constexpr double kExclusionScreenMargin = 0.05;

/// Linearised system at one position.
struct Linearised {
  Eigen::MatrixXd H;                           // n x (3 + clocks in use)
  Eigen::VectorXd v;                           // residuals (m)
  Eigen::VectorXd range_m;                     // geometric range of each row at the position (m)
  Eigen::VectorXd variance;                    // per measurement (m^2)
  std::vector<int> rows;                       // measurement index of each row
  std::array<int, kNumClocks> clock_column{};  // column of each clock, -1 if unused
  int num_clocks = 0;
  bool have_position = false;  // the position was on the ground: elevation mask and atmosphere applied
};

int clock_index(Constellation system, const SppOptions& o) {
  if (system == Constellation::Qzss && !o.qzss_own_clock) return static_cast<int>(Constellation::Gps);
  return static_cast<int>(system);
}

std::vector<Measurement> prepare_measurements(const core::ObsEpoch& epoch, const EphemerisStore& eph,
                                              const SppOptions& options, EpochSatelliteStates& states) {
  std::vector<Measurement> out;
  out.reserve(epoch.sats.size());
  for (const core::SatelliteObs& sat_obs : epoch.sats) {
    if (!options.uses(sat_obs.sat.system)) continue;
    if (std::find(options.excluded.begin(), options.excluded.end(), sat_obs.sat) != options.excluded.end()) continue;
    const core::SignalObs* signal = spp_signal(sat_obs);
    if (signal == nullptr) continue;
    const bool with_velocity = core::has_value(signal->doppler_hz);  // satellite velocity serves Doppler only
    const auto state = states.at_reception(sat_obs.sat, signal->pseudorange_m, with_velocity);
    if (!state) continue;
    const int channel =
        sat_obs.sat.system == Constellation::Glonass ? eph.glonass_channel(sat_obs.sat.prn) : core::kNoGlonassChannel;
    const auto frequency = core::carrier_frequency_hz(sat_obs.sat.system, signal->code, channel);
    Measurement m;
    m.sat = sat_obs.sat;
    m.clock = clock_index(sat_obs.sat.system, options);
    m.pseudorange_m = signal->pseudorange_m;
    m.doppler_hz = signal->doppler_hz;
    m.wavelength_m = frequency ? core::kSpeedOfLightMps / *frequency : 0.0;
    m.iono_scale = frequency ? std::pow(1575.42e6 / *frequency, 2) : 1.0;
    m.group_delay_m = core::kSpeedOfLightMps * eph.group_delay_s(sat_obs.sat, signal->code, epoch.time);
    m.state = *state;
    m.atmosphere_p_E_m.setConstant(1e9);  // never computed
    out.push_back(m);
  }
  return out;
}

/// Builds H, v and variances at position x (3 + kNumClocks), skipping measurements below the mask and excluded
/// ones. `have_position` false means x is not yet a position on the ground: no mask, no atmosphere.
Linearised linearise(const std::vector<Measurement>& ms, const std::vector<bool>& active, const Eigen::VectorXd& x,
                     const core::GpsTime& t, const EphemerisStore& eph, const SppOptions& options) {
  const Eigen::Vector3d p_E = x.head<3>();
  const bool have_position = p_E.norm() > 6.0e6 && p_E.norm() < 7.0e6;
  const core::Geodetic rcv = core::ecef_to_geodetic(p_E);
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(rcv);
  const core::KlobucharParams klob = eph.nav().gps_klobuchar.value_or(default_klobuchar());

  Linearised lin;
  lin.clock_column.fill(-1);
  lin.have_position = have_position;
  using Row = Eigen::Matrix<double, 1, 3 + kNumClocks>;
  std::vector<Row> rows;
  std::vector<double> residuals;
  std::vector<double> ranges;
  std::vector<double> variances;
  rows.reserve(ms.size());
  residuals.reserve(ms.size());
  ranges.reserve(ms.size());
  variances.reserve(ms.size());
  lin.rows.reserve(ms.size());
  for (std::size_t i = 0; i < ms.size(); ++i) {
    if (!active[i]) continue;
    const Measurement& m = ms[i];
    Eigen::Vector3d los_E;
    const double range_m = geometric_range_m(m.state.p_E_m, p_E, &los_E);
    double sin_el = 1.0;
    double iono_m = 0.0;
    double tropo_m = 0.0;
    if (have_position) {
      const Eigen::Vector3d los_N = R_NE * los_E;
      const double elevation_rad = core::elevation_from_enu(los_N);  // the azimuth only for a refresh
      if (elevation_rad < options.elevation_mask_rad) continue;
      sin_el = std::max(std::sin(elevation_rad), kMinSinElevation);
      if ((m.atmosphere_p_E_m - p_E).squaredNorm() > kAtmosphereRefreshM * kAtmosphereRefreshM) {
        const core::AzEl azel = core::azimuth_elevation_from_enu(los_N);
        m.iono_m = options.ionosphere_klobuchar ? m.iono_scale * klobuchar_delay_m(t, rcv, azel, klob) : 0.0;
        m.tropo_m = options.troposphere_saastamoinen ? saastamoinen_delay_m(rcv, azel.elevation_rad) : 0.0;
        m.atmosphere_p_E_m = p_E;
      }
      iono_m = m.iono_m;
      tropo_m = m.tropo_m;
    }
    if (lin.clock_column[static_cast<std::size_t>(m.clock)] < 0) {
      lin.clock_column[static_cast<std::size_t>(m.clock)] = lin.num_clocks++;
    }
    const double clock_m = x[3 + m.clock];
    const double predicted_m =
        range_m + clock_m - core::kSpeedOfLightMps * m.state.clock_bias_s + m.group_delay_m + iono_m + tropo_m;
    Row row = Row::Zero();
    row.head<3>() = -los_E.transpose();
    row[3 + m.clock] = 1.0;
    rows.push_back(row);
    residuals.push_back(m.pseudorange_m - predicted_m);
    ranges.push_back(range_m);
    const double sigma2 = options.code_sigma_m * options.code_sigma_m * (1.0 + 1.0 / (sin_el * sin_el));
    const double iono_var = options.ionosphere_klobuchar ? std::pow(0.5 * iono_m, 2) : std::pow(5.0 * m.iono_scale, 2);
    const double tropo_var = options.troposphere_saastamoinen ? std::pow(0.3 / (sin_el + 0.1), 2) : 6.25;
    variances.push_back(sigma2 + m.state.variance_m2 + iono_var + tropo_var);
    lin.rows.push_back(static_cast<int>(i));
  }
  // Compress the clock columns to those in use.
  const int n = static_cast<int>(rows.size());
  lin.H.resize(n, 3 + lin.num_clocks);
  lin.v.resize(n);
  lin.range_m.resize(n);
  lin.variance.resize(n);
  for (int r = 0; r < n; ++r) {
    lin.H.row(r).head<3>() = rows[static_cast<std::size_t>(r)].head<3>();
    lin.H.row(r).tail(lin.num_clocks).setZero();
    for (int c = 0; c < kNumClocks; ++c) {
      const int column = lin.clock_column[static_cast<std::size_t>(c)];
      if (column >= 0) lin.H(r, 3 + column) = rows[static_cast<std::size_t>(r)][3 + c];
    }
    lin.v[r] = residuals[static_cast<std::size_t>(r)];
    lin.range_m[r] = ranges[static_cast<std::size_t>(r)];
    lin.variance[r] = variances[static_cast<std::size_t>(r)];
  }
  return lin;
}

/// Chi-square quantile for p = 0.999 (Wilson-Hilferty approximation; within 3 % of the exact value for dof >= 1).
double chi_square_999(int dof) {
  constexpr double kZ999 = 3.090232;
  const double k = dof;
  const double a = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - a + kZ999 * std::sqrt(a), 3);
}

struct Fix {
  Eigen::VectorXd x;  // 3 + kNumClocks
  Linearised lin;
  Eigen::MatrixXd Q;  // (H' W H)^-1
  double weighted_sum = 0.0;
  int iterations = 0;
};

/// x += dx, dx over the position and the clocks in use (columns of lin).
void apply_step(const Linearised& lin, const Eigen::VectorXd& dx, Eigen::VectorXd& x) {
  x.head<3>() += dx.head<3>();
  for (int c = 0; c < kNumClocks; ++c) {
    const int column = lin.clock_column[static_cast<std::size_t>(c)];
    if (column >= 0) x[3 + c] += dx[3 + column];
  }
}

/// The converged fix from lin (linearised before the last step dx), x after dx, and the residuals at x.
Fix converged(Linearised lin, const Eigen::VectorXd& x, Eigen::VectorXd residuals,
              const Eigen::LDLT<Eigen::MatrixXd>& ldlt, int iterations) {
  Fix fix;
  const auto m = lin.H.cols();
  lin.v = std::move(residuals);
  fix.lin = std::move(lin);
  fix.x = x;
  fix.Q = ldlt.solve(Eigen::MatrixXd::Identity(m, m));
  fix.weighted_sum = fix.lin.v.dot(fix.lin.v.cwiseQuotient(fix.lin.variance));
  fix.iterations = iterations;
  return fix;
}

/// The residuals at x after the step dx from where lin was linearised, when the next linearisation would give the
/// same rows, atmosphere delays and weights to within 1e-5 of themselves: a step shorter than kShortcutStepM from a
/// position on the ground (e.g. the last epoch's) that leaves every satellite's atmosphere delays unrefreshed
/// (kAtmosphereRefreshM) moves each line of sight and elevation by less than 1e-5 rad. The next Gauss-Newton step
/// is then, to within that, the one on lin's H and weights with these residuals, and needs only the ranges at x:
/// when that step converges the iteration ends without linearising again. The position then differs from a full
/// iteration's by about (step / range) x (residuals) x DOP: nothing on noise-free data, some micrometres with metres
/// of code residuals, far below what a single point resolves. nullopt otherwise.
std::optional<Eigen::VectorXd> residuals_after_short_step(const std::vector<Measurement>& ms, const Linearised& lin,
                                                          const Eigen::VectorXd& dx, const Eigen::VectorXd& x) {
  if (!lin.have_position || dx.head<3>().norm() >= kShortcutStepM) return std::nullopt;
  const Eigen::Vector3d p_E = x.head<3>();
  Eigen::VectorXd residuals = lin.v - lin.H.rightCols(lin.num_clocks) * dx.tail(lin.num_clocks);
  for (Eigen::Index r = 0; r < residuals.size(); ++r) {
    const Measurement& m = ms[static_cast<std::size_t>(lin.rows[static_cast<std::size_t>(r)])];
    if ((m.atmosphere_p_E_m - p_E).squaredNorm() > kAtmosphereRefreshM * kAtmosphereRefreshM) return std::nullopt;
    residuals[r] -= geometric_range_m(m.state.p_E_m, p_E) - lin.range_m[r];
  }
  return residuals;
}

/// Gauss-Newton iterations over the active measurements. Error string if it fails.
Result<Fix> iterate(const std::vector<Measurement>& ms, const std::vector<bool>& active, Eigen::VectorXd x,
                    const core::GpsTime& t, const EphemerisStore& eph, const SppOptions& options) {
  for (int it = 1; it <= options.max_iterations; ++it) {
    Linearised lin = linearise(ms, active, x, t, eph, options);
    const int n = static_cast<int>(lin.v.size());
    const int m = 3 + lin.num_clocks;
    if (n < m || lin.num_clocks == 0) {
      return Error{"too few satellites: " + std::to_string(n) + " usable for " + std::to_string(m) + " unknowns"};
    }
    const Eigen::VectorXd w = lin.variance.cwiseInverse();
    const Eigen::MatrixXd HtW = lin.H.transpose() * w.asDiagonal();
    const Eigen::MatrixXd N = HtW * lin.H;
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(N);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return Error{"singular geometry"};
    const Eigen::VectorXd dx = ldlt.solve(HtW * lin.v);
    apply_step(lin, dx, x);
    if (dx.norm() < options.convergence_m) {
      // Residuals at the solution: after a step this small the linearisation is exact to well below a micrometre
      // and the elevation mask cannot change the set, so v - H dx replaces another linearisation.
      Eigen::VectorXd residuals = lin.v - lin.H * dx;
      return converged(std::move(lin), x, std::move(residuals), ldlt, it);
    }
    if (it == options.max_iterations) break;
    if (auto residuals = residuals_after_short_step(ms, lin, dx, x)) {
      const Eigen::VectorXd next = ldlt.solve(HtW * *residuals);
      if (next.norm() < options.convergence_m) {
        apply_step(lin, next, x);
        *residuals -= lin.H * next;
        return converged(std::move(lin), x, std::move(*residuals), ldlt, it + 1);
      }
    }
  }
  return Error{"no convergence in " + std::to_string(options.max_iterations) + " iterations"};
}

/// First-order weighted residual sum of the solution without row r, for every row: at the converged solution,
/// least squares' deletion formula WSSR_r = WSSR - w_r v_r^2 / (1 - w_r h_r^T Q h_r). Leaving out a satellite moves
/// the solution by metres at most, where the ranges' curvature and the elevation weights change the sum by far less
/// than kExclusionScreenMargin. -inf where the row is the last of its clock (leverage 1: the clock leaves with it,
/// which the formula does not describe), so that exclusion is always solved.
std::vector<double> leave_one_out_sums(const Fix& fix) {
  const Linearised& lin = fix.lin;
  std::vector<double> sums(lin.rows.size());
  for (Eigen::Index r = 0; r < lin.H.rows(); ++r) {
    const double w = 1.0 / lin.variance[r];
    const double leverage = w * lin.H.row(r).dot(fix.Q * lin.H.row(r).transpose());
    sums[static_cast<std::size_t>(r)] = leverage < 1.0 - 1e-9
                                            ? fix.weighted_sum - w * lin.v[r] * lin.v[r] / (1.0 - leverage)
                                            : -std::numeric_limits<double>::infinity();
  }
  return sums;
}

bool passes_chi_square(const Fix& fix) {
  const int dof = static_cast<int>(fix.lin.v.size()) - static_cast<int>(fix.lin.H.cols());
  return dof <= 0 || fix.weighted_sum < chi_square_999(dof);
}

Dop compute_dop(const Linearised& lin, const Eigen::Vector3d& p_E) {
  // DOP from the unweighted geometry in ENU.
  const core::Geodetic g = core::ecef_to_geodetic(p_E);
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(g);
  Eigen::MatrixXd G = lin.H;
  G.leftCols<3>() = lin.H.leftCols<3>() * R_NE.transpose();
  const Eigen::MatrixXd Q = (G.transpose() * G).inverse();
  Dop d;
  d.gdop = std::sqrt(Q.trace());
  d.pdop = std::sqrt(Q(0, 0) + Q(1, 1) + Q(2, 2));
  d.hdop = std::sqrt(Q(0, 0) + Q(1, 1));
  d.vdop = std::sqrt(Q(2, 2));
  return d;
}

/// Velocity and clock drift from Doppler of the measurements used in the fix.
std::optional<Eigen::Vector3d> solve_velocity(const std::vector<Measurement>& ms, const Linearised& lin,
                                              const Eigen::Vector3d& p_E) {
  std::vector<int> rows;
  for (const int row : lin.rows) {
    const Measurement& m = ms[static_cast<std::size_t>(row)];
    if (core::has_value(m.doppler_hz) && m.wavelength_m > 0.0) rows.push_back(row);
  }
  if (rows.size() < 5) return std::nullopt;  // 4 unknowns and at least one check
  Eigen::VectorXd x = Eigen::VectorXd::Zero(4);
  for (int it = 0; it < 5; ++it) {
    Eigen::MatrixXd H(rows.size(), 4);
    Eigen::VectorXd v(rows.size());
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const Measurement& m = ms[static_cast<std::size_t>(rows[r])];
      Eigen::Vector3d los_E;
      (void)geometric_range_m(m.state.p_E_m, p_E, &los_E);
      const Eigen::Vector3d& vs = m.state.v_E_mps;
      const Eigen::Vector3d vr = x.head<3>();
      // Range rate with the Earth-rotation term of the Sagnac correction.
      const double rate = los_E.dot(vs - vr) + core::kEarthRotationRateRadps / core::kSpeedOfLightMps *
                                                   (vs.y() * p_E.x() + m.state.p_E_m.y() * vr.x() - vs.x() * p_E.y() -
                                                    m.state.p_E_m.x() * vr.y());
      const double observed = -m.wavelength_m * m.doppler_hz;
      v[static_cast<Eigen::Index>(r)] = observed - (rate + x[3] - core::kSpeedOfLightMps * m.state.clock_drift_sps);
      H.row(static_cast<Eigen::Index>(r)) << -los_E.transpose(), 1.0;
    }
    const Eigen::VectorXd dx = (H.transpose() * H).ldlt().solve(H.transpose() * v);
    x += dx;
    if (dx.norm() < 1e-6) break;
  }
  if (!x.allFinite()) return std::nullopt;
  return Eigen::Vector3d(x.head<3>());
}

}  // namespace

std::string SppOptions::validate() const {
  if (!(elevation_mask_rad >= 0.0 && elevation_mask_rad < core::kPi / 2.0)) {
    return "elevation_mask_rad must be in [0, pi/2)";
  }
  if (!(code_sigma_m > 0.0)) return "code_sigma_m must be > 0";
  if (max_iterations < 1) return "max_iterations must be >= 1";
  if (!(convergence_m > 0.0)) return "convergence_m must be > 0";
  if (!(max_gdop > 0.0)) return "max_gdop must be > 0";
  if (!any()) return "at least one system must be used";
  return {};
}

Result<SppSolution> solve_spp(const core::ObsEpoch& epoch, const EphemerisStore& ephemerides, const SppOptions& options,
                              const std::optional<Eigen::Vector3d>& initial_p_E_m, EpochSatelliteStates* states) {
  assert(states == nullptr || (states->receive_time() == epoch.time && &states->ephemerides() == &ephemerides));
  std::optional<EpochSatelliteStates> own_states;
  if (states == nullptr) states = &own_states.emplace(ephemerides, epoch.time);
  const std::vector<Measurement> ms = prepare_measurements(epoch, ephemerides, options, *states);
  if (ms.size() < 4) {
    return Error{"too few satellites with pseudorange and ephemeris: " + std::to_string(ms.size())};
  }
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(3 + kNumClocks);
  if (initial_p_E_m) x0.head<3>() = *initial_p_E_m;

  std::vector<bool> active(ms.size(), true);
  auto fix = iterate(ms, active, x0, epoch.time, ephemerides, options);
  if (!fix) return fix.error();

  std::vector<SatelliteId> excluded_by_raim;
  if (options.raim_fde && !passes_chi_square(*fix) && fix->lin.v.size() >= fix->lin.H.cols() + 2) {
    // Try the single exclusions that can give the least weighted sum, each solved from the converged position; keep
    // the best that passes.
    const std::vector<double> approximate = leave_one_out_sums(*fix);
    double least = std::numeric_limits<double>::infinity();
    for (const double sum : approximate) {
      if (std::isfinite(sum)) least = std::min(least, sum);
    }
    std::optional<Fix> best;
    std::size_t best_excluded = 0;
    for (std::size_t row = 0; row < fix->lin.rows.size(); ++row) {
      if (std::isfinite(approximate[row]) && approximate[row] > least + kExclusionScreenMargin * (1.0 + least)) {
        continue;  // cannot be the best
      }
      const int row_measurement = fix->lin.rows[row];
      std::vector<bool> trial = active;
      trial[static_cast<std::size_t>(row_measurement)] = false;
      auto candidate = iterate(ms, trial, fix->x, epoch.time, ephemerides, options);
      if (!candidate || !passes_chi_square(*candidate)) continue;
      if (!best || candidate->weighted_sum < best->weighted_sum) {
        best = std::move(candidate.value());
        best_excluded = static_cast<std::size_t>(row_measurement);
      }
    }
    if (best) {
      excluded_by_raim.push_back(ms[best_excluded].sat);
      fix = std::move(*best);
    }
  }

  SppSolution sol;
  sol.receiver_time = epoch.time;
  sol.p_E_m = fix->x.head<3>();
  sol.P_E_m2 = fix->Q.topLeftCorner<3, 3>();
  sol.dop = compute_dop(fix->lin, sol.p_E_m);
  if (sol.dop.gdop > options.max_gdop) {
    return Error{"GDOP " + std::to_string(sol.dop.gdop) + " exceeds " + std::to_string(options.max_gdop)};
  }
  double reference_clock_m = 0.0;
  bool have_reference = false;
  for (int c = 0; c < kNumClocks; ++c) {
    if (fix->lin.clock_column[static_cast<std::size_t>(c)] < 0) continue;
    sol.clock_bias_m.emplace_back(static_cast<Constellation>(c), fix->x[3 + c]);
    if (!have_reference) {
      reference_clock_m = fix->x[3 + c];  // GPS first when present (enum order)
      have_reference = true;
    }
  }
  sol.time = epoch.time - reference_clock_m / core::kSpeedOfLightMps;
  for (const int r : fix->lin.rows) sol.used.push_back(ms[static_cast<std::size_t>(r)].sat);
  sol.num_satellites = static_cast<int>(sol.used.size());
  sol.excluded_by_raim = std::move(excluded_by_raim);
  sol.iterations = fix->iterations;
  sol.residual_rms_m = std::sqrt(fix->lin.v.squaredNorm() / static_cast<double>(fix->lin.v.size()));
  sol.v_E_mps = solve_velocity(ms, fix->lin, sol.p_E_m);
  return sol;
}

const core::SignalObs* spp_signal(const core::SatelliteObs& sat_obs) {
  const core::SignalObs* best = nullptr;
  std::size_t best_rank = std::string_view::npos;
  for (const core::SignalObs& s : sat_obs.signals) {
    if (!core::has_value(s.pseudorange_m) || s.pseudorange_m < 1e6 || s.pseudorange_m > 1e8) continue;
    if (core::frequency_rank(sat_obs.sat.system, s.code.band) != 0) continue;
    const std::string_view priority = core::code_priority(sat_obs.sat.system, s.code.band);
    const std::size_t pos = priority.find(s.code.attribute);
    const std::size_t rank = pos == std::string_view::npos ? priority.size() : pos;
    if (best == nullptr || rank < best_rank) {
      best = &s;
      best_rank = rank;
    }
  }
  return best;
}

}  // namespace canyon::gnss
