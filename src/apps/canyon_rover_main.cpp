// canyon-rover: the real-time rover. The rover's observations replayed from RINEX at real-time pace (or faster),
// base corrections from a RINEX file or from the DDS RtcmFrame topic, VIO from files or from the DDS VioPose and
// TimeSyncSample topics (pipeline/live_vio.hpp), through the six-stage threaded
// pipeline (pipeline/epoch_pipeline.hpp, the same stages as canyon process); solutions and stage timing published on
// DDS (idl/RoverPipeline.idl). `canyon rover ...` runs this executable; config/rover.yaml documents the configuration.
// SIGINT/SIGTERM stop it cleanly: ingest stops, the epochs in flight are finished and published.
// Exit codes: 0 success, 1 input or runtime failure, 2 bad command line or configuration.

#include <atomic>
#include <chrono>
#include <csignal>
#include <iostream>
#include <memory>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>
#include <readerwriterqueue/readerwritercircularbuffer.h>
#include <spdlog/spdlog.h>

#include "canyon/commands/process.hpp"
#include "canyon/config/rover_config.hpp"
#include "canyon/dds/dds.hpp"
#include "canyon/dds/rover_msgs.hpp"
#include "canyon/dds/rtcm_frame.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/io/nmea.hpp"
#include "canyon/io/pos_file.hpp"
#include "canyon/pipeline/cpu_affinity.hpp"
#include "canyon/pipeline/epoch_pipeline.hpp"
#include "canyon/pipeline/live_vio.hpp"
#include "canyon/pipeline/observation_stream.hpp"
#include "canyon/pipeline/rover_ingest.hpp"

#include "main_guard.hpp"

