// Float validation, Algorithm 1 line 8 (see float_validation.hpp).

#include "canyon/fusion/float_validation.hpp"

#include <cstdio>
#include <limits>

#include <Eigen/Cholesky>

namespace canyon::fusion {

std::string FloatValidationOptions::validate() const {
  if (!(max_post_fit_normalised > 0.0) || !(max_prior_chi2 > 0.0)) {
    return "max_post_fit_normalised and max_prior_chi2 must be > 0";
  }
  return {};
}

double chi_square_3d(const Eigen::Vector3d& d, const Eigen::Matrix3d& S) {
  const Eigen::LLT<Eigen::Matrix3d> llt(0.5 * (S + S.transpose()));
  if (llt.info() != Eigen::Success) return std::numeric_limits<double>::infinity();
  return d.dot(llt.solve(d));
}

std::string validate_float(const rtk::RtkEpoch& epoch, const FloatValidationOptions& options) {
  if (epoch.num_dd_measurements == 0) return "no double-differenced phase";
  char text[256];
  if (epoch.max_post_fit_normalised > options.max_post_fit_normalised) {
    std::snprintf(text, sizeof text, "post-fit residual %.1f times the rejection threshold",
                  epoch.max_post_fit_normalised);
    return text;
  }
  const double c = chi_square_3d(epoch.float_p_E_m - epoch.prior_p_E_m, epoch.prior_P_E_m2);
  if (c > options.max_prior_chi2) {
    std::snprintf(text, sizeof text, "float %.2f m from the VIO prior (chi-square %.0f)",
                  (epoch.float_p_E_m - epoch.prior_p_E_m).norm(), c);
    return text;
  }
  return {};
}

bool failed_on_prior_only(const rtk::RtkEpoch& epoch, const std::string& verdict,
                          const FloatValidationOptions& options) {
  return !verdict.empty() && epoch.num_dd_measurements > 0 &&
         epoch.max_post_fit_normalised <= options.max_post_fit_normalised;
}

}  // namespace canyon::fusion
