// Kinematic RTK filter (model and state layout in engine.hpp).

#include "canyon/rtk/engine.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdio>

#include <Eigen/Cholesky>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/core/statistics.hpp"
#include "canyon/gnss/atmosphere.hpp"
#include "canyon/rtk/lambda.hpp"

namespace canyon::rtk {
namespace {

using core::Constellation;
using core::SatelliteId;

constexpr std::size_t kPrunedSubsets = 3;  // partial fixing prunes at most this many group-excluded subsets

/// Wavelength of a satellite's first frequency (rank 0), the reference of the ionosphere state.
double first_wavelength_m(const gnss::EphemerisStore& eph, SatelliteId sat) {
  const char band = sat.system == Constellation::BeiDou ? '2' : '1';
  const int channel = sat.system == Constellation::Glonass ? eph.glonass_channel(sat.prn) : core::kNoGlonassChannel;
  return core::wavelength_m(sat.system, core::SignalCode{band, 'C'}, channel).value_or(0.19029367279836487);
}

/// Zero-difference carrier-phase variance (m^2) of a signal at `elevation_rad` with C/N0 `snr_dbhz` (NaN: unknown):
/// a^2 + b^2 / sin^2(el), the second term scaled by 10^((snr_reference - snr) / 10) below the reference C/N0 when
/// SNR weighting is on (noise power grows as C/N0 falls; reflected signals arrive weaker).
double zero_diff_phase_variance(const RtkOptions& o, double elevation_rad, double snr_dbhz) {
  const double b2 = o.phase_sigma_el_m * o.phase_sigma_el_m;
  if (o.snr_weighting && core::has_value(snr_dbhz) && snr_dbhz > 0.0) {
    return o.phase_sigma_m * o.phase_sigma_m + b2 * std::pow(10.0, (o.snr_reference_dbhz - snr_dbhz) / 10.0);
  }
  const double sin_el = std::max(std::sin(elevation_rad), 0.05);
  return o.phase_sigma_m * o.phase_sigma_m + b2 / (sin_el * sin_el);
}

/// A linear(ised) DD measurement row, sparse: h = h_pos . p + sum of entries (state index, coefficient); innovation v,
/// and which SDs it differences. At most 4 non-position entries: two ambiguities and two ionosphere states.
struct DdRow {
  Eigen::Vector3d h_pos = Eigen::Vector3d::Zero();
  std::array<std::pair<int, double>, 4> entries{};
  int num_entries = 0;
  double innovation_m = 0.0;
  int sd = -1;         // index into the SD list of satellite s
  int reference = -1;  // index of the reference satellite's SD
  bool phase = true;

  void add(int index, double coefficient) {
    for (int k = 0; k < num_entries; ++k) {
      if (entries[static_cast<std::size_t>(k)].first == index) {
        entries[static_cast<std::size_t>(k)].second += coefficient;
        return;
      }
    }
    entries[static_cast<std::size_t>(num_entries++)] = {index, coefficient};
  }
  /// h . c for a state-sized column c (e.g. a column of P H^T).
  [[nodiscard]] double dot(const Eigen::Ref<const Eigen::VectorXd>& c) const {
    double sum = h_pos.dot(c.head<3>());
    for (int k = 0; k < num_entries; ++k) {
      sum += entries[static_cast<std::size_t>(k)].second * c[entries[static_cast<std::size_t>(k)].first];
    }
    return sum;
  }
  /// P h for a symmetric P: one column of P H^T, from columns of P.
  void covariance_times(const Eigen::MatrixXd& P, Eigen::Ref<Eigen::VectorXd> P_h) const {
    P_h = h_pos[0] * P.col(0) + h_pos[1] * P.col(1) + h_pos[2] * P.col(2);
    for (int k = 0; k < num_entries; ++k) {
      P_h += entries[static_cast<std::size_t>(k)].second * P.col(entries[static_cast<std::size_t>(k)].first);
    }
  }
};

// The Kalman update, for the sizes of RTK (tens of states and rows). Column major throughout; the kernels below are
// plain loops and matrix-vector products because Eigen's blocked matrix-matrix routines spend more on packing than
// on arithmetic at these sizes.

/// In-place Cholesky factorisation A = L L^T of a symmetric positive definite m x m matrix given by its lower
/// triangle; L overwrites the lower triangle, the strict upper triangle is neither read nor written. False if A is
/// not positive definite.
bool cholesky_lower_in_place(Eigen::MatrixXd& A) {
  const Eigen::Index m = A.rows();
  double* a = A.data();
  for (Eigen::Index j = 0; j < m; ++j) {
    // Left looking: column j minus the contributions of the columns already factorised, four at a time (one pass
    // over column j per four), then scaled.
    double* a_j = a + j * m;
    Eigen::Index k = 0;
    for (; k + 4 <= j; k += 4) {
      const double* a_0 = a + k * m;
      const double* a_1 = a_0 + m;
      const double* a_2 = a_1 + m;
      const double* a_3 = a_2 + m;
      const double l_0 = a_0[j], l_1 = a_1[j], l_2 = a_2[j], l_3 = a_3[j];
      for (Eigen::Index i = j; i < m; ++i) a_j[i] -= (l_0 * a_0[i] + l_1 * a_1[i]) + (l_2 * a_2[i] + l_3 * a_3[i]);
    }
    for (; k < j; ++k) {
      const double* a_k = a + k * m;
      const double l_jk = a_k[j];
      for (Eigen::Index i = j; i < m; ++i) a_j[i] -= l_jk * a_k[i];
    }
    if (!(a_j[j] > 0.0)) return false;
    const double l_jj = std::sqrt(a_j[j]);
    a_j[j] = l_jj;
    for (Eigen::Index i = j + 1; i < m; ++i) a_j[i] /= l_jj;
  }
  return true;
}

/// B <- L^-1 B in place (L lower triangular m x m, in the lower triangle of L; B m x k).
template <typename Derived>
void solve_lower_in_place(const Eigen::MatrixXd& L, Eigen::MatrixBase<Derived>& B) {
  const Eigen::Index m = L.rows();
  for (Eigen::Index j = 0; j < B.cols(); ++j) {
    auto b = B.col(j);
    for (Eigen::Index k = 0; k < m; ++k) {
      const double y_k = b[k] / L(k, k);
      b[k] = y_k;
      b.tail(m - k - 1) -= y_k * L.col(k).tail(m - k - 1);
    }
  }
}

/// X <- X L^-T in place (X n x m, L lower triangular m x m): column k of the result is
/// (X_k - sum_{j<k} L_kj X_j) / L_kk, one matrix-vector product per column.
void solve_transposed_lower_from_right_in_place(const Eigen::MatrixXd& L, Eigen::MatrixXd& X) {
  for (Eigen::Index k = 0; k < X.cols(); ++k) {
    if (k > 0) X.col(k).noalias() -= X.leftCols(k) * L.row(k).head(k).transpose();
    X.col(k) /= L(k, k);
  }
}

/// P <- sym(P) - U V^T for an n x n P with U V^T symmetric (U, V n x r), where sym(P) = (P + P^T) / 2 (P itself when
/// symmetric): computed on the lower triangle, one matrix-vector product per column, and mirrored, so that P is
/// exactly symmetric afterwards.
void subtract_symmetric_product(Eigen::MatrixXd& P, const Eigen::MatrixXd& U, const Eigen::MatrixXd& V) {
  const Eigen::Index n = P.rows();
  const Eigen::Index r = U.cols();
  for (Eigen::Index j = 0; j < n; ++j) {
    double* p_j = P.col(j).data();
    for (Eigen::Index i = j + 1; i < n; ++i) p_j[i] = 0.5 * (p_j[i] + P(j, i));
    Eigen::Index c = 0;
    for (; c + 4 <= r; c += 4) {  // four columns of U per pass over column j of P
      const double* u_0 = U.col(c).data();
      const double* u_1 = U.col(c + 1).data();
      const double* u_2 = U.col(c + 2).data();
      const double* u_3 = U.col(c + 3).data();
      const double v_0 = V(j, c), v_1 = V(j, c + 1), v_2 = V(j, c + 2), v_3 = V(j, c + 3);
      for (Eigen::Index i = j; i < n; ++i) p_j[i] -= (v_0 * u_0[i] + v_1 * u_1[i]) + (v_2 * u_2[i] + v_3 * u_3[i]);
    }
    for (; c < r; ++c) {
      const double v_jc = V(j, c);
      const double* u_c = U.col(c).data();
      for (Eigen::Index i = j; i < n; ++i) p_j[i] -= v_jc * u_c[i];
    }
    for (Eigen::Index i = j + 1; i < n; ++i) P(j, i) = p_j[i];
  }
}

/// The states a block of DD rows touches, ascending, and the rows' Jacobian on them (H = H_J on J, zero elsewhere).
struct CompressedJacobian {
  std::vector<int> states;  // J
  Eigen::MatrixXd H_J;      // rows x |J|
};

CompressedJacobian compress(const std::vector<const DdRow*>& rows) {
  CompressedJacobian c;
  c.states = {0, 1, 2};
  for (const DdRow* row : rows) {
    for (int k = 0; k < row->num_entries; ++k) c.states.push_back(row->entries[static_cast<std::size_t>(k)].first);
  }
  std::sort(c.states.begin(), c.states.end());
  c.states.erase(std::unique(c.states.begin(), c.states.end()), c.states.end());
  c.H_J = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(c.states.size()));
  for (std::size_t a = 0; a < rows.size(); ++a) {
    const auto r = static_cast<Eigen::Index>(a);
    c.H_J.row(r).head<3>() = rows[a]->h_pos.transpose();
    for (int k = 0; k < rows[a]->num_entries; ++k) {
      const auto& [state, coefficient] = rows[a]->entries[static_cast<std::size_t>(k)];
      const auto column = std::lower_bound(c.states.begin(), c.states.end(), state) - c.states.begin();
      c.H_J(r, column) += coefficient;
    }
  }
  return c;
}

/// The effect of one block of measurements on the state: x' = x + dx, P' = P - U V^T.
struct KalmanStep {
  Eigen::VectorXd dx;
  Eigen::MatrixXd U;
  Eigen::MatrixXd V;
};

/// Update with rows that touch few states (the DD code: position, and ionosphere states when estimated), in
/// compressed form. With A = P E_J (the columns of P of the states J) and S = H_J P_JJ H_J^T + R = L L^T:
///   G = L^-1 H_J,  W = G^T G = H_J^T S^-1 H_J,  dx = A G^T L^-1 v,  P' = P - (A W) A^T.
/// R(a, b), a >= b, is the measurement covariance. nullopt if S is not positive definite.
template <typename Covariance>
std::optional<KalmanStep> compressed_update(const Eigen::MatrixXd& P, const std::vector<const DdRow*>& rows,
                                            Eigen::VectorXd v, const Covariance& R) {
  const CompressedJacobian c = compress(rows);
  const auto m = static_cast<Eigen::Index>(rows.size());
  const auto q = static_cast<Eigen::Index>(c.states.size());
  KalmanStep step;
  step.V.resize(P.rows(), q);  // A
  for (Eigen::Index j = 0; j < q; ++j) step.V.col(j) = P.col(c.states[static_cast<std::size_t>(j)]);
  Eigen::MatrixXd P_JJ(q, q);
  for (Eigen::Index i = 0; i < q; ++i) P_JJ.row(i) = step.V.row(c.states[static_cast<std::size_t>(i)]);
  const Eigen::MatrixXd H_P_JJ = c.H_J.lazyProduct(P_JJ);
  Eigen::MatrixXd S(m, m);
  for (Eigen::Index b = 0; b < m; ++b) {
    for (Eigen::Index a = b; a < m; ++a) S(a, b) = H_P_JJ.row(a).dot(c.H_J.row(b)) + R(a, b);
  }
  if (!cholesky_lower_in_place(S)) return std::nullopt;
  Eigen::MatrixXd G = c.H_J;
  solve_lower_in_place(S, G);
  solve_lower_in_place(S, v);
  step.dx = step.V * (G.transpose() * v);
  step.U = step.V.lazyProduct(G.transpose().lazyProduct(G));
  return step;
}

/// Update with rows that touch most states (the DD phase), at the covariance P - U_prior V_prior^T of a preceding
/// step that is not applied yet. With X = P H^T (from the sparse rows) and S = H X + R = L L^T:
///   dx = (X L^-T) L^-1 v,  P' = P - (X L^-T) (X L^-T)^T.
/// R(a, b), a >= b, is the measurement covariance. nullopt if S is not positive definite.
template <typename Covariance>
std::optional<KalmanStep> dense_update(const Eigen::MatrixXd& P, const KalmanStep& prior,
                                       const std::vector<const DdRow*>& rows, Eigen::VectorXd v, const Covariance& R) {
  const auto m = static_cast<Eigen::Index>(rows.size());
  KalmanStep step;
  step.U.resize(P.rows(), m);
  for (Eigen::Index a = 0; a < m; ++a) {
    const DdRow& row = *rows[static_cast<std::size_t>(a)];
    row.covariance_times(P, step.U.col(a));
    for (Eigen::Index j = 0; j < prior.V.cols(); ++j) step.U.col(a) -= row.dot(prior.V.col(j)) * prior.U.col(j);
  }
  Eigen::MatrixXd S(m, m);
  for (Eigen::Index b = 0; b < m; ++b) {
    for (Eigen::Index a = b; a < m; ++a) S(a, b) = rows[static_cast<std::size_t>(a)]->dot(step.U.col(b)) + R(a, b);
  }
  if (!cholesky_lower_in_place(S)) return std::nullopt;
  solve_transposed_lower_from_right_in_place(S, step.U);
  solve_lower_in_place(S, v);
  step.dx = step.U * v;
  step.V = step.U;
  return step;
}

}  // namespace

