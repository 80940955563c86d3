// `canyon base` configuration: strict YAML parsing, printing and validation.

#include "canyon/config/base_config.hpp"

#include <cstdio>
#include <filesystem>

#include "canyon/config/yaml_reader.hpp"
#include "canyon/core/time.hpp"

namespace canyon::config {
namespace {

std::string resolve(const std::string& path, const std::string& file) {
  if (path.empty() || file.empty() || std::filesystem::path(path).is_absolute()) return path;
  return (std::filesystem::path(file).parent_path() / path).lexically_normal().string();
}

std::string format_gps(const core::GpsTime& t) {
  const core::CalendarTime c = core::gps_to_calendar(t);
  char text[32];
  std::snprintf(text, sizeof text, "%04d-%02d-%02d %02d:%02d:%02d", c.year, c.month, c.day, c.hour, c.minute,
                static_cast<int>(c.second));
  return text;
}

}  // namespace

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
  if (!dds.enabled && !ntrip.enabled && !tcp.enabled) return "at least one output (dds, ntrip, tcp) must be enabled";
  if (!(progress_interval_s >= 0.0)) return "log.progress_interval_s must be >= 0";
  return {};
}

bool operator==(const BaseConfig& a, const BaseConfig& b) {
  return to_yaml(a) == to_yaml(b);
}

Result<BaseConfig> parse_base_config(const YAML::Node& node, const std::string& file, BaseConfig defaults) {
  BaseConfig c = std::move(defaults);
  YamlMap top(node, file);
  {
    YamlMap s = top.sub("station");
    s.get("id", c.station.id);
    if (s.has("position")) {
      std::vector<double> xyz;
      s.get("position", xyz);
      if (xyz.size() != 3) {
        s.fail("position", "must be [X, Y, Z], ECEF metres");
      } else {
        c.station.position_E_m = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
      }
    }
    if (s.has("antenna_height_m")) {
      double h = 0.0;
      s.get("antenna_height_m", h);
      c.station.antenna_height_m = h;
    }
    s.get("antenna", c.station.antenna);
    s.get("receiver", c.station.receiver);
    s.reject_unknown_keys();
  }
  {
    YamlMap in = top.sub("input");
    std::string kind = input_kind_name(c.input.kind);
    in.get("kind", kind);
    if (kind == "rinex") {
      c.input.kind = BaseInputKind::Rinex;
    } else if (kind == "ubx") {
      c.input.kind = BaseInputKind::Ubx;
    } else if (kind == "rtcm3") {
      c.input.kind = BaseInputKind::Rtcm3;
    } else {
      in.fail("kind", "must be rinex, ubx or rtcm3, not '" + kind + "'");
    }
    std::string source = input_source_name(c.input.source);
    in.get("source", source);
    if (source == "file") {
      c.input.source = BaseInputSource::File;
    } else if (source == "serial") {
      c.input.source = BaseInputSource::Serial;
    } else if (source == "tcp") {
      c.input.source = BaseInputSource::Tcp;
    } else if (source == "ntrip") {
      c.input.source = BaseInputSource::Ntrip;
    } else {
      in.fail("source", "must be file, serial, tcp or ntrip, not '" + source + "'");
    }
    in.get("path", c.input.path);
    if (c.input.source == BaseInputSource::File) c.input.path = resolve(c.input.path, file);
    in.get("nav", c.input.nav);
    for (std::string& n : c.input.nav) n = resolve(n, file);
    in.get("pace", c.input.pace);
    if (in.has("approx_time")) {
      std::string text;
      in.get("approx_time", text);
      c.input.approx_time = core::parse_gps_calendar(text);
      if (!c.input.approx_time) in.fail("approx_time", "must be 'YYYY-MM-DD HH:MM:SS' (GPST), not '" + text + "'");
    }
    in.get("baud", c.input.baud);
    in.get("host", c.input.host);
    in.get("port", c.input.port);
    in.get("mountpoint", c.input.mountpoint);
    in.get("user", c.input.user);
    in.get("password", c.input.password);
    in.reject_unknown_keys();
  }
  {
    YamlMap r = top.sub("rtcm");
    r.get("msm", c.rtcm.msm);
    r.get("station_interval_s", c.rtcm.station_interval_s);
    r.get("ephemeris_interval_s", c.rtcm.ephemeris_interval_s);
    r.reject_unknown_keys();
  }
  {
    YamlMap out = top.sub("outputs");
    YamlMap d = out.sub("dds");
    d.get("enabled", c.dds.enabled);
    d.get("domain", c.dds.domain);
    d.get("topic", c.dds.topic);
    d.get("profiles", c.dds.profiles);
    c.dds.profiles = resolve(c.dds.profiles, file);
    d.reject_unknown_keys();
    YamlMap n = out.sub("ntrip");
    n.get("enabled", c.ntrip.enabled);
    n.get("bind", c.ntrip.bind);
    n.get("port", c.ntrip.port);
    n.get("mountpoint", c.ntrip.mountpoint);
    n.get("user", c.ntrip.user);
    n.get("password", c.ntrip.password);
    n.reject_unknown_keys();
    YamlMap t = out.sub("tcp");
    t.get("enabled", c.tcp.enabled);
    t.get("bind", c.tcp.bind);
    t.get("port", c.tcp.port);
    t.reject_unknown_keys();
    out.reject_unknown_keys();
  }
  {
    YamlMap l = top.sub("log");
    l.get("progress_interval_s", c.progress_interval_s);
    l.reject_unknown_keys();
  }
  top.reject_unknown_keys();
  if (Status s = top.status(); !s.ok()) return s.error();
  return c;
}

