#pragma once
// Visual-inertial odometry of the head-worn device, as a real VIO reports it: poses T_OI of the IMU in the device's
// own odometry frame O, stamped with the device clock, drifting with the distance walked, with covariances that
// describe exactly that drift; and the time-sync pairs of the device's built-in GPS.
//
// Frames: I is the IMU/body frame (x along the walking direction, y left, z up; the wearer keeps the head level);
// the antenna is at t_IA in I. O is gravity-aligned (the ENU frame N at the city origin rotated by
// `odometry_yaw_deg` about up), with its origin at the IMU's start position: T_EO = (R_EN R_NO, p_E_I(start)), and
// the true VIO pose is T_OI = T_EO^-1 T_EI.
//
// Drift model (right perturbation, xi = [delta p; delta theta], T_est = T Exp(xi), as in DESIGN.md): each pose
// composes the true increment with a random one,
//   T_est,k = T_est,k-1 dT_k Exp(n_k),   dT_k = T_k-1^-1 T_k,   n_k ~ N(0, Q_k),
//   Q_k = d_k / 1000 m * diag(s_p^2, s_p^2, s_p^2, s_t^2, s_t^2, s_y^2),
// d_k the distance walked in the step, s_p = position_drift_fraction * 1000 m / sqrt(3) (per axis, so that the 3-D
// translation random walk is position_drift_fraction of 1 km after 1 km), s_y, s_t the heading and tilt random walks
// after 1 km. The heading error bends the path, so the position drift grows faster than sqrt(distance): as
// distance^1.5, smoothly, while the translation random walk grows as sqrt(distance) with the same jitter at every
// frame. Real VIO drifts mostly in heading and scale and is millimetre-accurate from one frame to the next, so the
// defaults put the drift in the heading (0.5 deg after 1 km) and keep the translation random walk small (0.05 %):
// the 1-sigma 3-D error after a straight kilometre is 0.5 % of it (5 m), after 10 m of walk about 5 cm, and from
// one 0.1 s frame to the next 3 mm per axis. (A translation random walk of 0.4 % alone would also give 0.5 % after
// 1 km, but 2.7 cm of jitter per axis between consecutive 10 Hz frames, far beyond any VIO.) The reported
// covariance is propagated to first order:
//   P_k = A_k P_k-1 A_k^T + Q_k,   A_k = Ad(dT_est,k^-1),   cov(xi_k-1, xi_k) = P_k-1 A_k^T,
// with the VIO's estimated increment dT_est,k = dT_k Exp(n_k), as a VIO filter propagates (first order, the same as
// with dT_k; but consistent with the reported poses, so that a consumer chaining the covariances with the reported
// relative motions, fusion/vio_track.hpp, gets the increments' small covariances right),
// with Ad(T) = [[R, [t]x R], [0, R]] for the [translation; rotation] ordering; P_0 = diag(1e-8 m^2 x 3,
// 1e-10 rad^2 x 3) (O is defined by the first pose).
//
// Real VIO's errors the drift model leaves out, as options (both off by default): a scale error (every increment's
// translation (1 + scale_error) times the true one, not in the covariance) and over-confidence (the reported
// covariance is the one above over covariance_optimism^2).
//
// Clocks: the device clock reads t_ns = (device_clock_offset_s + (t - start)(1 + drift_ppm 1e-6)) 1e9 at GPST t.
// Poses are at every 1 / rate_hz of device time; time-sync pairs at every whole GPST second, their device time with
// Gaussian jitter.

#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "canyon/core/geodesy.hpp"
#include "canyon/core/se3.hpp"
#include "canyon/core/time.hpp"
#include "canyon/sim/route.hpp"
#include "canyon/sim/scenario.hpp"

namespace canyon::sim {

// The SE(3) maths (Pose, Exp/Log, adjoint, [translation; rotation] ordering, right perturbation) is canyon's one copy
// in core/se3.hpp.
using core::Matrix6d;
using core::Pose;
using core::se3_adjoint;
using core::se3_exp;
using core::se3_log;
using core::Vector6d;

struct VioSample {
  std::int64_t t_ns = 0;                       ///< device clock
  core::GpsTime time;                          ///< true GPST of the pose
  Pose T_OI;                                   ///< as the VIO reports it
  Pose T_OI_true;                              ///< ground truth
  Matrix6d covariance = Matrix6d::Zero();      ///< of xi_OI
  Matrix6d cross_previous = Matrix6d::Zero();  ///< cov(xi of the previous sample, xi of this one); 0 for the first
};

struct TimeSyncSample {
  std::int64_t t_ns = 0;  ///< device clock when the built-in GPS reported `time`
  core::GpsTime time;
};

struct VioRun {
  std::vector<VioSample> poses;
  std::vector<TimeSyncSample> timesync;
  Pose T_EO;  ///< true odometry frame in ECEF
};

/// The device's VIO and time sync along the rover trajectory of `scenario` (its city origin and start time). The
/// same seed gives the same run.
[[nodiscard]] VioRun simulate_vio(const Scenario& scenario, const Trajectory& trajectory, std::uint64_t seed);

/// The VIO of any true body motion: `T_OI_true(t_s)` is the true IMU pose in the odometry frame `T_EO` at t_s
/// seconds after `start`, for t_s in [0, duration_s]; poses and time sync as simulate_vio() makes them (same clock,
/// drift and covariance model, same random streams).
[[nodiscard]] VioRun simulate_vio_along(const VioOptions& options, const core::GpsTime& start, double duration_s,
                                        const std::function<Pose(double)>& T_OI_true, const Pose& T_EO,
                                        std::uint64_t seed);

/// One sample of a 6-DoF ground truth: the antenna position and the body attitude R_EI (I: x forward, y left,
/// z up).
struct SixDofSample {
  core::GpsTime time;
  Eigen::Vector3d p_E_A_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_EI = Eigen::Quaterniond::Identity();
};

/// The VIO of a device carried along a recorded 6-DoF truth (`canyon simulate --vio-from-truth`): the IMU at
/// p_E_A - R_EI t_IA (options.t_IA_m), O gravity-aligned (ENU at the first sample rotated by odometry_yaw_deg) with
/// its origin at the IMU's first position; truth interpolated linearly in position and on SO(3) in attitude. Pose
/// times span the truth's. Samples must be in time order, at least two.
[[nodiscard]] VioRun simulate_vio_from_truth(const VioOptions& options, const std::vector<SixDofSample>& truth,
                                             std::uint64_t seed);

/// Body attitude R_NI at time t_s (seconds since the start): level, x along the walking direction.
[[nodiscard]] Eigen::Matrix3d body_attitude_N(const Trajectory& trajectory, double t_s);

}  // namespace canyon::sim