namespace {

constexpr int kExitRuntime = 1;
constexpr int kExitUsage = 2;

using canyon::Result;
using canyon::Status;
namespace core = canyon::core;
namespace pl = canyon::dds;

std::atomic<canyon::pipeline::EpochPipeline*> g_pipeline{nullptr};
std::atomic<bool> g_stop{false};

extern "C" void on_signal(int /*signal*/) {
  g_stop.store(true);
  if (canyon::pipeline::EpochPipeline* p = g_pipeline.load()) p->stop();
}

/// An RTCM frame from the DDS listener to ingest.
struct BaseFrameSample {
  std::vector<std::uint8_t> bytes;
  std::int64_t send_ns = 0;
};

/// The DDS base: the RtcmFrame samples the listener queued, into the live base cursor.
canyon::pipeline::BaseInput::PollFn dds_base_poll(
    moodycamel::BlockingReaderWriterCircularBuffer<BaseFrameSample>& frames) {
  return [&frames](std::int64_t timeout_us, canyon::pipeline::LiveBaseCursor& cursor) {
    BaseFrameSample frame;
    if (!frames.wait_dequeue_timed(frame, timeout_us)) return !g_stop.load();
    cursor.push(frame.bytes, frame.send_ns);
    while (frames.try_dequeue(frame)) cursor.push(frame.bytes, frame.send_ns);
    return true;
  };
}

void log_warning(const std::string& text) {
  spdlog::warn("{}", text);
}

/// A link's events, prefixed with its role ("rover", "base").
canyon::pipeline::ByteLink::LogFn link_log(const std::string& role) {
  return [role](bool problem, const std::string& text) {
    if (problem) {
      spdlog::warn("{} {}", role, text);
    } else {
      spdlog::info("{} {}", role, text);
    }
  };
}

/// The rover's input: the RINEX file (estimator.rover) or the receiver link (input.rover_source).
Result<canyon::pipeline::RoverInput> open_rover(const canyon::config::RoverConfig& config,
                                                const canyon::io::ObsFilter& filter) {
  canyon::pipeline::RoverInput input;
  if (config.rover == canyon::config::RoverInputKind::Ubx) {
    auto address = canyon::pipeline::LinkAddress::parse(config.rover_source);
    if (!address) return address.error();
    auto link = canyon::pipeline::ByteLink::open(*address, config.link, link_log("rover"));
    if (!link) return link.error();
    input.receiver = std::make_unique<canyon::pipeline::ReceiverStream>(std::move(*link), filter, log_warning);
    input.paced = address->kind == canyon::pipeline::LinkAddress::Kind::File;
    return input;
  }
  auto rover = canyon::pipeline::ObservationStream::open(config.estimator.rover_obs, filter);
  if (!rover) return rover.error();
  input.rinex.emplace(std::move(*rover));
  return input;
}

/// The base's input and position: the RINEX file (position from estimator.base_position or its header), or a
/// stream (DDS frames, an NTRIP or TCP link; position from estimator.base_position, else from the stream's 1005/1006,
/// handed to the stages with the epochs by RoverIngest).
Result<canyon::pipeline::BaseInput> open_base(
    const canyon::config::RoverConfig& config, const canyon::io::ObsFilter& filter,
    const std::optional<core::GpsTime>& rover_start,
    moodycamel::BlockingReaderWriterCircularBuffer<BaseFrameSample>& dds_frames, Eigen::Vector3d& p_E_base,
    std::shared_ptr<canyon::pipeline::ByteLink>& base_link) {
  const canyon::config::ProcessConfig& est = config.estimator;
  canyon::pipeline::BaseInput input;
  if (est.base_position_E_m) p_E_base = *est.base_position_E_m;
  switch (config.base) {
    case canyon::config::RoverBaseSource::File: {
      auto base = canyon::pipeline::ObservationStream::open(est.base_obs, filter, rover_start);
      if (!base) return base.error();
      if (!est.base_position_E_m) {
        if (!base->header().receiver.approx_position_E_m) {
          return canyon::Error{"no base position: give estimator.base_position", est.base_obs, 0};
        }
        p_E_base = *base->header().receiver.approx_position_E_m;
      }
      input.file.emplace(std::move(*base));
      return input;
    }
    case canyon::config::RoverBaseSource::Dds:
      input.poll = dds_base_poll(dds_frames);
      input.name = "base DDS " + config.rtcm_topic;
      break;
    case canyon::config::RoverBaseSource::Ntrip:
    case canyon::config::RoverBaseSource::Tcp: {
      auto address = canyon::pipeline::LinkAddress::parse(config.base_source);
      if (!address) return address.error();
      canyon::pipeline::LinkOptions options = config.link;
      options.gga_interval_s = config.ntrip_gga_interval_s;  // ntrip only (validated)
      auto link = canyon::pipeline::ByteLink::open(*address, options, link_log("base"));
      if (!link) return link.error();
      std::shared_ptr<canyon::pipeline::ByteLink> shared(std::move(*link));
      input.poll = canyon::pipeline::link_base_poll(shared, log_warning);
      input.name = "base " + address->text;
      input.link = shared;
      base_link = std::move(shared);
      break;
    }
  }
  return input;  // without estimator.base_position: the stream's 1005/1006 (RoverIngestOptions)
}

/// VIO over DDS: the live VIO feed of the fusion engine and the two readers that fill it (the listeners only queue).
Status open_live_vio(const canyon::config::RoverConfig& config, pl::DdsParticipant& participant,
                     canyon::fusion::FusionEngine& engine, std::unique_ptr<canyon::pipeline::LiveVio>& live,
                     std::unique_ptr<pl::VioPoseReader>& poses, std::unique_ptr<pl::TimeSyncReader>& pairs) {
  canyon::pipeline::LiveVioOptions options;
  options.wait_s = config.vio_wait_s;
  options.queue_poses = config.vio_queue_poses;
  options.vio_on_gps_time = config.estimator.fusion.vio_on_gps_time;
  options.time_sync = config.estimator.fusion.time_sync;
  options.time_sync.causal = true;
  if (const std::string e = options.validate(); !e.empty()) return canyon::Error{"input.vio dds: " + e};
  live = std::make_unique<canyon::pipeline::LiveVio>(engine, options, log_warning);
  canyon::pipeline::LiveVio* feed = live.get();
  auto p = pl::VioPoseReader::create(participant, config.vio_topic, canyon::dds::profile::kVioReader,
                                     [feed](canyon::msg::VioPose&& m) {
                                       auto pose = pl::from_msg(m);
                                       if (pose) {
                                         feed->push_pose(std::move(*pose));
                                       } else {
                                         spdlog::warn("VIO: {} (sample dropped)", pose.error().message);
                                       }
                                     });
  if (!p) return p.error();
  poses = std::move(*p);
  auto s = pl::TimeSyncReader::create(participant, config.timesync_topic, canyon::dds::profile::kVioReader,
                                      [feed](canyon::msg::TimeSyncSample&& m) {
                                        auto pair = pl::from_msg(m);
                                        if (pair) {
                                          feed->push_pair(*pair);
                                        } else {
                                          spdlog::warn("VIO time sync: {} (sample dropped)", pair.error().message);
                                        }
                                      });
  if (!s) return s.error();
  pairs = std::move(*s);
  return canyon::Ok{};
}

int run(int argc, char** argv) {
  CLI::App cli{"canyon-rover: the real-time rover pipeline (six stage threads, DDS in and out)"};
  std::string config_file;
  bool print_config = false;
  double pace = -1.0;
  std::string out;
  int wait_subscribers = 0;
  double wait_timeout_s = 30.0;
  bool quiet = false;
  std::string pipeline_mode;
  cli.add_option("--config", config_file, "YAML configuration (strict; config/rover.yaml documents every key)")
      ->required()
      ->check(CLI::ExistingFile);
  cli.add_flag("--print-config", print_config, "Print the effective configuration as YAML and exit");
  cli.add_option("--pace", pace, "Override input.pace (rover replay speed; 0 as fast as possible)")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--out", out, "Override estimator.out (.pos the rover writes itself)");
  cli.add_option("--pipeline", pipeline_mode, "Override pipeline.threaded: threaded or sequential")
      ->check(CLI::IsMember({"threaded", "sequential"}));
  cli.add_option("--wait-for-subscribers", wait_subscribers,
                 "Start once this many readers of the solution topic are matched (so they miss nothing)")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--wait-timeout", wait_timeout_s, "Give up waiting for subscribers after this many seconds");
  cli.add_flag("-q,--quiet", quiet, "Warnings and errors only");
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : kExitUsage;
  }
  spdlog::set_pattern("[%Y-%m-%d %H:%M:%S.%e] [canyon-rover] [%^%l%$] %v");
  if (quiet) spdlog::set_level(spdlog::level::warn);

