#pragma once
// A small Fast DDS 2.9 shell: XML QoS profiles loaded once before any participant (profiles.hpp: the shipped QoS
// file, and a deployment file's transport and discovery on top), a participant that owns its topics, and typed
// writers and readers created from named profiles (the profile:: constants). Entities are deleted in reverse order
// by the destructors. Readers hand samples to a callback on Fast DDS's listener
// thread: the callback should only queue them.
//
// QoS comes from the XML profiles only (TOOLCHAIN.md: a profile applies when it is loaded before the participant is
// created and the entity is created from it; QoS set in code would be overwritten or would override it).

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <fastcdr/exceptions/Exception.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/common/SerializedPayload.h>

#include "canyon/core/result.hpp"
#include "canyon/dds/profiles.hpp"
#include "canyon/dds/session_recorder.hpp"

namespace canyon::dds {

namespace fdds = eprosima::fastdds::dds;

class DdsParticipant {
 public:
  /// A participant on `domain` from the participant profile `profile` (ProfileSet::participant_profile()).
  static Result<std::unique_ptr<DdsParticipant>> create(int domain, const std::string& profile);
  ~DdsParticipant();
  DdsParticipant(const DdsParticipant&) = delete;
  DdsParticipant& operator=(const DdsParticipant&) = delete;

  [[nodiscard]] fdds::DomainParticipant* get() const { return participant_; }
  /// The topic `name` of type `type` (registered on first use; the same Topic for the same name).
  Result<fdds::Topic*> topic(const std::string& name, const fdds::TypeSupport& type);

 private:
  explicit DdsParticipant(fdds::DomainParticipant* participant) : participant_(participant) {}
  fdds::DomainParticipant* participant_;
  std::mutex mutex_;
};

/// Payloads a reader could not deserialize (malformed CDR: a packet corrupted on the way), in this process.
std::uint64_t malformed_payloads();

namespace detail {
void count_malformed_payload();
}  // namespace detail

/// A fastddsgen PubSubType whose deserialize() refuses a malformed payload instead of throwing. The generated code
/// catches only NotEnoughMemoryException: a corrupted packet (e.g. a bad encapsulation) threw BadParamException
/// through Fast DDS's listener thread and terminated the subscriber. Refused payloads are dropped by Fast DDS (with
/// its "error deserializing" log line) and counted (malformed_payloads()).
template <typename PubSub>
class GuardedPubSubType final : public PubSub {
 public:
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    try {
      return PubSub::deserialize(payload, data);
    } catch (const eprosima::fastcdr::exception::Exception&) {
      detail::count_malformed_payload();
      return false;
    }
  }
};

/// A writer of samples of type Msg (PubSub: the fastddsgen PubSubType) from a data_writer profile.
template <typename Msg, typename PubSub>
class DdsWriter {
 public:
  static Result<std::unique_ptr<DdsWriter>> create(DdsParticipant& participant, const std::string& topic_name,
                                                   const std::string& profile) {
    // Guarded too: the first registration of a type in a participant is the one its readers use.
    auto topic = participant.topic(topic_name, fdds::TypeSupport(new GuardedPubSubType<PubSub>()));
    if (!topic) return topic.error();
    std::unique_ptr<DdsWriter> w(new DdsWriter(participant));
    w->publisher_ = participant.get()->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
    if (w->publisher_ == nullptr) return Error{"DDS: cannot create a publisher"};
    w->writer_ = w->publisher_->create_datawriter_with_profile(*topic, profile, &w->listener_);
    if (w->writer_ == nullptr) {
      return Error{"DDS: cannot create a data writer from profile '" + profile + "' on topic '" + topic_name + "'"};
    }
    return w;
  }
  ~DdsWriter() {
    if (writer_ != nullptr) publisher_->delete_datawriter(writer_);
    if (publisher_ != nullptr) participant_.get()->delete_publisher(publisher_);
  }
  DdsWriter(const DdsWriter&) = delete;
  DdsWriter& operator=(const DdsWriter&) = delete;

