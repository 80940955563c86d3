// `canyon rover` configuration (see rover_config.hpp).

#include "canyon/app/rover_config.hpp"

#include "canyon/app/yaml_reader.hpp"

namespace canyon::app {

std::string RoverConfig::validate() const {
  if (estimator.mode == ProcessMode::Spp) return "estimator.mode must be rtk or fusion";
  ProcessConfig e = estimator;
  if (e.out.empty()) e.out = "-";                                            // the rover's own .pos is optional
  if (base == RoverBaseSource::Dds && e.base_obs.empty()) e.base_obs = "-";  // the base comes over DDS
  if (const std::string s = e.validate(); !s.empty()) return "estimator: " + s;
  if (estimator.exclude_most_observed != 0) return "estimator.exclude_most_observed needs the whole file: batch only";
  if (rover_id.empty() || rover_id.size() > 64) return "rover_id must have 1 to 64 characters";
  if (!(pace >= 0.0)) return "input.pace must be >= 0";
  if (!(base_wait_s > 0.0 && base_wait_s <= 60.0)) return "input.base_wait_s must be in (0, 60]";
  if (base_queue_frames < 16 || base_queue_frames > 1000000) return "input.base_queue_frames must be in 16..1000000";
  if (const std::string s = pipeline.validate(); !s.empty()) return "pipeline." + s;
  if (domain < 0 || domain > 232) return "dds.domain must be in 0..232";
  if (rtcm_topic.empty() || solution_topic.empty() || timing_topic.empty()) return "dds topics must not be empty";
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
  std::string base = c.base == RoverBaseSource::Dds ? "dds" : "file";
  input.get("base", base);
  if (base == "file") {
    c.base = RoverBaseSource::File;
  } else if (base == "dds") {
    c.base = RoverBaseSource::Dds;
  } else {
    input.fail("base", "must be file or dds, not '" + base + "'");
  }
  input.get("base_wait_s", c.base_wait_s);
  int frames = static_cast<int>(c.base_queue_frames);
  input.get("base_queue_frames", frames);
  c.base_queue_frames = frames < 0 ? 0 : static_cast<std::size_t>(frames);
  input.reject_unknown_keys();
  YamlMap pipeline = top.sub("pipeline");
  pipeline.get("threaded", c.pipeline.threaded);
  int capacity = static_cast<int>(c.pipeline.queue_capacity);
  pipeline.get("queue_capacity", capacity);
  c.pipeline.queue_capacity = capacity < 0 ? 0 : static_cast<std::size_t>(capacity);
  pipeline.reject_unknown_keys();
  YamlMap dds = top.sub("dds");
  dds.get("domain", c.domain);
  dds.get("profiles", c.profiles);
  dds.get("rtcm_topic", c.rtcm_topic);
  dds.get("solution_topic", c.solution_topic);
  dds.get("timing_topic", c.timing_topic);
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
  out << YAML::Key << "base" << YAML::Value << (c.base == RoverBaseSource::Dds ? "dds" : "file");
  out << YAML::Key << "base_wait_s" << YAML::Value << c.base_wait_s;
  out << YAML::Key << "base_queue_frames" << YAML::Value << c.base_queue_frames;
  out << YAML::EndMap;
  out << YAML::Key << "pipeline" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "threaded" << YAML::Value << c.pipeline.threaded;
  out << YAML::Key << "queue_capacity" << YAML::Value << c.pipeline.queue_capacity;
  out << YAML::EndMap;
  out << YAML::Key << "dds" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "domain" << YAML::Value << c.domain;
  out << YAML::Key << "profiles" << YAML::Value << c.profiles;
  out << YAML::Key << "rtcm_topic" << YAML::Value << c.rtcm_topic;
  out << YAML::Key << "solution_topic" << YAML::Value << c.solution_topic;
  out << YAML::Key << "timing_topic" << YAML::Value << c.timing_topic;
  out << YAML::Key << "publish_stages" << YAML::Value << c.publish_stages;
  out << YAML::EndMap;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace canyon::app
