#pragma once
// DDS samples as the bytes on the wire, for recordings (canyon record --out SESSION.mcap) and tests: a type support
// whose sample is its serialized payload (CDR encapsulation header included), registered under a real type's name so
// that it matches that type's writers; and what a recording needs to know of each topic it can record: the DDS type
// name, the OMG IDL text that defines it (the schema a reader decodes the bytes with) and the reader profile.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <fastdds/dds/topic/TopicDataType.hpp>

namespace canyon::msgs {
/// The text of idl/FILE (e.g. "RoverPipeline.idl") as built; empty if there is no such file (idl/CMakeLists.txt).
std::string idl_text(const std::string& file);
}  // namespace canyon::msgs

namespace canyon::dds {

using RawSample = std::vector<std::uint8_t>;

/// A type whose samples are their serialized bytes, copied in and out as they are.
class RawSampleType final : public eprosima::fastdds::dds::TopicDataType {
 public:
  explicit RawSampleType(const std::string& type_name);
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override;
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override;
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override;
  void* createData() override;
  void deleteData(void* data) override;
  bool getKey(void* data, eprosima::fastrtps::rtps::InstanceHandle_t* handle, bool force_md5) override;
};

struct RecordedTopic {
  std::string type_name;  ///< e.g. "canyon::msg::Solution"
  std::string schema;     ///< OMG IDL text defining it (with the types it uses)
  const char* reader_profile = nullptr;
  const char* writer_profile = nullptr;  ///< canyon play publishes it with the profile of its original writer
};

/// What recording `topic` takes (by its suffix, as canyon record and echo tell topics apart; "rt/..." topics: the
/// ROS 2 types canyon publishes); nullopt for a topic canyon does not know.
[[nodiscard]] std::optional<RecordedTopic> recorded_topic(const std::string& topic);

/// What recording and playing a topic of DDS type `type_name` takes (a topic renamed beyond the suffixes above);
/// nullopt for a type canyon does not publish.
[[nodiscard]] std::optional<RecordedTopic> recorded_type(const std::string& type_name);

}  // namespace canyon::dds