  /// Publishes a sample; false if Fast DDS refused it (history full past max_blocking_time). With record_to(), the
  /// sample is recorded too.
  bool write(Msg& sample) {
    const bool written = writer_->write(&sample);
    if (recorder_ != nullptr) record(sample);
    return written;
  }
  /// Also records every sample written from now on, serialized as on the wire, to `recorder` on `channel`.
  void record_to(SessionRecorder& recorder, std::uint16_t channel) {
    recorder_ = &recorder;
    channel_ = channel;
  }
  /// Readers matched now.
  [[nodiscard]] int matched() const { return listener_.matched.load(); }
  /// The DDS type name of the samples ("canyon::msg::Solution", "sensor_msgs::msg::dds_::NavSatFix_").
  [[nodiscard]] std::string type_name() const { return type_.getName(); }
  /// Waits until every matched reader acknowledged every sample (reliable), at most `timeout_s`.
  bool wait_for_acknowledgments(double timeout_s) {
    const auto seconds = static_cast<std::int32_t>(timeout_s);
    const auto nanos = static_cast<std::uint32_t>((timeout_s - seconds) * 1e9);
    return writer_->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(seconds, nanos)) ==
           eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK;
  }

 private:
  struct Listener : fdds::DataWriterListener {
    void on_publication_matched(fdds::DataWriter* /*writer*/, const fdds::PublicationMatchedStatus& info) override {
      matched.store(info.current_count);
    }
    std::atomic<int> matched{0};
  };
  explicit DdsWriter(DdsParticipant& participant) : participant_(participant) {}
  void record(Msg& sample) {
    const std::int64_t start = thread_cpu_ns();
    eprosima::fastrtps::rtps::SerializedPayload_t payload(type_.getSerializedSizeProvider(&sample)());
    if (type_.serialize(&sample, &payload)) {
      // On the wire the payload is padded with zeros to a multiple of 4 bytes: record the same bytes.
      std::vector<std::uint8_t> bytes(payload.data, payload.data + payload.length);
      bytes.resize((bytes.size() + 3U) / 4U * 4U, 0);
      (void)recorder_->record(channel_, std::move(bytes));  // an error is reported when the recording is closed
    }
    recorder_->add_cpu_ns(thread_cpu_ns() - start);
  }
  DdsParticipant& participant_;
  fdds::Publisher* publisher_ = nullptr;
  fdds::DataWriter* writer_ = nullptr;
  Listener listener_;
  PubSub type_;                          ///< serializes the samples record() takes
  SessionRecorder* recorder_ = nullptr;  ///< record_to(); not owned
  std::uint16_t channel_ = 0;
};

/// A reader of samples of type Msg from a data_reader profile; every sample taken goes to `on_sample`.
template <typename Msg, typename PubSub>
class DdsReader {
 public:
  using SampleFn = std::function<void(Msg&&)>;
  static Result<std::unique_ptr<DdsReader>> create(DdsParticipant& participant, const std::string& topic_name,
                                                   const std::string& profile, SampleFn on_sample) {
    auto topic = participant.topic(topic_name, fdds::TypeSupport(new GuardedPubSubType<PubSub>()));
    if (!topic) return topic.error();
    std::unique_ptr<DdsReader> r(new DdsReader(participant, std::move(on_sample)));
    r->subscriber_ = participant.get()->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
    if (r->subscriber_ == nullptr) return Error{"DDS: cannot create a subscriber"};
    r->reader_ = r->subscriber_->create_datareader_with_profile(*topic, profile, &r->listener_);
    if (r->reader_ == nullptr) {
      return Error{"DDS: cannot create a data reader from profile '" + profile + "' on topic '" + topic_name + "'"};
    }
    return r;
  }
  ~DdsReader() {
    if (reader_ != nullptr) {
      reader_->set_listener(nullptr);
      subscriber_->delete_datareader(reader_);
    }
    if (subscriber_ != nullptr) participant_.get()->delete_subscriber(subscriber_);
  }
  DdsReader(const DdsReader&) = delete;
  DdsReader& operator=(const DdsReader&) = delete;

  /// Writers matched now.
  [[nodiscard]] int matched() const { return listener_.matched.load(); }
  /// Deadline periods (profile) that passed without a sample: a silent publisher.
  [[nodiscard]] int deadlines_missed() const { return listener_.deadlines_missed.load(); }

 private:
  struct Listener : fdds::DataReaderListener {
    explicit Listener(SampleFn fn) : on_sample(std::move(fn)) {}
    void on_data_available(fdds::DataReader* reader) override {
      Msg sample;
      fdds::SampleInfo info;
      while (reader->take_next_sample(&sample, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
        if (info.valid_data) on_sample(std::move(sample));
        sample = Msg();
      }
    }
    void on_subscription_matched(fdds::DataReader* /*reader*/, const fdds::SubscriptionMatchedStatus& info) override {
      matched.store(info.current_count);
    }
    void on_requested_deadline_missed(fdds::DataReader* /*reader*/,
                                      const fdds::RequestedDeadlineMissedStatus& status) override {
      deadlines_missed.store(status.total_count);
    }
    SampleFn on_sample;
    std::atomic<int> matched{0};
    std::atomic<int> deadlines_missed{0};
  };
  DdsReader(DdsParticipant& participant, SampleFn fn) : participant_(participant), listener_(std::move(fn)) {}
  DdsParticipant& participant_;
  fdds::Subscriber* subscriber_ = nullptr;
  fdds::DataReader* reader_ = nullptr;
  Listener listener_;
};

}  // namespace canyon::dds
