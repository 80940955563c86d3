#pragma once
// canyon vio: a VIO node for recorded runs. Publishes the poses of vio.csv as canyon::msg::VioPose samples and the
// device's time-sync pairs of timesync.csv as TimeSyncSample samples, merged in device-time order, at real-time pace
// or faster (app.hpp: constructed, run() once, stop() from anywhere). With `ros2`, as a ROS 2 VIO node does instead:
// each pose as nav_msgs/msg/Odometry on rt/<ros2_topic> (ros2_msgs.hpp, to_ros2_odometry; canyon rover reads it
// with input.vio ros2), which needs poses stamped with GPST (no time-sync file: ROS time is UTC).

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "canyon/dds/app.hpp"
#include "canyon/dds/dds.hpp"
#include "canyon/dds/ros2_msgs.hpp"
#include "canyon/dds/rover_msgs.hpp"
#include "canyon/io/vio_file.hpp"

namespace canyon::dds {

struct VioOptions {
  std::string vio;                                 ///< VIO poses (vio.csv)
  std::string timesync;                            ///< time-sync pairs (timesync.csv); empty: VIO stamped with GPST
  double pace = 1.0;                               ///< replay speed: 1 real time, 0 as fast as readers acknowledge
  int domain = 0;                                  ///< DDS domain id
  std::string profiles;                            ///< deployment profile file on top of the shipped QoS; "": none
  std::string vio_topic = "canyon/vio";            ///< topic of the VioPose samples
  std::string timesync_topic = "canyon/timesync";  ///< topic of the TimeSyncSample samples
  int wait_readers = 0;                            ///< start once this many readers of each topic are matched
  double wait_timeout_s = 30.0;                    ///< give up waiting for readers after this long (s)
  double linger_s = 2.0;                           ///< at the end, stay up this long (s) while readers are matched
  bool ros2 = false;                               ///< publish nav_msgs/msg/Odometry instead (see above)
  std::string ros2_topic = "vio/odometry";         ///< its ROS 2 topic (DDS topic rt/ + this)
  std::string ros2_frame_id = "odom";              ///< header.frame_id: the VIO's odometry frame O
  std::string ros2_child_frame_id = "imu";         ///< child_frame_id: the IMU frame I
};

class VioApp {
 public:
  /// Reads the files, loads the profiles, creates the participant and the writers; AppError if any fails.
  explicit VioApp(VioOptions options);
  ~VioApp();
  VioApp(const VioApp&) = delete;
  VioApp& operator=(const VioApp&) = delete;

  /// Publishes every sample (or until stop()); 0, or 1 if the writers refused samples.
  int run();
  /// Ends run() promptly (thread- and async-signal-safe).
  void stop() { stop_.store(true); }

 private:
  bool wait_for_readers() const;
  /// The readers matched on every topic published (the fewest).
  [[nodiscard]] int matched() const;
  /// Whether every reader acknowledged every sample within `timeout_s`.
  bool acknowledged(double timeout_s);
  /// Publishes poses and pairs in device-time order; the number of samples the writers refused.
  std::uint64_t publish();
  void linger() const;

  VioOptions options_;
  io::VioFile vio_;
  std::optional<io::TimeSyncFile> sync_;
  std::unique_ptr<DdsParticipant> participant_;
  std::unique_ptr<VioPoseWriter> poses_;
  std::unique_ptr<TimeSyncWriter> pairs_;     ///< only with a time-sync file
  std::unique_ptr<OdometryWriter> odometry_;  ///< ros2 only (then poses_ and pairs_ are not created)
  core::LeapSecondTable leaps_;
  std::atomic<bool> stop_{false};
};

}  // namespace canyon::dds
