// `canyon rover` configuration (see rover_config.hpp): its keys described once, parsed, printed and compared from
// that description; validation.

#include "canyon/config/rover_config.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <optional>

#include "canyon/pipeline/cpu_affinity.hpp"

namespace canyon::config {
namespace {

using R = RoverConfig;

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

/// A link address (rover_source, base_source), checked as it is read; `relative_file`: a file: address is relative
/// to the configuration file's folder.
struct LinkText {
  using Yaml = std::string;
  bool relative_file = false;
  [[nodiscard]] std::string to(const std::string& text) const { return text; }
  void from(const std::string& value, std::string& text, Reading& reading) const {
    text = relative_file ? resolve_link(value, reading.file()) : value;
    if (auto a = pipeline::LinkAddress::parse(text); !text.empty() && !a) reading.fail(a.error().message);
  }
};

/// pipeline.cpu_affinity.STAGE: the CPUs of a stage thread, [CPU, ...]; printed only when there are some.
struct CpuList {
  using Yaml = std::vector<double>;
  [[nodiscard]] Yaml to(const std::vector<int>& cpus) const { return {cpus.begin(), cpus.end()}; }
  [[nodiscard]] bool omitted(const std::vector<int>& cpus) const { return cpus.empty(); }
  void from(const Yaml& numbers, std::vector<int>& cpus, Reading& reading) const {
    cpus.clear();
    for (const double n : numbers) {
      if (n != std::floor(n) || n < 0.0 || n > pipeline::max_cpu_number()) {
        reading.fail("CPU numbers are integers in 0.." + std::to_string(pipeline::max_cpu_number()));
        break;
      }
      cpus.push_back(static_cast<int>(n));
    }
    std::sort(cpus.begin(), cpus.end());
    cpus.erase(std::unique(cpus.begin(), cpus.end()), cpus.end());
  }
};

const Table<pipeline::PipelineOptions>& cpu_affinity_table() {
  static const Table<pipeline::PipelineOptions> table = [] {
    Table<pipeline::PipelineOptions> t;
    for (std::size_t s = 0; s < pipeline::kNumStages; ++s) {
      const std::string stage = pipeline::stage_name(static_cast<pipeline::Stage>(s));
      t.emplace_back(
          stage, "", "threaded: the CPUs the " + stage + " stage's thread may run on (absent: any)",
          [s](auto& p) -> auto& { return p.cpu_affinity[s]; }, CpuList{});
    }
    return t;
  }();
  return table;
}

const Table<pipeline::PipelineOptions>& pipeline_table() {
  using P = pipeline::PipelineOptions;
  static const Table<P> table{
      {"threaded", "", "true: six threads and queues; false: one thread (as canyon process --pipeline sequential)",
       at(&P::threaded)},
      {"queue_capacity", "", "epochs per queue; a full queue blocks its producer", at(&P::queue_capacity), Count{}},
      {"cpu_affinity", "threaded: the CPUs each stage thread may run on", whole, cpu_affinity_table()},
  };
  return table;
}

Names<RoverBaseSource> base_source_names() {
  Names<RoverBaseSource> names;
  for (const auto& [source, name] : kBaseSources) names.names.emplace_back(source, name);
  return names;
}

const Table<R>& input_table() {
  using L = pipeline::LinkOptions;
  static const Table<R> table{
      {"pace", "", "rover file replay speed: 1 real time, 10 ten times faster, 0 as fast as possible", at(&R::pace)},
      {"rover", "", "rinex: estimator.rover | ubx: a u-blox receiver's UBX from rover_source", at(&R::rover),
       Names<RoverInputKind>{{{RoverInputKind::Rinex, "rinex"}, {RoverInputKind::Ubx, "ubx"}}}},
      {"rover_source", "", "ubx: file:PATH, serial:///dev/X?baud=N, tcp://HOST:PORT or ntrip://...",
       at(&R::rover_source), LinkText{true}},
      {"base", "", "file: estimator.base | dds: RtcmFrame samples | ntrip, tcp: RTCM 3 from base_source", at(&R::base),
       base_source_names()},
      {"base_source", "", "ntrip: ntrip://[USER[:PASSWORD]@]HOST:PORT/MOUNT; tcp: tcp://HOST:PORT", at(&R::base_source),
       LinkText{false}},
      {"stream_ephemerides", "", "add the ephemerides of the UBX and RTCM 3 streams to estimator.nav's",
       at(&R::stream_ephemerides)},
      {"link_attempts", "", "tcp, ntrip: give up after this many failed connection attempts in a row (0: never)",
       at(&R::link, &L::attempts)},
      {"link_stall_timeout_s", "s", "tcp, ntrip: no byte for this long counts as a dead connection",
       at(&R::link, &L::stall_timeout_s)},
      {"base_wait_s", "s", "dds, ntrip, tcp: how long a rover epoch waits for the base to reach its time",
       at(&R::base_wait_s)},
      {"ntrip_gga_interval_s", "s", "ntrip: upload the rover's latest position as NMEA GGA this often; 0: never",
       at(&R::ntrip_gga_interval_s)},
      {"base_queue_frames", "", "dds: RTCM frames queued between the DDS listener and ingest; beyond: dropped",
       at(&R::base_queue_frames), Count{}},
      {"vio", "",
       "fusion: file: estimator.vio and timesync | dds: VioPose and TimeSyncSample samples | ros2: "
       "nav_msgs/msg/Odometry on ros2.vio_topic",
       at(&R::vio),
       Names<RoverVioSource>{
           {{RoverVioSource::File, "file"}, {RoverVioSource::Dds, "dds"}, {RoverVioSource::Ros2, "ros2"}}}},
      {"vio_wait_s", "s", "dds VIO: longest an epoch waits for the VIO to cover its time", at(&R::vio_wait_s)},
      {"vio_queue_poses", "", "dds VIO: poses queued between the DDS listener and the time bridge; beyond: dropped",
       at(&R::vio_queue_poses), Count{}},
  };
  return table;
}

const Table<R>& dds_table() {
  static const Table<R> table{
      {"domain", "", "DDS domain id, 0-232", at(&R::domain)},
      {"profiles", "", "Fast DDS XML profiles (\"\": the shipped config/dds/canyon_profiles.xml)", at(&R::profiles)},
      {"rtcm_topic", "", "base corrections in (input.base dds)", at(&R::rtcm_topic)},
      {"solution_topic", "", "canyon::msg::Solution out, one per epoch", at(&R::solution_topic)},
      {"timing_topic", "", "canyon::msg::StageTiming out: stage times, queues, drops, correction age",
       at(&R::timing_topic)},
      {"vio_topic", "", "canyon::msg::VioPose in (input.vio dds)", at(&R::vio_topic)},
      {"timesync_topic", "", "canyon::msg::TimeSyncSample in (input.vio dds)", at(&R::timesync_topic)},
      {"publish_stages", "", "also the stages' outputs: canyon/bridged, alignment, prior and float",
       at(&R::publish_stages)},
      {"publish_observations", "",
       "also the rover's observation epochs as ingested: canyon/observations (a recorded session then holds the "
       "rover's inputs: canyon process --session)",
       at(&R::publish_observations)},
      {"record", "",
       "SESSION.mcap: every topic this rover publishes, recorded in-process as canyon record would take it off the "
       "wire (zstd chunks); \"\": none",
       at(&R::record), Path{}},
  };
  return table;
}

const Table<Ros2Options>& ros2_table() {
  using O = Ros2Options;
  static const Table<O> table{
      {"enabled", "", "publish the ROS 2 topics below (ROS 2 names and types, docs/usage.md#ros-2)", at(&O::enabled)},
      {"fix_topic", "", "sensor_msgs/msg/NavSatFix out (DDS topic rt/ + this), sensor-data QoS", at(&O::fix_topic)},
      {"odometry_topic", "", "nav_msgs/msg/Odometry out in the local ENU frame, sensor-data QoS",
       at(&O::odometry_topic)},
      {"diagnostics_topic", "", "diagnostic_msgs/msg/DiagnosticArray out: stage timing, canyon's exact status",
       at(&O::diagnostics_topic)},
      {"fix_frame_id", "", "NavSatFix header.frame_id (the antenna)", at(&O::fix_frame_id)},
      {"map_frame_id", "", "Odometry header.frame_id (the local ENU frame)", at(&O::map_frame_id)},
      {"antenna_frame_id", "", "Odometry child_frame_id", at(&O::antenna_frame_id)},
      {"vio_topic", "", "input.vio ros2: nav_msgs/msg/Odometry in, T_OI (DDS topic rt/ + this)", at(&O::vio_topic)},
      {"vio_frame_id", "", "input.vio ros2: the Odometry's expected header.frame_id (the VIO's odometry frame)",
       at(&O::vio_frame_id)},
      {"vio_child_frame_id", "", "input.vio ros2: the Odometry's expected child_frame_id (the IMU frame)",
       at(&O::vio_child_frame_id)},
      {"enu_origin_llh", "", "ENU origin [lat_deg, lon_deg, h_m] (ellipsoidal height); []: the first GNSS fix",
       at(&O::enu_origin_llh)},
  };
  return table;
}

/// estimator: the keys of canyon process, read by parse_process_config() (its errors name the keys without the
/// `estimator.` prefix, as before the tables).
Entry<R> estimator_entry() {
  Entry<R> e{"estimator", "the estimator and its inputs: the keys of canyon process (mode rtk or fusion)",
             at(&R::estimator), process_table()};
  e.read = [](R& c, YamlMap& map) {
    auto estimator = parse_process_config(map.raw("estimator"), map.file());
    if (estimator) {
      c.estimator = std::move(*estimator);
    } else {
      map.add_error(estimator.error());
    }
  };
  return e;
}

}  // namespace

const Table<RoverConfig>& rover_table() {
  static const Table<R> table{
      estimator_entry(),
      {"rover_id", "", "names this rover in its messages (1-64 characters)", at(&R::rover_id)},
      {"input", "the rover's observations, the base's corrections and the VIO", whole, input_table()},
      {"pipeline", "the six stages' threads and queues", at(&R::pipeline), pipeline_table()},
      {"dds", "DDS domain, QoS profiles and topics", whole, dds_table()},
      {"ros2", "ROS 2-compatible topics (off by default)", at(&R::ros2), ros2_table()},
  };
  return table;
}

std::vector<KeyDescription> describe_rover_config() {
  return describe_keys(rover_table(), RoverConfig{}, Numbers::Digits12);
}

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
  if (streamed_vio()) {
    if (estimator.mode != ProcessMode::Fusion) {
      return std::string("input.vio ") + (vio == RoverVioSource::Dds ? "dds" : "ros2") + " needs estimator.mode fusion";
    }
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
  if (ros2.fix_topic.empty() || ros2.odometry_topic.empty() || ros2.diagnostics_topic.empty() ||
      ros2.vio_topic.empty()) {
    return "ros2 topics must not be empty";
  }
  if (!ros2.enu_origin_llh.empty() &&
      (ros2.enu_origin_llh.size() != 3 || !(std::abs(ros2.enu_origin_llh[0]) <= 90.0) ||
       !(std::abs(ros2.enu_origin_llh[1]) <= 180.0) || !(std::abs(ros2.enu_origin_llh[2]) < 1e5))) {
    return "ros2.enu_origin_llh must be [] or [lat_deg, lon_deg, h_m] with |lat| <= 90, |lon| <= 180, |h| < 100 km";
  }
  return {};
}

bool operator==(const RoverConfig& a, const RoverConfig& b) {
  return equal_keys(rover_table(), a, b);
}

Result<RoverConfig> parse_rover_config(const YAML::Node& node, const std::string& file) {
  RoverConfig c;
  YamlMap top(node, file);
  if (!top.has("estimator")) {
    return Error{"'estimator:' (the canyon process keys: mode, rover, base, nav, ...) is required", file, 0};
  }
  read_keys(rover_table(), top, c);
  if (Status s = top.status(); !s) return s.error();
  return c;
}

Result<RoverConfig> load_rover_config(const std::string& path) {
  auto node = load_yaml_file(path);
  if (!node) return node.error();
  return parse_rover_config(*node, path);
}

std::string to_yaml(const RoverConfig& c) {
  return yaml_text(rover_table(), c, Numbers::Digits12);
}

}  // namespace canyon::config
