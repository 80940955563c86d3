#pragma once
// Outlier satellite pruning in the measurement update (the paper's Section "Outlier Satellite Pruning"; Algorithm 1,
// line 6), as the RTK filter's injected gate policy (rtk::InnovationGate, rtk/dd_update.hpp):
//   the paper's gate: a DD phase innovation beyond motion_factor x |dp_E| (5 x the VIO incremental motion, at least
//     min_gate_m, and with max_gate_m > 0 at most that: the speed-aware gate, since at a vehicle's 15 m/s five times
//     the motion is metres and gates nothing) is not used. Applied to phase only (DD code noise is of that size), and
//     only to rows whose predicted sigma sqrt(h P h^T) is within a third of the gate (a new ambiguity's prediction is
//     no test);
//   beyond the paper, a chi-square gate on phase and code: |v| <= sigmas sqrt(h P h^T + r);
//   beyond the paper, NLOS by VIO consistency: a DD code row whose innovation exceeds nlos_sigmas sqrt(h P h^T + r)
//     upward (the satellite's code longer than the VIO-held prior allows: a reflection's extra path is always
//     positive, and a street canyon's NLOS codes are metres long) is refused, and with it every phase row of that
//     signal (its phase carries the same extra path, modulo a wavelength, which the prediction may not see).

#include <optional>
#include <string>

#include "canyon/rtk/dd_update.hpp"

namespace canyon::fusion {

enum class GateKind { Off, Paper, ChiSquare, Both };
[[nodiscard]] const char* gate_kind_name(GateKind kind);

struct GateOptions {
  GateKind kind = GateKind::Both;
  double motion_factor = 5.0;  ///< paper: 5 x the VIO incremental motion
  double min_gate_m = 0.5;     ///< the motion gate is at least this (standing still) (m)
  double max_gate_m = 0.0;     ///< the motion gate is at most this (m; speed-aware); 0: no cap, as the paper
  double sigmas = 4.0;         ///< chi-square gate: |v| <= this x sqrt(h P h^T + r)
  double nlos_sigmas = 3.0;    ///< NLOS gate: a code row with v > this x sqrt(h P h^T + r) refuses its signal; 0: off

  [[nodiscard]] std::string validate() const;
};

/// One epoch's gates.
class VioInnovationGates final : public rtk::InnovationGate {
 public:
  VioInnovationGates() = default;
  /// The gates of an epoch whose predicted motion is `motion_m` long.
  VioInnovationGates(const GateOptions& options, double motion_m);
  [[nodiscard]] bool passes(const rtk::DdInnovation& row) const override;
  [[nodiscard]] bool refuses_signal_with_code() const override { return max_nlos_sigmas_.has_value(); }

  [[nodiscard]] const std::optional<double>& max_phase_innovation_m() const { return max_phase_innovation_m_; }
  [[nodiscard]] const std::optional<double>& max_normalised_innovation() const { return max_normalised_innovation_; }

 private:
  std::optional<double> max_phase_innovation_m_;     // the paper's gate (m)
  std::optional<double> max_normalised_innovation_;  // the chi-square gate (sigmas)
  std::optional<double> max_nlos_sigmas_;            // the NLOS gate (sigmas, upward, code rows)
};

}  // namespace canyon::fusion
