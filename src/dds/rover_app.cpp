// canyon rover (see rover_app.hpp).

#include "canyon/dds/rover_app.hpp"

#include <chrono>
#include <thread>
#include <utility>

#include <spdlog/spdlog.h>
#include <sys/resource.h>

#include "canyon/commands/process.hpp"
#include "canyon/pipeline/cpu_affinity.hpp"
#include "canyon/pipeline/observation_stream.hpp"

namespace canyon::dds {
namespace {

void log_warning(const std::string& text) {
  spdlog::warn("{}", text);
}

/// A link's events, prefixed with its role ("rover", "base").
pipeline::ByteLink::LogFn link_log(const std::string& role) {
  return [role](bool problem, const std::string& text) {
    if (problem) {
      spdlog::warn("{} {}", role, text);
    } else {
      spdlog::info("{} {}", role, text);
    }
  };
}

/// The rover's input: the RINEX file (estimator.rover) or the receiver link (input.rover_source).
Result<pipeline::RoverInput> open_rover(const config::RoverConfig& config, const io::ObsFilter& filter) {
  pipeline::RoverInput input;
  if (config.rover == config::RoverInputKind::Ubx) {
    auto address = pipeline::LinkAddress::parse(config.rover_source);
    if (!address) return address.error();
    auto link = pipeline::ByteLink::open(*address, config.link, link_log("rover"));
    if (!link) return link.error();
    input.receiver = std::make_unique<pipeline::ReceiverStream>(std::move(*link), filter, log_warning);
    input.paced = address->kind == pipeline::LinkAddress::Kind::File;
    return input;
  }
  auto rover = pipeline::ObservationStream::open(config.estimator.rover_obs, filter);
  if (!rover) return rover.error();
  input.rinex.emplace(std::move(*rover));
  return input;
}

/// The base's input and position: the RINEX file (position from estimator.base_position or its header), or a
/// stream (`dds_poll` for DDS frames, an NTRIP or TCP link; position from estimator.base_position, else from the
/// stream's 1005/1006, handed to the stages with the epochs by RoverIngest).
Result<pipeline::BaseInput> open_base_input(const config::RoverConfig& config, const io::ObsFilter& filter,
                                            const std::optional<core::GpsTime>& rover_start,
                                            pipeline::BaseInput::PollFn dds_poll, Eigen::Vector3d& p_E_base,
                                            std::shared_ptr<pipeline::ByteLink>& base_link) {
  const config::ProcessConfig& est = config.estimator;
  pipeline::BaseInput input;
  if (est.base_position_E_m) p_E_base = *est.base_position_E_m;
  switch (config.base) {
    case config::RoverBaseSource::File: {
      auto base = pipeline::ObservationStream::open(est.base_obs, filter, rover_start);
      if (!base) return base.error();
      if (!est.base_position_E_m) {
        if (!base->header().receiver.approx_position_E_m) {
          return Error{"no base position: give estimator.base_position", est.base_obs, 0};
        }
        p_E_base = *base->header().receiver.approx_position_E_m;
      }
      input.file.emplace(std::move(*base));
      return input;
    }
    case config::RoverBaseSource::Dds:
      input.poll = std::move(dds_poll);
      input.name = "base DDS " + config.rtcm_topic;
      break;
    case config::RoverBaseSource::Ntrip:
    case config::RoverBaseSource::Tcp: {
      auto address = pipeline::LinkAddress::parse(config.base_source);
      if (!address) return address.error();
      pipeline::LinkOptions options = config.link;
      options.gga_interval_s = config.ntrip_gga_interval_s;  // ntrip only (validated)
      auto link = pipeline::ByteLink::open(*address, options, link_log("base"));
      if (!link) return link.error();
      std::shared_ptr<pipeline::ByteLink> shared(std::move(*link));
      input.poll = pipeline::link_base_poll(shared, log_warning);
      input.name = "base " + address->text;
      input.link = shared;
      base_link = std::move(shared);
      break;
    }
  }
  return input;  // without estimator.base_position: the stream's 1005/1006 (RoverIngestOptions)
}

/// Where the VIO comes from, for the start-up line.
std::string vio_from(const config::RoverConfig& c) {
  switch (c.vio) {
    case config::RoverVioSource::Dds: return ", VIO from DDS " + c.vio_topic + " and " + c.timesync_topic;
    case config::RoverVioSource::Ros2:
      return ", VIO from ROS 2 Odometry " + c.ros2.vio_topic + " (" + c.ros2.vio_frame_id + " -> " +
             c.ros2.vio_child_frame_id + ")";
    case config::RoverVioSource::File: break;
  }
  return "";
}

}  // namespace

RoverApp::RoverApp(RoverOptions options)
    : options_(std::move(options)), config_(options_.config), base_frames_(options_.config.base_queue_frames) {
  // DDS first: profiles before any participant.
  const ProfileSet profiles = value_or_throw(load_profiles(config_.profiles), kExitUsage);
  participant_ = value_or_throw(DdsParticipant::create(config_.domain, profiles.participant_profile()), kExitRuntime);
  outputs_ = std::make_unique<RoverOutputs>(*participant_, config_);
  if (config_.base == config::RoverBaseSource::Dds) create_rtcm_reader();

  // The estimator, as canyon process builds it.
  const config::ProcessConfig& est = config_.estimator;
  commands::ProcessSummary notes;
  // No navigation file: the ephemerides come from the streams only (RoverConfig::validate checks they can).
  auto nav = est.nav.empty() ? Result<core::NavigationData>(core::NavigationData{})
                             : commands::load_navigation(est.nav, notes.warnings);
  ephemerides_ = std::make_unique<gnss::EphemerisStore>(value_or_throw(std::move(nav), kExitRuntime));
  const io::ObsFilter filter = commands::process_observation_filter(est);
  pipeline::RoverInput rover = value_or_throw(open_rover(config_, filter), kExitRuntime);
  const std::optional<core::GpsTime> rover_start =
      rover.rinex ? rover.rinex->header().first_obs : std::optional<core::GpsTime>{};
  pipeline::BaseInput base = open_base(filter, rover_start);
  build_estimator(notes);
  for (const std::string& w : notes.warnings) spdlog::warn("{}", w);
  for (const std::string& r : notes.report) spdlog::info("{}", r);
  open_pos();
  build_pipeline(std::move(rover), std::move(base));
}

RoverApp::~RoverApp() = default;

void RoverApp::stop() {
  stop_.store(true);
  pipeline_->stop();
}

void RoverApp::create_rtcm_reader() {
  rtcm_reader_ = value_or_throw(
      RtcmReader::create(
          *participant_, config_.rtcm_topic, profile::kRtcmReader,
          [this](msg::RtcmFrame&& m) {
            auto frame = from_msg(m);
            if (!frame) {
              base_frames_bad_.fetch_add(1);
              return;
            }
            if (!base_frames_.try_enqueue(BaseFrameSample{std::move(frame->bytes), m.send_monotonic_ns()})) {
              base_frames_dropped_.fetch_add(1);
            }
          }),
      kExitRuntime);
}

pipeline::BaseInput RoverApp::open_base(const io::ObsFilter& filter, const std::optional<core::GpsTime>& rover_start) {
  // The DDS base: the RtcmFrame samples the listener queued, into the live base cursor.
  pipeline::BaseInput::PollFn dds_poll = [this](std::int64_t timeout_us, pipeline::LiveBaseCursor& cursor) {
    BaseFrameSample frame;
    if (!base_frames_.wait_dequeue_timed(frame, timeout_us)) return !stop_.load();
    cursor.push(frame.bytes, frame.send_ns);
    while (base_frames_.try_dequeue(frame)) cursor.push(frame.bytes, frame.send_ns);
    return true;
  };
  auto base = open_base_input(config_, filter, rover_start, std::move(dds_poll), p_E_base_, base_link_);
  if (!base) throw AppError(kExitUsage, Error{options_.config_file + ": " + base.error().to_string()});
  return std::move(*base);
}

void RoverApp::build_estimator(commands::ProcessSummary& notes) {
  const config::ProcessConfig& est = config_.estimator;
  if (est.mode == config::ProcessMode::Fusion) {
    auto track = config_.streamed_vio() ? Result<fusion::VioTrack>(fusion::VioTrack::streaming(est.fusion.vio))
                                        : commands::load_vio_track(est, notes);
    fusion_engine_ = std::make_unique<fusion::FusionEngine>(est.fusion, est.rtk_engine_options(), *ephemerides_,
                                                            p_E_base_, value_or_throw(std::move(track), kExitRuntime));
    if (config_.streamed_vio()) open_live_vio();
    estimator_ = std::make_unique<pipeline::FusionEstimator>(*fusion_engine_, live_vio_.get());
  } else {
    rtk_engine_ = std::make_unique<rtk::RtkEngine>(est.rtk_engine_options(), *ephemerides_, p_E_base_);
    estimator_ = std::make_unique<pipeline::RtkEstimator>(*rtk_engine_);
  }
  feed_ = std::make_unique<pipeline::EphemerisFeed>(*estimator_, *ephemerides_);
}

void RoverApp::open_live_vio() {
  // VIO over DDS: the live VIO feed of the fusion engine and the two readers that fill it (the listeners only queue).
  pipeline::LiveVioOptions options;
  options.wait_s = config_.vio_wait_s;
  options.queue_poses = config_.vio_queue_poses;
  // ROS 2 Odometry is stamped with ROS time, taken as UTC: GPST after the leap seconds (dds/ros2_msgs.hpp).
  options.vio_on_gps_time = config_.estimator.fusion.vio_on_gps_time || config_.vio == config::RoverVioSource::Ros2;
  options.time_sync = config_.estimator.fusion.time_sync;
  options.time_sync.causal = true;
  if (const std::string e = options.validate(); !e.empty()) {
    const char* source = config_.vio == config::RoverVioSource::Ros2 ? "input.vio ros2: " : "input.vio dds: ";
    throw AppError(kExitRuntime, Error{source + e});
  }
  live_vio_ = std::make_unique<pipeline::LiveVio>(*fusion_engine_, options, log_warning);
  pipeline::LiveVio* feed = live_vio_.get();
  if (config_.vio == config::RoverVioSource::Ros2) {
    open_ros2_vio(*feed);
    return;
  }
  vio_reader_ = value_or_throw(VioPoseReader::create(*participant_, config_.vio_topic, profile::kVioReader,
                                                     [feed](msg::VioPose&& m) {
                                                       auto pose = from_msg(m);
                                                       if (pose) {
                                                         feed->push_pose(std::move(*pose));
                                                       } else {
                                                         spdlog::warn("VIO: {} (sample dropped)", pose.error().message);
                                                       }
                                                     }),
                               kExitRuntime);
  timesync_reader_ = value_or_throw(TimeSyncReader::create(*participant_, config_.timesync_topic, profile::kVioReader,
                                                           [feed](msg::TimeSyncSample&& m) {
                                                             auto pair = from_msg(m);
                                                             if (pair) {
                                                               feed->push_pair(*pair);
                                                             } else {
                                                               spdlog::warn("VIO time sync: {} (sample dropped)",
                                                                            pair.error().message);
                                                             }
                                                           }),
                                    kExitRuntime);
}

void RoverApp::open_ros2_vio(pipeline::LiveVio& feed) {
  // Refused samples (frames, values) are named in the log: the first ones, then every 100th, with the count.
  auto refused = std::make_shared<std::atomic<std::uint64_t>>(0);
  const config::Ros2Options options = config_.ros2;
  ros2_vio_reader_ = value_or_throw(
      OdometryReader::create(
          *participant_, ros2_dds_topic(options.vio_topic), profile::kRos2SensorDataReader,
          [&feed, refused, options, leaps = core::builtin_leap_seconds()](nav_msgs::msg::dds_::Odometry_&& m) {
            auto pose = from_ros2_odometry(m, options, leaps);
            if (pose) {
              feed.push_pose(std::move(*pose));
              return;
            }
            const std::uint64_t n = refused->fetch_add(1) + 1;
            if (n <= 10 || n % 100 == 0) {
              spdlog::warn("VIO (ROS 2 {}): {} (sample dropped; {} so far)", options.vio_topic, pose.error().message,
                           n);
            }
          }),
      kExitRuntime);
}

void RoverApp::open_pos() {
  const config::ProcessConfig& est = config_.estimator;
  if (est.out.empty()) return;
  outputs_->set_pos(value_or_throw(
      io::PosWriter::create(est.out, {est.coordinates, est.time_format, commands::pos_header_lines(est)}),
      kExitRuntime));
}

void RoverApp::build_pipeline(pipeline::RoverInput rover, pipeline::BaseInput base) {
  pipeline::RoverIngestOptions ingest_options;
  ingest_options.pace = config_.pace;
  ingest_options.base_wait_s = config_.base_wait_s;
  ingest_options.stream_ephemerides = config_.stream_ephemerides;
  ingest_options.base_position_from_stream = config_.streamed_base() && !config_.estimator.base_position_E_m;
  source_ = std::make_unique<pipeline::RoverIngest>(
      std::move(rover), std::move(base), ingest_options, [this] { return stop_.load(); }, log_warning);
  if (base_link_ && config_.ntrip_gga_interval_s > 0.0) outputs_->set_gga_link(base_link_);
  pipeline_ = std::make_unique<pipeline::EpochPipeline>(*source_, *feed_, outputs_->sink(), config_.pipeline,
                                                        outputs_->observer());
  outputs_->set_sources(*source_, live_vio_.get(), *pipeline_);
}

void RoverApp::wait_for_subscribers() const {
  const int wanted = options_.wait_subscribers;
  if (wanted <= 0) return;
  spdlog::info("waiting for {} solution subscriber(s), ROS 2 topics included (at most {} s)", wanted,
               options_.wait_timeout_s);
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(options_.wait_timeout_s);
  while (outputs_->solution_readers() < wanted && std::chrono::steady_clock::now() < until && !stop_.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (outputs_->solution_readers() < wanted) {
    spdlog::warn("only {} of {} subscribers matched; starting anyway", outputs_->solution_readers(), wanted);
  }
}

void RoverApp::log_start() const {
  const config::RoverConfig& c = config_;
  const auto shown = [](const std::string& link) {  // a link as messages show it (no password)
    auto address = pipeline::LinkAddress::parse(link);
    return address ? address->text : link;
  };
  const std::string rover_from = c.rover == config::RoverInputKind::Ubx ? shown(c.rover_source) : c.estimator.rover_obs;
  const std::string base_from = c.base == config::RoverBaseSource::File  ? c.estimator.base_obs
                                : c.base == config::RoverBaseSource::Dds ? "DDS " + c.rtcm_topic
                                                                         : shown(c.base_source);
  spdlog::info(
      "rover '{}': {} mode, rover from {}, base from {}, {} pipeline, pace {}; publishing {} and {} on domain {}",
      c.rover_id, config::mode_name(c.estimator.mode), rover_from, base_from + vio_from(c),
      c.pipeline.threaded ? "threaded" : "sequential", c.pace, c.solution_topic, c.timing_topic, c.domain);
  for (std::size_t s = 0; s < pipeline::kNumStages; ++s) {
    const std::vector<int>& cpus = c.pipeline.cpu_affinity[s];
    if (!cpus.empty()) {
      spdlog::info("{} stage thread on CPU {}", pipeline::stage_name(static_cast<pipeline::Stage>(s)),
                   pipeline::cpu_list_text(cpus));
    }
  }
}

namespace {

/// The CPU time (user and system) this process has used so far (s).
double process_cpu_s() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
  };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

}  // namespace

int RoverApp::run() {
  wait_for_subscribers();
  log_start();
  const auto start = std::chrono::steady_clock::now();
  Status status = pipeline_->run();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (Status c = outputs_->close_pos(); !c && status) status = c;
  if (Status c = outputs_->close_record(process_cpu_s()); !c && status) status = c;
  if (!outputs_->wait_for_acknowledgments(5.0)) {
    spdlog::warn("DDS: not every solution was acknowledged by every reader within 5 s");
  }
  if (outputs_->refused() > 0) {
    spdlog::warn("DDS: {} samples refused by the writers (history full)", outputs_->refused());
  }
  if (base_frames_dropped_.load() > 0 || base_frames_bad_.load() > 0) {
    spdlog::warn("base: {} RTCM frames dropped (queue full), {} malformed", base_frames_dropped_.load(),
                 base_frames_bad_.load());
  }
  report_inputs();
  report_stats(wall_s);
  if (!status.ok()) {
    spdlog::error("{}", status.error().to_string());
    return kExitRuntime;
  }
  return kExitOk;
}

void RoverApp::report_inputs() const {
  for (const pipeline::RoverIngest::Summary& s : source_->summary()) {
    if (s.problems) {
      spdlog::warn("{}", s.text);
    } else {
      spdlog::info("{}", s.text);
    }
  }
  if (malformed_payloads() > 0) {
    spdlog::warn("DDS: {} malformed samples dropped (packets corrupted on the way)", malformed_payloads());
  }
  if (const auto& p = source_->streamed_base_position()) {
    spdlog::info("base position from the stream's RTCM 1005/1006: [{:.4f}, {:.4f}, {:.4f}] m ECEF", p->x(), p->y(),
                 p->z());
  }
  if (source_->base_without_position() > 0) {
    spdlog::warn("base: {} epochs went on without the base: no base position (RTCM 1005/1006) had arrived yet",
                 source_->base_without_position());
  }
  if (source_->base_late() > 0) {
    spdlog::warn("base: {} epochs went on without waiting longer for their base epoch (input.base_wait_s {})",
                 source_->base_late(), config_.base_wait_s);
  }
  if (feed_->added() > 0) {
    spdlog::info("{} ephemerides from the streams (UBX SFRBX, RTCM 3) used besides the navigation files'",
                 feed_->added());
  }
  if (live_vio_) {
    const pipeline::LiveVioCounts c = live_vio_->counts();
    const bool problems = c.dropped > 0 || c.unmapped > 0 || c.out_of_order > 0 || c.late_epochs > 0;
    spdlog::log(problems ? spdlog::level::warn : spdlog::level::info,
                "VIO over DDS: {} poses and {} time-sync pairs received, {} poses used; {} dropped (queue full), {} "
                "not mapped to GPST, {} out of order; {} epochs went on without waiting longer for their VIO",
                c.poses, c.pairs, c.appended, c.dropped, c.unmapped, c.out_of_order, c.late_epochs);
  }
  if (fusion_engine_) {
    for (const std::string& line : fusion_engine_->report()) spdlog::info("{}", line);
  }
}

void RoverApp::report_stats(double wall_s) const {
  const pipeline::PipelineStats stats = pipeline_->stats();
  std::uint64_t waits = 0;
  std::string by_producer;  // each queue's waits, named by the stage that fills it
  for (std::size_t i = 0; i < stats.full_waits.size(); ++i) {
    waits += stats.full_waits[i];
    if (stats.full_waits[i] == 0) continue;
    by_producer += (by_producer.empty() ? " (" : ", ") +
                   std::string(pipeline::stage_name(static_cast<pipeline::Stage>(i))) + " " +
                   std::to_string(stats.full_waits[i]);
  }
  if (!by_producer.empty()) by_producer += ")";
  const std::uint64_t epochs = outputs_->epochs();
  spdlog::info("{} epochs, {} solved, {} fixed in {:.3f} s ({:.0f} epochs/s); queue-full waits {}{}{}", epochs,
               outputs_->solved(), outputs_->fixed(), wall_s, wall_s > 0 ? static_cast<double>(epochs) / wall_s : 0.0,
               waits, by_producer, stop_.load() ? " (stopped by signal)" : "");
}

}  // namespace canyon::dds
