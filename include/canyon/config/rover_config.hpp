#pragma once
// `canyon rover` configuration (config/rover.yaml documents every key): strict YAML parsing, printing, comparison
// and validation, all from the keys described once in rover_table(). No DDS here: the rover executable
// (src/apps/canyon_rover_main.cpp) reads it.

#include <string>

#include <yaml-cpp/yaml.h>

#include "canyon/config/process_config.hpp"
#include "canyon/core/result.hpp"
#include "canyon/pipeline/byte_link.hpp"
#include "canyon/pipeline/epoch_pipeline.hpp"

namespace canyon::config {

enum class RoverInputKind { Rinex, Ubx };
enum class RoverBaseSource { File, Dds, Ntrip, Tcp };
/// Where a fusion rover's VIO comes from: estimator.vio and timesync files, canyon's VioPose and TimeSyncSample over
/// DDS, or a ROS 2 nav_msgs/msg/Odometry topic (ros2.vio_topic; stamps on ROS time, see dds/ros2_msgs.hpp).
enum class RoverVioSource { File, Dds, Ros2 };
[[nodiscard]] const char* rover_base_source_name(RoverBaseSource source);

/// ROS 2-compatible topics (dds/ros2_msgs.hpp): the solution as sensor_msgs/msg/NavSatFix and nav_msgs/msg/Odometry
/// (local ENU), the stage timing and canyon's exact status as diagnostic_msgs/msg/DiagnosticArray, on ROS 2's topic
/// names ("rt/" + topic) and type names. Off by default.
struct Ros2Options {
  bool enabled = false;
  std::string fix_topic = "canyon/fix";            ///< NavSatFix (DDS topic rt/canyon/fix), sensor-data QoS
  std::string odometry_topic = "canyon/odometry";  ///< Odometry in the local ENU frame, sensor-data QoS
  std::string diagnostics_topic = "diagnostics";   ///< DiagnosticArray (ROS 2's /diagnostics), default QoS
  std::string fix_frame_id = "gnss";               ///< NavSatFix header.frame_id: the antenna
  std::string map_frame_id = "map";                ///< Odometry header.frame_id: the local ENU frame
  std::string antenna_frame_id = "gnss_antenna";   ///< Odometry child_frame_id
  std::vector<double> enu_origin_llh;              ///< [lat_deg, lon_deg, h_m] of the ENU origin; empty: first fix
  // input.vio ros2: the VIO as nav_msgs/msg/Odometry, pose T_OI of child frame I in frame O.
  std::string vio_topic = "vio/odometry";  ///< Odometry in (DDS topic rt/vio/odometry)
  std::string vio_frame_id = "odom";       ///< the expected header.frame_id: the VIO's odometry frame O
  std::string vio_child_frame_id = "imu";  ///< the expected child_frame_id: the IMU frame I
};

struct RoverConfig {
  /// The estimator and its inputs: the keys of `canyon process` (mode rtk or fusion, rover, base, nav, vio,
  /// timesync, base_position, rtk, fusion, output; `out`: a .pos the rover writes itself, optional).
  ProcessConfig estimator;
  std::string rover_id = "rover";  ///< names the rover in its messages
  double pace = 1.0;               ///< rover file replay speed: 1 real time, 10 ten times faster, 0 as fast as possible
  RoverInputKind rover = RoverInputKind::Rinex;  ///< rinex: estimator.rover; ubx: a u-blox receiver at rover_source
  std::string rover_source;  ///< ubx: file:PATH (replayed at pace), serial:///dev/X?baud=N, tcp://HOST:PORT, ntrip://
  RoverBaseSource base = RoverBaseSource::File;  ///< file: estimator.base; dds: RtcmFrame samples; ntrip, tcp: RTCM 3
  std::string base_source;         ///< ntrip: ntrip://[USER[:PASSWORD]@]HOST:PORT/MOUNT; tcp: tcp://HOST:PORT
  bool stream_ephemerides = true;  ///< add the ephemerides of the UBX (SFRBX) and RTCM streams to estimator.nav's
  pipeline::LinkOptions link;      ///< attempts, stall_timeout_s of the network links (rover and base)
  double base_wait_s = 2.0;        ///< how long a rover epoch waits for its base epoch (streamed), from when it is due
  double ntrip_gga_interval_s = 0.0;  ///< base ntrip: upload the rover's latest position as GGA this often (0: never)
  std::size_t base_queue_frames = 4096;  ///< RTCM frames between the DDS listener and ingest; beyond: dropped, counted
  RoverVioSource vio = RoverVioSource::File;  ///< fusion: VIO from files, DDS (vio_topic, timesync_topic) or ROS 2
  double vio_wait_s = 0.2;                    ///< dds VIO: longest an epoch waits for the VIO to cover it (s)
  std::size_t vio_queue_poses = 4096;  ///< dds VIO: poses between the DDS listener and the time bridge; beyond: dropped
  pipeline::PipelineOptions pipeline{true, 64};  ///< threaded, queue_capacity
  int domain = 0;                                ///< DDS domain id
  std::string profiles;                          ///< Fast DDS XML profiles ("": config/dds/canyon_profiles.xml)
  std::string rtcm_topic = "canyon/rtcm";
  std::string solution_topic = "canyon/solution";
  std::string timing_topic = "canyon/timing";
  std::string vio_topic = "canyon/vio";            ///< canyon::msg::VioPose in (input.vio dds)
  std::string timesync_topic = "canyon/timesync";  ///< canyon::msg::TimeSyncSample in (input.vio dds)
  bool publish_stages = true;         ///< also canyon/bridged, canyon/alignment, canyon/prior, canyon/float
  bool publish_observations = false;  ///< also canyon/observations: the rover's epochs as ingested
  std::string record;                 ///< MCAP: every topic this rover publishes, recorded in-process; "": none
  Ros2Options ros2;

  /// Empty if usable, else the first broken rule.
  [[nodiscard]] std::string validate() const;
  /// Whether the VIO streams in (dds, ros2), not from files.
  [[nodiscard]] bool streamed_vio() const { return vio != RoverVioSource::File; }
  /// Whether the base comes as RTCM 3 that streams in (dds, ntrip, tcp).
  [[nodiscard]] bool streamed_base() const { return base != RoverBaseSource::File; }
};

/// Equal when every key of rover_table() is.
[[nodiscard]] bool operator==(const RoverConfig& a, const RoverConfig& b);
Result<RoverConfig> parse_rover_config(const YAML::Node& node, const std::string& file);
Result<RoverConfig> load_rover_config(const std::string& path);
[[nodiscard]] std::string to_yaml(const RoverConfig& config);

/// The rover's keys (options_table.hpp); `estimator:` holds process_table()'s.
[[nodiscard]] const Table<RoverConfig>& rover_table();
/// Every key with its unit, default (of RoverConfig{}) and doc.
[[nodiscard]] std::vector<KeyDescription> describe_rover_config();

}  // namespace canyon::config
