// canyon base (see base_app.hpp).

#include "canyon/dds/base_app.hpp"

#include <string>
#include <utility>

#include <spdlog/spdlog.h>

namespace canyon::dds {

BaseApp::BaseApp(BaseOptions options) : options_(std::move(options)) {
  // DDS first: its profiles must be loaded before any participant exists.
  if (options_.config.dds.enabled || options_.config.ros2.enabled) create_dds_output();
  base_ = value_or_throw(
      base::BaseStation::create(options_.config, [](const std::string& line) { spdlog::info("{}", line); }),
      kExitRuntime);
  if (writer_) {
    RtcmWriter* w = writer_.get();
    base_->add_sink([w, this](const base::BaseFrame& frame) {
      if (!publish_rtcm_frame(*w, frame)) refused_.fetch_add(1);
    });
  }
  if (ros2_writer_) {
    RtcmMessageWriter* w = ros2_writer_.get();
    const std::string frame_id = options_.config.ros2.frame_id;
    base_->add_sink([w, frame_id, this](const base::BaseFrame& frame) {
      auto message = to_ros2_rtcm(frame.bytes, ros_time_now(), frame_id);
      if (!w->write(message)) refused_.fetch_add(1);
    });
  }
  if (writer_ || ros2_writer_) {
    base_->set_subscriber_count(
        [this] { return (writer_ ? writer_->matched() : 0) + (ros2_writer_ ? ros2_writer_->matched() : 0); });
  }
}

BaseApp::~BaseApp() = default;

void BaseApp::create_dds_output() {
  const config::BaseConfig::Dds& dds = options_.config.dds;
  const ProfileSet profiles = value_or_throw(load_profiles(dds.profiles), kExitUsage);
  participant_ = value_or_throw(DdsParticipant::create(dds.domain, profiles.participant_profile()), kExitRuntime);
  const std::string shown_profiles = dds.profiles.empty() ? "shipped" : dds.profiles;
  if (dds.enabled) {
    writer_ = value_or_throw(RtcmWriter::create(*participant_, dds.topic, profile::kRtcmWriter), kExitRuntime);
    spdlog::info("DDS: publishing canyon::msg::RtcmFrame on topic '{}', domain {} (profiles {})", dds.topic, dds.domain,
                 shown_profiles);
  }
  if (options_.config.ros2.enabled) {
    const std::string topic = ros2_dds_topic(options_.config.ros2.topic);
    ros2_writer_ =
        value_or_throw(RtcmMessageWriter::create(*participant_, topic, profile::kRos2StreamWriter), kExitRuntime);
    spdlog::info("ROS 2: publishing rtcm_msgs/msg/Message on DDS topic '{}', domain {} (profiles {})", topic,
                 dds.domain, shown_profiles);
  }
}

int BaseApp::run() {
  if (options_.wait_clients > 0) {
    spdlog::info("waiting for {} subscriber(s) (at most {} s)", options_.wait_clients, options_.wait_timeout_s);
    if (!base_->wait_for_clients(options_.wait_clients, options_.wait_timeout_s) && !base_->stop_requested()) {
      spdlog::warn("only some subscribers connected within {} s; starting anyway", options_.wait_timeout_s);
    }
  }
  const Status status = base_->run();
  if ((writer_ && !writer_->wait_for_acknowledgments(5.0)) ||
      (ros2_writer_ && !ros2_writer_->wait_for_acknowledgments(5.0))) {
    spdlog::warn("DDS: not every frame was acknowledged by every reader within 5 s");
  }
  if (refused_.load() > 0) spdlog::warn("DDS: {} frames refused by the writer (history full)", refused_.load());
  if (!status.ok()) {
    spdlog::error("{}", status.error().to_string());
    return kExitRuntime;
  }
  return kExitOk;
}

}  // namespace canyon::dds
