// The DD measurement update (see dd_update.hpp).

#include "canyon/rtk/dd_update.hpp"

#include <cmath>
#include <map>

#include "canyon/rtk/kalman.hpp"

namespace canyon::rtk {
namespace {

/// The row of SD `i` against its group's reference `reference` at `state`.
DdRow form_row(const FilterState& state, const std::vector<SingleDiff>& sds, int i, int reference, bool phase) {
  const Eigen::VectorXd& x = state.x();
  const SingleDiff& sd = sds[static_cast<std::size_t>(i)];
  const SingleDiff& ref = sds[static_cast<std::size_t>(reference)];
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
    predicted_m = sd.wavelength_m * x[sd.ambiguity] - ref.wavelength_m * x[ref.ambiguity];
    observed_m = sd.phase_m - ref.phase_m;
  } else {
    observed_m = sd.code_m - ref.code_m;
    if (sd.code_bias >= 0) {
      row.add(sd.code_bias, 1.0);
      predicted_m += x[sd.code_bias];
    }
    if (ref.code_bias >= 0) {
      row.add(ref.code_bias, -1.0);
      predicted_m -= x[ref.code_bias];
    }
  }
  if (sd.iono >= 0 && ref.iono >= 0) {
    // The ionosphere advances phase and delays code by iono_scale * I_sd.
    const double sign = phase ? -1.0 : 1.0;
    row.add(sd.iono, sign * sd.iono_scale);
    row.add(ref.iono, -sign * ref.iono_scale);
    predicted_m += sign * (sd.iono_scale * x[sd.iono] - ref.iono_scale * x[ref.iono]);
  }
  // The SD residuals were formed at the prior position: the geometry term is already in observed_m, and the
  // position correction enters through H; at the prior, the predicted DD range residual is zero.
  row.innovation_m = observed_m - predicted_m;
  return row;
}

bool usable(const SingleDiff& sd, bool phase) {
  return phase ? sd.ambiguity >= 0 : core::has_value(sd.code_m);
}

/// Measurement variance of one SD in a row of the given kind.
double sd_variance(const std::vector<SingleDiff>& sds, bool phase, int i) {
  const SingleDiff& sd = sds[static_cast<std::size_t>(i)];
  return phase ? sd.phase_variance_m2 : sd.code_variance_m2;
}

/// The DD measurement covariance of a block of rows of one kind (on and below the diagonal): the SD variances of s
/// and of its reference on the diagonal; rows that share a reference are correlated through it.
Eigen::MatrixXd block_covariance(const std::vector<SingleDiff>& sds, const std::vector<const DdRow*>& block) {
  const auto m = static_cast<Eigen::Index>(block.size());
  Eigen::MatrixXd R(m, m);
  for (Eigen::Index b = 0; b < m; ++b) {
    const DdRow& rb = *block[static_cast<std::size_t>(b)];
    for (Eigen::Index a = b; a < m; ++a) {
      const DdRow& ra = *block[static_cast<std::size_t>(a)];
      if (a == b) {
        R(a, b) = sd_variance(sds, ra.phase, ra.sd) + sd_variance(sds, ra.phase, ra.reference);
      } else {
        R(a, b) = rb.phase == ra.phase && rb.reference == ra.reference ? sd_variance(sds, ra.phase, ra.reference) : 0.0;
      }
    }
  }
  return R;
}

/// The innovations of a block after a correction dx: v - H dx.
Eigen::VectorXd innovations(const std::vector<const DdRow*>& block, const Eigen::VectorXd& dx) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(block.size()));
  for (std::size_t a = 0; a < block.size(); ++a) {
    v[static_cast<Eigen::Index>(a)] = block[a]->innovation_m - block[a]->dot(dx);
  }
  return v;
}

/// The worst post-fit residual of one update.
struct PostFit {
  int worst_sd = -1;              // SD of the largest normalised post-fit residual
  double worst_normalised = 0.0;  // |residual| / (measurement sigma * threshold of its kind): beyond when > 1
  bool worst_is_code = false;     // the worst residual is a code one
};

