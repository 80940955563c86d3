#pragma once
// canyon base: the base station. Reads the base receiver (base::BaseStation), produces RTCM 3 and publishes it as
// RtcmFrame samples on a DDS topic (and as ROS 2's rtcm_msgs/msg/Message with outputs.ros2), on its NTRIP caster and
// TCP server (app.hpp: constructed, run() once, stop() from anywhere).

#include <atomic>
#include <cstdint>
#include <memory>

#include "canyon/base/base_station.hpp"
#include "canyon/config/base_config.hpp"
#include "canyon/dds/app.hpp"
#include "canyon/dds/dds.hpp"
#include "canyon/dds/ros2_msgs.hpp"
#include "canyon/dds/rtcm_frame.hpp"

namespace canyon::dds {

struct BaseOptions {
  config::BaseConfig config;     ///< validated (config::BaseConfig::validate); outputs.dds.profiles: deployment file
  int wait_clients = 0;          ///< hold a file replay until this many subscribers (NTRIP, TCP, DDS readers)
  double wait_timeout_s = 30.0;  ///< give up waiting for them after this long (s)
};

class BaseApp {
 public:
  /// Loads the profiles and creates the participant and writer (outputs.dds.enabled), then the base station (its
  /// input, caster and server); AppError if any fails.
  explicit BaseApp(BaseOptions options);
  ~BaseApp();
  BaseApp(const BaseApp&) = delete;
  BaseApp& operator=(const BaseApp&) = delete;

  /// Runs the base station until its input ends, stop() or a fatal input error; 0, or 1 on an error.
  int run();
  /// Ends run() promptly (thread- and async-signal-safe).
  void stop() { base_->stop(); }

  /// What the station has sent so far.
  [[nodiscard]] base::BaseStationStats stats() const { return base_->stats(); }

 private:
  void create_dds_output();

  BaseOptions options_;
  std::unique_ptr<DdsParticipant> participant_;     ///< outputs.dds.enabled or outputs.ros2.enabled
  std::unique_ptr<RtcmWriter> writer_;              ///< outputs.dds.enabled only
  std::unique_ptr<RtcmMessageWriter> ros2_writer_;  ///< outputs.ros2.enabled only
  std::atomic<std::uint64_t> refused_{0};
  std::unique_ptr<base::BaseStation> base_;
};

}  // namespace canyon::dds