  auto config = canyon::config::load_rover_config(config_file);
  if (!config) {
    spdlog::error("{}", config.error().to_string());
    return kExitUsage;
  }
  if (pace >= 0.0) config->pace = pace;
  if (!out.empty()) config->estimator.out = out;
  if (!pipeline_mode.empty()) config->pipeline.threaded = pipeline_mode == "threaded";
  if (!pipeline_mode.empty() && !config->pipeline.threaded && config->pipeline.pinned()) {
    spdlog::warn("pipeline.cpu_affinity applies to the threaded pipeline only: ignored with --pipeline sequential");
    config->pipeline.cpu_affinity = {};
  }
  if (print_config) {
    std::cout << canyon::config::to_yaml(*config);
    return 0;
  }
  if (const std::string e = config->validate(); !e.empty()) {
    spdlog::error("{}: {}", config_file, e);
    return kExitUsage;
  }
  if (const std::string e = config->pipeline.unavailable_cpu(); !e.empty()) {
    spdlog::error("{}: pipeline.{}", config_file, e);
    return kExitUsage;
  }
  const canyon::config::ProcessConfig& est = config->estimator;
  const bool dds_base = config->base == canyon::config::RoverBaseSource::Dds;
  const auto shown = [](const std::string& link) {  // a link as messages show it (no password)
    auto address = canyon::pipeline::LinkAddress::parse(link);
    return address ? address->text : link;
  };
  const std::string rover_from =
      config->rover == canyon::config::RoverInputKind::Ubx ? shown(config->rover_source) : est.rover_obs;
  const std::string base_from = config->base == canyon::config::RoverBaseSource::File ? est.base_obs
                                : dds_base                                            ? "DDS " + config->rtcm_topic
                                                                                      : shown(config->base_source);