/// One single-differenced (rover - base) observable ready for double differencing.
struct SingleDiff {
  SatelliteId sat;
  int frequency = 0;
  int group = 0;  // constellation * kMaxFrequencies + frequency
  double wavelength_m = 0.0;
  double phase_m = core::kNoValue;  // lambda (Phi_r - Phi_b) - (model_r - model_b)
  double code_m = core::kNoValue;   // (P_r - P_b) - (model_r - model_b)
  double phase_variance_m2 = 0.0;
  double code_variance_m2 = 0.0;
  double test_variance_m2 = 0.0;  // phase variance of the elevation model alone, for the post-fit tests
  Eigen::Vector3d los_E = Eigen::Vector3d::Zero();  // rover line of sight
  double elevation_rad = 0.0;
  std::uint8_t lli = 0;     // rover | base loss-of-lock bits
  int ambiguity = -1;       // state index of N_sd, -1 if none
  int iono = -1;            // state index of the satellite's SD ionosphere, -1 if not estimated
  double iono_scale = 1.0;  // (f_1 / f)^2: the delay on this frequency per metre of first-frequency delay (when
                            // the ionosphere is estimated)
  bool fixable = false;
};

const char* ionosphere_model_name(IonosphereModel model) {
  switch (model) {
    case IonosphereModel::Off: return "off";
    case IonosphereModel::Estimate: return "estimate";
    case IonosphereModel::Auto: return "auto";
  }
  return "?";
}

namespace {

/// The aiding's innovation gates on one DD row at the state (x, P): a fixed gate on rows whose predicted sigma
/// sqrt(h P h^T) is within a third of it (not a new ambiguity), the normalised gate |v| <= k sqrt(h P h^T + r) on all.
bool aided_gate_passes(const RtkAiding& aiding, const DdRow& row, const std::vector<SingleDiff>& sds,
                       const Eigen::MatrixXd& P) {
  const std::optional<double>& fixed_gate = row.phase ? aiding.max_phase_innovation_m : aiding.max_code_innovation_m;
  if (!fixed_gate && !aiding.max_normalised_innovation) return true;
  // Predicted sigma of the row, sqrt(h P h^T), and its measurement variance r.
  Eigen::VectorXd P_h(P.rows());
  row.covariance_times(P, P_h);
  const double hPh = std::max(row.dot(P_h), 0.0);
  const SingleDiff& sd = sds[static_cast<std::size_t>(row.sd)];
  const SingleDiff& ref = sds[static_cast<std::size_t>(row.reference)];
  const double r =
      row.phase ? sd.phase_variance_m2 + ref.phase_variance_m2 : sd.code_variance_m2 + ref.code_variance_m2;
  const double v = std::abs(row.innovation_m);
  // A fixed gate judges only rows whose prediction is good to a third of it (not a new ambiguity).
  if (fixed_gate && 9.0 * hPh <= *fixed_gate * *fixed_gate && v > *fixed_gate) return false;
  return !(aiding.max_normalised_innovation && v > *aiding.max_normalised_innovation * std::sqrt(hPh + r));
}

}  // namespace

const char* ar_mode_name(ArMode mode) {
  switch (mode) {
    case ArMode::Off: return "off";
    case ArMode::Continuous: return "continuous";
    case ArMode::Instantaneous: return "instantaneous";
    case ArMode::FixAndHold: return "fix_and_hold";
  }
  return "?";
}

