// DDS samples as the bytes on the wire (see raw_samples.hpp).

#include "canyon/dds/raw_samples.hpp"

#include <cstring>
#include <span>
#include <utility>

#include "canyon/dds/profiles.hpp"

namespace canyon::dds {
namespace {

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

/// canyon's own types: every canyon IDL file, so that a type's schema holds the types it uses.
std::string canyon_schema() {
  return msgs::idl_text("GnssObservation.idl") + "\n" + msgs::idl_text("RtcmFrame.idl") + "\n" +
         msgs::idl_text("RoverPipeline.idl");
}

}  // namespace

RawSampleType::RawSampleType(const std::string& type_name) {
  setName(type_name.c_str());
  m_typeSize = 1U << 16U;  // the largest payload canyon publishes is a few kB (Fast DDS preallocates this per sample)
  m_isGetKeyDefined = false;
}

bool RawSampleType::serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) {
  const auto& bytes = *static_cast<RawSample*>(data);
  if (bytes.size() > payload->max_size) return false;
  std::memcpy(payload->data, bytes.data(), bytes.size());
  payload->length = static_cast<std::uint32_t>(bytes.size());
  return true;
}

bool RawSampleType::deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) {
  static_cast<RawSample*>(data)->assign(payload->data, payload->data + payload->length);
  return true;
}

std::function<std::uint32_t()> RawSampleType::getSerializedSizeProvider(void* data) {
  return [data] { return static_cast<std::uint32_t>(static_cast<RawSample*>(data)->size()); };
}

void* RawSampleType::createData() {
  return new RawSample();
}

void RawSampleType::deleteData(void* data) {
  delete static_cast<RawSample*>(data);
}

bool RawSampleType::getKey(void* /*data*/, eprosima::fastrtps::rtps::InstanceHandle_t* /*handle*/, bool /*force_md5*/) {
  return false;
}

namespace {

/// The topics canyon records, by the suffix of their name, with their type and QoS.
struct Known {
  const char* suffix;
  const char* type;
  const char* profile;
  const char* writer;
};
constexpr Known kCanyonTopics[] = {
    {"solution", "canyon::msg::Solution", profile::kSolutionReader, profile::kSolutionWriter},
    {"timing", "canyon::msg::StageTiming", profile::kTimingReader, profile::kTimingWriter},
    {"rtcm", "canyon::msg::RtcmFrame", profile::kRtcmReader, profile::kRtcmWriter},
    {"bridged", "canyon::msg::BridgedEpoch", profile::kStageReader, profile::kStageWriter},
    {"prior", "canyon::msg::Prior", profile::kStageReader, profile::kStageWriter},
    {"float", "canyon::msg::FloatSolution", profile::kStageReader, profile::kStageWriter},
    {"alignment", "canyon::msg::Alignment", profile::kStageReader, profile::kStageWriter},
    {"vio", "canyon::msg::VioPose", profile::kVioReader, profile::kVioWriter},
    {"timesync", "canyon::msg::TimeSyncSample", profile::kVioReader, profile::kVioWriter},
    {"observations", "canyon::msg::GnssObservationEpoch", profile::kStageReader, profile::kStageWriter},
};
constexpr Known kRos2Topics[] = {
    {"fix", "sensor_msgs::msg::dds_::NavSatFix_", profile::kRos2SensorDataReader, profile::kRos2SensorDataWriter},
    {"odometry", "nav_msgs::msg::dds_::Odometry_", profile::kRos2SensorDataReader, profile::kRos2SensorDataWriter},
    {"diagnostics", "diagnostic_msgs::msg::dds_::DiagnosticArray_", profile::kRos2DefaultReader,
     profile::kRos2DefaultWriter},
    {"rtcm", "rtcm_msgs::msg::dds_::Message_", profile::kRos2DefaultReader, profile::kRos2StreamWriter},
};

RecordedTopic recorded(const Known& k, bool ros2) {
  return RecordedTopic{k.type, ros2 ? msgs::idl_text("Ros2Messages.idl") : canyon_schema(), k.profile, k.writer};
}

}  // namespace

std::optional<RecordedTopic> recorded_topic(const std::string& topic) {
  const bool ros2 = topic.rfind("rt/", 0) == 0;
  for (const Known& k : ros2 ? std::span<const Known>(kRos2Topics) : std::span<const Known>(kCanyonTopics)) {
    if (ends_with(topic, k.suffix)) return recorded(k, ros2);
  }
  return std::nullopt;
}

std::optional<RecordedTopic> recorded_type(const std::string& type_name) {
  for (const Known& k : kCanyonTopics) {
    if (type_name == k.type) return recorded(k, false);
  }
  for (const Known& k : kRos2Topics) {
    if (type_name == k.type) return recorded(k, true);
  }
  return std::nullopt;
}

}  // namespace canyon::dds
