#pragma once
// `canyon rover` configuration (config/rover.yaml documents every key): strict YAML parsing, printing, comparison
// and validation. No DDS here: the rover executable (src/apps/canyon_rover_main.cpp) reads it.

#include <string>

#include <yaml-cpp/yaml.h>

#include "canyon/app/epoch_pipeline.hpp"
#include "canyon/app/process_config.hpp"
#include "canyon/core/result.hpp"

namespace canyon::app {

enum class RoverBaseSource { File, Dds };

struct RoverConfig {
  /// The estimator and its inputs: the keys of `canyon process` (mode rtk or fusion, rover, base, nav, vio,
  /// timesync, base_position, rtk, fusion, output; `out`: a .pos the rover writes itself, optional).
  ProcessConfig estimator;
  std::string rover_id = "rover";  ///< names the rover in its messages
  double pace = 1.0;               ///< rover file replay speed: 1 real time, 10 ten times faster, 0 as fast as possible
  RoverBaseSource base = RoverBaseSource::File;  ///< file: estimator.base; dds: RtcmFrame samples
  double base_wait_s = 2.0;              ///< how long a rover epoch waits for its base epoch (dds), from when it is due
  std::size_t base_queue_frames = 4096;  ///< RTCM frames between the DDS listener and ingest; beyond: dropped, counted
  PipelineOptions pipeline{true, 64};    ///< threaded, queue_capacity
  int domain = 0;                        ///< DDS domain id
  std::string profiles;                  ///< Fast DDS XML profiles ("": config/dds/canyon_profiles.xml)
  std::string rtcm_topic = "canyon/rtcm";
  std::string solution_topic = "canyon/solution";
  std::string timing_topic = "canyon/timing";
  bool publish_stages = true;  ///< also canyon/bridged, canyon/alignment, canyon/prior, canyon/float

  /// Empty if usable, else the first broken rule.
  [[nodiscard]] std::string validate() const;
};

[[nodiscard]] bool operator==(const RoverConfig& a, const RoverConfig& b);
Result<RoverConfig> parse_rover_config(const YAML::Node& node, const std::string& file);
Result<RoverConfig> load_rover_config(const std::string& path);
[[nodiscard]] std::string to_yaml(const RoverConfig& config);

}  // namespace canyon::app
