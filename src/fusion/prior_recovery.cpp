// Recoveries from a drifted prior (see prior_recovery.hpp).

#include "canyon/fusion/prior_recovery.hpp"

namespace canyon::fusion {

std::string PriorRecoveryOptions::validate() const {
  if (max_prior_rejections < 0 || gate_conflict_epochs < 0 || !(reanchor_sigma_m > 0.0)) {
    return "max_prior_rejections must be >= 0, gate_conflict_epochs >= 0 and reanchor_sigma_m > 0";
  }
  return {};
}

bool PriorRecovery::reanchor(bool prior_only) {
  prior_rejections_ = prior_only ? prior_rejections_ + 1 : 0;
  if (!prior_only || prior_rejections_ <= options_.max_prior_rejections) return false;
  prior_rejections_ = 0;
  return true;
}

void PriorRecovery::count_gate_conflict(int rejected, int used) {
  if (options_.gate_conflict_epochs == 0) return;  // never widened
  gate_conflicts_ = rejected > used ? gate_conflicts_ + 1 : 0;
  if (gate_conflicts_ >= options_.gate_conflict_epochs) {
    widen_next_ = true;
    gate_conflicts_ = 0;
  }
}

std::optional<double> PriorRecovery::take_widening() {
  if (!widen_next_) return std::nullopt;
  widen_next_ = false;
  return options_.reanchor_sigma_m;
}

}  // namespace canyon::fusion