std::string RtkOptions::validate() const {
  if (observables.num_frequencies < 1 || observables.num_frequencies > kMaxFrequencies) {
    return "frequencies must be 1, 2 or 3";
  }
  if (!(elevation_mask_rad >= 0.0 && elevation_mask_rad < core::kPi / 2.0)) {
    return "elevation_mask_rad must be in [0, pi/2)";
  }
  if (!(ratio_threshold >= 1.0)) return "ratio_threshold must be >= 1";
  if (min_fix_ambiguities < 1) return "min_fix_ambiguities must be >= 1";
  if (!(min_success_rate >= 0.0 && min_success_rate <= 1.0)) return "min_success_rate must be in [0, 1]";
  if (!(float_consistency_level >= 0.0 && float_consistency_level < 0.5)) {
    return "float_consistency_level must be in [0, 0.5) (0: no test)";
  }
  if (!(min_partial_fraction >= 0.0 && min_partial_fraction <= 1.0)) return "min_partial_fraction must be in [0, 1]";
  if (!(max_partial_fix_sigma_m > 0.0)) return "max_partial_fix_sigma_m must be > 0";
  if (!(snr_reference_dbhz > 0.0)) return "snr_reference_dbhz must be > 0";
  if (!(iono_auto_baseline_km >= 0.0)) return "iono_auto_baseline_km must be >= 0";
  if (max_pruned_satellites < 0) return "max_pruned_satellites must be >= 0";
  if (!(phase_sigma_m > 0.0) || !(code_phase_ratio > 0.0)) return "phase_sigma_m and code_phase_ratio must be > 0";
  if (!(max_age_s > 0.0)) return "max_age_s must be > 0";
  if (!(initial_ambiguity_sigma_cyc > 0.0)) return "initial_ambiguity_sigma_cyc must be > 0";
  if (!(hold_sigma_cyc > 0.0)) return "hold_sigma_cyc must be > 0";
  if (!(max_post_fit_sigmas > 0.0) || !(max_post_fit_code_sigmas > 0.0) || max_post_fit_rejections < 0) {
    return "max_post_fit_sigmas and max_post_fit_code_sigmas must be > 0 and max_post_fit_rejections >= 0";
  }
  if (const std::string e = slips.validate(); !e.empty()) return "slips: " + e;
  if (const std::string e = spp.validate(); !e.empty()) return "spp: " + e;
  return {};
}

RtkEngine::RtkEngine(RtkOptions options, const gnss::EphemerisStore& ephemerides, Eigen::Vector3d p_E_base_m)
    : options_(std::move(options)),
      eph_(ephemerides),
      p_E_base_m_(std::move(p_E_base_m)),
      geometry_builder_(geometry_options(), eph_, p_E_base_m_),
      consistency_z_(options_.float_consistency_level > 0.0
                         ? core::normal_upper_quantile(options_.float_consistency_level)
                         : 0.0) {
  x_ = Eigen::VectorXd::Zero(num_kinematic_states());
  P_ = Eigen::MatrixXd::Zero(num_kinematic_states(), num_kinematic_states());
}

EpochGeometryBuilder::Options RtkEngine::geometry_options() const {
  return {options_.spp, options_.observables, options_.troposphere_saastamoinen, options_.slips, options_.max_age_s};
}

int RtkEngine::ambiguity_index(const AmbiguityKey& key) const {
  const auto it = std::find(ambiguity_keys_.begin(), ambiguity_keys_.end(), key);
  return it == ambiguity_keys_.end() ? -1 : num_kinematic_states() + static_cast<int>(it - ambiguity_keys_.begin());
}

void RtkEngine::add_states(const std::vector<NewState>& states) {
  if (states.empty()) return;
  const Eigen::Index n = x_.size();
  const auto added = static_cast<Eigen::Index>(states.size());
  // One new x and P (a copy of the old block, zeros, the new variances) rather than one resize per state.
  Eigen::VectorXd x(n + added);
  x.head(n) = x_;
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(n + added, n + added);
  P.topLeftCorner(n, n) = P_;
  for (Eigen::Index i = 0; i < added; ++i) {
    const NewState& state = states[static_cast<std::size_t>(i)];
    x[n + i] = state.value;
    P(n + i, n + i) = state.variance;
    ambiguity_keys_.push_back(state.key);
  }
  x_.swap(x);
  P_.swap(P);
}

void RtkEngine::add_ambiguity(const AmbiguityKey& key, double value, double variance) {
  add_states({NewState{key, value, variance}});
}

void RtkEngine::remove_ambiguity(const AmbiguityKey& key) {
  const int index = ambiguity_index(key);
  if (index < 0) return;
  // x and P without the state: one copy into new storage (four blocks of P), no shifting in place.
  const auto n = x_.size();
  const auto tail = n - index - 1;
  Eigen::VectorXd x(n - 1);
  x << x_.head(index), x_.tail(tail);
  Eigen::MatrixXd P(n - 1, n - 1);
  P.topLeftCorner(index, index) = P_.topLeftCorner(index, index);
  P.topRightCorner(index, tail) = P_.topRightCorner(index, tail);
  P.bottomLeftCorner(tail, index) = P_.bottomLeftCorner(tail, index);
  P.bottomRightCorner(tail, tail) = P_.bottomRightCorner(tail, tail);
  x_.swap(x);
  P_.swap(P);
  ambiguity_keys_.erase(ambiguity_keys_.begin() + (index - num_kinematic_states()));
  ambiguity_info_.erase(key);
  for (auto it = last_fix_.begin(); it != last_fix_.end();) {
    it = (it->first.first == key || it->first.second == key) ? last_fix_.erase(it) : std::next(it);
  }
}

void RtkEngine::choose_ionosphere_model(double baseline_m) {
  bool estimate = options_.ionosphere == IonosphereModel::Estimate;
  if (options_.ionosphere == IonosphereModel::Auto) {
    // Hysteresis: on beyond the threshold, off again only below 80 % of it (no toggling around it).
    const double on_m = options_.iono_auto_baseline_km * 1e3;
    estimate = iono_estimated_ ? baseline_m >= 0.8 * on_m : baseline_m > on_m;
  }
  if (iono_estimated_ && !estimate) {
    std::vector<AmbiguityKey> iono;
    for (const AmbiguityKey& key : ambiguity_keys_) {
      if (key.second == kIonoKey) iono.push_back(key);
    }
    for (const AmbiguityKey& key : iono) remove_ambiguity(key);
  }
  iono_estimated_ = estimate;
}

void RtkEngine::clear_ambiguities() {
  const int k = num_kinematic_states();
  x_.conservativeResize(k);
  P_.conservativeResize(k, k);
  ambiguity_keys_.clear();
  ambiguity_info_.clear();
  last_fix_.clear();
}

void RtkEngine::time_update(const core::GpsTime& t, const gnss::SppSolution& spp) {
  const double dt_s = last_time_ ? std::abs(t - *last_time_) : 0.0;
  const double var0 = options_.initial_position_sigma_m * options_.initial_position_sigma_m;
  const int k = num_kinematic_states();
  if (!options_.dynamics || !initialised_ || dt_s > 30.0) {
    // Position (and velocity, acceleration) from the single-point solution, uncorrelated with the ambiguities.
    P_.topRows(k).setZero();
    P_.leftCols(k).setZero();
    x_.head<3>() = spp.p_E_m;
    P_.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * var0;
    if (options_.dynamics) {
      x_.segment<3>(3) = spp.v_E_mps.value_or(Eigen::Vector3d::Zero());
      x_.segment<3>(6).setZero();
      P_.block<3, 3>(3, 3) = Eigen::Matrix3d::Identity() * 100.0;
      P_.block<3, 3>(6, 6) = Eigen::Matrix3d::Identity() * 100.0;
    }
    initialised_ = true;
  } else {
    // Constant acceleration: x' = F x, P' = F P F^T + Q with white jerk of the given spectral density (ENU). F is
    // the identity but for its kinematic block F_k, so P_kk' = F_k P_kk F_k^T, P_ka' = F_k P_ka and the ambiguity
    // block is unchanged: O(81 N) instead of the O(N^3) of the whole product.
    constexpr int kKinematic = 9;
    Eigen::Matrix<double, kKinematic, kKinematic> F_k = Eigen::Matrix<double, kKinematic, kKinematic>::Identity();
    for (int i = 0; i < 3; ++i) {
      F_k(i, 3 + i) = dt_s;
      F_k(i, 6 + i) = 0.5 * dt_s * dt_s;
      F_k(3 + i, 6 + i) = dt_s;
    }
    const Eigen::Index m = x_.size() - kKinematic;
    x_.head<kKinematic>() = F_k * x_.head<kKinematic>();
    P_.topLeftCorner<kKinematic, kKinematic>() = F_k * P_.topLeftCorner<kKinematic, kKinematic>() * F_k.transpose();
    if (m > 0) {
      P_.topRightCorner(kKinematic, m) = F_k * P_.topRightCorner(kKinematic, m);
      P_.bottomLeftCorner(m, kKinematic) = P_.topRightCorner(kKinematic, m).transpose();
    }
    const core::Geodetic g = core::ecef_to_geodetic(x_.head<3>());
    const Eigen::Matrix3d R_EN = core::rotation_enu_from_ecef(g).transpose();
    Eigen::Matrix3d Q_N = Eigen::Matrix3d::Zero();
    Q_N(0, 0) = Q_N(1, 1) = options_.accel_sigma_h_mps2 * options_.accel_sigma_h_mps2 * dt_s;
    Q_N(2, 2) = options_.accel_sigma_v_mps2 * options_.accel_sigma_v_mps2 * dt_s;
    P_.block<3, 3>(6, 6) += R_EN * Q_N * R_EN.transpose();
  }
  heading_live_ = false;  // an epoch without aiding: the next aided one restarts the heading error
  // Ambiguities and ionosphere: random walks.
  const double q_amb = options_.ambiguity_noise_cyc * options_.ambiguity_noise_cyc * dt_s;
  const double q_iono = options_.iono_noise_m * options_.iono_noise_m * dt_s;
  for (Eigen::Index i = k; i < x_.size(); ++i) {
    P_(i, i) += ambiguity_keys_[static_cast<std::size_t>(i - k)].second == kIonoKey ? q_iono : q_amb;
  }
  last_time_ = t;
}