  // DDS first: profiles before any participant.
  if (auto s = pl::load_profiles(config->profiles); !s.ok()) {
    spdlog::error("{}", s.error().to_string());
    return kExitUsage;
  }
  auto participant =
      pl::DdsParticipant::create(config->domain, pl::load_profiles(config->profiles)->participant_profile());
  if (!participant) {
    spdlog::error("{}", participant.error().to_string());
    return kExitRuntime;
  }
  auto solution_writer =
      pl::SolutionWriter::create(**participant, config->solution_topic, canyon::dds::profile::kSolutionWriter);
  auto timing_writer =
      pl::TimingWriter::create(**participant, config->timing_topic, canyon::dds::profile::kTimingWriter);
  if (!solution_writer || !timing_writer) {
    spdlog::error("{}", (!solution_writer ? solution_writer.error() : timing_writer.error()).to_string());
    return kExitRuntime;
  }
  std::unique_ptr<pl::BridgedWriter> bridged_writer;
  std::unique_ptr<pl::AlignmentWriter> alignment_writer;
  std::unique_ptr<pl::PriorWriter> prior_writer;
  std::unique_ptr<pl::FloatWriter> float_writer;
  if (config->publish_stages) {
    auto p = pl::PriorWriter::create(**participant, "canyon/prior", canyon::dds::profile::kStageWriter);
    auto f = pl::FloatWriter::create(**participant, "canyon/float", canyon::dds::profile::kStageWriter);
    if (!p || !f) {
      spdlog::error("{}", (!p ? p.error() : f.error()).to_string());
      return kExitRuntime;
    }
    prior_writer = std::move(*p);
    float_writer = std::move(*f);
    if (est.mode == canyon::config::ProcessMode::Fusion) {
      auto b = pl::BridgedWriter::create(**participant, "canyon/bridged", canyon::dds::profile::kStageWriter);
      auto a = pl::AlignmentWriter::create(**participant, "canyon/alignment", canyon::dds::profile::kStageWriter);
      if (!b || !a) {
        spdlog::error("{}", (!b ? b.error() : a.error()).to_string());
        return kExitRuntime;
      }
      bridged_writer = std::move(*b);
      alignment_writer = std::move(*a);
    }
  }

  // Base frames: the DDS listener only queues them (dropped and counted when the queue is full).
  moodycamel::BlockingReaderWriterCircularBuffer<BaseFrameSample> base_frames(config->base_queue_frames);
  std::atomic<std::uint64_t> base_frames_dropped{0};
  std::atomic<std::uint64_t> base_frames_bad{0};
  std::unique_ptr<pl::RtcmReader> rtcm_reader;
  if (dds_base) {
    auto r = pl::RtcmReader::create(
        **participant, config->rtcm_topic, canyon::dds::profile::kRtcmReader,
        [&base_frames, &base_frames_dropped, &base_frames_bad](canyon::msg::RtcmFrame&& m) {
          auto frame = pl::from_msg(m);
          if (!frame) {
            base_frames_bad.fetch_add(1);
            return;
          }
          if (!base_frames.try_enqueue(BaseFrameSample{std::move(frame->bytes), m.send_monotonic_ns()})) {
            base_frames_dropped.fetch_add(1);
          }
        });
    if (!r) {
      spdlog::error("{}", r.error().to_string());
      return kExitRuntime;
    }
    rtcm_reader = std::move(*r);
  }

