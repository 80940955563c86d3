#pragma once
// The protection levels output with each solution (beyond the paper; issue 28's "a protection level"): bounds on the
// horizontal and vertical position error that the solution's own covariance supports, in the local east-north-up
// frame at the solution.
//   HPL = k sqrt(lambda_max(C_EN)),  C_EN the horizontal (east, north) block of the covariance:
//         a Gaussian horizontal error exceeds it with probability at most exp(-k^2 / 2) (|e|^2 <= lambda_max
//         chi-square(2)), 1.5e-8 per epoch for k = 6;
//   VPL = k sigma_U: a Gaussian vertical error exceeds it with probability 2 Phi(-k), 2e-9 for k = 6.
// They are only as good as the covariance: canyon evaluate counts the epochs whose error exceeds them (misleading
// information), docs/results/urban-claim.md. Solutions without a usable covariance have none (NaN).

#include <Eigen/Core>

namespace canyon::core {

/// k above: the protection levels in sigmas.
inline constexpr double kProtectionLevelSigmas = 6.0;

struct ProtectionLevels {
  double horizontal_m;  ///< HPL (m), NaN without a usable covariance
  double vertical_m;    ///< VPL (m), NaN without a usable covariance
};

/// HPL of a horizontal (east, north) covariance (m^2): k sqrt(lambda_max), NaN if it is not finite, not positive
/// semi-definite or zero (a solution without covariance).
[[nodiscard]] double horizontal_protection_level_m(const Eigen::Matrix2d& C_EN_m2);

/// Both levels of a solution at `p_E_m` with ECEF covariance `P_E_m2`, rotated into east-north-up at the solution.
[[nodiscard]] ProtectionLevels protection_levels(const Eigen::Vector3d& p_E_m, const Eigen::Matrix3d& P_E_m2);

}  // namespace canyon::core
