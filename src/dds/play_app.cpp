// canyon play (see play_app.hpp).

#include "canyon/dds/play_app.hpp"

#include <algorithm>
#include <chrono>
#include <thread>
#include <utility>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <spdlog/spdlog.h>

#include "canyon/dds/app.hpp"
#include "canyon/dds/profiles.hpp"
#include "canyon/dds/raw_samples.hpp"

namespace canyon::dds {

struct PlayApp::Channel {
  Channel(DdsParticipant& participant, std::string topic_name)
      : participant(participant), topic(std::move(topic_name)) {}
  ~Channel() {
    if (writer != nullptr) publisher->delete_datawriter(writer);
    if (publisher != nullptr) participant.get()->delete_publisher(publisher);
  }
  Channel(const Channel&) = delete;
  Channel& operator=(const Channel&) = delete;
  [[nodiscard]] int matched() const {
    fdds::PublicationMatchedStatus status;
    return writer->get_publication_matched_status(status) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK
               ? status.current_count
               : 0;
  }
  DdsParticipant& participant;
  std::string topic;
  fdds::Publisher* publisher = nullptr;
  fdds::DataWriter* writer = nullptr;
  std::uint64_t messages = 0;
};

PlayApp::PlayApp(PlayOptions options) : options_(std::move(options)) {
  std::string problem;
  session_ = value_or_throw(io::read_mcap_partial(options_.session, &problem), kExitRuntime);
  if (!session_.complete) {
    spdlog::warn("{}; playing the {} messages before it", problem, session_.messages.size());
  }
  const ProfileSet profiles = value_or_throw(load_profiles(options_.profiles), kExitUsage);
  participant_ = value_or_throw(DdsParticipant::create(options_.domain, profiles.participant_profile()), kExitRuntime);
  for (const std::string& topic : options_.topics) {
    const auto in_session = [&](const auto& entry) { return entry.second.topic == topic; };
    if (std::none_of(session_.channels.begin(), session_.channels.end(), in_session)) {
      throw AppError(kExitUsage, Error{"topic '" + topic + "' (--topic) is not in the session", options_.session, 0});
    }
  }
  for (const auto& [id, channel] : session_.channels) {
    if (!options_.topics.empty() &&
        std::find(options_.topics.begin(), options_.topics.end(), channel.topic) == options_.topics.end()) {
      continue;
    }
    const auto schema = session_.schemas.find(channel.schema_id);
    auto known = recorded_topic(channel.topic);
    if (schema != session_.schemas.end() && (!known || known->type_name != schema->second.name)) {
      known = recorded_type(schema->second.name);  // a topic renamed (ros2.fix_topic: gps/navsat), a type canyon has
    }
    if (schema == session_.schemas.end() || schema->second.encoding != "omgidl" || channel.message_encoding != "cdr" ||
        !known || known->type_name != schema->second.name) {
      spdlog::warn("{}: channel {} ('{}', schema '{}') is not one canyon knows: left out", options_.session, id,
                   channel.topic, schema == session_.schemas.end() ? "missing" : schema->second.name);
      continue;
    }
    if (channels_.size() <= id) channels_.resize(id + 1U);
    auto c = std::make_unique<Channel>(*participant_, channel.topic);
    auto topic = value_or_throw(
        participant_->topic(channel.topic, fdds::TypeSupport(new RawSampleType(known->type_name))), kExitRuntime);
    c->publisher = participant_->get()->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
    if (c->publisher == nullptr) throw AppError(kExitRuntime, Error{"DDS: cannot create a publisher"});
    c->writer = c->publisher->create_datawriter_with_profile(topic, known->writer_profile);
    if (c->writer == nullptr) {
      throw AppError(kExitRuntime, Error{"DDS: cannot create a data writer on topic '" + channel.topic + "'"});
    }
    channels_[id] = std::move(c);
  }
  std::size_t played = 0;
  for (const auto& c : channels_) played += c ? 1 : 0;
  if (played == 0) throw AppError(kExitRuntime, Error{"no channel canyon can play", options_.session, 0});
}

PlayApp::~PlayApp() = default;

bool PlayApp::wait_for_readers() const {
  if (options_.wait_readers <= 0) return true;
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(options_.wait_timeout_s);
  while (!stop_.load() && std::chrono::steady_clock::now() < until) {
    bool all = true;
    for (const auto& c : channels_) all = all && (!c || c->matched() >= options_.wait_readers);
    if (all) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

int PlayApp::run() {
  if (!wait_for_readers()) spdlog::warn("not every topic has {} reader(s); playing anyway", options_.wait_readers);
  std::uint64_t refused = 0;
  const auto start = std::chrono::steady_clock::now();
  const std::uint64_t first_ns = session_.messages.empty() ? 0 : session_.messages.front().log_time_ns;
  for (io::McapMessage& m : session_.messages) {
    if (stop_.load()) break;
    Channel* c = m.channel_id < channels_.size() ? channels_[m.channel_id].get() : nullptr;
    if (c == nullptr) continue;
    if (options_.pace > 0.0 && m.log_time_ns >= first_ns) {
      const double at_s = 1e-9 * static_cast<double>(m.log_time_ns - first_ns) / options_.pace;
      std::this_thread::sleep_until(
          start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(at_s)));
    }
    RawSample bytes = std::move(m.data);
    if (!c->writer->write(&bytes)) ++refused;
    ++c->messages;
  }
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(options_.linger_s);
  while (!stop_.load() && std::chrono::steady_clock::now() < until) {
    bool any = false;
    for (const auto& c : channels_) any = any || (c && c->matched() > 0);
    if (!any) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  for (const auto& c : channels_) {
    if (c) spdlog::info("{}: {} messages played", c->topic, c->messages);
  }
  if (refused > 0) {
    spdlog::error("{} messages refused by the writers", refused);
    return kExitRuntime;
  }
  return kExitOk;
}

}  // namespace canyon::dds
