#pragma once
// canyon's solutions and stage timing as ROS 2 messages (idl/Ros2Messages.idl: the ROS 2 types field for field).
//
// Stamps: builtin_interfaces/Time is ROS 2's wall-clock time, POSIX seconds (UTC, without leap seconds): the epoch's
// GPST minus GPST-UTC. NavSatFix, the mapping of canyon's status (NavSatStatus cannot tell a fixed from a float
// solution, and a VIO fill-in is no GNSS fix):
//   fixed (1), float (2) and partial fix (8)  -> STATUS_GBAS_FIX (RTK: ground-based augmentation by the base)
//   single point (5)                          -> STATUS_FIX
//   VIO fill-in (7), no solution (0)          -> STATUS_NO_FIX, latitude/longitude/altitude NaN (the fill-in is on
//                                                Odometry only)
// canyon's exact status is in the DiagnosticArray of the same stamp (keys "status" and "status_code").
// position_covariance: the solution's ECEF covariance rotated into ENU at the solution, row-major, type KNOWN.
// Odometry: header.frame_id the local ENU frame (x east, y north, z up) from the origin, child_frame_id the antenna;
// every solved epoch (fill-ins too). Orientation unknown: identity with variance kUnknownVariance on the three
// rotations (ROS's convention for an unmeasured component: a huge variance); the twist is zero with that variance
// (canyon's solutions carry no velocity covariance).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "canyon/config/rover_config.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/core/observation.hpp"
#include "canyon/core/solution.hpp"
#include "canyon/core/time.hpp"
#include "canyon/dds/dds.hpp"
#include "canyon/io/vio_file.hpp"

#include "Ros2Messages.h"
#include "Ros2MessagesPubSubTypes.h"
#include "RoverPipeline.h"

