#pragma once
// Beyond the paper: two recoveries from a VIO prior that drifted (a poor alignment, a long fill-in). Why: float
// validation (float_validation.hpp) trusts the prior; once the prior is metres off, every good float fails against it
// and the fill-in drifts on. So
//   - after more than max_prior_rejections consecutive epochs whose float failed the prior check alone (its update and
//     post-fit residuals good), the float is taken: GNSS re-anchors the prior;
//   - after gate_conflict_epochs consecutive epochs whose gates rejected more DD rows than the update used, the next
//     prior's position sigma is widened by reanchor_sigma_m per axis (the gates, centred on a drifted prior, refuse
//     the good rows).

#include <optional>
#include <string>

namespace canyon::fusion {

struct PriorRecoveryOptions {
  int max_prior_rejections = 5;  ///< consecutive prior-only validation failures before the float is taken
  /// Consecutive epochs gating more rows than used before the prior is widened; 0: never (the default: in a street
  /// canyon the NLOS code rows conflict with a good prior for minutes, and each widening let them pull it tens of
  /// metres away, docs/results/urban-claim.md).
  int gate_conflict_epochs = 0;
  double reanchor_sigma_m = 2.0;  ///< the widening (m, per axis)

  [[nodiscard]] std::string validate() const;
};

class PriorRecovery {
 public:
  explicit PriorRecovery(const PriorRecoveryOptions& options) : options_(options) {}
  /// The epoch's float failed validation on the prior alone (`prior_only`), or not: true when the float is to be
  /// taken all the same (then the count starts again).
  bool reanchor(bool prior_only);
  /// The epoch's gates rejected `rejected` DD rows and the update used `used`.
  void count_gate_conflict(int rejected, int used);
  /// The widening for the next prior (once), if due.
  std::optional<double> take_widening();

 private:
  PriorRecoveryOptions options_;
  int prior_rejections_ = 0;  // consecutive
  int gate_conflicts_ = 0;    // consecutive
  bool widen_next_ = false;
};

}  // namespace canyon::fusion