void RtkEngine::aided_time_update(const core::GpsTime& t, const RtkAiding& aiding) {
  // External motion as the model: x_p' = x_p + d, P_pp' = P_pp + Q; the position's correlations with the ambiguities
  // carry over (x' = x + d with d independent of x). Other kinematic states (dynamics) are left as they are.
  const double dt_s = last_time_ ? std::abs(t - *last_time_) : 0.0;
  x_.head<3>() += aiding.delta_p_E_m;
  P_.topLeftCorner<3, 3>() += 0.5 * (aiding.Q_E_m2 + aiding.Q_E_m2.transpose());
  if (options_.aiding_heading_state) propagate_heading(aiding);
  const int k = num_kinematic_states();
  const double q_amb = options_.ambiguity_noise_cyc * options_.ambiguity_noise_cyc * dt_s;
  const double q_iono = options_.iono_noise_m * options_.iono_noise_m * dt_s;
  for (Eigen::Index i = k; i < x_.size(); ++i) {
    P_(i, i) += ambiguity_keys_[static_cast<std::size_t>(i - k)].second == kIonoKey ? q_iono : q_amb;
  }
  last_time_ = t;
}

void RtkEngine::propagate_heading(const RtkAiding& aiding) {
  const int h = heading_index();
  if (aiding.restart_heading || !heading_live_) {
    x_[h] = 0.0;
    P_.row(h).setZero();
    P_.col(h).setZero();
    P_(h, h) = aiding.heading_variance_rad2;
    heading_live_ = true;
  }
  // F = I + J e_h^T: F P gives the position rows J times row h, then (F P) F^T the position columns column h J^T.
  const Eigen::Vector3d& J = aiding.dp_d_heading_E_m;
  x_.head<3>() += J * x_[h];
  P_.topRows<3>() += J * P_.row(h);
  P_.leftCols<3>() += P_.col(h) * J.transpose();
  P_(h, h) += aiding.heading_noise_rad2;
}

std::optional<RtkEngine::HeadingError> RtkEngine::heading_error() const {
  if (!options_.aiding_heading_state || !heading_live_) return std::nullopt;
  const int h = heading_index();
  return HeadingError{x_[h], P_(h, h)};
}

void RtkEngine::set_position(const Eigen::Vector3d& p_E_m, const Eigen::Matrix3d& P_E_m2) {
  x_.head<3>() = p_E_m;
  P_.topRows<3>().setZero();
  P_.leftCols<3>().setZero();
  P_.topLeftCorner<3, 3>() = 0.5 * (P_E_m2 + P_E_m2.transpose());
}

std::optional<RtkEngine::HeadingError> RtkEngine::take_heading_error() {
  std::optional<HeadingError> heading = heading_error();
  if (heading) x_[heading_index()] = 0.0;
  return heading;
}

void RtkEngine::revert_to_prior() {
  if (!has_prior_) return;
  x_ = prior_x_;
  P_ = prior_P_;
  last_fix_ = prior_last_fix_;
  has_prior_ = false;
}

void RtkEngine::update_ambiguities(std::vector<SingleDiff>& sds, const core::GpsTime& t, const SlipScan& slips) {
  for (const SlipEvent& e : slips.events) remove_ambiguity({e.sat, e.frequency});
  // Remove ambiguities not seen for longer than the outage limit.
  std::vector<AmbiguityKey> stale;
  for (const auto& [key, info] : ambiguity_info_) {
    if (t - info.last_seen > options_.max_outage_s) stale.push_back(key);
  }
  for (const auto& key : stale) remove_ambiguity(key);
  // New states are collected and appended at once (in the order found, as one by one).
  std::vector<NewState> new_states;
  const auto has_state = [&](const AmbiguityKey& key) {
    return ambiguity_index(key) >= 0 ||
           std::any_of(new_states.begin(), new_states.end(), [&](const NewState& s) { return s.key == key; });
  };
  for (SingleDiff& sd : sds) {
    if (!core::has_value(sd.phase_m)) continue;
    const AmbiguityKey key{sd.sat, sd.frequency};
    if (!has_state(key)) {
      if (!core::has_value(sd.code_m)) continue;
      const double sigma = options_.initial_ambiguity_sigma_cyc;
      new_states.push_back(NewState{key, (sd.phase_m - sd.code_m) / sd.wavelength_m, sigma * sigma});
      ambiguity_info_[key] = AmbiguityInfo{};
    }
    AmbiguityInfo& a = ambiguity_info_[key];
    a.last_seen = t;
    ++a.lock_epochs;
    const bool half_cycle = (sd.lli & core::kLliHalfCycle) != 0 || slips.half_cycle(sd.sat, sd.frequency);
    const bool glonass_ok = sd.sat.system != Constellation::Glonass || options_.glonass_ar;
    sd.fixable = !half_cycle && glonass_ok && a.lock_epochs > options_.min_lock_epochs &&
                 sd.elevation_rad >= options_.ar_elevation_mask_rad;
  }
  if (iono_estimated_) {
    const double baseline_10km = (x_.head<3>() - p_E_base_m_).norm() / 1e4;
    const double sigma_m = std::max(options_.iono_sigma_per_10km_m * baseline_10km, options_.iono_sigma_min_m);
    for (const SingleDiff& sd : sds) {
      const AmbiguityKey key{sd.sat, kIonoKey};
      if (!has_state(key)) new_states.push_back(NewState{key, 0.0, sigma_m * sigma_m});
      ambiguity_info_[key].last_seen = t;
    }
  }
  add_states(new_states);
  for (SingleDiff& sd : sds) {
    sd.ambiguity = core::has_value(sd.phase_m) ? ambiguity_index({sd.sat, sd.frequency}) : -1;
    sd.iono = ambiguity_index({sd.sat, kIonoKey});
  }
}

int RtkEngine::measurement_update(std::vector<SingleDiff>& sds, std::vector<core::SatelliteId>& rejected,
                                  bool& consistent) {
  // Update, then check the post-fit residuals: a signal whose residual is beyond the threshold (a phase inconsistent
  // with the others, e.g. an undetected slip or signals two receivers track differently; a code far off, e.g. a
  // reflection) is dropped for this epoch and the update redone from the prior.
  const Eigen::VectorXd x0 = x_;
  const Eigen::MatrixXd P0 = P_;
  int used = 0;
  consistent = true;
  for (int attempt = 0; attempt <= options_.max_post_fit_rejections; ++attempt) {
    PostFit post_fit;
    used = update_once(sds, rejected, post_fit);
    last_post_fit_normalised_ = post_fit.worst_normalised;
    consistent = post_fit.worst_sd < 0 || post_fit.worst_normalised <= 1.0;
    if (consistent || attempt == options_.max_post_fit_rejections) break;
    SingleDiff& bad = sds[static_cast<std::size_t>(post_fit.worst_sd)];
    rejected.push_back(bad.sat);
    if (post_fit.worst_is_code) {
      bad.code_m = core::kNoValue;  // its code is not used this epoch
    } else {
      bad.ambiguity = -1;  // its phase is not used (nor fixed) this epoch
      bad.fixable = false;
    }
    x_ = x0;
    P_ = P0;
  }
  return used;
}