namespace canyon::dds {

using NavSatFixWriter = DdsWriter<sensor_msgs::msg::dds_::NavSatFix_, sensor_msgs::msg::dds_::NavSatFix_PubSubType>;
using OdometryWriter = DdsWriter<nav_msgs::msg::dds_::Odometry_, nav_msgs::msg::dds_::Odometry_PubSubType>;
using OdometryReader = DdsReader<nav_msgs::msg::dds_::Odometry_, nav_msgs::msg::dds_::Odometry_PubSubType>;
using RtcmMessageWriter = DdsWriter<rtcm_msgs::msg::dds_::Message_, rtcm_msgs::msg::dds_::Message_PubSubType>;
using DiagnosticsWriter =
    DdsWriter<diagnostic_msgs::msg::dds_::DiagnosticArray_, diagnostic_msgs::msg::dds_::DiagnosticArray_PubSubType>;

/// ROS 2's DDS topic of a ROS 2 topic name: "rt/" + the name without a leading '/'.
[[nodiscard]] std::string ros2_dds_topic(const std::string& ros_topic);

/// The variance of a component a message cannot fill (orientation, unknown velocity) (rad^2 or m^2/s^2).
inline constexpr double kUnknownVariance = 1e9;

/// builtin_interfaces/Time of GPST `t`: POSIX time (UTC), nanoseconds rounded.
[[nodiscard]] builtin_interfaces::msg::dds_::Time_ ros_time(const core::GpsTime& t, const core::LeapSecondTable& leaps);

/// NavSatStatus.service: the systems of the satellites in the rover epoch (SERVICE_GPS | GLONASS | COMPASS | GALILEO).
[[nodiscard]] std::uint16_t navsat_service(const core::ObsEpoch& rover);

/// The NavSatFix of an epoch at GPST `t` with `solution` (nullptr: not solved), see above.
[[nodiscard]] sensor_msgs::msg::dds_::NavSatFix_ to_navsatfix(const core::GpsTime& t, const core::Solution* solution,
                                                              std::uint16_t service, const config::Ros2Options& options,
                                                              const core::LeapSecondTable& leaps);

/// The Odometry of a solved epoch in the ENU frame at `origin`, see above.
[[nodiscard]] nav_msgs::msg::dds_::Odometry_ to_odometry(const core::Solution& solution, const core::Geodetic& origin,
                                                         const config::Ros2Options& options,
                                                         const core::LeapSecondTable& leaps);

/// The DiagnosticArray of an epoch: one DiagnosticStatus "canyon rover: <rover_id>" with canyon's exact status,
/// satellites, correction age, each stage's time (ms), the queues and the drops of `timing`; level OK, WARN when
/// the epoch has no solution or something was dropped, late or malformed so far.
[[nodiscard]] diagnostic_msgs::msg::dds_::DiagnosticArray_ to_diagnostics(const msg::StageTiming& timing,
                                                                          const core::Solution* solution,
                                                                          const core::LeapSecondTable& leaps);

/// A VIO pose from a ROS 2 Odometry (input.vio ros2). Assumed, as ROS 2 defines Odometry and as VIO nodes (OpenVINS)
/// publish it: the pose is T_OI, the IMU (child_frame_id) in the VIO's odometry frame (header.frame_id); its 6x6
/// covariance is row-major over (x, y, z, rotation about x, y, z) in header.frame_id. canyon's covariance is of the
/// right perturbation xi_OI = [delta p; delta theta] in the IMU frame, so it is rotated by R_IO: C = J C_ros J^T with
/// J = diag(R_IO, R_IO). Odometry has no cross-covariance with the previous pose: none (zero, as a vio.csv without
/// its 36 columns). The twist is not used. header.stamp is ROS time (POSIX, UTC) and becomes GPST with the leap
/// seconds: the VIO host's clock must follow GPS time (PTP, or NTP/chrony with a PPS), so no time-sync pairs are
/// needed. Errors (the sample is refused): frame ids other than `options.vio_frame_id` / `vio_child_frame_id`, a value
/// that is not finite, a quaternion that is no rotation, a covariance that is not positive definite.
Result<io::VioRecord> from_ros2_odometry(const nav_msgs::msg::dds_::Odometry_& odometry,
                                         const config::Ros2Options& options, const core::LeapSecondTable& leaps);

/// A VIO pose stamped on GPST (`record.t_ns`: ns since the GPS epoch) as a ROS 2 VIO node publishes it (canyon vio
/// --ros2): from_ros2_odometry's conventions the other way round, frames `frame_id` -> `child_frame_id`, the twist
/// unknown (zero, kUnknownVariance on the diagonal). from_ros2_odometry gives the record back (the covariance to
/// rounding).
[[nodiscard]] nav_msgs::msg::dds_::Odometry_ to_ros2_odometry(const io::VioRecord& record, const std::string& frame_id,
                                                              const std::string& child_frame_id,
                                                              const core::LeapSecondTable& leaps);

/// An RTCM 3 frame as rtcm_msgs/msg/Message (canyon base with outputs.ros2): the frame's bytes (preamble to CRC) in
/// `message`; header.stamp `sent` (ROS time of sending, as NTRIP clients on ROS 2 stamp what they receive).
[[nodiscard]] rtcm_msgs::msg::dds_::Message_ to_ros2_rtcm(const std::vector<std::uint8_t>& frame,
                                                          const builtin_interfaces::msg::dds_::Time_& sent,
                                                          const std::string& frame_id);

/// ROS time now (the system clock).
[[nodiscard]] builtin_interfaces::msg::dds_::Time_ ros_time_now();

/// The inverse of from_ros2_odometry's covariance mapping: canyon's xi_OI covariance as Odometry's, in frame O.
[[nodiscard]] core::Matrix6d ros2_pose_covariance(const core::Matrix6d& xi_covariance, const core::Pose& T_OI);

/// canyon's exact status name ("fixed", "float", "partial fix", "single", "fill-in", "none").
[[nodiscard]] std::string exact_status_name(std::uint8_t status);

}  // namespace canyon::dds
