// VIO prediction, Eqs. 3-6 (see vio_prediction.hpp).

#include "canyon/fusion/vio_prediction.hpp"

#include <Eigen/Eigenvalues>

namespace canyon::fusion {

Eigen::Vector3d antenna_increment(const core::Pose& T_OI_a, const core::Pose& T_OI_b, const Eigen::Vector3d& t_IA,
                                  Eigen::Matrix<double, 3, 12>* J_dp_xi) {
  Eigen::Matrix<double, 3, 6> J_a;
  Eigen::Matrix<double, 3, 6> J_b;
  const Eigen::Vector3d p_a = core::transform_point(T_OI_a, t_IA, &J_a);
  const Eigen::Vector3d p_b = core::transform_point(T_OI_b, t_IA, &J_b);
  if (J_dp_xi != nullptr) {
    J_dp_xi->leftCols<6>() = -J_a;
    J_dp_xi->rightCols<6>() = J_b;
  }
  return p_b - p_a;
}

VioIncrement vio_increment(const core::Pose& T_OI_a, const core::Pose& T_OI_b, const Matrix12d& joint,
                           const Eigen::Vector3d& t_IA, const Eigen::Matrix3d& R_EO, double yaw_sigma_rad,
                           const Eigen::Vector3d& up_E) {
  VioIncrement inc;
  Eigen::Matrix<double, 3, 12> J;
  inc.dp_O_m = antenna_increment(T_OI_a, T_OI_b, t_IA, &J);
  inc.cov_O_m2 = J * joint * J.transpose();
  inc.cov_O_m2 = 0.5 * (inc.cov_O_m2 + inc.cov_O_m2.transpose()).eval();
  // A VIO whose covariances do not match its poses can give an increment covariance with a negative eigenvalue (the
  // difference of absolute covariances of m^2 for one of mm^2): projected onto the positive semi-definite matrices.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(inc.cov_O_m2);
  if (eig.eigenvalues().minCoeff() < 0.0) {
    inc.cov_O_m2 = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() * eig.eigenvectors().transpose();
  }
  inc.dp_E_m = R_EO * inc.dp_O_m;
  inc.cov_E_m2 = R_EO * inc.cov_O_m2 * R_EO.transpose();
  if (yaw_sigma_rad > 0.0) {
    // d(Rz(psi) dp)/d psi = up x dp: the increment's horizontal part turned by 90 degrees.
    const Eigen::Vector3d d = up_E.cross(inc.dp_E_m);
    inc.cov_E_m2 += yaw_sigma_rad * yaw_sigma_rad * d * d.transpose();
  }
  return inc;
}

}  // namespace canyon::fusion
