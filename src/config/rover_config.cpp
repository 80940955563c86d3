// `canyon rover` configuration (see rover_config.hpp).

#include "canyon/config/rover_config.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <optional>

#include "canyon/config/yaml_reader.hpp"
#include "canyon/pipeline/cpu_affinity.hpp"

namespace canyon::config {
namespace {

/// pipeline.cpu_affinity: {STAGE: [CPU, ...]} for any of the six stages, into `pipeline`.
void read_cpu_affinity(YamlMap map, pipeline::PipelineOptions& pipeline) {
  for (std::size_t s = 0; s < pipeline::kNumStages; ++s) {
    const char* name = pipeline::stage_name(static_cast<pipeline::Stage>(s));
    std::vector<double> numbers;
    map.get(name, numbers);
    std::vector<int>& cpus = pipeline.cpu_affinity[s];
    cpus.clear();
    for (const double n : numbers) {
      if (n != std::floor(n) || n < 0.0 || n > pipeline::max_cpu_number()) {
        map.fail(name, "CPU numbers are integers in 0.." + std::to_string(pipeline::max_cpu_number()));
        break;
      }
      cpus.push_back(static_cast<int>(n));
    }
    std::sort(cpus.begin(), cpus.end());
    cpus.erase(std::unique(cpus.begin(), cpus.end()), cpus.end());
  }
  map.reject_unknown_keys();
}

constexpr std::array<std::pair<RoverBaseSource, const char*>, 4> kBaseSources{{
    {RoverBaseSource::File, "file"},
    {RoverBaseSource::Dds, "dds"},
    {RoverBaseSource::Ntrip, "ntrip"},
    {RoverBaseSource::Tcp, "tcp"},
}};

/// The link address rule for `key` (empty: fine).
std::string check_link(const std::string& key, const std::string& text,
                       std::optional<pipeline::LinkAddress::Kind> kind) {
  if (text.empty()) return key + " is required";
  auto address = pipeline::LinkAddress::parse(text);
  if (!address) return key + ": " + address.error().message;
  if (kind && address->kind != *kind)
    return key + " must be " + (*kind == pipeline::LinkAddress::Kind::Ntrip ? "ntrip://" : "tcp://") + "...";
  return {};
}

/// A file: link address relative to the configuration file's folder.
std::string resolve_link(const std::string& text, const std::string& file) {
  if (text.rfind("file:", 0) != 0 || file.empty()) return text;
  auto address = pipeline::LinkAddress::parse(text, std::filesystem::path(file).parent_path().string());
  return address ? "file:" + address->path : text;
}

}  // namespace

const char* rover_base_source_name(RoverBaseSource source) {
  for (const auto& [s, name] : kBaseSources) {
    if (s == source) return name;
  }
  return "?";
}

std::string RoverConfig::validate() const {
  if (estimator.mode == ProcessMode::Spp) return "estimator.mode must be rtk or fusion";
  ProcessConfig e = estimator;
  if (e.out.empty()) e.out = "-";                               // the rover's own .pos is optional
  if (streamed_base() && e.base_obs.empty()) e.base_obs = "-";  // the base streams in
  if (rover == RoverInputKind::Ubx && e.rover_obs.empty()) e.rover_obs = "-";
  const bool streams_nav = stream_ephemerides && (rover == RoverInputKind::Ubx || streamed_base());
  if (streams_nav && e.nav.empty()) e.nav = {"-"};  // ephemerides from the streams only
  if (vio_dds) {
    if (estimator.mode != ProcessMode::Fusion) return "input.vio dds needs estimator.mode fusion";
    if (e.vio.empty()) e.vio = "-";  // the VIO streams in
    if (e.timesync.empty()) e.timesync = "-";
  }
  if (const std::string s = e.validate(); !s.empty()) return "estimator: " + s;
  if (estimator.exclude_most_observed != 0) return "estimator.exclude_most_observed needs the whole file: batch only";
  if (rover_id.empty() || rover_id.size() > 64) return "rover_id must have 1 to 64 characters";
  if (!(pace >= 0.0)) return "input.pace must be >= 0";
  if (rover == RoverInputKind::Ubx) {
    if (std::string r = check_link("input.rover_source", rover_source, std::nullopt); !r.empty()) return r;
  }
  if (base == RoverBaseSource::Ntrip || base == RoverBaseSource::Tcp) {
    const auto kind =
        base == RoverBaseSource::Ntrip ? pipeline::LinkAddress::Kind::Ntrip : pipeline::LinkAddress::Kind::Tcp;
    if (std::string r = check_link("input.base_source", base_source, kind); !r.empty()) return r;
  }
  if (const std::string l = link.validate(); !l.empty()) return "input.link_" + l;
  if (!(base_wait_s > 0.0 && base_wait_s <= 60.0)) return "input.base_wait_s must be in (0, 60]";
  if (!(ntrip_gga_interval_s >= 0.0 && ntrip_gga_interval_s <= 3600.0)) {
    return "input.ntrip_gga_interval_s must be in [0, 3600]";
  }
  if (ntrip_gga_interval_s > 0.0 && base != RoverBaseSource::Ntrip)
    return "input.ntrip_gga_interval_s needs base ntrip";
  if (base_queue_frames < 16 || base_queue_frames > 1000000) return "input.base_queue_frames must be in 16..1000000";
  if (!(vio_wait_s >= 0.0 && vio_wait_s <= 10.0)) return "input.vio_wait_s must be in [0, 10]";
  if (vio_queue_poses < 16 || vio_queue_poses > 1000000) return "input.vio_queue_poses must be in 16..1000000";
  if (const std::string s = pipeline.validate(); !s.empty()) return "pipeline." + s;
  if (domain < 0 || domain > 232) return "dds.domain must be in 0..232";
  if (rtcm_topic.empty() || solution_topic.empty() || timing_topic.empty() || vio_topic.empty() ||
      timesync_topic.empty()) {
    return "dds topics must not be empty";
  }
  return {};
}

bool operator==(const RoverConfig& a, const RoverConfig& b) {
  return to_yaml(a) == to_yaml(b);
}

Result<RoverConfig> parse_rover_config(const YAML::Node& node, const std::string& file) {
  RoverConfig c;
  YamlMap top(node, file);
  if (!top.has("estimator")) {
    return Error{"'estimator:' (the canyon process keys: mode, rover, base, nav, ...) is required", file, 0};
  }
  (void)top.sub("estimator");
  auto estimator = parse_process_config(node["estimator"], file);
  if (!estimator) return estimator.error();
  c.estimator = std::move(*estimator);
  top.get("rover_id", c.rover_id);
  YamlMap input = top.sub("input");
  input.get("pace", c.pace);
  std::string rover = c.rover == RoverInputKind::Ubx ? "ubx" : "rinex";
  input.get("rover", rover);
  if (rover == "rinex" || rover == "ubx") {
    c.rover = rover == "ubx" ? RoverInputKind::Ubx : RoverInputKind::Rinex;
  } else {
    input.fail("rover", "must be rinex or ubx, not '" + rover + "'");
  }
  input.get("rover_source", c.rover_source);
  c.rover_source = resolve_link(c.rover_source, file);
  if (auto a = pipeline::LinkAddress::parse(c.rover_source); !c.rover_source.empty() && !a)
    input.fail("rover_source", a.error().message);
  std::string base = rover_base_source_name(c.base);
  input.get("base", base);
  const auto* known =
      std::find_if(kBaseSources.begin(), kBaseSources.end(), [&](const auto& s) { return base == s.second; });
  if (known != kBaseSources.end()) {
    c.base = known->first;
  } else {
    input.fail("base", "must be file, dds, ntrip or tcp, not '" + base + "'");
  }
  input.get("base_source", c.base_source);
  if (auto a = pipeline::LinkAddress::parse(c.base_source); !c.base_source.empty() && !a)
    input.fail("base_source", a.error().message);
  input.get("stream_ephemerides", c.stream_ephemerides);
  input.get("link_attempts", c.link.attempts);
  input.get("link_stall_timeout_s", c.link.stall_timeout_s);
  input.get("base_wait_s", c.base_wait_s);
  input.get("ntrip_gga_interval_s", c.ntrip_gga_interval_s);
  int frames = static_cast<int>(c.base_queue_frames);
  input.get("base_queue_frames", frames);
  c.base_queue_frames = frames < 0 ? 0 : static_cast<std::size_t>(frames);
  std::string vio = c.vio_dds ? "dds" : "file";
  input.get("vio", vio);
  if (vio != "file" && vio != "dds") input.fail("vio", "must be file or dds, not '" + vio + "'");
  c.vio_dds = vio == "dds";
  input.get("vio_wait_s", c.vio_wait_s);
  int poses = static_cast<int>(c.vio_queue_poses);
  input.get("vio_queue_poses", poses);
  c.vio_queue_poses = poses < 0 ? 0 : static_cast<std::size_t>(poses);
  input.reject_unknown_keys();
  YamlMap pipeline = top.sub("pipeline");
  pipeline.get("threaded", c.pipeline.threaded);
  int capacity = static_cast<int>(c.pipeline.queue_capacity);
  pipeline.get("queue_capacity", capacity);
  c.pipeline.queue_capacity = capacity < 0 ? 0 : static_cast<std::size_t>(capacity);
  read_cpu_affinity(pipeline.sub("cpu_affinity"), c.pipeline);
  pipeline.reject_unknown_keys();
  YamlMap dds = top.sub("dds");
  dds.get("domain", c.domain);
  dds.get("profiles", c.profiles);
  dds.get("rtcm_topic", c.rtcm_topic);
  dds.get("solution_topic", c.solution_topic);
  dds.get("timing_topic", c.timing_topic);
  dds.get("vio_topic", c.vio_topic);
  dds.get("timesync_topic", c.timesync_topic);
  dds.get("publish_stages", c.publish_stages);
  dds.reject_unknown_keys();
  top.reject_unknown_keys();
  if (Status s = top.status(); !s) return s.error();
  return c;
}

Result<RoverConfig> load_rover_config(const std::string& path) {
  auto node = load_yaml_file(path);
  if (!node) return node.error();
  return parse_rover_config(*node, path);
}

std::string to_yaml(const RoverConfig& c) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "estimator" << YAML::Value << YAML::Load(to_yaml(c.estimator));
  out << YAML::Key << "rover_id" << YAML::Value << c.rover_id;
  out << YAML::Key << "input" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "pace" << YAML::Value << c.pace;
  out << YAML::Key << "rover" << YAML::Value << (c.rover == RoverInputKind::Ubx ? "ubx" : "rinex");
  out << YAML::Key << "rover_source" << YAML::Value << c.rover_source;
  out << YAML::Key << "base" << YAML::Value << rover_base_source_name(c.base);
  out << YAML::Key << "base_source" << YAML::Value << c.base_source;
  out << YAML::Key << "stream_ephemerides" << YAML::Value << c.stream_ephemerides;
  out << YAML::Key << "link_attempts" << YAML::Value << c.link.attempts;
  out << YAML::Key << "link_stall_timeout_s" << YAML::Value << c.link.stall_timeout_s;
  out << YAML::Key << "base_wait_s" << YAML::Value << c.base_wait_s;
  out << YAML::Key << "ntrip_gga_interval_s" << YAML::Value << c.ntrip_gga_interval_s;
  out << YAML::Key << "base_queue_frames" << YAML::Value << c.base_queue_frames;
  out << YAML::Key << "vio" << YAML::Value << (c.vio_dds ? "dds" : "file");
  out << YAML::Key << "vio_wait_s" << YAML::Value << c.vio_wait_s;
  out << YAML::Key << "vio_queue_poses" << YAML::Value << c.vio_queue_poses;
  out << YAML::EndMap;
  out << YAML::Key << "pipeline" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "threaded" << YAML::Value << c.pipeline.threaded;
  out << YAML::Key << "queue_capacity" << YAML::Value << c.pipeline.queue_capacity;
  out << YAML::Key << "cpu_affinity" << YAML::Value << YAML::BeginMap;
  for (std::size_t s = 0; s < pipeline::kNumStages; ++s) {
    const std::vector<int>& cpus = c.pipeline.cpu_affinity[s];
    if (cpus.empty()) continue;
    out << YAML::Key << pipeline::stage_name(static_cast<pipeline::Stage>(s)) << YAML::Value << YAML::Flow << cpus;
  }
  out << YAML::EndMap;
  out << YAML::EndMap;
  out << YAML::Key << "dds" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "domain" << YAML::Value << c.domain;
  out << YAML::Key << "profiles" << YAML::Value << c.profiles;
  out << YAML::Key << "rtcm_topic" << YAML::Value << c.rtcm_topic;
  out << YAML::Key << "solution_topic" << YAML::Value << c.solution_topic;
  out << YAML::Key << "timing_topic" << YAML::Value << c.timing_topic;
  out << YAML::Key << "vio_topic" << YAML::Value << c.vio_topic;
  out << YAML::Key << "timesync_topic" << YAML::Value << c.timesync_topic;
  out << YAML::Key << "publish_stages" << YAML::Value << c.publish_stages;
  out << YAML::EndMap;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace canyon::config
