// Outlier satellite pruning in the measurement update (see innovation_gates.hpp).

#include "canyon/fusion/innovation_gates.hpp"

#include <algorithm>
#include <cmath>

namespace canyon::fusion {

const char* gate_kind_name(GateKind kind) {
  switch (kind) {
    case GateKind::Off: return "off";
    case GateKind::Paper: return "paper";
    case GateKind::ChiSquare: return "chi_square";
    case GateKind::Both: return "both";
  }
  return "?";
}

std::string GateOptions::validate() const {
  if (!(motion_factor > 0.0) || !(min_gate_m > 0.0) || !(sigmas > 0.0)) {
    return "gate_motion_factor, min_gate_m and gate_sigmas must be > 0";
  }
  if (!(max_gate_m == 0.0 || max_gate_m >= min_gate_m) || !std::isfinite(max_gate_m)) {
    return "max_gate_m must be 0 (no cap) or at least min_gate_m";
  }
  if (!(nlos_sigmas >= 0.0 && std::isfinite(nlos_sigmas))) return "gate_nlos_sigmas must be finite and >= 0 (0: off)";
  return {};
}

VioInnovationGates::VioInnovationGates(const GateOptions& options, double motion_m) {
  if (options.kind == GateKind::Paper || options.kind == GateKind::Both) {
    const double paper_gate_m = options.motion_factor * motion_m;
    const double capped_m = options.max_gate_m > 0.0 ? std::min(paper_gate_m, options.max_gate_m) : paper_gate_m;
    max_phase_innovation_m_ = std::max(capped_m, options.min_gate_m);
  }
  if (options.kind == GateKind::ChiSquare || options.kind == GateKind::Both) {
    max_normalised_innovation_ = options.sigmas;
  }
  if (options.kind != GateKind::Off && options.nlos_sigmas > 0.0) max_nlos_sigmas_ = options.nlos_sigmas;
}

bool VioInnovationGates::passes(const rtk::DdInnovation& row) const {
  const std::optional<double> fixed_gate = row.phase() ? max_phase_innovation_m_ : std::nullopt;
  const std::optional<double> nlos_gate = row.phase() ? std::nullopt : max_nlos_sigmas_;
  if (!fixed_gate && !max_normalised_innovation_ && !nlos_gate) return true;
  const double hPh = row.predicted_variance_m2();
  const double r = row.measurement_variance_m2();
  const double v = std::abs(row.innovation_m());
  if (nlos_gate && row.innovation_m() > *nlos_gate * std::sqrt(hPh + r)) return false;
  // The paper's gate judges only rows whose prediction is good to a third of it (not a new ambiguity).
  if (fixed_gate && 9.0 * hPh <= *fixed_gate * *fixed_gate && v > *fixed_gate) return false;
  return !(max_normalised_innovation_ && v > *max_normalised_innovation_ * std::sqrt(hPh + r));
}

}  // namespace canyon::fusion