int RtkEngine::update_once(std::vector<SingleDiff>& sds, std::vector<core::SatelliteId>& rejected, PostFit& post_fit) {
  // Group by (constellation, frequency); the reference is the highest satellite with the observable.
  const Eigen::Index n = x_.size();
  std::vector<DdRow> rows;
  std::map<int, std::vector<int>> groups;
  for (int i = 0; i < static_cast<int>(sds.size()); ++i) groups[sds[static_cast<std::size_t>(i)].group].push_back(i);
  for (const bool phase : {true, false}) {
    for (const auto& [group, members] : groups) {
      int reference = -1;
      for (const int i : members) {
        const SingleDiff& sd = sds[static_cast<std::size_t>(i)];
        const bool usable = phase ? sd.ambiguity >= 0 : core::has_value(sd.code_m);
        if (usable && (reference < 0 || sd.elevation_rad > sds[static_cast<std::size_t>(reference)].elevation_rad)) {
          reference = i;
        }
      }
      if (reference < 0) continue;
      const SingleDiff& ref = sds[static_cast<std::size_t>(reference)];
      for (const int i : members) {
        const SingleDiff& sd = sds[static_cast<std::size_t>(i)];
        if (i == reference || (phase ? sd.ambiguity < 0 : !core::has_value(sd.code_m))) continue;
        DdRow row;
        row.phase = phase;
        row.sd = i;
        row.reference = reference;
        row.h_pos = -(sd.los_E - ref.los_E);
        double predicted_m = 0.0;
        double observed_m = 0.0;
        if (phase) {
          row.add(sd.ambiguity, sd.wavelength_m);
          row.add(ref.ambiguity, -ref.wavelength_m);
          predicted_m = sd.wavelength_m * x_[sd.ambiguity] - ref.wavelength_m * x_[ref.ambiguity];
          observed_m = sd.phase_m - ref.phase_m;
        } else {
          observed_m = sd.code_m - ref.code_m;
        }
        if (sd.iono >= 0 && ref.iono >= 0) {
          // The ionosphere advances phase and delays code by iono_scale * I_sd.
          const double sign = phase ? -1.0 : 1.0;
          row.add(sd.iono, sign * sd.iono_scale);
          row.add(ref.iono, -sign * ref.iono_scale);
          predicted_m += sign * (sd.iono_scale * x_[sd.iono] - ref.iono_scale * x_[ref.iono]);
        }
        // The SD residuals were formed at the prior position: the geometry term is already in observed_m, and
        // the position correction enters through H; at the prior, the predicted DD range residual is zero.
        row.innovation_m = observed_m - predicted_m;
        const double gate = phase ? options_.max_phase_innovation_m : options_.max_code_innovation_m;
        if (std::abs(row.innovation_m) > gate || (aiding_ != nullptr && !aided_gate_passes(*aiding_, row, sds, P_))) {
          rejected.push_back(sd.sat);
          // Its ambiguity is not updated by this epoch: not fixed either (the prior's integer is no fix).
          if (phase) sds[static_cast<std::size_t>(i)].fixable = false;
          continue;
        }
        rows.push_back(std::move(row));
      }
    }
  }
  if (rows.empty()) return 0;
  // DD measurement covariance: the SD variances of s and of its reference on the diagonal; rows of one kind that
  // share a reference are correlated through it. Code and phase rows are uncorrelated.
  const auto sd_variance = [&](const DdRow& row, int i) {
    const SingleDiff& sd = sds[static_cast<std::size_t>(i)];
    return row.phase ? sd.phase_variance_m2 : sd.code_variance_m2;
  };
  const auto covariance = [&](const DdRow& ra, const DdRow& rb) {
    if (&ra == &rb) return sd_variance(ra, ra.sd) + sd_variance(ra, ra.reference);
    return rb.phase == ra.phase && rb.reference == ra.reference ? sd_variance(ra, ra.reference) : 0.0;
  };
  // The post-fit tests measure residuals against the elevation model alone: SNR weighting lowers the weight of weak
  // signals in the estimate, not the scrutiny they get (a reflection must still stand out as an outlier).
  const auto test_variance = [&](const DdRow& row) {
    const SingleDiff& s = sds[static_cast<std::size_t>(row.sd)];
    const SingleDiff& r = sds[static_cast<std::size_t>(row.reference)];
    const double ratio2 = row.phase ? 1.0 : options_.code_phase_ratio * options_.code_phase_ratio;
    return (s.test_variance_m2 + r.test_variance_m2) * ratio2;
  };
  // R being block diagonal, the update is two sequential ones, the same as the joint update in exact arithmetic:
  // the code rows, which touch only the position (and ionosphere states), in compressed form, then the phase rows at
  // the code-updated covariance. Neither is applied before both factorisations have succeeded.
  std::vector<const DdRow*> code_rows;
  std::vector<const DdRow*> phase_rows;
  for (const DdRow& row : rows) (row.phase ? phase_rows : code_rows).push_back(&row);
  const auto block_covariance = [&](const std::vector<const DdRow*>& block) {
    return [&covariance, &block](Eigen::Index a, Eigen::Index b) {
      return covariance(*block[static_cast<std::size_t>(a)], *block[static_cast<std::size_t>(b)]);
    };
  };
  const auto innovations = [](const std::vector<const DdRow*>& block, const Eigen::VectorXd& dx) {
    Eigen::VectorXd v(static_cast<Eigen::Index>(block.size()));
    for (std::size_t a = 0; a < block.size(); ++a)
      v[static_cast<Eigen::Index>(a)] = block[a]->innovation_m - block[a]->dot(dx);
    return v;
  };
  KalmanStep code_step{Eigen::VectorXd::Zero(n), Eigen::MatrixXd(n, 0), Eigen::MatrixXd(n, 0)};
  if (!code_rows.empty()) {
    auto step = compressed_update(P_, code_rows, innovations(code_rows, code_step.dx), block_covariance(code_rows));
    if (!step) return 0;
    code_step = std::move(*step);
  }
  KalmanStep phase_step{Eigen::VectorXd::Zero(n), Eigen::MatrixXd(n, 0), Eigen::MatrixXd(n, 0)};
  if (!phase_rows.empty()) {
    auto step =
        dense_update(P_, code_step, phase_rows, innovations(phase_rows, code_step.dx), block_covariance(phase_rows));
    if (!step) return 0;
    phase_step = std::move(*step);
  }
  const Eigen::VectorXd dx = code_step.dx + phase_step.dx;
  x_ += dx;
  Eigen::MatrixXd U(n, code_step.U.cols() + phase_step.U.cols());
  Eigen::MatrixXd V(n, U.cols());
  U << code_step.U, phase_step.U;
  V << code_step.V, phase_step.V;
  subtract_symmetric_product(P_, U, V);
  // Post-fit DD residuals, normalised by their measurement sigma and by the threshold of their kind (phase or code):
  // the worst one is reported, beyond its threshold when the normalised value exceeds 1.
  post_fit = PostFit{};
  const auto check = [&](const std::vector<const DdRow*>& block, double threshold_sigmas, bool code) {
    for (const DdRow* row : block) {
      const double sigmas = std::abs(row->innovation_m - row->dot(dx)) / std::sqrt(test_variance(*row));
      const double normalised = sigmas / threshold_sigmas;
      if (normalised > post_fit.worst_normalised) {
        post_fit.worst_normalised = normalised;
        post_fit.worst_sd = row->sd;
        post_fit.worst_is_code = code;
      }
    }
  };
  check(phase_rows, options_.max_post_fit_sigmas, false);
  check(code_rows, options_.max_post_fit_code_sigmas, true);
  last_code_rows_ = static_cast<int>(code_rows.size());
  return static_cast<int>(phase_rows.size());
}

namespace {

/// Which fixable SDs a DD ambiguity set leaves out: one (constellation, frequency) group, or a whole constellation.
struct Exclusion {
  int group = -1;
  int constellation = -1;
  [[nodiscard]] bool excludes(const SingleDiff& sd) const {
    return sd.group == group || sd.group / kMaxFrequencies == constellation;
  }
};

/// DD ambiguities (state index of s, state index of its group's reference) of the fixable SDs not excluded; the
/// reference of each group is its highest fixable satellite.
std::vector<std::pair<int, int>> dd_ambiguities(const std::vector<SingleDiff>& sds, const Exclusion& excluded) {
  std::map<int, int> reference;  // group -> SD index
  for (int i = 0; i < static_cast<int>(sds.size()); ++i) {
    const SingleDiff& sd = sds[static_cast<std::size_t>(i)];
    if (!sd.fixable || sd.ambiguity < 0 || excluded.excludes(sd)) continue;
    auto it = reference.find(sd.group);
    if (it == reference.end() || sd.elevation_rad > sds[static_cast<std::size_t>(it->second)].elevation_rad) {
      reference[sd.group] = i;
    }
  }
  std::vector<std::pair<int, int>> dd;
  for (int i = 0; i < static_cast<int>(sds.size()); ++i) {
    const SingleDiff& sd = sds[static_cast<std::size_t>(i)];
    if (!sd.fixable || sd.ambiguity < 0 || excluded.excludes(sd)) continue;
    const int r = reference.at(sd.group);
    if (r != i) dd.emplace_back(sd.ambiguity, sds[static_cast<std::size_t>(r)].ambiguity);
  }
  return dd;
}

/// The exclusions partial fixing tries after pruning: each (constellation, frequency) group, then each
/// constellation that has more than one group (dual-frequency signals that two receivers track differently, or a
/// constellation whose ambiguities are biased as a whole).
std::vector<Exclusion> partial_exclusions(const std::vector<SingleDiff>& sds) {
  std::map<int, int> groups_per_constellation;
  std::map<int, bool> groups;
  for (const SingleDiff& sd : sds) {
    if (!sd.fixable || sd.ambiguity < 0 || groups.count(sd.group) != 0) continue;
    groups[sd.group] = true;
    ++groups_per_constellation[sd.group / kMaxFrequencies];
  }
  std::vector<Exclusion> out;
  for (const auto& [group, unused] : groups) {
    (void)unused;
    out.push_back(Exclusion{group, -1});
  }
  if (groups_per_constellation.size() > 1) {
    for (const auto& [constellation, count] : groups_per_constellation) {
      if (count > 1) out.push_back(Exclusion{-1, constellation});
    }
  }
  return out;
}

}  // namespace