  // The estimator, as canyon process builds it.
  canyon::commands::ProcessSummary notes;
  // No navigation file: the ephemerides come from the streams only (RoverConfig::validate checks they can).
  auto nav = est.nav.empty() ? Result<core::NavigationData>(core::NavigationData{})
                             : canyon::commands::load_navigation(est.nav, notes.warnings);
  if (!nav) {
    spdlog::error("{}", nav.error().to_string());
    return kExitRuntime;
  }
  canyon::gnss::EphemerisStore ephemerides(std::move(*nav));  // grows by the streams' ephemerides (EphemerisFeed)
  const canyon::io::ObsFilter filter = canyon::commands::process_observation_filter(est);
  auto rover = open_rover(*config, filter);
  if (!rover) {
    spdlog::error("{}", rover.error().to_string());
    return kExitRuntime;
  }
  const std::optional<core::GpsTime> rover_start =
      rover->rinex ? rover->rinex->header().first_obs : std::optional<core::GpsTime>{};
  Eigen::Vector3d p_E_base = Eigen::Vector3d::Zero();
  std::shared_ptr<canyon::pipeline::ByteLink> base_link;  // ntrip, tcp: the link (the rover's position goes up as GGA)
  auto base = open_base(*config, filter, rover_start, base_frames, p_E_base, base_link);
  if (!base) {
    spdlog::error("{}: {}", config_file, base.error().to_string());
    return kExitUsage;
  }
  std::unique_ptr<canyon::rtk::RtkEngine> rtk_engine;
  std::unique_ptr<canyon::fusion::FusionEngine> fusion_engine;
  std::unique_ptr<canyon::pipeline::EpochEstimator> estimator;
  std::unique_ptr<canyon::pipeline::LiveVio> live_vio;
  std::unique_ptr<pl::VioPoseReader> vio_reader;
  std::unique_ptr<pl::TimeSyncReader> timesync_reader;
  if (est.mode == canyon::config::ProcessMode::Fusion) {
    auto track = config->vio_dds ? Result<canyon::fusion::VioTrack>(canyon::fusion::VioTrack::streaming(est.fusion.vio))
                                 : canyon::commands::load_vio_track(est, notes);
    if (!track) {
      spdlog::error("{}", track.error().to_string());
      return kExitRuntime;
    }
    fusion_engine = std::make_unique<canyon::fusion::FusionEngine>(est.fusion, est.rtk_engine_options(), ephemerides,
                                                                   p_E_base, std::move(*track));
    if (config->vio_dds) {
      auto readers = open_live_vio(*config, **participant, *fusion_engine, live_vio, vio_reader, timesync_reader);
      if (!readers) {
        spdlog::error("{}", readers.error().to_string());
        return kExitRuntime;
      }
    }
    estimator = std::make_unique<canyon::pipeline::FusionEstimator>(*fusion_engine, live_vio.get());
  } else {
    rtk_engine = std::make_unique<canyon::rtk::RtkEngine>(est.rtk_engine_options(), ephemerides, p_E_base);
    estimator = std::make_unique<canyon::pipeline::RtkEstimator>(*rtk_engine);
  }
  canyon::pipeline::EphemerisFeed feed(*estimator, ephemerides);
  for (const std::string& w : notes.warnings) spdlog::warn("{}", w);
  for (const std::string& r : notes.report) spdlog::info("{}", r);

  std::optional<canyon::io::PosWriter> pos;
  if (!est.out.empty()) {
    auto p = canyon::io::PosWriter::create(est.out,
                                           {est.coordinates, est.time_format, canyon::commands::pos_header_lines(est)});
    if (!p) {
      spdlog::error("{}", p.error().to_string());
      return kExitRuntime;
    }
    pos = std::move(*p);
  }

