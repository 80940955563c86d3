// The fusion's decision on proposed fixes (see false_fix_guard.hpp).

#include "canyon/fusion/false_fix_guard.hpp"

#include <Eigen/Eigenvalues>

#include "canyon/fusion/float_validation.hpp"

namespace canyon::fusion {

std::string FalseFixGuardOptions::validate() const {
  if (!(max_fix_sigma_m > 0.0)) return "max_fix_sigma_m must be > 0";
  if (!(chi2 > 0.0)) return "false_fix_chi2 must be > 0";
  return {};
}

bool FalseFixGuard::accepts(const rtk::FixCandidate& fix, const Prior& prior) {
  if (!fix.position_ok) return false;  // no position to judge
  const double max_variance = options_.max_fix_sigma_m * options_.max_fix_sigma_m;
  if (Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(fix.P_E_m2, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff() >
      max_variance) {
    ++refused_as_undetermined_;
    return false;
  }
  if (!options_.enabled || chi_square_3d(fix.p_E_m - prior.p_E_m, prior.P_E_m2 + fix.P_E_m2) <= options_.chi2) {
    return true;
  }
  ++refused_by_prior_;
  return false;
}

}  // namespace canyon::fusion
