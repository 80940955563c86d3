#pragma once
// The double-differenced (DD) measurement update of the RTK filter: the rows, the gates, the Kalman update and the
// post-fit checks.
//
// Measurements, per group g = (constellation, frequency) with reference satellite r (the highest with the
// observable) and every other satellite s of the group, in metres:
//   DD phase: (lambda_s Phi_sd,s - lambda_r Phi_sd,r) = DD rho(p_E_u) + lambda_s N_sd,s - lambda_r N_sd,r + e
//   DD code:  (P_sd,s - P_sd,r)                       = DD rho(p_E_u) + e
// (single differences and their models: single_difference.hpp; receiver clocks cancel). With the ionosphere
// estimated, it enters as -mu_s I_sd,s + mu_r I_sd,r on phase and with the opposite sign on code, mu = (f_1 / f)^2.
// The DD covariance follows from the SD variances: rows of one kind sharing a reference are correlated through it;
// code and phase rows are not, so the update is two sequential ones (code, then phase: kalman.hpp).
//
// Gates: a DD innovation beyond max_phase_innovation_m / max_code_innovation_m is not used; an injected
// InnovationGate (the fusion's VIO gates) may refuse more rows; a phase row that its prediction cannot test (predicted
// sigma beyond one cycle: a new or re-initialised ambiguity) then takes the verdict of its signal's code row, so a
// reflected signal whose code the gate refuses does not start its ambiguity from a phase with the same extra path. A
// refused phase row's ambiguity is not fixed that epoch (its value is the prior's, not this epoch's).
// Post-fit: after the update, the DD phase or code whose post-fit residual exceeds its threshold (max_post_fit_sigmas
// for phase, max_post_fit_code_sigmas for code, in sigmas of the elevation model) by the largest factor is dropped for
// the epoch and the update redone from the prior, at most max_post_fit_rejections times. A code outlier (an NLOS
// signal) pulls the float position and with it every ambiguity; rejecting it keeps the float fixable. When residuals
// are still beyond their thresholds after the rejections allowed, the update is not consistent: the float fails
// validation and no fix is attempted.

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/satellite.hpp"
#include "canyon/rtk/dd_row.hpp"
#include "canyon/rtk/filter_state.hpp"
#include "canyon/rtk/rtk_options.hpp"
#include "canyon/rtk/single_difference.hpp"

namespace canyon::rtk {

/// What an innovation gate sees of one DD row at the prior state.
class DdInnovation {
 public:
  DdInnovation(const DdRow& row, const Eigen::MatrixXd& P, double measurement_variance_m2)
      : row_(row), P_(P), r_(measurement_variance_m2) {}
  /// A carrier-phase row (else pseudorange).
  [[nodiscard]] bool phase() const { return row_.phase; }
  /// Its innovation v (m).
  [[nodiscard]] double innovation_m() const { return row_.innovation_m; }
  /// Its measurement variance r (m^2).
  [[nodiscard]] double measurement_variance_m2() const { return r_; }
  /// Its predicted variance h P h^T (m^2, at least 0), computed when first asked.
  [[nodiscard]] double predicted_variance_m2() const;

 private:
  const DdRow& row_;
  const Eigen::MatrixXd& P_;
  double r_;
  mutable std::optional<double> hPh_;
};

/// A gate policy injected into the update (the fusion's, fusion/innovation_gates.hpp): a row it refuses is not used.
class InnovationGate {
 public:
  virtual ~InnovationGate() = default;
  [[nodiscard]] virtual bool passes(const DdInnovation& row) const = 0;
  /// True: a signal whose code row it refuses loses its phase rows as well, even those its prediction could test (a
  /// code far beyond the prior marks a reflected signal, whose phase carries the same extra path).
  [[nodiscard]] virtual bool refuses_signal_with_code() const { return false; }
};

struct DdUpdateResult {
  int phase_rows = 0;  ///< DD phase rows used (0: no DD phase, or the update failed)
  int code_rows = 0;   ///< DD code rows used in the last update
  /// The largest DD post-fit residual over its rejection threshold (> 1: beyond), after the rejections.
  double worst_post_fit_normalised = 0.0;
  bool consistent = true;  ///< no post-fit residual is left beyond its threshold
};

/// The update described above on `state` with the epoch's single differences (whose phases or codes it may drop for
/// the epoch); satellites whose rows were gated or rejected after the fit are appended to `rejected`.
DdUpdateResult dd_measurement_update(FilterState& state, std::vector<SingleDiff>& sds, const RtkOptions& options,
                                     const InnovationGate* gate, std::vector<core::SatelliteId>& rejected);

/// The DD rows of the epoch at `state` (unfiltered), phase then code, group by group: for tests and diagnostics.
[[nodiscard]] std::vector<DdRow> dd_rows(const FilterState& state, const std::vector<SingleDiff>& sds);

}  // namespace canyon::rtk