std::optional<RtkEngine::Fix> RtkEngine::try_fix(const std::vector<std::pair<int, int>>& dd, int min_size) const {
  const auto nd = static_cast<Eigen::Index>(dd.size());
  if (nd < std::max(min_size, options_.min_fix_ambiguities)) return std::nullopt;
  Fix fix;
  fix.dd = dd;
  // D has +1 and -1 per row: D x, P D^T and D P D^T from columns of P, without dense products.
  fix.a_float.resize(nd);
  fix.PDt.resize(x_.size(), nd);
  for (Eigen::Index k = 0; k < nd; ++k) {
    const auto [s, r] = dd[static_cast<std::size_t>(k)];
    fix.a_float[k] = x_[s] - x_[r];
    fix.PDt.col(k) = P_.col(s) - P_.col(r);
  }
  fix.Q_a.resize(nd, nd);
  for (Eigen::Index k = 0; k < nd; ++k) {
    const auto [s, r] = dd[static_cast<std::size_t>(k)];
    fix.Q_a.row(k) = fix.PDt.row(s) - fix.PDt.row(r);
  }
  fix.Q_a = 0.5 * (fix.Q_a + fix.Q_a.transpose()).eval();
  CarriedDecorrelation& carried = carried_decorrelations_[dd_keys(dd)];
  carried.last_epoch = ar_epoch_;
  MlambdaOptions search_options;
  search_options.with_z = true;  // for success_rate_subset_fix()
  auto search = mlambda(fix.a_float, fix.Q_a, search_options, &carried.warm);
  if (!search) return std::nullopt;
  fix.ratio = ratio_test(*search, options_.ratio_threshold).ratio;
  fix.squared_norm = search->squared_norms[0];
  fix.success_rate = success_rate(search->conditional_variances);
  fix.a_fix = search->candidates.col(0);
  fix.Z = std::move(search->Z);
  fix.d = std::move(search->conditional_variances);
  return fix;
}

double RtkEngine::success_rate(const Eigen::VectorXd& d) const {
  return float_variance_factor_ > 1.0 ? bootstrap_success_rate(d * float_variance_factor_) : bootstrap_success_rate(d);
}

void RtkEngine::test_float_consistency(Fix& full) {
  if (!(consistency_z_ > 0.0)) return;
  const auto n = static_cast<double>(full.a_fix.size());
  if (!(full.squared_norm > core::chi_square_upper_quantile(n, consistency_z_))) return;
  float_variance_factor_ = full.squared_norm / n;
  full.success_rate = success_rate(full.d);
}

bool RtkEngine::agrees_with_last_fix(const Fix& fix) const {
  if (fix.combinations) return true;  // no DD integers to compare
  for (std::size_t k = 0; k < fix.dd.size(); ++k) {
    const auto it = last_fix_.find(dd_key(fix.dd[k]));
    if (it != last_fix_.end() && it->second != fix.a_fix[static_cast<Eigen::Index>(k)]) return false;
  }
  return true;
}

int RtkEngine::fixable_directions(const std::vector<std::pair<int, int>>& dd) const {
  // Satellites joined by their pairs: each pair merges the groups of its two satellites (a union-find over few).
  std::vector<SatelliteId> sats;
  std::vector<int> group;
  const auto node = [&](const SatelliteId& sat) {
    const auto it = std::find(sats.begin(), sats.end(), sat);
    if (it != sats.end()) return static_cast<int>(it - sats.begin());
    sats.push_back(sat);
    group.push_back(static_cast<int>(group.size()));
    return static_cast<int>(group.size()) - 1;
  };
  const auto root = [&](int i) {
    while (group[static_cast<std::size_t>(i)] != i) i = group[static_cast<std::size_t>(i)];
    return i;
  };
  for (const auto& [s, r] : dd) {
    const int a = node(satellite_of_state(s));
    const int b = node(satellite_of_state(r));
    group[static_cast<std::size_t>(root(a))] = root(b);
  }
  int groups = 0;
  for (std::size_t i = 0; i < group.size(); ++i) groups += root(static_cast<int>(i)) == static_cast<int>(i) ? 1 : 0;
  return static_cast<int>(sats.size()) - groups;
}

RtkEngine::DdKey RtkEngine::dd_key(const std::pair<int, int>& dd) const {
  const auto k = static_cast<std::size_t>(num_kinematic_states());
  return {ambiguity_keys_[static_cast<std::size_t>(dd.first) - k],
          ambiguity_keys_[static_cast<std::size_t>(dd.second) - k]};
}

std::vector<RtkEngine::DdKey> RtkEngine::dd_keys(const std::vector<std::pair<int, int>>& dd) const {
  std::vector<DdKey> keys;
  keys.reserve(dd.size());
  for (const auto& pair : dd) keys.push_back(dd_key(pair));
  return keys;
}

std::string RtkEngine::rejection_reason(const Fix& fix) const {
  char figures[96];
  std::snprintf(figures, sizeof figures, " (%d ambiguities, ratio %.1f, success rate %.3f",
                static_cast<int>(fix.a_fix.size()), fix.ratio, fix.success_rate);
  std::string numbers = figures;
  if (float_variance_factor_ > 1.0) {
    std::snprintf(figures, sizeof figures,
                  " with the float covariance scaled by %.1f: no integer vector fits the float",
                  float_variance_factor_);
    numbers += figures;
  }
  numbers += ")";
  if (fix.ratio < options_.ratio_threshold) return std::string("ratio test failed") + numbers;
  if (fix.success_rate < options_.min_success_rate) return std::string("success rate too low") + numbers;
  if (!agrees_with_last_fix(fix)) return std::string("contradicts the last fix") + numbers;
  if (!fix.combinations && fixable_directions(fix.dd) < 3) return std::string("fewer than 4 satellites") + numbers;
  return std::string("refused by the aiding (its false-fix guard or position check)") + numbers;
}

bool RtkEngine::accepted(const Fix& fix) const {
  // A subset (partial fixing) from fewer than 4 satellites leaves the position open as the whole epoch's would.
  if (!fix.combinations && fixable_directions(fix.dd) < 3) return false;
  if (!agrees_with_last_fix(fix)) return false;
  if (!(fix.ratio >= options_.ratio_threshold && fix.success_rate >= options_.min_success_rate)) return false;
  if (aiding_ != nullptr && aiding_->accept_fix) {
    Eigen::Vector3d p;
    Eigen::Matrix3d P;
    return fix_position(fix, p, P) && aiding_->accept_fix(p, P);
  }
  return true;
}

bool RtkEngine::fix_position(const Fix& fix, Eigen::Vector3d& p, Eigen::Matrix3d& P) const {
  const Eigen::LLT<Eigen::MatrixXd> llt(fix.Q_a);
  if (llt.info() != Eigen::Success) return false;
  // Only the position rows of P D^T are needed (the whole x_fix, P_fix would cost n^2 nd).
  const Eigen::Matrix<double, 3, Eigen::Dynamic> B = fix.PDt.topRows<3>();  // cov(p, a)
  p = x_.head<3>() - B * llt.solve(fix.a_float - fix.a_fix);
  P = P_.topLeftCorner<3, 3>() - B * llt.solve(B.transpose());
  return true;
}

SatelliteId RtkEngine::satellite_of_state(int index) const {
  return ambiguity_keys_[static_cast<std::size_t>(index - num_kinematic_states())].first;
}

SatelliteId RtkEngine::satellite_of_largest_contribution(const std::vector<std::pair<int, int>>& dd,
                                                         const Eigen::VectorXd& contributions) const {
  std::map<SatelliteId, double> per_satellite;
  for (std::size_t k = 0; k < dd.size(); ++k) {
    per_satellite[satellite_of_state(dd[k].first)] += contributions[static_cast<Eigen::Index>(k)];
  }
  const auto worst = std::max_element(per_satellite.begin(), per_satellite.end(),
                                      [](const auto& l, const auto& r) { return l.second < r.second; });
  return worst->first;
}

std::optional<RtkEngine::Fix> RtkEngine::prune(Fix fix, int min_size) const {
  // The paper's pruning: drop the satellite whose DD ambiguities contribute most to the integer least-squares
  // residual of the best candidate (the sum of their squared w-test statistics) and solve again, until a fix is
  // accepted. Satellite by satellite, because what biases an ambiguity (multipath, reflection, a low elevation)
  // biases all frequencies of that satellite.
  for (int pruned = 0; pruned < options_.max_pruned_satellites; ++pruned) {
    const auto contributions = ils_residual_contributions(fix.a_float, fix.Q_a, fix.a_fix);
    if (!contributions) return std::nullopt;
    const SatelliteId worst = satellite_of_largest_contribution(fix.dd, *contributions);
    std::vector<std::pair<int, int>> dd = fix.dd;
    dd.erase(std::remove_if(dd.begin(), dd.end(),
                            [&](const std::pair<int, int>& p) { return satellite_of_state(p.first) == worst; }),
             dd.end());
    auto next = try_fix(dd, min_size);
    if (!next) return std::nullopt;
    next->pruned = fix.pruned;
    next->pruned.push_back(worst);
    if (accepted(*next)) return next;
    fix = std::move(*next);
  }
  return std::nullopt;
}

std::optional<RtkEngine::Fix> RtkEngine::last_subset_fix(const std::vector<std::pair<int, int>>& all,
                                                         int min_size) const {
  if (last_fix_.empty()) return std::nullopt;
  std::vector<std::pair<int, int>> dd;
  for (const auto& pair : all) {
    if (last_fix_.count(dd_key(pair)) != 0) dd.push_back(pair);
  }
  if (dd.size() == all.size()) return std::nullopt;  // the full set, tried already
  auto fix = try_fix(dd, min_size);
  if (fix && accepted(*fix)) return fix;
  return std::nullopt;
}

