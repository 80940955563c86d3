#pragma once
// Float validation (Algorithm 1, line 8): the epoch's float solution is kept only when
//   - the update used at least one DD phase,
//   - its largest DD post-fit residual, over the RTK filter's rejection threshold, is <= max_post_fit_normalised (the
//     filter's own rejections could not clear the epoch of outliers otherwise, rtk/dd_update.hpp),
//   - it is consistent with the VIO prior: (p_float - p_prior)^T P_prior^-1 (p_float - p_prior) <= max_prior_chi2.
// A float that fails is undone and the epoch's output is the prior (the VIO fill-in, Algorithm 1, line 22:
// vio_fill_in.hpp).

#include <string>

#include <Eigen/Core>

#include "canyon/rtk/engine.hpp"

namespace canyon::fusion {

struct FloatValidationOptions {
  double max_post_fit_normalised = 1.0;  ///< largest DD post-fit residual over the RTK filter's rejection threshold
  double max_prior_chi2 = 16.27;         ///< chi-square(3) of the float against the prior (0.999)

  [[nodiscard]] std::string validate() const;
};

/// d^T S^-1 d for a 3-vector d and its covariance S (symmetrised), or infinity if S is not positive definite.
[[nodiscard]] double chi_square_3d(const Eigen::Vector3d& d, const Eigen::Matrix3d& S);

/// Why the epoch's float fails validation, or "" if it passes (see above).
[[nodiscard]] std::string validate_float(const rtk::RtkEpoch& epoch, const FloatValidationOptions& options);

/// The float failed validation on its consistency with the prior alone (its update and post-fit residuals are good):
/// the case in which the prior, not GNSS, may be wrong (prior_recovery.hpp).
[[nodiscard]] bool failed_on_prior_only(const rtk::RtkEpoch& epoch, const std::string& verdict,
                                        const FloatValidationOptions& options);

}  // namespace canyon::fusion
