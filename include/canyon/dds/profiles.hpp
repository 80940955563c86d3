#pragma once
// The Fast DDS XML profiles, written once.
//
// - config/dds/canyon_profiles.xml (the shipped QoS file) holds every QoS: the writer and reader profiles below and
//   the default participant (kParticipant: Fast DDS' builtin transports, shared memory and UDP, multicast discovery).
// - A deployment file (deploy/dds/*.xml, and the secure variants deploy/security/make-pki.sh makes of them) holds
//   only transport and discovery: one participant profile, kDeploymentParticipant, with its transport descriptors
//   and builtin (discovery) settings. It defines no QoS profile: a profile name defined twice is refused.
// - A program loads the shipped QoS file first and the deployment file, if it was given one, on top
//   (load_profiles()); it then creates its participant from the deployment's participant profile, or from the
//   shipped one without a deployment (ProfileSet::participant_profile()). Writers and readers always come from the
//   shipped QoS profiles.
//
// Every profile name a program asks for is a constant here, and requested_profiles() lists them: the profile test
// (tests/dds/profile_sets_test.cpp) checks that each resolves in every shipped profile set.

#include <string>
#include <vector>

#include "canyon/core/result.hpp"

namespace canyon::dds {

namespace profile {
/// The participant of the shipped QoS file (no deployment file given).
inline constexpr char kParticipant[] = "canyon_participant";
/// The participant of a deployment file (transport and discovery).
inline constexpr char kDeploymentParticipant[] = "canyon_deployment";
inline constexpr char kRtcmWriter[] = "rtcm_writer";
inline constexpr char kRtcmReader[] = "rtcm_reader";
inline constexpr char kVioWriter[] = "vio_writer";  ///< canyon/vio and canyon/timesync
inline constexpr char kVioReader[] = "vio_reader";
inline constexpr char kSolutionWriter[] = "solution_writer";
inline constexpr char kSolutionReader[] = "solution_reader";
inline constexpr char kTimingWriter[] = "timing_writer";
inline constexpr char kTimingReader[] = "timing_reader";
inline constexpr char kStageWriter[] = "stage_writer";  ///< canyon/bridged, /alignment, /prior, /float
inline constexpr char kStageReader[] = "stage_reader";
/// ROS 2's QoS profiles (ros2_outputs.hpp): sensor data (best effort, keep last 5) and default (reliable, keep 10).
inline constexpr char kRos2SensorDataWriter[] = "ros2_sensor_data_writer";
inline constexpr char kRos2SensorDataReader[] = "ros2_sensor_data_reader";
inline constexpr char kRos2DefaultWriter[] = "ros2_default_writer";
inline constexpr char kRos2DefaultReader[] = "ros2_default_reader";
/// ROS 2's default QoS with a deeper history (keep last 256; depth plays no part in matching): streams that come in
/// bursts and must not lose a sample (canyon base's RTCM, canyon vio's Odometry).
inline constexpr char kRos2StreamWriter[] = "ros2_stream_writer";
}  // namespace profile

enum class ProfileKind { Participant, DataWriter, DataReader };

/// A profile a program asks for.
struct RequestedProfile {
  ProfileKind kind;
  const char* name;
  const char* used_by;  ///< the programs and topics, for messages
  /// Participant profiles only: asked for with a deployment file loaded (else without one).
  bool deployment = false;
};

/// Every profile the DDS programs (canyon base, rover, vio, record, echo, monitor, canyon-rtcm-probe) ask for.
[[nodiscard]] const std::vector<RequestedProfile>& requested_profiles();

/// The profile files a program loaded.
struct ProfileSet {
  std::string qos_file;         ///< the shipped config/dds/canyon_profiles.xml, as found
  std::string deployment_file;  ///< the deployment file loaded on top; empty: none
  /// kDeploymentParticipant with a deployment file, else kParticipant.
  [[nodiscard]] const char* participant_profile() const {
    return deployment_file.empty() ? profile::kParticipant : profile::kDeploymentParticipant;
  }
};

/// The shipped QoS file (config/dds/canyon_profiles.xml next to the executable or in the source tree).
Result<std::string> default_profiles_file();

/// Loads the shipped QoS file, then `deployment_file` on top (empty, or the shipped file itself: none). Call before
/// creating participants; loading the same files again is a no-op. Error naming the file: missing or invalid XML, a
/// profile defined twice (a deployment file that repeats a QoS profile), or a deployment file without the
/// participant profile kDeploymentParticipant.
Result<ProfileSet> load_profiles(const std::string& deployment_file);
/// load_profiles() with another QoS file than the shipped one (tests).
Result<ProfileSet> load_profile_files(const std::string& qos_file, const std::string& deployment_file);

}  // namespace canyon::dds
