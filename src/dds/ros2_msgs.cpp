// canyon's solutions and stage timing as ROS 2 messages (see ros2_msgs.hpp).

#include "canyon/dds/ros2_msgs.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <vector>

#include <Eigen/Cholesky>

namespace canyon::dds {
namespace {

namespace sm = sensor_msgs::msg;
namespace dm = diagnostic_msgs::msg;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::int64_t kGpsEpochPosixS = 315964800;  // 1980-01-06 00:00:00 UTC
constexpr double kDegPerRad = 180.0 / std::numbers::pi;
constexpr const char* kStageNames[6] = {"ingest", "time_bridge", "alignment", "prediction", "update", "ambiguity"};

std_msgs::msg::dds_::Header_ header(const builtin_interfaces::msg::dds_::Time_& stamp, const std::string& frame_id) {
  std_msgs::msg::dds_::Header_ h;
  h.stamp(stamp);
  h.frame_id(frame_id);
  return h;
}

std_msgs::msg::dds_::Header_ header(const core::GpsTime& t, const std::string& frame_id,
                                    const core::LeapSecondTable& leaps) {
  return header(ros_time(t, leaps), frame_id);
}

/// Row-major copy of a matrix into a ROS covariance array.
template <int N, typename Array>
void put_row_major(const Eigen::Matrix<double, N, N>& m, Array& out) {
  std::size_t k = 0;
  for (int r = 0; r < N; ++r) {
    for (int c = 0; c < N; ++c) out[k++] = m(r, c);
  }
}

/// diag(R, R): turns a pose covariance over (position, rotation) by R.
Matrix6d block_rotation(const Eigen::Matrix3d& R) {
  Matrix6d J = Matrix6d::Zero();
  J.topLeftCorner<3, 3>() = R;
  J.bottomRightCorner<3, 3>() = R;
  return J;
}

dm::dds_::KeyValue_ key_value(const std::string& key, const std::string& value) {
  dm::dds_::KeyValue_ kv;
  kv.key(key);
  kv.value(value);
  return kv;
}

std::string number(double value, const char* format = "%.3f") {
  if (!std::isfinite(value)) return "nan";
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

}  // namespace

std::string ros2_dds_topic(const std::string& ros_topic) {
  return "rt/" + (!ros_topic.empty() && ros_topic.front() == '/' ? ros_topic.substr(1) : ros_topic);
}

builtin_interfaces::msg::dds_::Time_ ros_time(const core::GpsTime& t, const core::LeapSecondTable& leaps) {
  const double whole_tow = std::floor(t.tow_s);
  auto nanos = static_cast<std::int64_t>(std::llround((t.tow_s - whole_tow) * 1e9));
  std::int64_t seconds = kGpsEpochPosixS + static_cast<std::int64_t>(t.week) * core::kSecondsPerWeek +
                         static_cast<std::int64_t>(whole_tow) - leaps.gps_minus_utc_at_gps(t);
  if (nanos >= 1000000000) {
    seconds += 1;
    nanos -= 1000000000;
  }
  builtin_interfaces::msg::dds_::Time_ time;
  time.sec(static_cast<std::int32_t>(seconds));
  time.nanosec(static_cast<std::uint32_t>(nanos));
  return time;
}

std::uint16_t navsat_service(const core::ObsEpoch& rover) {
  std::uint16_t service = 0;
  for (const core::SatelliteObs& sat : rover.sats) {
    switch (sat.sat.system) {
      case core::Constellation::Gps:
      case core::Constellation::Qzss: service |= sm::NavSatStatus_Constants::SERVICE_GPS; break;
      case core::Constellation::Glonass: service |= sm::NavSatStatus_Constants::SERVICE_GLONASS; break;
      case core::Constellation::Galileo: service |= sm::NavSatStatus_Constants::SERVICE_GALILEO; break;
      case core::Constellation::BeiDou: service |= sm::NavSatStatus_Constants::SERVICE_COMPASS; break;
    }
  }
  return service;
}

sm::dds_::NavSatFix_ to_navsatfix(const core::GpsTime& t, const core::Solution* solution, std::uint16_t service,
                                  const config::Ros2Options& options, const core::LeapSecondTable& leaps) {
  sm::dds_::NavSatFix_ fix;
  fix.header(header(solution != nullptr ? solution->time : t, options.fix_frame_id, leaps));
  sm::dds_::NavSatStatus_ status;
  status.service(service);
  const bool gnss = solution != nullptr && solution->status != core::SolutionStatus::VioFillIn &&
                    solution->status != core::SolutionStatus::None;
  if (!gnss) {
    status.status(sm::NavSatStatus_Constants::STATUS_NO_FIX);
    fix.status(status);
    fix.latitude(kNaN);
    fix.longitude(kNaN);
    fix.altitude(kNaN);
    fix.position_covariance_type(sm::NavSatFix_Constants::COVARIANCE_TYPE_UNKNOWN);
    return fix;
  }
  status.status(solution->status == core::SolutionStatus::Single ? sm::NavSatStatus_Constants::STATUS_FIX
                                                                 : sm::NavSatStatus_Constants::STATUS_GBAS_FIX);
  fix.status(status);
  const core::Geodetic g = core::ecef_to_geodetic(solution->p_E_m);
  fix.latitude(g.lat_rad * kDegPerRad);
  fix.longitude(g.lon_rad * kDegPerRad);
  fix.altitude(g.height_m);
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(g);
  const Eigen::Matrix3d P_N = R_NE * solution->P_E_m2 * R_NE.transpose();
  std::array<double, 9> covariance{};
  put_row_major<3>(P_N, covariance);
  fix.position_covariance(covariance);
  fix.position_covariance_type(sm::NavSatFix_Constants::COVARIANCE_TYPE_KNOWN);
  return fix;
}

nav_msgs::msg::dds_::Odometry_ to_odometry(const core::Solution& solution, const core::Geodetic& origin,
                                           const config::Ros2Options& options, const core::LeapSecondTable& leaps) {
  nav_msgs::msg::dds_::Odometry_ odometry;
  odometry.header(header(solution.time, options.map_frame_id, leaps));
  odometry.child_frame_id(options.antenna_frame_id);
  const Eigen::Vector3d p_N = core::ecef_to_enu(solution.p_E_m - core::geodetic_to_ecef(origin), origin);
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(origin);
  geometry_msgs::msg::dds_::PoseWithCovariance_ pose;
  pose.pose().position().x(p_N.x());
  pose.pose().position().y(p_N.y());
  pose.pose().position().z(p_N.z());
  pose.pose().orientation().w(1.0);
  Matrix6d pose_covariance = Matrix6d::Zero();
  pose_covariance.topLeftCorner<3, 3>() = R_NE * solution.P_E_m2 * R_NE.transpose();
  pose_covariance.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * kUnknownVariance;
  put_row_major<6>(pose_covariance, pose.covariance());
  odometry.pose(pose);
  geometry_msgs::msg::dds_::TwistWithCovariance_ twist;  // canyon's solutions carry no velocity covariance
  const Matrix6d twist_covariance = Matrix6d::Identity() * kUnknownVariance;
  put_row_major<6>(twist_covariance, twist.covariance());
  odometry.twist(twist);
  return odometry;
}

nav_msgs::msg::dds_::Odometry_ to_ros2_odometry(const io::VioRecord& record, const std::string& frame_id,
                                                const std::string& child_frame_id, const core::LeapSecondTable& leaps) {
  constexpr std::int64_t kNsPerS = 1000000000;
  const std::int64_t gps_s = record.t_ns / kNsPerS;
  // ros_time() rounds the time of week to the nanosecond: exact for a week's seconds (double: 1e-10 s at 604,800 s).
  const core::GpsTime t{
      static_cast<int>(gps_s / core::kSecondsPerWeek),
      static_cast<double>(gps_s % core::kSecondsPerWeek) + 1e-9 * static_cast<double>(record.t_ns % kNsPerS)};
  nav_msgs::msg::dds_::Odometry_ odometry;
  odometry.header(header(t, frame_id, leaps));
  odometry.child_frame_id(child_frame_id);
  geometry_msgs::msg::dds_::PoseWithCovariance_ pose;
  pose.pose().position().x(record.T_OI.p.x());
  pose.pose().position().y(record.T_OI.p.y());
  pose.pose().position().z(record.T_OI.p.z());
  pose.pose().orientation().x(record.T_OI.q.x());
  pose.pose().orientation().y(record.T_OI.q.y());
  pose.pose().orientation().z(record.T_OI.q.z());
  pose.pose().orientation().w(record.T_OI.q.w());
  put_row_major<6>(ros2_pose_covariance(record.covariance, record.T_OI), pose.covariance());
  odometry.pose(pose);
  geometry_msgs::msg::dds_::TwistWithCovariance_ twist;  // a pose-only VIO output: the twist is unknown
  put_row_major<6>(Matrix6d(Matrix6d::Identity() * kUnknownVariance), twist.covariance());
  odometry.twist(twist);
  return odometry;
}

rtcm_msgs::msg::dds_::Message_ to_ros2_rtcm(const std::vector<std::uint8_t>& frame,
                                            const builtin_interfaces::msg::dds_::Time_& sent,
                                            const std::string& frame_id) {
  rtcm_msgs::msg::dds_::Message_ message;
  message.header(header(sent, frame_id));
  message.message(frame);
  return message;
}

builtin_interfaces::msg::dds_::Time_ ros_time_now() {
  const auto since_epoch = std::chrono::system_clock::now().time_since_epoch();
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(since_epoch).count();
  builtin_interfaces::msg::dds_::Time_ time;
  time.sec(static_cast<std::int32_t>(ns / 1000000000));
  time.nanosec(static_cast<std::uint32_t>(ns % 1000000000));
  return time;
}

core::Matrix6d ros2_pose_covariance(const core::Matrix6d& xi_covariance, const core::Pose& T_OI) {
  const Matrix6d J = block_rotation(T_OI.rotation());
  return J * xi_covariance * J.transpose();
}

Result<io::VioRecord> from_ros2_odometry(const nav_msgs::msg::dds_::Odometry_& odometry,
                                         const config::Ros2Options& options, const core::LeapSecondTable& leaps) {
  const auto& stamp = odometry.header().stamp();
  const std::string which =
      "Odometry at " + std::to_string(stamp.sec()) + "." + std::to_string(stamp.nanosec()) + " s (ROS time)";
  if (odometry.header().frame_id() != options.vio_frame_id || odometry.child_frame_id() != options.vio_child_frame_id) {
    return Error{which + ": frames '" + odometry.header().frame_id() + "' -> '" + odometry.child_frame_id() +
                 "', expected '" + options.vio_frame_id + "' -> '" + options.vio_child_frame_id +
                 "' (ros2.vio_frame_id, ros2.vio_child_frame_id)"};
  }
  const auto& pose = odometry.pose().pose();
  const auto& covariance = odometry.pose().covariance();
  const double values[7] = {pose.position().x(),    pose.position().y(),    pose.position().z(),
                            pose.orientation().x(), pose.orientation().y(), pose.orientation().z(),
                            pose.orientation().w()};
  const auto finite = [](double v) { return std::isfinite(v); };
  if (!std::all_of(std::begin(values), std::end(values), finite) ||
      !std::all_of(covariance.begin(), covariance.end(), finite)) {
    return Error{which + ": a value of the pose or its covariance is not finite"};
  }
  io::VioRecord r;
  const std::int64_t posix_s = stamp.sec();
  // GPST - UTC at this instant: the table is keyed by GPST, one leap second apart at most near a step.
  const core::GpsTime approx{static_cast<int>((posix_s - kGpsEpochPosixS) / core::kSecondsPerWeek),
                             static_cast<double>((posix_s - kGpsEpochPosixS) % core::kSecondsPerWeek)};
  const std::int64_t leap_s = leaps.gps_minus_utc_at_gps(approx);
  r.t_ns = (posix_s - kGpsEpochPosixS + leap_s) * 1000000000LL + static_cast<std::int64_t>(stamp.nanosec());
  r.T_OI.p = Eigen::Vector3d(values[0], values[1], values[2]);
  const Eigen::Quaterniond q(values[6], values[3], values[4], values[5]);
  const double norm = q.norm();
  if (!(norm >= 0.5 && norm <= 1.5))
    return Error{which + ": quaternion norm " + number(norm, "%.6f") + ", no rotation"};
  r.T_OI.q = q.normalized();  // as the vio.csv reader does
  Matrix6d C_ros;
  for (int row = 0; row < 6; ++row) {
    for (int col = 0; col < 6; ++col) C_ros(row, col) = covariance[static_cast<std::size_t>(row) * 6 + col];
  }
  const Matrix6d J = block_rotation(r.T_OI.rotation().transpose());
  r.covariance = J * (0.5 * (C_ros + C_ros.transpose())) * J.transpose();
  if (Eigen::LLT<core::Matrix6d>(r.covariance).info() != Eigen::Success) {
    return Error{which + ": the pose covariance is not positive definite"};
  }
  return r;
}

std::string exact_status_name(std::uint8_t status) {
  switch (status) {
    case 1: return "fixed";
    case 2: return "float";
    case 5: return "single";
    case 7: return "fill-in";
    case core::kPartialFixStatus: return "partial fix";
    default: return "none";
  }
}

dm::dds_::DiagnosticArray_ to_diagnostics(const msg::StageTiming& timing, const core::Solution* solution,
                                          const core::LeapSecondTable& leaps) {
  const core::GpsTime t{timing.gps_week(), timing.gps_tow_s()};
  dm::dds_::DiagnosticStatus_ status;
  const std::string rover_id = timing.rover_id().to_string();
  status.name("canyon rover: " + rover_id);
  status.hardware_id(rover_id);
  const std::uint8_t code = solution != nullptr ? core::exact_status(*solution) : 0;
  std::vector<dm::dds_::KeyValue_> values;
  values.push_back(key_value("status", exact_status_name(code)));
  values.push_back(key_value("status_code", std::to_string(code)));
  values.push_back(key_value("satellites", std::to_string(solution != nullptr ? solution->num_satellites : 0)));
  values.push_back(key_value("correction_age_s", number(timing.correction_age_s())));
  const msg::StageStamps& stamps = timing.stamps();
  for (std::size_t k = 0; k < 6; ++k) {
    const std::int64_t enter = stamps.enter_monotonic_ns()[k];
    const std::int64_t exit = stamps.exit_monotonic_ns()[k];
    values.push_back(key_value(std::string(kStageNames[k]) + "_ms",
                               enter > 0 && exit >= enter ? number(1e-6 * double(exit - enter)) : "nan"));
  }
  const std::int64_t arrival = stamps.arrival_monotonic_ns();
  const std::int64_t done = stamps.exit_monotonic_ns()[5];
  values.push_back(
      key_value("latency_ms", arrival > 0 && done >= arrival ? number(1e-6 * double(done - arrival)) : "nan"));
  std::uint64_t waits = 0;
  for (const std::uint64_t w : timing.queue_full_waits()) waits += w;
  values.push_back(key_value("queue_full_waits", std::to_string(waits)));
  values.push_back(key_value("vio_dropped", std::to_string(timing.vio_dropped())));
  values.push_back(key_value("vio_late", std::to_string(timing.vio_late())));
  values.push_back(key_value("base_late", std::to_string(timing.base_late())));
  values.push_back(key_value("malformed_samples", std::to_string(timing.malformed_samples())));
  status.values(values);
  const bool troubled = code == 0 || timing.vio_dropped() > 0 || timing.malformed_samples() > 0;
  status.level(troubled ? dm::DiagnosticStatus_Constants::WARN : dm::DiagnosticStatus_Constants::OK);
  status.message(troubled ? (code == 0 ? "no solution" : "samples dropped or malformed")
                          : "solved: " + exact_status_name(code));
  dm::dds_::DiagnosticArray_ array;
  array.header(header(t, "", leaps));
  array.status({status});
  return array;
}

}  // namespace canyon::dds
