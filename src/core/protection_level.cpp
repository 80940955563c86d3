// The protection levels of a solution (see protection_level.hpp).

#include "canyon/core/protection_level.hpp"

#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include "canyon/core/geodesy.hpp"

namespace canyon::core {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

double horizontal_protection_level_m(const Eigen::Matrix2d& C_EN_m2) {
  if (!C_EN_m2.allFinite()) return kNaN;
  const Eigen::Matrix2d C = 0.5 * (C_EN_m2 + C_EN_m2.transpose());
  const Eigen::Vector2d eigenvalues =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(C, Eigen::EigenvaluesOnly).eigenvalues();
  if (eigenvalues[0] < 0.0 || !(eigenvalues[1] > 0.0)) return kNaN;  // not a covariance, or none (zero)
  return kProtectionLevelSigmas * std::sqrt(eigenvalues[1]);
}

ProtectionLevels protection_levels(const Eigen::Vector3d& p_E_m, const Eigen::Matrix3d& P_E_m2) {
  if (!p_E_m.allFinite() || !P_E_m2.allFinite() || p_E_m.isZero()) return {kNaN, kNaN};
  const Eigen::Matrix3d R_NE = rotation_enu_from_ecef(ecef_to_geodetic(p_E_m));
  const Eigen::Matrix3d C = R_NE * P_E_m2 * R_NE.transpose();
  const double hpl = horizontal_protection_level_m(C.topLeftCorner<2, 2>());
  const double up_m2 = C(2, 2);
  return {hpl, std::isnan(hpl) || !(up_m2 >= 0.0) ? kNaN : kProtectionLevelSigmas * std::sqrt(up_m2)};
}

}  // namespace canyon::core
