// Simulated visual-inertial odometry and device time sync (see vio.hpp).

#include "canyon/sim/vio.hpp"

#include <algorithm>
#include <cmath>

#include "canyon/core/constants.hpp"
#include "canyon/sim/random.hpp"

namespace canyon::sim {
namespace {

constexpr std::uint64_t kVioStream = 0x710, kSyncStream = 0x5C;
constexpr double kInitialPositionVarM2 = 1e-8;
constexpr double kInitialAngleVarRad2 = 1e-10;

/// Device clock reading (ns) at `t_s` seconds after the start.
double device_ns(const VioOptions& o, double t_s) {
  return (o.device_clock_offset_s + t_s * (1.0 + o.device_clock_drift_ppm * 1e-6)) * 1e9;
}

/// Seconds after the start at which the device clock reads `t_ns`.
double true_seconds(const VioOptions& o, double t_ns) {
  return (t_ns * 1e-9 - o.device_clock_offset_s) / (1.0 + o.device_clock_drift_ppm * 1e-6);
}

/// True body pose in the city frame N: (R_NI, p_N_I).
Pose body_pose_N(const Trajectory& trajectory, const Eigen::Vector3d& t_IA, double t_s) {
  const Eigen::Matrix3d R_NI = body_attitude_N(trajectory, t_s);
  return {Eigen::Quaterniond(R_NI), trajectory.antenna_N(t_s) - R_NI * t_IA};
}

Matrix6d step_noise(const VioOptions& o, double distance_m) {
  const double per_km = distance_m / 1000.0;
  const double s_p = o.position_drift_fraction * 1000.0 / std::sqrt(3.0);
  const double s_t = o.tilt_drift_deg_per_km * core::kDegToRad;
  const double s_y = o.yaw_drift_deg_per_km * core::kDegToRad;
  Vector6d d;
  d << s_p * s_p, s_p * s_p, s_p * s_p, s_t * s_t, s_t * s_t, s_y * s_y;
  return (per_km * d).asDiagonal();
}

}  // namespace

Eigen::Matrix3d body_attitude_N(const Trajectory& trajectory, double t_s) {
  const Eigen::Vector2d h = trajectory.heading_N(t_s);
  Eigen::Matrix3d R_NI;
  R_NI.col(0) = Eigen::Vector3d(h.x(), h.y(), 0.0);
  R_NI.col(2) = Eigen::Vector3d::UnitZ();
  R_NI.col(1) = R_NI.col(2).cross(R_NI.col(0));
  return R_NI;
}

VioRun simulate_vio_along(const VioOptions& o, const core::GpsTime& start, double duration_s,
                          const std::function<Pose(double)>& T_OI_true, const Pose& T_EO, std::uint64_t seed) {
  VioRun run;
  run.T_EO = T_EO;
  Rng rng = Rng::stream(seed, kVioStream);
  const double first_ns = std::ceil(device_ns(o, 0.0));
  const double step_ns = 1e9 / o.rate_hz;
  Pose estimate;
  Pose previous_true;
  Matrix6d P = Matrix6d::Zero();
  P.diagonal() << Eigen::Vector3d::Constant(kInitialPositionVarM2), Eigen::Vector3d::Constant(kInitialAngleVarRad2);
  // The covariance reported: the drift model's (P, linear in Q and P_0) over the optimism squared.
  const double reported = 1.0 / (o.covariance_optimism * o.covariance_optimism);
  for (int k = 0;; ++k) {
    const double t_ns = first_ns + std::round(k * step_ns);
    const double t_s = true_seconds(o, t_ns);
    if (t_s > duration_s) break;
    VioSample s;
    s.t_ns = static_cast<std::int64_t>(t_ns);
    s.time = start + t_s;
    s.T_OI_true = T_OI_true(t_s);
    if (k == 0) {
      estimate = s.T_OI_true;
    } else {
      const Pose dT = previous_true.inverse() * s.T_OI_true;
      const Matrix6d Q = step_noise(o, dT.p.norm());
      Vector6d n;
      for (int i = 0; i < 6; ++i) n(i) = std::sqrt(Q(i, i)) * rng.normal();
      const Pose dT_scaled{dT.q, (1.0 + o.scale_error) * dT.p};  // the VIO's scale error, unknown to its covariance
      const Pose dT_estimate = dT_scaled * se3_exp(n);
      estimate = estimate * dT_estimate;
      // Propagated with the VIO's own (estimated) increment, as a VIO filter does: the reported covariances are then
      // consistent with the reported poses, which matters when a user differences absolute covariances of metres^2 to
      // get an increment's of millimetres^2 (A from the true increment differs by the increment's noise).
      const Matrix6d A = se3_adjoint(dT_estimate.inverse());
      s.cross_previous = P * A.transpose() * reported;
      P = A * P * A.transpose() + Q;
    }
    s.T_OI = estimate;
    s.covariance = 0.5 * (P + P.transpose()) * reported;
    previous_true = s.T_OI_true;
    run.poses.push_back(s);
  }
  Rng sync_rng = Rng::stream(seed, kSyncStream);
  // Time-sync pairs at every whole GPST second of the span.
  const double first_second = std::ceil(start.tow_s) - start.tow_s;
  for (int i = 0; first_second + i <= duration_s; ++i) {
    const double t_s = first_second + i;
    TimeSyncSample t;
    t.time = start + t_s;
    t.t_ns = std::llround(device_ns(o, t_s) + o.timesync_jitter_s * 1e9 * sync_rng.normal());
    run.timesync.push_back(t);
  }
  return run;
}

VioRun simulate_vio(const Scenario& scenario, const Trajectory& trajectory, std::uint64_t seed) {
  const VioOptions& o = scenario.vio;
  // T_EO: O is the city ENU frame rotated by the odometry yaw, at the IMU's start position.
  const Eigen::Matrix3d R_EN = core::rotation_enu_from_ecef(scenario.origin).transpose();
  const Eigen::Vector3d origin_E = core::geodetic_to_ecef(scenario.origin);
  const Pose T_NO{Eigen::Quaterniond(Eigen::AngleAxisd(o.odometry_yaw_deg * core::kDegToRad, Eigen::Vector3d::UnitZ())),
                  body_pose_N(trajectory, o.t_IA_m, 0.0).p};
  const Pose T_EN{Eigen::Quaterniond(R_EN), origin_E};
  const Pose T_ON = T_NO.inverse();
  return simulate_vio_along(
      o, scenario.start, scenario.duration_s, [&](double t_s) { return T_ON * body_pose_N(trajectory, o.t_IA_m, t_s); },
      T_EN * T_NO, seed);
}

VioRun simulate_vio_from_truth(const VioOptions& o, const std::vector<SixDofSample>& truth, std::uint64_t seed) {
  const auto T_EI_at = [&](double t_s) {
    const core::GpsTime t = truth.front().time + t_s;
    auto it = std::lower_bound(truth.begin(), truth.end(), t,
                               [](const SixDofSample& s, const core::GpsTime& when) { return s.time - when < 0.0; });
    if (it == truth.begin()) ++it;
    if (it == truth.end()) --it;
    const SixDofSample& b = *it;
    const SixDofSample& a = *(it - 1);
    const double span = b.time - a.time;
    const double x = span > 0.0 ? (t - a.time) / span : 0.0;
    const Eigen::Vector3d p_E_A = a.p_E_A_m + x * (b.p_E_A_m - a.p_E_A_m);
    const Eigen::Quaterniond q = a.q_EI.slerp(x, b.q_EI).normalized();
    return Pose{q, p_E_A - (q * o.t_IA_m)};
  };
  const Pose T_EI_0 = T_EI_at(0.0);
  const core::Geodetic g = core::ecef_to_geodetic(T_EI_0.p);
  const Eigen::Matrix3d R_EN = core::rotation_enu_from_ecef(g).transpose();
  const Pose T_EO{
      Eigen::Quaterniond(
          R_EN * Eigen::AngleAxisd(o.odometry_yaw_deg * core::kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix())
          .normalized(),
      T_EI_0.p};
  const Pose T_OE = T_EO.inverse();
  const double duration_s = truth.back().time - truth.front().time;
  return simulate_vio_along(
      o, truth.front().time, duration_s, [&](double t_s) { return T_OE * T_EI_at(t_s); }, T_EO, seed);
}

}  // namespace canyon::sim