/// Post-fit DD residuals, normalised by their measurement sigma (elevation model alone: SNR weighting lowers the
/// weight of weak signals in the estimate, not the scrutiny they get) and by the threshold of their kind.
void check_post_fit(const std::vector<SingleDiff>& sds, const RtkOptions& options,
                    const std::vector<const DdRow*>& block, const Eigen::VectorXd& dx, bool code, PostFit& post_fit) {
  const double threshold_sigmas = code ? options.max_post_fit_code_sigmas : options.max_post_fit_sigmas;
  for (const DdRow* row : block) {
    const SingleDiff& s = sds[static_cast<std::size_t>(row->sd)];
    const SingleDiff& r = sds[static_cast<std::size_t>(row->reference)];
    const double ratio2 = row->phase ? 1.0 : options.code_phase_ratio * options.code_phase_ratio;
    const double test_variance = (s.test_variance_m2 + r.test_variance_m2) * ratio2;
    const double sigmas = std::abs(row->innovation_m - row->dot(dx)) / std::sqrt(test_variance);
    const double normalised = sigmas / threshold_sigmas;
    if (normalised > post_fit.worst_normalised) {
      post_fit.worst_normalised = normalised;
      post_fit.worst_sd = row->sd;
      post_fit.worst_is_code = code;
    }
  }
}

/// The rows the gates let through; the satellites of the others are appended to `rejected`, and a refused phase
/// row's ambiguity is not fixed this epoch. With an injected gate, a phase row whose prediction cannot test it (a new
/// or re-initialised ambiguity: predicted sigma beyond one cycle) takes the verdict of its signal's code row: a
/// reflected signal whose code the gate refuses would otherwise start its ambiguity from a phase carrying the same
/// extra path (tens of metres in a street canyon), and hold it.
std::vector<DdRow> gated_rows(const FilterState& state, std::vector<SingleDiff>& sds, const RtkOptions& options,
                              const InnovationGate* gate, std::vector<core::SatelliteId>& rejected) {
  std::vector<DdRow> rows = dd_rows(state, sds);
  // Each row's verdict; an untestable phase row's is its code row's, known once every row is judged (code rows come
  // after the phase rows).
  enum class Verdict : char { Refused, Passes, FollowsCode };
  std::vector<Verdict> verdicts(rows.size(), Verdict::Refused);
  std::vector<char> code_refused(sds.size(), 0);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const DdRow& row = rows[k];
    const double limit_m = row.phase ? options.max_phase_innovation_m : options.max_code_innovation_m;
    bool pass = !(std::abs(row.innovation_m) > limit_m);
    bool untestable = false;
    if (pass && gate != nullptr) {
      const double r = sd_variance(sds, row.phase, row.sd) + sd_variance(sds, row.phase, row.reference);
      const DdInnovation innovation(row, state.P(), r);
      pass = gate->passes(innovation);
      const double wavelength_m = sds[static_cast<std::size_t>(row.sd)].wavelength_m;
      untestable = row.phase && innovation.predicted_variance_m2() > wavelength_m * wavelength_m;
      if (!pass && !row.phase) code_refused[static_cast<std::size_t>(row.sd)] = 1;
    }
    if (pass) verdicts[k] = untestable ? Verdict::FollowsCode : Verdict::Passes;
  }
  const bool whole_signal = gate != nullptr && gate->refuses_signal_with_code();
  std::vector<DdRow> kept;
  kept.reserve(rows.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const DdRow& row = rows[k];
    const bool code_ok = code_refused[static_cast<std::size_t>(row.sd)] == 0;
    const bool passes = (verdicts[k] == Verdict::Passes && (code_ok || !whole_signal || !row.phase)) ||
                        (verdicts[k] == Verdict::FollowsCode && code_ok);
    if (passes) {
      kept.push_back(row);
      continue;
    }
    SingleDiff& sd = sds[static_cast<std::size_t>(row.sd)];
    rejected.push_back(sd.sat);
    if (row.phase) sd.fixable = false;  // the prior's ambiguity is no fix
  }
  return kept;
}

/// The rows one update used: phase rows (0 if it could not update), code rows once the update is done.
struct RowsUsed {
  int phase = 0;
  std::optional<int> code;
};

