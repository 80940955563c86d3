// The protection levels output with each solution (core/protection_level.hpp): 6 sigma of the horizontal major axis
// and of the vertical, in the local frame at the solution; none (NaN) without a usable covariance.

#include "canyon/core/protection_level.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "canyon/core/geodesy.hpp"

namespace canyon::core {
namespace {

const Eigen::Vector3d kPosition_E_m(-2304110.5752, -3640248.0044, 4687482.7231);

/// An ECEF covariance from an east-north-up one at kPosition_E_m.
Eigen::Matrix3d ecef_from_enu(const Eigen::Matrix3d& C_N) {
  const Eigen::Matrix3d R_NE = rotation_enu_from_ecef(ecef_to_geodetic(kPosition_E_m));
  return R_NE.transpose() * C_N * R_NE;
}

TEST(ProtectionLevel, SixSigmaOfTheHorizontalMajorAxisAndOfTheVertical) {
  // East 3 cm, north 4 cm, correlated 0.5: major axis variance (9 + 16) / 2 + sqrt(((16 - 9) / 2)^2 + 6^2) cm^2.
  Eigen::Matrix3d C_N = Eigen::Matrix3d::Zero();
  C_N(0, 0) = 9e-4;
  C_N(1, 1) = 16e-4;
  C_N(0, 1) = C_N(1, 0) = 0.5 * 0.03 * 0.04;
  C_N(2, 2) = 25e-4;
  const double major_m2 = 12.5e-4 + std::sqrt(3.5e-4 * 3.5e-4 + 6e-4 * 6e-4);
  const ProtectionLevels pl = protection_levels(kPosition_E_m, ecef_from_enu(C_N));
  EXPECT_NEAR(pl.horizontal_m, 6.0 * std::sqrt(major_m2), 1e-9);
  EXPECT_NEAR(pl.vertical_m, 6.0 * 0.05, 1e-9);
  EXPECT_NEAR(horizontal_protection_level_m(C_N.topLeftCorner<2, 2>()), pl.horizontal_m, 1e-9);
}

TEST(ProtectionLevel, NoneWithoutAUsableCovariance) {
  EXPECT_TRUE(std::isnan(protection_levels(kPosition_E_m, Eigen::Matrix3d::Zero()).horizontal_m));
  EXPECT_TRUE(std::isnan(protection_levels(kPosition_E_m, Eigen::Matrix3d::Zero()).vertical_m));
  Eigen::Matrix3d nan = Eigen::Matrix3d::Identity();
  nan(1, 1) = std::nan("");
  EXPECT_TRUE(std::isnan(protection_levels(kPosition_E_m, nan).horizontal_m));
  Eigen::Matrix2d indefinite;
  indefinite << 1.0, 2.0, 2.0, 1.0;  // eigenvalues 3 and -1
  EXPECT_TRUE(std::isnan(horizontal_protection_level_m(indefinite)));
  EXPECT_TRUE(std::isnan(protection_levels(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity()).horizontal_m));
}

}  // namespace
}  // namespace canyon::core
