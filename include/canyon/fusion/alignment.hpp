#pragma once
// Alignment of the VIO odometry frame O to ECEF and calibration of the antenna lever arm (the paper's Eq. 2),
// solved with Ceres on SE(3).
//
// Model, for a window of k GNSS antenna positions p_E,i and the VIO poses T_OI,i at the same times:
//   min over T_EO in SE(3), t_IA in R^3 of  sum_i || T_EO T_OI,i t_IA - p_E,i ||^2            (Eq. 2)
// Solver: Ceres' TinySolver (Levenberg-Marquardt, header-only: the statically linked canyon command cannot link
// Ceres' full solver library, whose glog, SuiteSparse and LAPACK dependencies Debian ships as shared libraries or
// without their static dependencies), with analytic Jacobians (AlignmentProblem below), on SE(3) through the right
// perturbation T (+) x = (R Exp(theta), p + R rho), re-centred after each solve (at most kOuterIterations). For
// conditioning both point sets are taken about their centroids, T_EO = Trans(c_E) T' Trans(-c_O); "identity
// start" means T' = identity.
//
// Two passes (paper, Sec. IV-A): pass 1 holds t_IA = 0 and starts T_EO from identity; pass 2 starts from pass 1
// and solves T_EO and t_IA jointly. Re-alignment (VIO drifts) solves T_EO only, t_IA held at its calibrated value.
//
// Lever-arm observability. With the translation of T_EO free, t_IA is seen only through the variation of the
// attitude R_EO R_OI,i over the window: its information (per point) is I_t = I - Rbar^T Rbar, Rbar the mean of
// R_OI,i. An eigen-direction u of I_t with eigenvalue below min_lever_arm_excitation is not excited (a level head
// turning about the vertical does not excite the vertical component): pass 2 holds u^T t_IA at the prior (a residual
// (u^T (t_IA - t_prior)) / lever_arm_prior_sigma_m), and the result says so.
//
// Window quality (persistence of excitation): the first eigenvalue ratio (FER) of the covariance of the positions
// p_E,i, lambda_1 / (lambda_1 + lambda_2 + lambda_3), must be below max_first_eigenvalue_ratio (paper: 0.97), and
// the fit's RMSE, sqrt(sum_i |r_i|^2 / k), below max_rmse_m (paper: 0.1 m).
//
// Coarse alignment (beyond the paper, for starts where no window qualifies): VIO's odometry frame is gravity-aligned
// (its z axis is up), so R_EO = R_EN Rz(psi) with R_EN the local ENU frame at the window's centroid, and a window of
// metre-level solutions still determines the yaw psi: a weighted 2-D Procrustes fit of the horizontal positions
// (iterated, Huber weights), translation from the centroids. Its yaw uncertainty, sigma_psi = RMSE / (RMS horizontal
// distance of the VIO positions from their centroid), is returned so that the prediction can account for it.

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/result.hpp"
#include "canyon/core/se3.hpp"

namespace canyon::fusion {

struct AlignmentOptions {
  double max_first_eigenvalue_ratio = 0.97;  ///< paper: windows whose positions' FER is above are not used
  double max_rmse_m = 0.1;                   ///< paper: alignments with a larger fit RMSE are not used (m)
  int min_points = 10;                       ///< fewer points: no alignment
  double min_lever_arm_excitation = 0.02;    ///< lever-arm directions with less information per point are held
  double lever_arm_prior_sigma_m = 1e-4;     ///< sigma of the prior holding unexcited directions (m)
  int max_iterations = 50;                   ///< Levenberg-Marquardt iterations per solve

  [[nodiscard]] std::string validate() const;
};

struct AlignmentPoint {
  core::Pose T_OI;                                  ///< VIO pose at the epoch
  Eigen::Vector3d p_E_m = Eigen::Vector3d::Zero();  ///< GNSS antenna position at the epoch
};

struct LeverArmObservability {
  Eigen::Matrix3d directions_I = Eigen::Matrix3d::Identity();  ///< eigenvectors of I_t (columns, IMU frame)
  Eigen::Vector3d excitation = Eigen::Vector3d::Zero();        ///< eigenvalues of I_t per point (0..2)
  std::array<bool, 3> excited{};
  /// "x: excited (0.62), y: excited (0.41), z: not excited (0.000), kept at its prior" (directions named by their
  /// nearest IMU axis).
  [[nodiscard]] std::string describe() const;
};

struct AlignmentResult {
  core::Pose T_EO;
  Eigen::Vector3d t_IA_m = Eigen::Vector3d::Zero();
  int points = 0;
  double first_eigenvalue_ratio = 1.0;
  double rmse_m = 0.0;                      ///< of the final fit
  double rmse_without_calibration_m = 0.0;  ///< pass 1 (t_IA = 0); equal to rmse_m for a re-alignment
  bool calibrated = false;                  ///< t_IA was estimated (pass 2)
  LeverArmObservability lever_arm;
  bool converged = false;

