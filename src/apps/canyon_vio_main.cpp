// canyon-vio: publishes a VIO run on DDS, as a VIO node would: the poses of vio.csv as canyon::msg::VioPose samples
// (topic canyon/vio) and the device's time-sync pairs of timesync.csv as TimeSyncSample samples (canyon/timesync),
// merged in device-time order, at real-time pace or faster (--pace; 0: as fast as the readers acknowledge); with
// --ros2 each pose as nav_msgs/msg/Odometry on ROS 2's names instead.
// `canyon vio ...` runs this executable; canyon rover with input.vio dds subscribes. SIGINT/SIGTERM stop it.
// The application is canyon::dds::VioApp. Exit codes: 0 success, 1 input or runtime failure, 2 bad command line.

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "canyon/dds/vio_app.hpp"

#include "main_guard.hpp"

namespace {

namespace dds = canyon::dds;

int run(int argc, char** argv) {
  CLI::App cli{"canyon-vio: publish VIO poses and time-sync pairs on DDS (a VIO node; canyon rover input.vio dds)"};
  dds::VioOptions a;
  bool quiet = false;
  cli.add_option("--vio", a.vio, "VIO poses (vio.csv, DESIGN.md contract)")->required()->check(CLI::ExistingFile);
  cli.add_option("--timesync", a.timesync, "Time-sync pairs (timesync.csv); omit for VIO stamped with GPST")
      ->check(CLI::ExistingFile);
  cli.add_option("--pace", a.pace, "Replay speed: 1 real time, 10 ten times faster, 0 as fast as readers acknowledge")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--domain", a.domain, "DDS domain id")->check(CLI::Range(0, 232));
  cli.add_option("--profiles", a.profiles,
                 "Deployment profiles (transport and discovery, deploy/dds/*.xml) on top of the shipped "
                 "config/dds/canyon_profiles.xml");
  cli.add_option("--vio-topic", a.vio_topic, "Topic of the VioPose samples");
  cli.add_option("--timesync-topic", a.timesync_topic, "Topic of the TimeSyncSample samples");
  cli.add_option("--wait-for-readers", a.wait_readers, "Start once this many readers of each topic are matched")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--wait-timeout", a.wait_timeout_s, "Give up waiting for readers after this many seconds");
  cli.add_option("--linger", a.linger_s,
                 "At the end, stay up to this many seconds while readers are matched (a reader still taking the "
                 "last samples from shared memory loses them when the writer goes)")
      ->check(CLI::NonNegativeNumber);
  cli.add_flag("--ros2", a.ros2,
               "Publish nav_msgs/msg/Odometry on rt/<--ros2-topic> instead, as a ROS 2 VIO node (poses on GPST: no "
               "--timesync; canyon rover input.vio ros2 reads it)");
  cli.add_option("--ros2-topic", a.ros2_topic, "--ros2: the ROS 2 topic (DDS topic rt/ + this)");
  cli.add_option("--ros2-frame-id", a.ros2_frame_id, "--ros2: header.frame_id, the VIO's odometry frame");
  cli.add_option("--ros2-child-frame-id", a.ros2_child_frame_id, "--ros2: child_frame_id, the IMU frame");
  cli.add_flag("-q,--quiet", quiet, "Warnings and errors only");
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : dds::kExitUsage;
  }
  spdlog::set_pattern("[%Y-%m-%d %H:%M:%S.%e] [canyon-vio] [%^%l%$] %v");
  if (quiet) spdlog::set_level(spdlog::level::warn);
  return dds::run_app<dds::VioApp>(std::move(a), [](const dds::AppError& e) { spdlog::error("{}", e.what()); });
}

}  // namespace

int main(int argc, char** argv) {
  return canyon::apps::guarded_main("canyon-vio", canyon::dds::kExitRuntime, run, argc, argv);
}
