// `canyon base` configuration: its keys described once (config/base.yaml shows each with its unit), parsed, printed
// and compared from that description; validation.

#include "canyon/config/base_config.hpp"

#include <cstdio>

#include "canyon/core/time.hpp"

namespace canyon::config {
namespace {

using B = BaseConfig;

std::string format_gps(const core::GpsTime& t) {
  const core::CalendarTime c = core::gps_to_calendar(t);
  char text[32];
  std::snprintf(text, sizeof text, "%04d-%02d-%02d %02d:%02d:%02d", c.year, c.month, c.day, c.hour, c.minute,
                static_cast<int>(c.second));
  return text;
}

/// input.approx_time: "YYYY-MM-DD HH:MM:SS" (GPST).
struct GpsCalendar {
  using Yaml = std::string;
  [[nodiscard]] std::string to(const core::GpsTime& t) const { return format_gps(t); }
  void from(const std::string& text, core::GpsTime& t, Reading& reading) const {
    const auto parsed = core::parse_gps_calendar(text);
    if (!parsed) {
      reading.fail("must be 'YYYY-MM-DD HH:MM:SS' (GPST), not '" + text + "'");
      return;
    }
    t = *parsed;
  }
};

/// input.path: a file relative to the configuration file's folder (source file), else a serial device as it is.
struct InputPath {
  using Yaml = std::string;
  [[nodiscard]] std::string to(const B::Input& in) const { return in.path; }
  void from(const std::string& value, B::Input& in, Reading& reading) const {
    in.path = in.source == BaseInputSource::File ? resolve_path(value, reading.file()) : value;
  }
};

const Table<B::Station>& station_table() {
  using S = B::Station;
  static const Table<S> table{
      {"id", "", "RTCM reference station id (DF003), 0-4095", at(&S::id)},
      {"position", "m", "ARP position, ECEF [X, Y, Z] (1005); default: the input's header, 1005 or first fix",
       at(&S::position_E_m), Optional<Vector3>{{"must be [X, Y, Z], ECEF metres"}}},
      {"antenna_height_m", "m", "height of the ARP above the marker (0-6.5535): sends 1006 instead of 1005",
       at(&S::antenna_height_m), Optional<Same<double>>{}},
      {"antenna", "", "IGS antenna type for 1033, at most 31 characters (\"\" and receiver \"\": no 1033)",
       at(&S::antenna)},
      {"receiver", "", "receiver type for 1033", at(&S::receiver)},
  };
  return table;
}

const Table<B::Input>& input_table() {
  using I = B::Input;
  static const Table<I> table{
      {"kind", "", "rinex | ubx | rtcm3: what the base receiver delivers", at(&I::kind),
       names_of({BaseInputKind::Rinex, BaseInputKind::Ubx, BaseInputKind::Rtcm3}, input_kind_name)},
      {"source", "", "file | serial | tcp | ntrip (rinex: file only)", at(&I::source),
       names_of({BaseInputSource::File, BaseInputSource::Serial, BaseInputSource::Tcp, BaseInputSource::Ntrip},
                input_source_name)},
      {"path", "", "file (may be .gz) or serial device (/dev/ttyACM0)", whole, InputPath{}},
      {"nav", "", "rinex: navigation files whose ephemerides are sent", at(&I::nav), Paths{}},
      {"pace", "", "file replay speed: 1 real time, 10 ten times faster, 0 as fast as possible", at(&I::pace)},
      {"approx_time", "", "rtcm3 input: GPST within a few days of the data (default: the clock)", at(&I::approx_time),
       Optional<GpsCalendar>{}},
      {"baud", "", "serial: 9600 ... 921600", at(&I::baud)},
      {"host", "", "tcp / ntrip source: host name or address", at(&I::host)},
      {"port", "", "tcp / ntrip source: port", at(&I::port)},
      {"mountpoint", "", "ntrip source: mount point", at(&I::mountpoint)},
      {"user", "", "ntrip source: Basic authentication (\"\": none)", at(&I::user)},
      {"password", "", "ntrip source: its password", at(&I::password)},
  };
  return table;
}

const Table<B::Rtcm>& rtcm_table() {
  using R = B::Rtcm;
  static const Table<R> table{
      {"msm", "", "7 (MSM7: full resolution, Doppler) or 4 (MSM4: compact); 5 and 6 accepted", at(&R::msm)},
      {"station_interval_s", "s", "1005/1006 (and 1033) every this many seconds of data; 0: once at the start",
       at(&R::station_interval_s)},
      {"ephemeris_interval_s", "s", "each current ephemeris again every this many seconds; 0: only when new",
       at(&R::ephemeris_interval_s)},
  };
  return table;
}

const Table<B::Dds>& dds_table() {
  using D = B::Dds;
  static const Table<D> table{
      {"enabled", "", "publish every frame as canyon::msg::RtcmFrame", at(&D::enabled)},
      {"domain", "", "DDS domain id, 0-232", at(&D::domain)},
      {"topic", "", "topic name", at(&D::topic)},
      {"profiles", "", "Fast DDS XML profiles (\"\": the shipped config/dds/canyon_profiles.xml)", at(&D::profiles),
       Path{}},
  };
  return table;
}

const Table<B::Ntrip>& ntrip_table() {
  using N = B::Ntrip;
  static const Table<N> table{
      {"enabled", "", "NTRIP caster (versions 1 and 2) with the source table", at(&N::enabled)},
      {"bind", "", "address to listen on", at(&N::bind)},
      {"port", "", "TCP port (0: any free port, logged)", at(&N::port)},
      {"mountpoint", "", "mount point name (no ' ', '/', ';')", at(&N::mountpoint)},
      {"user", "", "Basic authentication of clients (\"\" and password \"\": none)", at(&N::user)},
      {"password", "", "its password", at(&N::password)},
  };
  return table;
}

const Table<B::Tcp>& tcp_table() {
  using T = B::Tcp;
  static const Table<T> table{
      {"enabled", "", "plain TCP server: every client gets the raw RTCM 3 stream", at(&T::enabled)},
      {"bind", "", "address to listen on", at(&T::bind)},
      {"port", "", "TCP port (0: any free port, logged)", at(&T::port)},
  };
  return table;
}

const Table<B::Ros2>& ros2_table() {
  using R = B::Ros2;
  static const Table<R> table{
      {"enabled", "", "publish every frame as rtcm_msgs/msg/Message on ROS 2's names (domain, profiles: dds's)",
       at(&R::enabled)},
      {"topic", "", "ROS 2 topic (DDS topic rt/ + this)", at(&R::topic)},
      {"frame_id", "", "header.frame_id", at(&R::frame_id)},
  };
  return table;
}

const Table<B>& outputs_table() {
  static const Table<B> table{
      {"dds", "the DDS topic", at(&B::dds), dds_table()},
      {"ntrip", "the NTRIP caster", at(&B::ntrip), ntrip_table()},
      {"tcp", "the plain TCP server", at(&B::tcp), tcp_table()},
      {"ros2", "the ROS 2 topic (off by default)", at(&B::ros2), ros2_table()},
  };
  return table;
}

const Table<B>& log_table() {
  static const Table<B> table{
      {"progress_interval_s", "s", "a progress line every this many seconds; 0: none", at(&B::progress_interval_s)},
  };
  return table;
}

}  // namespace

const Table<BaseConfig>& base_table() {
  static const Table<B> table{
      {"station", "the reference station: id, position, antenna and receiver", at(&B::station), station_table()},
      {"input", "the base receiver's data: kind, source and where", at(&B::input), input_table()},
      {"rtcm", "the RTCM 3 messages sent", at(&B::rtcm), rtcm_table()},
      {"outputs", "where the RTCM 3 stream goes", whole, outputs_table()},
      {"log", "progress lines", whole, log_table()},
  };
  return table;
}

std::vector<KeyDescription> describe_base_config() {
  return describe_keys(base_table(), BaseConfig{}, Numbers::Digits12);
}

std::string input_kind_name(BaseInputKind kind) {
  switch (kind) {
    case BaseInputKind::Rinex: return "rinex";
    case BaseInputKind::Ubx: return "ubx";
    case BaseInputKind::Rtcm3: return "rtcm3";
  }
  return "rinex";
}

std::string input_source_name(BaseInputSource source) {
  switch (source) {
    case BaseInputSource::File: return "file";
    case BaseInputSource::Serial: return "serial";
    case BaseInputSource::Tcp: return "tcp";
    case BaseInputSource::Ntrip: return "ntrip";
  }
  return "file";
}

std::string BaseConfig::validate() const {
  if (station.id < 0 || station.id > 4095) return "station.id must be within 0-4095";
  if (station.antenna_height_m && !(*station.antenna_height_m >= 0.0 && *station.antenna_height_m < 6.5535)) {
    return "station.antenna_height_m must be within 0-6.5535 m";
  }
  if (station.antenna.size() > 31 || station.receiver.size() > 31) {
    return "station.antenna and station.receiver have at most 31 characters (RTCM 1033)";
  }
  if (input.kind == BaseInputKind::Rinex && input.source != BaseInputSource::File) {
    return "input.kind rinex needs input.source file";
  }
  if ((input.source == BaseInputSource::File || input.source == BaseInputSource::Serial) && input.path.empty()) {
    return "input.path is required for input.source " + input_source_name(input.source);
  }
  if ((input.source == BaseInputSource::Tcp || input.source == BaseInputSource::Ntrip) &&
      (input.host.empty() || input.port < 1 || input.port > 65535)) {
    return "input.host and input.port (1-65535) are required for input.source " + input_source_name(input.source);
  }
  if (input.source == BaseInputSource::Ntrip && input.mountpoint.empty()) return "input.mountpoint is required";
  if (!(input.pace >= 0.0)) return "input.pace must be >= 0 (0: as fast as possible)";
  if (rtcm.msm < 4 || rtcm.msm > 7) return "rtcm.msm must be 7 or 4 (or 5, 6)";
  if (!(rtcm.station_interval_s >= 0.0)) return "rtcm.station_interval_s must be >= 0";
  if (!(rtcm.ephemeris_interval_s >= 0.0)) return "rtcm.ephemeris_interval_s must be >= 0";
  if (dds.enabled && dds.topic.empty()) return "outputs.dds.topic must not be empty";
  if (dds.domain < 0 || dds.domain > 232) return "outputs.dds.domain must be within 0-232";
  if (ntrip.enabled && (ntrip.port < 0 || ntrip.port > 65535)) return "outputs.ntrip.port must be within 0-65535";
  if (ntrip.enabled && (ntrip.mountpoint.empty() || ntrip.mountpoint.find_first_of(" /;") != std::string::npos)) {
    return "outputs.ntrip.mountpoint must be a name without ' ', '/', ';'";
  }
  if (ntrip.enabled && ntrip.user.empty() != ntrip.password.empty()) {
    return "outputs.ntrip.user and outputs.ntrip.password go together";
  }
  if (tcp.enabled && (tcp.port < 0 || tcp.port > 65535)) return "outputs.tcp.port must be within 0-65535";
  if (ros2.enabled && ros2.topic.empty()) return "outputs.ros2.topic must not be empty";
  if (!dds.enabled && !ntrip.enabled && !tcp.enabled && !ros2.enabled) {
    return "at least one output (dds, ntrip, tcp, ros2) must be enabled";
  }
  if (!(progress_interval_s >= 0.0)) return "log.progress_interval_s must be >= 0";
  return {};
}

bool operator==(const BaseConfig& a, const BaseConfig& b) {
  return equal_keys(base_table(), a, b);
}

Result<BaseConfig> parse_base_config(const YAML::Node& node, const std::string& file, BaseConfig defaults) {
  BaseConfig c = std::move(defaults);
  YamlMap top(node, file);
  read_keys(base_table(), top, c);
  if (Status s = top.status(); !s.ok()) return s.error();
  return c;
}

Result<BaseConfig> load_base_config(const std::string& path, BaseConfig defaults) {
  auto node = load_yaml_file(path);
  if (!node) return node.error();
  return parse_base_config(*node, path, std::move(defaults));
}

std::string to_yaml(const BaseConfig& c) {
  return yaml_text(base_table(), c, Numbers::Digits12);
}

}  // namespace canyon::config