  /// The paper's gates: FER and RMSE below their thresholds.
  [[nodiscard]] bool qualifies(const AlignmentOptions& options) const {
    return converged && first_eigenvalue_ratio < options.max_first_eigenvalue_ratio && rmse_m < options.max_rmse_m;
  }
};

/// lambda_1 / (lambda_1 + lambda_2 + lambda_3) of the covariance of the positions; 1 for fewer than two points.
[[nodiscard]] double first_eigenvalue_ratio(const std::vector<Eigen::Vector3d>& positions);

/// The lever-arm information of a window (see above).
[[nodiscard]] LeverArmObservability lever_arm_observability(const std::vector<AlignmentPoint>& points,
                                                            double min_excitation);

/// The paper's two passes: T_EO from identity with t_IA = 0, then T_EO and t_IA jointly (unexcited directions held
/// at `t_IA_prior`). With `calibrate` false, pass 2 is skipped and t_IA = t_IA_prior throughout (the paper's
/// "without calibration" is t_IA_prior = 0). Error if there are fewer than min_points points.
Result<AlignmentResult> align_and_calibrate(const std::vector<AlignmentPoint>& points,
                                            const Eigen::Vector3d& t_IA_prior, bool calibrate,
                                            const AlignmentOptions& options);

/// Re-alignment: T_EO only, from `T_EO_start`, with t_IA fixed.
Result<AlignmentResult> realign(const std::vector<AlignmentPoint>& points, const Eigen::Vector3d& t_IA,
                                const core::Pose& T_EO_start, const AlignmentOptions& options);

struct CoarseAlignment {
  core::Pose T_EO;
  double yaw_sigma_rad = 0.0;  ///< RMSE / RMS horizontal spread
  double rmse_m = 0.0;         ///< horizontal residual RMSE (robustly weighted)
  double spread_m = 0.0;       ///< RMS horizontal distance of the VIO antenna positions from their centroid
};

/// Gravity-aligned yaw + translation fit (see above). Error for fewer than min_points points or no spread.
Result<CoarseAlignment> coarse_align(const std::vector<AlignmentPoint>& points, const Eigen::Vector3d& t_IA,
                                     const AlignmentOptions& options);

/// Eq. 2 as a least-squares problem for Ceres' TinySolver (Levenberg-Marquardt, dense). Parameters
/// x = [rho; theta] (6), the right perturbation of a pose T_0 by the retraction
///   T_0 (+) x = (R_0 Exp(theta), p_0 + R_0 rho),
/// then, when the lever arm is estimated, t_IA (3). Residuals: per point r_i = T x_i - p_E,i with
/// x_i = p_OI,i + R_OI,i t_IA (3 each), then one per held lever-arm direction, (u^T t_IA - u^T t_prior) / sigma.
/// Jacobians: dr_i/drho = R_0, dr_i/dtheta = -R_0 Exp(theta) [x_i]x J_r(theta), dr_i/dt_IA = R R_OI,i.
class AlignmentProblem {
 public:
  using Scalar = double;
  enum { NUM_RESIDUALS = Eigen::Dynamic, NUM_PARAMETERS = Eigen::Dynamic };

  struct HeldDirection {
    Eigen::Vector3d u;
    double target = 0.0;  ///< u^T t_prior
    double inverse_sigma = 1.0;
  };

  AlignmentProblem(const std::vector<AlignmentPoint>& points, const core::Pose& T_0, const Eigen::Vector3d& t_IA,
                   bool estimate_lever_arm, std::vector<HeldDirection> held = {});
  /// x (NumParameters()), residuals (NumResiduals()), jacobian column-major NumResiduals() x NumParameters() or null.
  bool operator()(const double* x, double* residuals, double* jacobian) const;
  [[nodiscard]] int NumResiduals() const {
    return 3 * static_cast<int>(points_.size()) + static_cast<int>(held_.size());
  }
  [[nodiscard]] int NumParameters() const { return estimate_lever_arm_ ? 9 : 6; }
  /// T_0 (+) x.
  [[nodiscard]] static core::Pose retract(const core::Pose& T_0, const double* x);

 private:
  const std::vector<AlignmentPoint>& points_;
  core::Pose T_0_;
  Eigen::Vector3d t_IA_;  // used when the lever arm is not estimated
  bool estimate_lever_arm_;
  std::vector<HeldDirection> held_;
};

}  // namespace canyon::fusion