Result<BaseConfig> load_base_config(const std::string& path, BaseConfig defaults) {
  auto node = load_yaml_file(path);
  if (!node) return node.error();
  return parse_base_config(*node, path, std::move(defaults));
}

std::string to_yaml(const BaseConfig& c) {
  YAML::Emitter out;
  out.SetDoublePrecision(12);
  out << YAML::BeginMap;
  out << YAML::Key << "station" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "id" << YAML::Value << c.station.id;
  if (c.station.position_E_m) {
    out << YAML::Key << "position" << YAML::Value << YAML::Flow << YAML::BeginSeq << c.station.position_E_m->x()
        << c.station.position_E_m->y() << c.station.position_E_m->z() << YAML::EndSeq;
  }
  if (c.station.antenna_height_m) out << YAML::Key << "antenna_height_m" << YAML::Value << *c.station.antenna_height_m;
  out << YAML::Key << "antenna" << YAML::Value << c.station.antenna;
  out << YAML::Key << "receiver" << YAML::Value << c.station.receiver;
  out << YAML::EndMap;
  out << YAML::Key << "input" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "kind" << YAML::Value << input_kind_name(c.input.kind);
  out << YAML::Key << "source" << YAML::Value << input_source_name(c.input.source);
  out << YAML::Key << "path" << YAML::Value << c.input.path;
  out << YAML::Key << "nav" << YAML::Value << YAML::Flow << c.input.nav;
  out << YAML::Key << "pace" << YAML::Value << c.input.pace;
  if (c.input.approx_time) out << YAML::Key << "approx_time" << YAML::Value << format_gps(*c.input.approx_time);
  out << YAML::Key << "baud" << YAML::Value << c.input.baud;
  out << YAML::Key << "host" << YAML::Value << c.input.host;
  out << YAML::Key << "port" << YAML::Value << c.input.port;
  out << YAML::Key << "mountpoint" << YAML::Value << c.input.mountpoint;
  out << YAML::Key << "user" << YAML::Value << c.input.user;
  out << YAML::Key << "password" << YAML::Value << c.input.password;
  out << YAML::EndMap;
  out << YAML::Key << "rtcm" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "msm" << YAML::Value << c.rtcm.msm;
  out << YAML::Key << "station_interval_s" << YAML::Value << c.rtcm.station_interval_s;
  out << YAML::Key << "ephemeris_interval_s" << YAML::Value << c.rtcm.ephemeris_interval_s;
  out << YAML::EndMap;
  out << YAML::Key << "outputs" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "dds" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "enabled" << YAML::Value << c.dds.enabled;
  out << YAML::Key << "domain" << YAML::Value << c.dds.domain;
  out << YAML::Key << "topic" << YAML::Value << c.dds.topic;
  out << YAML::Key << "profiles" << YAML::Value << c.dds.profiles;
  out << YAML::EndMap;
  out << YAML::Key << "ntrip" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "enabled" << YAML::Value << c.ntrip.enabled;
  out << YAML::Key << "bind" << YAML::Value << c.ntrip.bind;
  out << YAML::Key << "port" << YAML::Value << c.ntrip.port;
  out << YAML::Key << "mountpoint" << YAML::Value << c.ntrip.mountpoint;
  out << YAML::Key << "user" << YAML::Value << c.ntrip.user;
  out << YAML::Key << "password" << YAML::Value << c.ntrip.password;
  out << YAML::EndMap;
  out << YAML::Key << "tcp" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "enabled" << YAML::Value << c.tcp.enabled;
  out << YAML::Key << "bind" << YAML::Value << c.tcp.bind;
  out << YAML::Key << "port" << YAML::Value << c.tcp.port;
  out << YAML::EndMap;
  out << YAML::EndMap;
  out << YAML::Key << "log" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "progress_interval_s" << YAML::Value << c.progress_interval_s;
  out << YAML::EndMap;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace canyon::config