/// One Kalman update with the gated rows and its post-fit check.
RowsUsed update_once(FilterState& state, std::vector<SingleDiff>& sds, const RtkOptions& options,
                     const InnovationGate* gate, std::vector<core::SatelliteId>& rejected, PostFit& post_fit) {
  const std::vector<DdRow> rows = gated_rows(state, sds, options, gate, rejected);
  if (rows.empty()) return {};
  // The code rows, which touch only the position (and ionosphere states), in compressed form, then the phase rows at
  // the code-updated covariance. Neither is applied before both factorisations have succeeded.
  std::vector<const DdRow*> code_rows;
  std::vector<const DdRow*> phase_rows;
  for (const DdRow& row : rows) (row.phase ? phase_rows : code_rows).push_back(&row);
  const Eigen::Index n = state.size();
  KalmanStep code_step = no_step(n);
  if (!code_rows.empty()) {
    auto step =
        compressed_update(state.P(), code_rows, innovations(code_rows, code_step.dx), block_covariance(sds, code_rows));
    if (!step) return {};
    code_step = std::move(*step);
  }
  KalmanStep phase_step = no_step(n);
  if (!phase_rows.empty()) {
    auto step = dense_update(state.P(), code_step, phase_rows, innovations(phase_rows, code_step.dx),
                             block_covariance(sds, phase_rows));
    if (!step) return {};
    phase_step = std::move(*step);
  }
  const Eigen::VectorXd dx = code_step.dx + phase_step.dx;
  Eigen::MatrixXd U(n, code_step.U.cols() + phase_step.U.cols());
  Eigen::MatrixXd V(n, U.cols());
  U << code_step.U, phase_step.U;
  V << code_step.V, phase_step.V;
  state.correct(dx, U, V);
  post_fit = PostFit{};
  check_post_fit(sds, options, phase_rows, dx, false, post_fit);
  check_post_fit(sds, options, code_rows, dx, true, post_fit);
  return {static_cast<int>(phase_rows.size()), static_cast<int>(code_rows.size())};
}

}  // namespace

double DdInnovation::predicted_variance_m2() const {
  if (!hPh_) {
    Eigen::VectorXd P_h(P_.rows());
    row_.covariance_times(P_, P_h);
    hPh_ = std::max(row_.dot(P_h), 0.0);
  }
  return *hPh_;
}

std::vector<DdRow> dd_rows(const FilterState& state, const std::vector<SingleDiff>& sds) {
  // Group by (constellation, frequency); the reference is the highest satellite with the observable.
  std::map<int, std::vector<int>> groups;
  for (int i = 0; i < static_cast<int>(sds.size()); ++i) groups[sds[static_cast<std::size_t>(i)].group].push_back(i);
  std::vector<DdRow> rows;
  for (const bool phase : {true, false}) {
    for (const auto& [group, members] : groups) {
      int reference = -1;
      for (const int i : members) {
        const SingleDiff& sd = sds[static_cast<std::size_t>(i)];
        if (usable(sd, phase) &&
            (reference < 0 || sd.elevation_rad > sds[static_cast<std::size_t>(reference)].elevation_rad)) {
          reference = i;
        }
      }
      if (reference < 0) continue;
      for (const int i : members) {
        if (i != reference && usable(sds[static_cast<std::size_t>(i)], phase)) {
          rows.push_back(form_row(state, sds, i, reference, phase));
        }
      }
    }
  }
  return rows;
}

DdUpdateResult dd_measurement_update(FilterState& state, std::vector<SingleDiff>& sds, const RtkOptions& options,
                                     const InnovationGate* gate, std::vector<core::SatelliteId>& rejected) {
  // Update, then check the post-fit residuals: a signal whose residual is beyond the threshold (a phase inconsistent
  // with the others, e.g. an undetected slip or signals two receivers track differently; a code far off, e.g. a
  // reflection) is dropped for this epoch and the update redone from the prior.
  const Eigen::VectorXd x0 = state.x();
  const Eigen::MatrixXd P0 = state.P();
  DdUpdateResult result;
  for (int attempt = 0; attempt <= options.max_post_fit_rejections; ++attempt) {
    PostFit post_fit;
    const RowsUsed used = update_once(state, sds, options, gate, rejected, post_fit);
    result.phase_rows = used.phase;
    if (used.code) result.code_rows = *used.code;  // an update that could not be made leaves the last one's
    result.worst_post_fit_normalised = post_fit.worst_normalised;
    result.consistent = post_fit.worst_sd < 0 || post_fit.worst_normalised <= 1.0;
    if (result.consistent || attempt == options.max_post_fit_rejections) break;
    SingleDiff& bad = sds[static_cast<std::size_t>(post_fit.worst_sd)];
    rejected.push_back(bad.sat);
    if (post_fit.worst_is_code) {
      bad.code_m = core::kNoValue;  // its code is not used this epoch
    } else {
      bad.ambiguity = -1;  // its phase is not used (nor fixed) this epoch
      bad.fixable = false;
    }
    state.restore_values(x0, P0);
  }
  return result;
}

}  // namespace canyon::rtk