  canyon::pipeline::RoverIngestOptions ingest_options;
  ingest_options.pace = config->pace;
  ingest_options.base_wait_s = config->base_wait_s;
  ingest_options.stream_ephemerides = config->stream_ephemerides;
  ingest_options.base_position_from_stream = config->streamed_base() && !est.base_position_E_m;
  canyon::pipeline::RoverIngest source(
      std::move(*rover), std::move(*base), ingest_options, [] { return g_stop.load(); }, log_warning);
  std::uint64_t solved = 0, fixed = 0, epochs = 0;
  std::atomic<std::uint64_t> refused{0};  // the time bridge's and the ambiguity stage's threads publish
  const auto sink = [&](const canyon::pipeline::EpochItem& item) -> Status {
    ++epochs;
    if (item.output) {
      ++solved;
      if (item.output->solution.status == core::SolutionStatus::Fixed) ++fixed;
      if (base_link && config->ntrip_gga_interval_s > 0.0) {
        base_link->set_gga(canyon::io::format_gga(item.output->solution));  // uploaded at the link's interval
      }
      if (pos) return pos->write(item.output->solution);
    }
    return canyon::Ok{};
  };
  canyon::pipeline::EpochPipeline* pipeline_ptr = nullptr;
  pl::EpochContext context;
  context.rover_id = config->rover_id;
  // The solution is written as soon as the ambiguity stage has it. The stage outputs (canyon/bridged, /prior,
  // /float, /alignment: every stage's output is still in the epoch then) and the timing are taken then too and written
  // once the epoch has moved on (StageObserver): their DDS writes delay no epoch and, in the threaded pipeline, no
  // other stage's thread (on two cores a write on the time bridge's thread held up the next stage's wake-up). The
  // pending messages belong to the ambiguity stage's thread.
  std::optional<canyon::msg::BridgedEpoch> bridged_pending;
  std::optional<canyon::msg::Prior> prior_pending;
  std::optional<canyon::msg::FloatSolution> float_pending;
  std::optional<canyon::msg::Alignment> alignment_pending;
  std::optional<canyon::msg::StageTiming> timing_pending;
  const auto write = [&refused](auto& writer, auto& pending) {
    if (pending && !writer->write(*pending)) ++refused;
    pending.reset();
  };
  canyon::pipeline::StageObserver observer;
  observer.taken = [&](canyon::pipeline::Stage stage, const canyon::pipeline::EpochItem& item) {
    if (stage != canyon::pipeline::Stage::Ambiguity) return;
    context.base_late = source.base_late();
    context.malformed_samples = pl::malformed_payloads();
    if (live_vio) {
      const canyon::pipeline::LiveVioCounts vio = live_vio->counts();
      context.vio_dropped = vio.dropped;
      context.vio_late = vio.late_epochs;
    }
    if (pipeline_ptr != nullptr) {
      context.queue_depth = pipeline_ptr->queue_depths();
      context.queue_full_waits = pipeline_ptr->stats().full_waits;
    }
    context.alignment_rmse_m = std::numeric_limits<double>::quiet_NaN();
    if (item.output && item.output->alignment) {
      context.alignment_rmse_m = item.output->alignment->rmse_m;
      context.alignment_eigen_ratio = item.output->alignment->first_eigenvalue_ratio;
      context.lever_arm_m = item.output->alignment->t_IA_m;
    }
    auto solution = pl::to_msg_solution(item, context);
    if (!(*solution_writer)->write(solution)) ++refused;
    timing_pending = pl::to_msg_timing(item, context);
    if (prior_writer) {
      prior_pending = pl::to_msg_prior(item);
      float_pending = pl::to_msg_float(item);
    }
    if (bridged_writer) bridged_pending = pl::to_msg_bridged(item);
    if (alignment_writer) alignment_pending = pl::to_msg_alignment(item);
  };
  observer.handed_on = [&](canyon::pipeline::Stage stage) {
    if (stage != canyon::pipeline::Stage::Ambiguity) return;
    write(*timing_writer, timing_pending);
    write(bridged_writer, bridged_pending);
    write(prior_writer, prior_pending);
    write(float_writer, float_pending);
    write(alignment_writer, alignment_pending);
  };
  canyon::pipeline::EpochPipeline pipeline(source, feed, sink, config->pipeline, observer);
  pipeline_ptr = &pipeline;
  g_pipeline.store(&pipeline);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  if (wait_subscribers > 0) {
    spdlog::info("waiting for {} solution subscriber(s) (at most {} s)", wait_subscribers, wait_timeout_s);
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_timeout_s);
    while ((*solution_writer)->matched() < wait_subscribers && std::chrono::steady_clock::now() < until &&
           !g_stop.load()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    if ((*solution_writer)->matched() < wait_subscribers) {
      spdlog::warn("only {} of {} subscribers matched; starting anyway", (*solution_writer)->matched(),
                   wait_subscribers);
    }
  }
  spdlog::info(
      "rover '{}': {} mode, rover from {}, base from {}, {} pipeline, pace {}; publishing {} and {} on domain {}",
      config->rover_id, canyon::config::mode_name(est.mode), rover_from,
      base_from + (config->vio_dds ? ", VIO from DDS " + config->vio_topic + " and " + config->timesync_topic : ""),
      config->pipeline.threaded ? "threaded" : "sequential", config->pace, config->solution_topic, config->timing_topic,
      config->domain);
  for (std::size_t s = 0; s < canyon::pipeline::kNumStages; ++s) {
    const std::vector<int>& cpus = config->pipeline.cpu_affinity[s];
    if (!cpus.empty()) {
      spdlog::info("{} stage thread on CPU {}", canyon::pipeline::stage_name(static_cast<canyon::pipeline::Stage>(s)),
                   canyon::pipeline::cpu_list_text(cpus));
    }
  }
  const auto start = std::chrono::steady_clock::now();
  Status status = pipeline.run();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  g_pipeline.store(nullptr);
  if (pos) {
    if (Status c = pos->close(); !c && status) status = c;
  }
  if (!(*solution_writer)->wait_for_acknowledgments(5.0) || !(*timing_writer)->wait_for_acknowledgments(5.0)) {
    spdlog::warn("DDS: not every solution was acknowledged by every reader within 5 s");
  }
  if (refused.load() > 0) spdlog::warn("DDS: {} samples refused by the writers (history full)", refused.load());
  if (base_frames_dropped.load() > 0 || base_frames_bad.load() > 0) {
    spdlog::warn("base: {} RTCM frames dropped (queue full), {} malformed", base_frames_dropped.load(),
                 base_frames_bad.load());
  }
  for (const canyon::pipeline::RoverIngest::Summary& s : source.summary()) {
    if (s.problems) {
      spdlog::warn("{}", s.text);
    } else {
      spdlog::info("{}", s.text);
    }
  }
  if (pl::malformed_payloads() > 0) {
    spdlog::warn("DDS: {} malformed samples dropped (packets corrupted on the way)", pl::malformed_payloads());
  }
  if (const auto& p = source.streamed_base_position()) {
    spdlog::info("base position from the stream's RTCM 1005/1006: [{:.4f}, {:.4f}, {:.4f}] m ECEF", p->x(), p->y(),
                 p->z());
  }
  if (source.base_without_position() > 0) {
    spdlog::warn("base: {} epochs went on without the base: no base position (RTCM 1005/1006) had arrived yet",
                 source.base_without_position());
  }
  if (source.base_late() > 0) {
    spdlog::warn("base: {} epochs went on without waiting longer for their base epoch (input.base_wait_s {})",
                 source.base_late(), config->base_wait_s);
  }
  if (feed.added() > 0) {
    spdlog::info("{} ephemerides from the streams (UBX SFRBX, RTCM 3) used besides the navigation files'",
                 feed.added());
  }
  if (live_vio) {
    const canyon::pipeline::LiveVioCounts c = live_vio->counts();
    const bool problems = c.dropped > 0 || c.unmapped > 0 || c.out_of_order > 0 || c.late_epochs > 0;
    spdlog::log(problems ? spdlog::level::warn : spdlog::level::info,
                "VIO over DDS: {} poses and {} time-sync pairs received, {} poses used; {} dropped (queue full), {} "
                "not mapped to GPST, {} out of order; {} epochs went on without waiting longer for their VIO",
                c.poses, c.pairs, c.appended, c.dropped, c.unmapped, c.out_of_order, c.late_epochs);
  }
  if (fusion_engine) {
    for (const std::string& line : fusion_engine->report()) spdlog::info("{}", line);
  }
  const canyon::pipeline::PipelineStats stats = pipeline.stats();
  std::uint64_t waits = 0;
  std::string by_producer;  // each queue's waits, named by the stage that fills it
  for (std::size_t i = 0; i < stats.full_waits.size(); ++i) {
    waits += stats.full_waits[i];
    if (stats.full_waits[i] == 0) continue;
    by_producer += (by_producer.empty() ? " (" : ", ") +
                   std::string(canyon::pipeline::stage_name(static_cast<canyon::pipeline::Stage>(i))) + " " +
                   std::to_string(stats.full_waits[i]);
  }
  if (!by_producer.empty()) by_producer += ")";
  spdlog::info("{} epochs, {} solved, {} fixed in {:.3f} s ({:.0f} epochs/s); queue-full waits {}{}{}", epochs, solved,
               fixed, wall_s, wall_s > 0 ? static_cast<double>(epochs) / wall_s : 0.0, waits, by_producer,
               g_stop.load() ? " (stopped by signal)" : "");
  if (!status.ok()) {
    spdlog::error("{}", status.error().to_string());
    return kExitRuntime;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return canyon::apps::guarded_main("canyon-rover", kExitRuntime, run, argc, argv);
}
