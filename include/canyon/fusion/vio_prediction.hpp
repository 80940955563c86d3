#pragma once
// The EKF prior from VIO (the paper's Eqs. 3-6; Algorithm 1, lines 3-5), with the antenna's increment.
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
// from a coarse alignment, coarse_alignment.hpp) adds the variance of the rotated increment: (sigma_psi |dp_E,h|)^2
// along the horizontal direction perpendicular to the increment. The ablation vio_covariance: false replaces
// cov(dp_E) by constant_increment_sigma_m^2 I. The RTK filter applies the same increment to its whole state
// (rtk/time_update.hpp: the position's correlations with the ambiguities carried over).

#include <optional>

#include <Eigen/Core>

#include "canyon/core/se3.hpp"
#include "canyon/fusion/vio_track.hpp"

namespace canyon::fusion {

enum class Prediction { Vio, ConstantVelocity };
[[nodiscard]] const char* prediction_name(Prediction p);

struct PredictionOptions {
  Prediction kind = Prediction::Vio;         ///< the paper's VIO, or the constant-velocity ablation
  bool vio_covariance = true;                ///< Eqs. 4-6; false: constant_increment_sigma_m per axis (ablation)
  double constant_increment_sigma_m = 0.05;  ///< (m)
  /// Beyond the paper: the VIO's own increment covariance (Eq. 4) is taken times this squared. Real VIO reports
  /// sigmas a few times too small (its estimator ignores correlated feature and IMU errors); 1: as reported. 2 on
  /// downtown's development seeds: 3 fixed no more there and fixed wrongly in urban-moderate
  /// (docs/results/urban-claim.md).
  double vio_sigma_factor = 2.0;
  /// Beyond the paper: the VIO's scale error (not in its covariance) as a filter state s, p += dp (1 + s), learnt
  /// from the DD phases (rtk::ExternalMotion); it starts at 0 with vio_scale_sigma on each new VIO segment and walks
  /// by vio_scale_random_walk_per_sqrt_km.
  bool scale_state = true;
  double vio_scale_sigma = 0.01;                     ///< (relative, 1 sigma)
  double vio_scale_random_walk_per_sqrt_km = 0.001;  ///< (relative per sqrt(km) walked)
  /// Beyond the paper: the error of the VIO position interpolated at a GNSS epoch between two VIO samples
  /// (vio_track.hpp's interpolation_accel_mps2) as a filter state (rtk/time_update.hpp), not in the increment's
  /// covariance: there it would enter every increment (times vio_sigma_factor^2) and accumulate like a random walk,
  /// though the interpolated position is never further off than one interval's missed acceleration. Matters with
  /// VIO slower than the GNSS epochs (1-2 Hz against 5 Hz).
  bool interpolation_state = false;
};

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

/// A prior: the predicted position and its covariance.
struct Prior {
  Eigen::Vector3d p_E_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d P_E_m2 = Eigen::Matrix3d::Zero();
};

/// One epoch's prediction: the motion the filter applies (dp_E, its covariance Q) and the prior.
struct MotionPrediction {
  VioIncrement increment;  ///< Eqs. 4-5 (VIO prediction only)
  Eigen::Vector3d dp_E_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d Q_E_m2 = Eigen::Matrix3d::Zero();
  Prior prior;
};

/// The filter state at epoch i (its position and covariance) and the VIO poses of epochs i and i+1.
struct VioPredictionInput {
  Eigen::Vector3d p_E_m;       ///< p_E,i|i
  Eigen::Matrix3d P_E_m2;      ///< P_i|i
  core::Pose T_OI_i;           ///< VIO pose at epoch i
  core::Pose T_OI_next;        ///< at epoch i+1
  Matrix12d joint;             ///< cov([xi_i; xi_i+1])
  Eigen::Vector3d t_IA_m;      ///< the lever arm
  Eigen::Matrix3d R_EO;        ///< the alignment's rotation
  double yaw_sigma_rad = 0.0;  ///< the alignment's heading uncertainty carried as noise (0: none)
  Eigen::Vector3d up_E = Eigen::Vector3d::UnitZ();
};

/// Algorithm 1, lines 3-5: Eqs. 4-5 (the increment and its covariance), then Eqs. 3 and 6 (the prior), the increment's
/// covariance taken times vio_sigma_factor^2. `widen_sigma_m` (prior_recovery.hpp) adds its square to the increment's
/// covariance per axis.
[[nodiscard]] MotionPrediction predict_with_vio(const VioPredictionInput& in, const PredictionOptions& options,
                                                std::optional<double> widen_sigma_m = std::nullopt);

/// Eqs. 3 and 6 for any motion: p_E,i+1|i = p_E,i|i + dp_E, P_i+1|i = P_i|i + Q (`widen_sigma_m` first added to Q).
void complete_prediction(MotionPrediction& prediction, const Eigen::Vector3d& p_E_m, const Eigen::Matrix3d& P_E_m2,
                         std::optional<double> widen_sigma_m);

}  // namespace canyon::fusion
