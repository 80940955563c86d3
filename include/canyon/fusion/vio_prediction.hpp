#pragma once
// EKF prior prediction from VIO (the paper's Eqs. 3-6), with the antenna's increment.
//
// Between the GNSS epochs i and i+1, with the interpolated VIO poses T_OI,i and T_OI,i+1:
//   antenna increment in O:   dp_O = T_OI,i+1 t_IA - T_OI,i t_IA = (p_i+1 - p_i) + (R_i+1 - R_i) t_IA
//     (Eq. 3 uses the IMU's increment p_i+1 - p_i and drops the rotated lever arm, which matters when the head turns)
//   Jacobians (right perturbation of each pose, xi = [delta p; delta theta]):
//     J_dp_xi_i   = -[R_i,   -R_i [t_IA]x]
//     J_dp_xi_i+1 =  [R_i+1, -R_i+1 [t_IA]x]
//   Eq. 4:  cov(dp_O) = [J_dp_xi_i  J_dp_xi_i+1] cov([xi_i; xi_i+1]) [J_dp_xi_i  J_dp_xi_i+1]^T   (12 x 12 joint)
//   Eq. 5:  dp_E = R_EO dp_O,   cov(dp_E) = R_EO cov(dp_O) R_EO^T
//   Eq. 3:  p_E,i+1|i = p_E,i|i + dp_E
//   Eq. 6:  P_i+1|i = P_i|i + cov(dp_E)
// A cov(dp_O) with a negative eigenvalue (covariances inconsistent with the poses) is projected onto the positive
// semi-definite matrices (negative eigenvalues set to zero). Beyond the paper, an uncertain yaw of R_EO (sigma_psi,
// from a coarse alignment) adds the variance of the rotated increment: (sigma_psi |dp_E,h|)^2 along the horizontal
// direction perpendicular to the increment.

#include <Eigen/Core>

#include "canyon/core/se3.hpp"
#include "canyon/fusion/vio_track.hpp"

namespace canyon::fusion {

struct VioIncrement {
  Eigen::Vector3d dp_O_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov_O_m2 = Eigen::Matrix3d::Zero();
  Eigen::Vector3d dp_E_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov_E_m2 = Eigen::Matrix3d::Zero();
};

/// The antenna increment dp_O between two poses and its Jacobian on [xi_a; xi_b] (3 x 12).
[[nodiscard]] Eigen::Vector3d antenna_increment(const core::Pose& T_OI_a, const core::Pose& T_OI_b,
                                                const Eigen::Vector3d& t_IA,
                                                Eigen::Matrix<double, 3, 12>* J_dp_xi = nullptr);

/// Eqs. 4 and 5 (and the yaw term above when `yaw_sigma_rad` > 0). `up_E` is the local vertical (unit) for it.
[[nodiscard]] VioIncrement vio_increment(const core::Pose& T_OI_a, const core::Pose& T_OI_b, const Matrix12d& joint,
                                         const Eigen::Vector3d& t_IA, const Eigen::Matrix3d& R_EO,
                                         double yaw_sigma_rad = 0.0,
                                         const Eigen::Vector3d& up_E = Eigen::Vector3d::UnitZ());

}  // namespace canyon::fusion