bool RtkEngine::better_fix(const Fix& l, const Fix& r) {
  return l.a_fix.size() > r.a_fix.size() || (l.a_fix.size() == r.a_fix.size() && l.ratio > r.ratio);
}

std::optional<RtkEngine::Fix> RtkEngine::success_rate_subset_fix(const Fix& full, int min_size) const {
  const auto n = full.a_float.size();
  if (full.Z.rows() != n || full.d.size() != n) return std::nullopt;
  // Longest trailing run of levels whose bootstrapped success rate stays at or above the threshold.
  double success = 1.0;
  Eigen::Index k0 = n;
  while (k0 > 0) {
    const double with_next = success * success_rate(full.d.segment(k0 - 1, 1));
    if (with_next < options_.min_success_rate) break;
    success = with_next;
    --k0;
  }
  const Eigen::Index m = n - k0;
  if (m == n || m < std::max(min_size, options_.min_fix_ambiguities)) return std::nullopt;
  const Eigen::MatrixXd Z_S = full.Z.rightCols(m);
  Fix sub;
  sub.dd = full.dd;
  sub.combinations = true;
  sub.a_float = Z_S.transpose() * full.a_float;
  sub.Q_a = Z_S.transpose() * full.Q_a * Z_S;
  sub.Q_a = 0.5 * (sub.Q_a + sub.Q_a.transpose()).eval();
  sub.PDt = full.PDt * Z_S;
  auto search = mlambda(sub.a_float, sub.Q_a);
  if (!search) return std::nullopt;
  sub.ratio = ratio_test(*search, options_.ratio_threshold).ratio;
  sub.squared_norm = search->squared_norms[0];
  sub.success_rate = success_rate(search->conditional_variances);
  sub.a_fix = search->candidates.col(0);
  if (!accepted(sub)) return std::nullopt;
  // A few precise combinations need not pin the position down: the fix counts only if they do (otherwise the caller
  // may still use them to sharpen the float position).
  Eigen::Vector3d p;
  Eigen::Matrix3d P_p;
  if (!fix_position(sub, p, P_p)) return std::nullopt;
  sub.imprecise = !(std::sqrt(std::max(P_p.trace(), 0.0)) <= options_.max_partial_fix_sigma_m);
  return sub;
}

std::optional<RtkEngine::Fix> RtkEngine::partial_fix(const std::vector<SingleDiff>& sds, std::optional<Fix> full,
                                                     int min_size, std::optional<Fix>& imprecise,
                                                     bool last_subset_tried) const {
  // First prune satellites from the full set. Then leave out whole groups or constellations (signals that the two
  // receivers track differently bias a whole group): the accepted subset with the most ambiguities, or else the
  // best of pruning the kPrunedSubsets subsets closest to passing (highest ratio). At most
  // 2 + (1 + kPrunedSubsets) max_pruned_satellites + (number of exclusions) integer searches per epoch. Before all
  // that, the subset of the last fix still tracked: in continuous mode it usually passes again (one search).
  if (!last_subset_tried) {
    if (auto again = last_subset_fix(dd_ambiguities(sds, Exclusion{}), min_size)) return again;
  }
  if (full) {
    if (auto combinations = success_rate_subset_fix(*full, min_size)) {
      if (!combinations->imprecise) return combinations;
      imprecise = std::move(combinations);
    }
    if (auto pruned = prune(std::move(*full), min_size)) return pruned;
  }
  std::optional<Fix> best_accepted;
  std::vector<Fix> rejected;
  for (const Exclusion& exclusion : partial_exclusions(sds)) {
    auto candidate = try_fix(dd_ambiguities(sds, exclusion), min_size);
    if (!candidate) continue;
    if (!accepted(*candidate)) {
      rejected.push_back(std::move(*candidate));
    } else if (!best_accepted || better_fix(*candidate, *best_accepted)) {
      best_accepted = std::move(candidate);
    }
  }
  if (best_accepted) return best_accepted;
  // Prune the subsets closest to passing (highest ratio first).
  std::sort(rejected.begin(), rejected.end(), [](const Fix& l, const Fix& r) { return l.ratio > r.ratio; });
  if (rejected.size() > kPrunedSubsets) rejected.resize(kPrunedSubsets);
  for (Fix& candidate : rejected) {
    auto pruned = prune(std::move(candidate), min_size);
    if (pruned && (!best_accepted || better_fix(*pruned, *best_accepted))) best_accepted = std::move(pruned);
  }
  return best_accepted;
}

bool RtkEngine::resolve_ambiguities(const std::vector<SingleDiff>& sds, RtkEpoch& out) {
  ++ar_epoch_;
  std::erase_if(carried_decorrelations_, [&](const auto& entry) { return entry.second.last_epoch < ar_epoch_ - 1; });
  const auto all = dd_ambiguities(sds, Exclusion{});
  if (static_cast<int>(all.size()) < options_.min_fix_ambiguities) {
    out.note = "too few ambiguities to fix: " + std::to_string(all.size());
    return false;
  }
  if (fixable_directions(all) < 3) {
    out.note = "too few satellites to fix: their double differences leave the position open along a line";
    out.too_few_to_fix = true;
    return false;
  }
  // A subset keeps at least min_partial_fraction of the ambiguities: the position of a small subset rests on the
  // float ambiguities left out, which are biased when the full set fails.
  const auto min_size = static_cast<int>(std::ceil(options_.min_partial_fraction * static_cast<double>(all.size())));
  const std::vector<DdKey> all_keys = dd_keys(all);
  // The same full set failed at the last epoch and a subset was fixed: the subset is tried first, and the full set
  // again only every kFullSetRetryEpochs epochs (or when the set changes). One epoch more of data seldom turns a
  // failing set around, and each integer search of the full set costs as much as the rest of the epoch.
  std::optional<Fix> best;
  bool last_subset_tried = false;  // and failed: partial fixing need not search it again
  if (options_.partial_ar && all_keys == failed_full_set_ && epochs_since_full_set_ < kFullSetRetryEpochs) {
    best = last_subset_fix(all, min_size);
    last_subset_tried = true;
    ++epochs_since_full_set_;
  }
  if (best) {
    out.solution.ratio = std::min(best->ratio, 999.9);
  } else {
    float_variance_factor_ = 1.0;  // the full set is tested afresh: its own success rate unscaled first
    best = try_fix(all, options_.min_fix_ambiguities);
    if (best) test_float_consistency(*best);
    out.float_variance_factor = float_variance_factor_;
    epochs_since_full_set_ = 0;
    failed_full_set_.clear();
    if (best) out.solution.ratio = std::min(best->ratio, 999.9);
    if (!best || !accepted(*best)) {
      failed_full_set_ = all_keys;
      const std::string why = !best ? std::string("integer search failed") : rejection_reason(*best);
      std::optional<Fix> imprecise;
      best = options_.partial_ar ? partial_fix(sds, std::move(best), min_size, imprecise, last_subset_tried)
                                 : std::nullopt;
      if (!best) {
        out.note = why;
        if (imprecise) {
          // The most precise combinations are fixed, but not enough of them to call the position fixed: the float
          // position conditioned on them is still the better one.
          (void)fix_position(*imprecise, out.solution.p_E_m, out.solution.P_E_m2);  // Q_a factorised already
          out.note += "; float position conditioned on " + std::to_string(imprecise->a_fix.size()) +
                      " fixed integer combinations";
        }
        return false;
      }
      out.solution.ratio = std::min(best->ratio, 999.9);
    }
  }
  // Conditional update on the fixed DD ambiguities: x_fix = x - P D^T Q_a^-1 (a_float - a_fix), the position rows.
  if (!fix_position(*best, out.solution.p_E_m, out.solution.P_E_m2)) {
    out.note = "float ambiguity covariance not positive definite";
    return false;
  }
  out.solution.status = core::SolutionStatus::Fixed;
  out.num_fixed_ambiguities = static_cast<int>(best->a_fix.size());
  out.ar_pruned = best->pruned;
  // The integers of the DD ambiguities, for the next fixes to agree with (combinations fix no DD ambiguity as such).
  last_fix_.clear();
  if (!best->combinations) {
    for (std::size_t k = 0; k < best->dd.size(); ++k)
      last_fix_[dd_key(best->dd[k])] = best->a_fix[static_cast<Eigen::Index>(k)];
  }
  if (options_.ar_mode == ArMode::FixAndHold) {
    // Hold: the fixed DD ambiguities as pseudo-measurements with a small variance, into the float filter.
    const double var = options_.hold_sigma_cyc * options_.hold_sigma_cyc;
    const auto nd = best->a_fix.size();
    const Eigen::MatrixXd S = best->Q_a + var * Eigen::MatrixXd::Identity(nd, nd);
    const Eigen::LLT<Eigen::MatrixXd> hold(S);
    x_ -= best->PDt * hold.solve(best->a_float - best->a_fix);
    P_ -= best->PDt * hold.solve(best->PDt.transpose());
    P_ = 0.5 * (P_ + P_.transpose()).eval();
  }
  return true;
}

