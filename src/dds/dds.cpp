// Fast DDS shell (see dds.hpp).

#include "canyon/dds/dds.hpp"

namespace canyon::dds {
namespace {

std::atomic<std::uint64_t> g_malformed_payloads{0};

}  // namespace

std::uint64_t malformed_payloads() {
  return g_malformed_payloads.load();
}

void detail::count_malformed_payload() {
  g_malformed_payloads.fetch_add(1);
}

Result<std::unique_ptr<DdsParticipant>> DdsParticipant::create(int domain, const std::string& profile) {
  fdds::DomainParticipant* p =
      fdds::DomainParticipantFactory::get_instance()->create_participant_with_profile(domain, profile);
  if (p == nullptr) {
    return Error{"DDS: cannot create a participant on domain " + std::to_string(domain) + " from profile '" + profile +
                 "' (are the XML profiles loaded?)"};
  }
  return std::unique_ptr<DdsParticipant>(new DdsParticipant(p));
}

DdsParticipant::~DdsParticipant() {
  if (participant_ != nullptr) {
    participant_->delete_contained_entities();
    fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
}

Result<fdds::Topic*> DdsParticipant::topic(const std::string& name, const fdds::TypeSupport& type) {
  const std::lock_guard lock(mutex_);
  if (fdds::TopicDescription* existing = participant_->lookup_topicdescription(name); existing != nullptr) {
    auto* topic = dynamic_cast<fdds::Topic*>(existing);
    if (topic == nullptr) return Error{"DDS: '" + name + "' is not a topic"};
    return topic;
  }
  if (type.register_type(participant_) != eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK &&
      participant_->find_type(type.get_type_name()).empty()) {
    return Error{"DDS: cannot register type " + type.get_type_name()};
  }
  fdds::Topic* topic = participant_->create_topic(name, type.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
  if (topic == nullptr) return Error{"DDS: cannot create topic '" + name + "'"};
  return topic;
}

}  // namespace canyon::dds
