#pragma once
// Configuration of `canyon base`, the base station that publishes RTCM 3 corrections: where the receiver data comes
// from, what RTCM 3 it becomes, and where it goes. Strict YAML (an unknown or misspelt key is an error naming the
// file and line); relative paths are relative to the YAML file's folder. config/base.yaml documents every key.
//
//   station:   id, position [X, Y, Z] (ECEF m; default: the input's RINEX header or RTCM 1005), antenna_height_m
//              (1006 instead of 1005), antenna / receiver descriptors (1033)
//   input:     kind (rinex | ubx | rtcm3), source (file | serial | tcp | ntrip), path, nav files, pace, approx_time,
//              serial baud, host / port / mountpoint / user / password
//   rtcm:      msm (7 | 4), station_interval_s, ephemeris_interval_s
//   outputs:   dds (enabled, domain, topic, profiles file), ntrip (enabled, bind, port, mountpoint, user, password),
//              tcp (enabled, bind, port), ros2 (enabled, topic, frame_id)
//   log:       progress_interval_s

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

#include "canyon/config/options_table.hpp"
#include "canyon/core/result.hpp"
#include "canyon/core/time.hpp"

namespace canyon::config {

enum class BaseInputKind { Rinex, Ubx, Rtcm3 };
enum class BaseInputSource { File, Serial, Tcp, Ntrip };

struct BaseConfig {
  struct Station {
    int id = 0;                                   ///< RTCM reference station id (DF003), 0-4095
    std::optional<Eigen::Vector3d> position_E_m;  ///< antenna reference point, ECEF (m)
    std::optional<double> antenna_height_m;       ///< ARP above the marker (m): sends 1006 instead of 1005
    std::string antenna;                          ///< IGS antenna type for 1033 (empty: no 1033)
    std::string receiver;                         ///< receiver type for 1033
  } station;
  struct Input {
    BaseInputKind kind = BaseInputKind::Rinex;
    BaseInputSource source = BaseInputSource::File;
    std::string path;              ///< file (rinex, ubx, rtcm3; may be .gz) or serial device
    std::vector<std::string> nav;  ///< rinex: navigation files (ephemerides to send)
    double pace = 1.0;             ///< file replay speed: 1 real time, 10 ten times faster, 0 as fast as possible
    std::optional<core::GpsTime> approx_time;  ///< rtcm3 input: GPST within days of the data (default: now)
    int baud = 115200;                         ///< serial
    std::string host;                          ///< tcp / ntrip
    int port = 0;
    std::string mountpoint;  ///< ntrip
    std::string user;
    std::string password;
  } input;
  struct Rtcm {
    int msm = 7;                         ///< 7 (MSM7) or 4 (MSM4); 5 and 6 accepted
    double station_interval_s = 10.0;    ///< 1005/1006 (and 1033) every this many seconds
    double ephemeris_interval_s = 60.0;  ///< each current ephemeris again every this many seconds (0: when new)
  } rtcm;
  struct Dds {
    bool enabled = true;
    int domain = 0;
    std::string topic = "canyon/rtcm";
    std::string profiles;  ///< Fast DDS XML profiles file (default: the shipped config/dds/canyon_profiles.xml)
  } dds;
  struct Ntrip {
    bool enabled = true;
    std::string bind = "0.0.0.0";
    int port = 2101;  ///< 0: any free port
    std::string mountpoint = "CANYON";
    std::string user;  ///< empty: no authentication
    std::string password;
  } ntrip;
  struct Tcp {
    bool enabled = false;
    std::string bind = "0.0.0.0";
    int port = 2102;
  } tcp;
  /// rtcm_msgs/msg/Message on ROS 2's names (DDS topic rt/ + topic), on the domain and profiles of `dds`.
  struct Ros2 {
    bool enabled = false;
    std::string topic = "rtcm";          ///< the ROS 2 topic (ntrip_client's name)
    std::string frame_id = "gnss_base";  ///< header.frame_id
  } ros2;
  double progress_interval_s = 10.0;  ///< a progress line every this many seconds (0: none)

  /// Empty if complete and consistent, else the first violated rule.
  [[nodiscard]] std::string validate() const;
};

/// Equal when every key of base_table() is.
[[nodiscard]] bool operator==(const BaseConfig& a, const BaseConfig& b);

/// Parses a YAML node; `file` names the source in errors and anchors relative paths.
Result<BaseConfig> parse_base_config(const YAML::Node& node, const std::string& file, BaseConfig defaults = {});
Result<BaseConfig> load_base_config(const std::string& path, BaseConfig defaults = {});
/// The configuration as YAML that parse_base_config() reads back to an equal configuration.
[[nodiscard]] std::string to_yaml(const BaseConfig& config);

[[nodiscard]] std::string input_kind_name(BaseInputKind kind);
[[nodiscard]] std::string input_source_name(BaseInputSource source);

/// The base's keys (options_table.hpp), described once: they parse, print and compare it.
[[nodiscard]] const Table<BaseConfig>& base_table();
/// Every key with its unit, default (of BaseConfig{}) and doc.
[[nodiscard]] std::vector<KeyDescription> describe_base_config();

}  // namespace canyon::config
