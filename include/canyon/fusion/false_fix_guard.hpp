#pragma once
// Beyond the paper: the fusion's decision on each fix the RTK filter proposes (rtk proposes, fusion decides:
// rtk/ambiguity_resolution.hpp). Why: in a street canyon, biased floats (reflections, multipath correlated over
// minutes) pass the ratio test with wrong integers, and the VIO prior, which the filter's fix does not see as a
// constraint, shows them: a candidate is refused when
//   - its position is poorly determined: the largest axis of its covariance exceeds max_fix_sigma_m (a weak DD
//     geometry, e.g. integer combinations that pin two directions), or
//   - with the guard on, it disagrees with the prior: (p_fix - p_prior)^T (P_prior + P_fix)^-1 (p_fix - p_prior) >
//     false_fix_chi2.
// A refused candidate sends the search on as rtk's own refusals do (Algorithm 1's pruning, lines 13-14, and the rest
// of partial fixing).

#include <string>

#include "canyon/fusion/vio_prediction.hpp"
#include "canyon/rtk/ambiguity_resolution.hpp"

namespace canyon::fusion {

struct FalseFixGuardOptions {
  bool enabled = true;           ///< fixes must agree with the prior
  double chi2 = 16.27;           ///< chi-square(3) bound of the guard (0.999)
  double max_fix_sigma_m = 0.1;  ///< a fix whose position sigma (largest axis) exceeds this is not taken

  [[nodiscard]] std::string validate() const;
};

class FalseFixGuard {
 public:
  explicit FalseFixGuard(const FalseFixGuardOptions& options) : options_(options) {}
  /// Forgets the last epoch's counts.
  void start_epoch() { refused_by_prior_ = refused_as_undetermined_ = 0; }
  /// The decision on a candidate fix of the epoch whose prior is `prior`.
  [[nodiscard]] bool accepts(const rtk::FixCandidate& fix, const Prior& prior);
  /// Candidates refused this epoch for disagreeing with the prior, and for a poorly determined position.
  [[nodiscard]] int refused_by_prior() const { return refused_by_prior_; }
  [[nodiscard]] int refused_as_undetermined() const { return refused_as_undetermined_; }

 private:
  FalseFixGuardOptions options_;
  int refused_by_prior_ = 0;
  int refused_as_undetermined_ = 0;
};

}  // namespace canyon::fusion
