// VIO prediction, Eqs. 3-6 (see vio_prediction.hpp).

#include "canyon/fusion/vio_prediction.hpp"

#include <Eigen/Eigenvalues>

namespace canyon::fusion {

const char* prediction_name(Prediction p) {
  return p == Prediction::Vio ? "vio" : "constant_velocity";
}

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
  inc.cov_O_m2 = J * joint * J.transpose();  // Eq. 4
  inc.cov_O_m2 = 0.5 * (inc.cov_O_m2 + inc.cov_O_m2.transpose()).eval();
  // A VIO whose covariances do not match its poses can give an increment covariance with a negative eigenvalue (the
  // difference of absolute covariances of m^2 for one of mm^2): projected onto the positive semi-definite matrices.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(inc.cov_O_m2);
  if (eig.eigenvalues().minCoeff() < 0.0) {
    inc.cov_O_m2 = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() * eig.eigenvectors().transpose();
  }
  inc.dp_E_m = R_EO * inc.dp_O_m;  // Eq. 5
  inc.cov_E_m2 = R_EO * inc.cov_O_m2 * R_EO.transpose();
  if (yaw_sigma_rad > 0.0) {
    // d(Rz(psi) dp)/d psi = up x dp: the increment's horizontal part turned by 90 degrees.
    const Eigen::Vector3d d = up_E.cross(inc.dp_E_m);
    inc.cov_E_m2 += yaw_sigma_rad * yaw_sigma_rad * d * d.transpose();
  }
  return inc;
}

MotionPrediction predict_with_vio(const VioPredictionInput& in, const PredictionOptions& options,
                                  std::optional<double> widen_sigma_m) {
  MotionPrediction prediction;
  prediction.increment = vio_increment(in.T_OI_i, in.T_OI_next, in.joint, in.t_IA_m, in.R_EO, in.yaw_sigma_rad,
                                       in.up_E);  // Eqs. 4-5
  prediction.dp_E_m = prediction.increment.dp_E_m;
  if (options.vio_covariance) {
    // Beyond the paper: the VIO's own part taken times vio_sigma_factor^2 (the alignment's yaw part as it is).
    const double k2 = options.vio_sigma_factor * options.vio_sigma_factor;
    prediction.Q_E_m2 =
        prediction.increment.cov_E_m2 + (k2 - 1.0) * in.R_EO * prediction.increment.cov_O_m2 * in.R_EO.transpose();
  } else {
    prediction.Q_E_m2 =
        Eigen::Matrix3d::Identity() * options.constant_increment_sigma_m * options.constant_increment_sigma_m;
  }
  complete_prediction(prediction, in.p_E_m, in.P_E_m2, widen_sigma_m);  // Eqs. 3 and 6
  return prediction;
}

void complete_prediction(MotionPrediction& prediction, const Eigen::Vector3d& p_E_m, const Eigen::Matrix3d& P_E_m2,
                         std::optional<double> widen_sigma_m) {
  if (widen_sigma_m) prediction.Q_E_m2 += Eigen::Matrix3d::Identity() * *widen_sigma_m * *widen_sigma_m;
  prediction.prior.p_E_m = p_E_m + prediction.dp_E_m;    // Eq. 3
  prediction.prior.P_E_m2 = P_E_m2 + prediction.Q_E_m2;  // Eq. 6
}

}  // namespace canyon::fusion
