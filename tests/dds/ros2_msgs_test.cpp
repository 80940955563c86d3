// canyon's solutions as ROS 2 messages (dds/ros2_msgs.hpp): the status mapping, POSIX stamps, the covariance rotated
// into ENU, the Odometry's frame, the DiagnosticArray's exact status, ROS 2's DDS topic names and type names.
// tests/ros2/wire_check.sh decodes the samples on the wire with independent ROS 2 decoders.

#include "canyon/dds/ros2_msgs.hpp"

#include <cmath>
#include <map>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

namespace canyon::dds {
namespace {

namespace sm = sensor_msgs::msg;

core::Solution solution(core::SolutionStatus status) {
  core::Solution s;
  s.time = core::GpsTime{2266, 316800.2};
  s.status = status;
  s.p_E_m = core::geodetic_to_ecef({47.6 * std::numbers::pi / 180.0, -122.3 * std::numbers::pi / 180.0, 20.0});
  // 1 cm east, 2 cm north, 3 cm up, as an ECEF covariance.
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(core::ecef_to_geodetic(s.p_E_m));
  s.P_E_m2 = R_NE.transpose() * Eigen::Vector3d(1e-4, 4e-4, 9e-4).asDiagonal() * R_NE;
  s.num_satellites = 14;
  return s;
}

TEST(Ros2Msgs, StampsArePosixTimeOfTheEpoch) {
  const auto t = ros_time(core::GpsTime{2266, 316800.2}, core::builtin_leap_seconds());
  EXPECT_EQ(t.sec(), 1686758382);  // 2023-06-14 15:59:42 UTC = GPST 16:00:00 - 18 s
  EXPECT_EQ(t.nanosec(), 200000000U);
  const auto carry = ros_time(core::GpsTime{2266, 316800.9999999999}, core::builtin_leap_seconds());
  EXPECT_EQ(carry.sec(), 1686758383);
  EXPECT_EQ(carry.nanosec(), 0U);
}

TEST(Ros2Msgs, FixedAndFloatAreGbasSingleIsFixFillInIsNoFix) {
  const config::Ros2Options options;
  const auto leaps = core::builtin_leap_seconds();
  const core::Solution fixed = solution(core::SolutionStatus::Fixed);
  const auto fix = to_navsatfix(fixed.time, &fixed, 11, options, leaps);
  EXPECT_EQ(fix.status().status(), sm::NavSatStatus_Constants::STATUS_GBAS_FIX);
  EXPECT_EQ(fix.status().service(), 11);
  EXPECT_NEAR(fix.latitude(), 47.6, 1e-9);
  EXPECT_NEAR(fix.longitude(), -122.3, 1e-9);
  EXPECT_NEAR(fix.altitude(), 20.0, 1e-6);
  EXPECT_EQ(fix.position_covariance_type(), sm::NavSatFix_Constants::COVARIANCE_TYPE_KNOWN);
  EXPECT_NEAR(fix.position_covariance()[0], 1e-4, 1e-12);  // east
  EXPECT_NEAR(fix.position_covariance()[4], 4e-4, 1e-12);  // north
  EXPECT_NEAR(fix.position_covariance()[8], 9e-4, 1e-12);  // up
  EXPECT_NEAR(fix.position_covariance()[1], 0.0, 1e-12);
  EXPECT_EQ(fix.header().frame_id(), "gnss");
  core::Solution f = solution(core::SolutionStatus::Float);
  f.fixed_combinations = 3;  // a partial fix: still GBAS on NavSatFix
  EXPECT_EQ(to_navsatfix(f.time, &f, 11, options, leaps).status().status(),
            sm::NavSatStatus_Constants::STATUS_GBAS_FIX);
  const core::Solution single = solution(core::SolutionStatus::Single);
  EXPECT_EQ(to_navsatfix(single.time, &single, 11, options, leaps).status().status(),
            sm::NavSatStatus_Constants::STATUS_FIX);
  const core::Solution fill_in = solution(core::SolutionStatus::VioFillIn);
  const auto no_fix = to_navsatfix(fill_in.time, &fill_in, 11, options, leaps);
  EXPECT_EQ(no_fix.status().status(), sm::NavSatStatus_Constants::STATUS_NO_FIX);
  EXPECT_TRUE(std::isnan(no_fix.latitude()));
  EXPECT_EQ(no_fix.position_covariance_type(), sm::NavSatFix_Constants::COVARIANCE_TYPE_UNKNOWN);
  EXPECT_EQ(to_navsatfix(fill_in.time, nullptr, 0, options, leaps).status().status(),
            sm::NavSatStatus_Constants::STATUS_NO_FIX);
}

TEST(Ros2Msgs, OdometryIsEnuFromTheOriginWithUnknownOrientation) {
  const core::Solution s = solution(core::SolutionStatus::VioFillIn);
  core::Geodetic origin = core::ecef_to_geodetic(s.p_E_m);
  origin.height_m -= 2.0;  // the antenna 2 m above the origin
  const auto odometry = to_odometry(s, origin, config::Ros2Options{}, core::builtin_leap_seconds());
  EXPECT_NEAR(odometry.pose().pose().position().x(), 0.0, 1e-6);
  EXPECT_NEAR(odometry.pose().pose().position().y(), 0.0, 1e-6);
  EXPECT_NEAR(odometry.pose().pose().position().z(), 2.0, 1e-6);
  EXPECT_EQ(odometry.pose().pose().orientation().w(), 1.0);
  EXPECT_NEAR(odometry.pose().covariance()[0], 1e-4, 1e-12);
  EXPECT_NEAR(odometry.pose().covariance()[7], 4e-4, 1e-12);
  EXPECT_NEAR(odometry.pose().covariance()[14], 9e-4, 1e-12);
  EXPECT_EQ(odometry.pose().covariance()[21], kUnknownVariance);
  EXPECT_EQ(odometry.twist().covariance()[0], kUnknownVariance);
  EXPECT_EQ(odometry.header().frame_id(), "map");
  EXPECT_EQ(odometry.child_frame_id(), "gnss_antenna");
}

TEST(Ros2Msgs, DiagnosticsCarryTheExactStatusAndStageTimes) {
  msg::StageTiming timing;
  timing.rover_id("walker");
  timing.gps_week(2266);
  timing.gps_tow_s(316800.2);
  timing.stamps().arrival_monotonic_ns(1000);
  for (std::size_t k = 0; k < 6; ++k) {
    timing.stamps().enter_monotonic_ns()[k] = 1000 + static_cast<std::int64_t>(k) * 2000000;
    timing.stamps().exit_monotonic_ns()[k] = 1000 + static_cast<std::int64_t>(k) * 2000000 + 1000000;
  }
  core::Solution partial = solution(core::SolutionStatus::Float);
  partial.fixed_combinations = 2;
  const auto array = to_diagnostics(timing, &partial, core::builtin_leap_seconds());
  ASSERT_EQ(array.status().size(), 1U);
  const auto& status = array.status().front();
  EXPECT_EQ(status.name(), "canyon rover: walker");
  EXPECT_EQ(status.level(), diagnostic_msgs::msg::DiagnosticStatus_Constants::OK);
  std::map<std::string, std::string> values;
  for (const auto& kv : status.values()) values[kv.key()] = kv.value();
  EXPECT_EQ(values["status"], "partial fix");
  EXPECT_EQ(values["status_code"], "8");
  EXPECT_EQ(values["update_ms"], "1.000");
  EXPECT_EQ(values["latency_ms"], "11.000");
  EXPECT_EQ(to_diagnostics(timing, nullptr, core::builtin_leap_seconds()).status().front().level(),
            diagnostic_msgs::msg::DiagnosticStatus_Constants::WARN);
}

TEST(Ros2Msgs, Ros2NamesOnDds) {
  EXPECT_EQ(ros2_dds_topic("canyon/fix"), "rt/canyon/fix");
  EXPECT_EQ(ros2_dds_topic("/diagnostics"), "rt/diagnostics");
  EXPECT_EQ(std::string(sm::dds_::NavSatFix_PubSubType().getName()), "sensor_msgs::msg::dds_::NavSatFix_");
  EXPECT_EQ(std::string(nav_msgs::msg::dds_::Odometry_PubSubType().getName()), "nav_msgs::msg::dds_::Odometry_");
  EXPECT_EQ(std::string(diagnostic_msgs::msg::dds_::DiagnosticArray_PubSubType().getName()),
            "diagnostic_msgs::msg::dds_::DiagnosticArray_");
}

}  // namespace
}  // namespace canyon::dds
