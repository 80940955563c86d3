// The XML profile files and the profile names the programs ask for (see profiles.hpp).

#include "canyon/dds/profiles.hpp"

#include <filesystem>
#include <mutex>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastrtps/xmlparser/XMLProfileManager.h>

#include "canyon/config/shipped_config.hpp"

namespace canyon::dds {
namespace {

namespace fs = std::filesystem;
namespace fdds = eprosima::fastdds::dds;
namespace xml = eprosima::fastrtps::xmlparser;

/// Loads one file. Fast DDS keeps the first of two profiles of the same name and only logs the second (XML_NOK):
/// refused here, so that a deployment file cannot silently repeat (and drift from) a QoS profile.
Status load_file(const std::string& path) {
  switch (xml::XMLProfileManager::loadXMLFile(path)) {
    case xml::XMLP_ret::XML_OK: break;
    case xml::XMLP_ret::XML_NOK:
      return Error{
          "Fast DDS XML profiles: a profile could not be added (defined twice?): a deployment file holds only "
          "transport and discovery (its participant profile '" +
              std::string(profile::kDeploymentParticipant) +
              "' and transport descriptors); every QoS profile is in config/dds/canyon_profiles.xml",
          path, 0};
    default: return Error{"cannot load the Fast DDS XML profiles (missing file or invalid XML)", path, 0};
  }
  // The factory's default participant QoS follows the profiles (a no-op load: the file is parsed already).
  (void)fdds::DomainParticipantFactory::get_instance()->load_XML_profiles_file(path);
  return Ok{};
}

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  return fs::equivalent(a, b, ec) && !ec;
}

}  // namespace

const std::vector<RequestedProfile>& requested_profiles() {
  using K = ProfileKind;
  static const std::vector<RequestedProfile> requested = {
      {K::Participant, profile::kParticipant, "every program without a deployment file", false},
      {K::Participant, profile::kDeploymentParticipant, "every program with a deployment file", true},
      {K::DataWriter, profile::kRtcmWriter, "canyon base, canyon-rtcm-probe inject (canyon/rtcm)"},
      {K::DataReader, profile::kRtcmReader, "canyon rover input.base dds, record, echo, canyon-rtcm-probe"},
      {K::DataWriter, profile::kVioWriter, "canyon vio (canyon/vio, canyon/timesync)"},
      {K::DataReader, profile::kVioReader, "canyon rover input.vio dds, record, echo (canyon/vio, canyon/timesync)"},
      {K::DataWriter, profile::kSolutionWriter, "canyon rover (canyon/solution)"},
      {K::DataReader, profile::kSolutionReader, "canyon record, echo, monitor (canyon/solution)"},
      {K::DataWriter, profile::kTimingWriter, "canyon rover (canyon/timing)"},
      {K::DataReader, profile::kTimingReader, "canyon record, echo, monitor (canyon/timing)"},
      {K::DataWriter, profile::kStageWriter, "canyon rover dds.publish_stages (bridged, alignment, prior, float)"},
      {K::DataReader, profile::kStageReader, "canyon record, echo (bridged, alignment, prior, float)"},
      {K::DataWriter, profile::kRos2SensorDataWriter, "canyon rover ros2 (NavSatFix, Odometry)"},
      {K::DataReader, profile::kRos2SensorDataReader, "canyon-ros2-raw (tests: ROS 2 samples as bytes)"},
      {K::DataWriter, profile::kRos2DefaultWriter, "canyon rover ros2 (DiagnosticArray)"},
      {K::DataReader, profile::kRos2DefaultReader, "canyon-ros2-raw (tests: ROS 2 samples as bytes)"},
      {K::DataWriter, profile::kRos2StreamWriter, "canyon base outputs.ros2 (rtcm_msgs), canyon vio --ros2"},
  };
  return requested;
}

Result<std::string> default_profiles_file() {
  return config::find_shipped_config("dds/canyon_profiles.xml");
}

Result<ProfileSet> load_profiles(const std::string& deployment_file) {
  auto qos = default_profiles_file();
  if (!qos) return qos.error();
  return load_profile_files(*qos, deployment_file);
}

Result<ProfileSet> load_profile_files(const std::string& qos_file, const std::string& deployment_file) {
  static std::mutex mutex;  // Fast DDS' profile store is global and not locked
  const std::lock_guard lock(mutex);
  ProfileSet set;
  set.qos_file = qos_file;
  if (Status s = load_file(set.qos_file); !s) return s.error();
  if (deployment_file.empty() || same_file(deployment_file, set.qos_file)) return set;
  if (Status s = load_file(deployment_file); !s) return s.error();
  fdds::DomainParticipantQos participant;
  if (fdds::DomainParticipantFactory::get_instance()->get_participant_qos_from_profile(
          profile::kDeploymentParticipant, participant) != eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
    return Error{"a deployment file must define the participant profile '" +
                     std::string(profile::kDeploymentParticipant) + "' (transport and discovery; deploy/README.md)",
                 deployment_file, 0};
  }
  set.deployment_file = deployment_file;
  return set;
}

}  // namespace canyon::dds