/// The epoch between the stages of process() (predict, update, resolve).
struct RtkEngine::PendingEpoch {
  RtkEpoch out;
  std::vector<SingleDiff> sds;
  bool consistent = true;
};

RtkEngine::~RtkEngine() = default;
RtkEngine::RtkEngine(RtkEngine&&) noexcept = default;

Result<RtkEpoch> RtkEngine::process(const core::ObsEpoch& rover, const core::ObsEpoch* base, const RtkAiding* aiding) {
  auto more = predict(rover, base, aiding);
  if (!more) return more.error();
  if (*more && update()) resolve();
  return take_epoch();
}

void RtkEngine::set_base_position(const Eigen::Vector3d& p_E_base_m) {
  p_E_base_m_ = p_E_base_m;
  geometry_builder_.set_base_position(p_E_base_m);
}

Result<bool> RtkEngine::predict(const core::ObsEpoch& rover, const core::ObsEpoch* base, const RtkAiding* aiding,
                                EpochGeometry* geometry) {
  has_prior_ = false;
  if (aiding != nullptr && !initialised_) aiding = nullptr;  // nothing to add the increment to yet
  // The epoch's geometry (single-point solution, observables, satellite states, cycle slips): built ahead by the
  // caller, or here.
  std::optional<EpochGeometry> own_geometry;
  if (geometry == nullptr) geometry = &own_geometry.emplace(geometry_builder_.build(rover, base, aiding != nullptr));
  assert(geometry->has_base == (base != nullptr));
  const Result<gnss::SppSolution>& spp = geometry->spp;
  if (!spp && aiding == nullptr) return spp.error();

  pending_ = std::make_unique<PendingEpoch>();
  RtkEpoch& out = pending_->out;
  core::Solution& sol = out.solution;
  if (spp) {
    sol.time = spp->time;
    sol.status = core::SolutionStatus::Single;
    sol.p_E_m = spp->p_E_m;
    sol.P_E_m2 = spp->P_E_m2;
    sol.v_E_mps = spp->v_E_mps;
    sol.num_satellites = spp->num_satellites;
    out.hdop = spp->dop.hdop;
  } else if (aiding != nullptr) {
    // Aided: the prior stands in for the single-point solution.
    sol.time = rover.time;
    sol.status = core::SolutionStatus::None;
    sol.p_E_m = x_.head<3>() + aiding->delta_p_E_m;
    sol.P_E_m2 = P_.topLeftCorner<3, 3>() + aiding->Q_E_m2;
    out.note = "no single-point solution: " + spp.error().message;
  }
  if (base == nullptr) {
    out.note = "no base observations";
    return false;
  }
  const double age_s = rover.time - base->time;
  sol.age_s = age_s;
  if (base_out_of_time(age_s, options_.max_age_s)) {
    out.note = "base observations too old (age " + std::to_string(age_s) + " s)";
    return false;
  }

  if (!geometry->slips) {
    // A builder of other options than geometry_options() (a longer base age), a geometry built ahead unaided for an
    // aided epoch without a single point, or a geometry not from a builder.
    return Error("rtk: the epoch's geometry has no cycle-slip scan (not built with the engine's geometry_options())");
  }
  if (options_.ar_mode == ArMode::Instantaneous) clear_ambiguities();
  choose_ionosphere_model((sol.p_E_m - p_E_base_m_).norm());  // single-point position, or the aided prior
  if (aiding != nullptr) {
    aided_time_update(rover.time, *aiding);
  } else {
    time_update(rover.time, *spp);
  }
  pending_->sds = single_differences(*geometry);
  update_ambiguities(pending_->sds, rover.time, *geometry->slips);
  if (aiding != nullptr) {
    out.aided = true;
    out.prior_p_E_m = x_.head<3>();
    out.prior_P_E_m2 = P_.topLeftCorner<3, 3>();
    prior_x_ = x_;
    prior_P_ = P_;
    prior_last_fix_ = last_fix_;
    has_prior_ = true;
  }
  aiding_ = aiding;
  return true;
}

bool RtkEngine::update() {
  assert(pending_ && "update() after a predict() that returned true");
  RtkEpoch& out = pending_->out;
  std::vector<SingleDiff>& sds = pending_->sds;
  core::Solution& sol = out.solution;
  last_code_rows_ = 0;
  bool consistent = true;
  out.num_dd_measurements = measurement_update(sds, out.rejected, consistent);
  out.max_post_fit_normalised = last_post_fit_normalised_;
  out.num_dd_code_measurements = last_code_rows_;
  if (out.num_dd_measurements == 0) {
    aiding_ = nullptr;
    out.note = "no double-differenced phase";
    return false;
  }
  sol.status = core::SolutionStatus::Float;
  sol.p_E_m = x_.head<3>();
  sol.P_E_m2 = P_.topLeftCorner<3, 3>();
  out.float_p_E_m = sol.p_E_m;
  out.float_P_E_m2 = sol.P_E_m2;
  int satellites = 0;
  for (std::size_t i = 0; i < sds.size(); ++i) {
    if (sds[i].frequency == 0 || (i > 0 && sds[i - 1].sat != sds[i].sat)) ++satellites;
  }
  sol.num_satellites = satellites;
  if (!consistent) {
    // Float validation: residuals still beyond their thresholds after the rejections allowed (more outliers than
    // the epoch can shed, e.g. reflections in a street canyon): the float solution and its covariance cannot be
    // trusted, and neither can integers fixed from them.
    out.note = "float solution failed validation (post-fit residuals beyond their thresholds after " +
               std::to_string(options_.max_post_fit_rejections) + " rejections)";
    return false;
  }
  if (options_.ar_mode == ArMode::Off) {
    aiding_ = nullptr;
    return false;
  }
  return true;
}

void RtkEngine::resolve() {
  assert(pending_ && "resolve() after an update() that returned true");
  resolve_ambiguities(pending_->sds, pending_->out);
  aiding_ = nullptr;
}

RtkEpoch RtkEngine::take_epoch() {
  assert(pending_ && "take_epoch() after a predict() that succeeded");
  RtkEpoch out = std::move(pending_->out);
  pending_.reset();
  return out;
}

std::vector<SingleDiff> RtkEngine::single_differences(EpochGeometry& geometry) const {
  const ReceiverObservables& rover_obs = geometry.rover_obs;
  const ReceiverObservables& base_obs = geometry.base_obs;
  const ReceiverGeometry rover(x_.head<3>());
  const bool tropo = options_.troposphere_saastamoinen;
  std::vector<SingleDiff> sds;
  sds.reserve(rover_obs.signals.size());
  SatelliteId current{};
  ZeroDiff zr;
  ZeroDiff zb;
  for (const SignalObservable& r : rover_obs.signals) {
    const SignalObservable* b = base_obs.find(r.sat, r.frequency);
    if (b == nullptr) continue;
    if (r.sat != current || sds.empty()) {
      // Each receiver's geometry at its own transmission time (its own time tag and pseudorange).
      current = r.sat;
      const double pr_r = any_pseudorange(rover_obs, r.sat);
      zr = core::has_value(pr_r) ? zero_difference(geometry.rover_states, r.sat, pr_r, rover, tropo) : ZeroDiff{};
      zb = geometry.base_model(r.sat);
    }
    if (!zr.valid || !zb.valid || zr.elevation_rad < options_.elevation_mask_rad) continue;
    SingleDiff sd;
    sd.sat = r.sat;
    sd.frequency = r.frequency;
    sd.group = static_cast<int>(r.sat.system) * kMaxFrequencies + r.frequency;
    sd.wavelength_m = r.wavelength_m;
    if (iono_estimated_) {
      sd.iono_scale = std::pow(r.wavelength_m / first_wavelength_m(eph_, r.sat), 2);
    }
    sd.lli = static_cast<std::uint8_t>(r.lli | b->lli);
    const double model_m = zr.model_m - zb.model_m;
    if (core::has_value(r.carrier_phase_cyc) && core::has_value(b->carrier_phase_cyc) &&
        std::abs(r.wavelength_m - b->wavelength_m) < 1e-9) {
      sd.phase_m = r.wavelength_m * (r.carrier_phase_cyc - b->carrier_phase_cyc) - model_m;
    }
    if (core::has_value(r.pseudorange_m) && core::has_value(b->pseudorange_m)) {
      sd.code_m = (r.pseudorange_m - b->pseudorange_m) - model_m;
    }
    const double var_sd = zero_diff_phase_variance(options_, zr.elevation_rad, r.snr_dbhz) +
                          zero_diff_phase_variance(options_, zb.elevation_rad, b->snr_dbhz);
    sd.phase_variance_m2 = var_sd;
    sd.code_variance_m2 = var_sd * options_.code_phase_ratio * options_.code_phase_ratio;
    sd.test_variance_m2 = zero_diff_phase_variance(options_, zr.elevation_rad, core::kNoValue) +
                          zero_diff_phase_variance(options_, zb.elevation_rad, core::kNoValue);
    sd.los_E = zr.los_E;
    sd.elevation_rad = zr.elevation_rad;
    sds.push_back(sd);
  }
  return sds;
}

}  // namespace canyon::rtk
