// The rover's per-epoch outputs (see rover_outputs.hpp).

#include "canyon/dds/rover_outputs.hpp"

#include <limits>
#include <numbers>
#include <string>
#include <utility>

#include <spdlog/spdlog.h>

#include "canyon/dds/app.hpp"
#include "canyon/io/nmea.hpp"

namespace canyon::dds {
namespace {

template <typename Writer>
std::unique_ptr<Writer> create_writer(DdsParticipant& participant, const std::string& topic, const char* profile) {
  return value_or_throw(Writer::create(participant, topic, profile), kExitRuntime);
}

/// Writes the pending message, if any, and forgets it; counts a refusal.
template <typename Writer, typename Msg>
void write_pending(Writer& writer, std::optional<Msg>& pending, std::atomic<std::uint64_t>& refused) {
  if (writer && pending && !writer->write(*pending)) refused.fetch_add(1);
  pending.reset();
}

}  // namespace

RoverOutputs::RoverOutputs(DdsParticipant& participant, const config::RoverConfig& config)
    : rover_id_(config.rover_id), ros2_(config.ros2), leaps_(core::builtin_leap_seconds()) {
  solution_ = create_writer<SolutionWriter>(participant, config.solution_topic, profile::kSolutionWriter);
  timing_ = create_writer<TimingWriter>(participant, config.timing_topic, profile::kTimingWriter);
  if (ros2_.enabled) {
    ros2_fix_ =
        create_writer<NavSatFixWriter>(participant, ros2_dds_topic(ros2_.fix_topic), profile::kRos2SensorDataWriter);
    ros2_odometry_ = create_writer<OdometryWriter>(participant, ros2_dds_topic(ros2_.odometry_topic),
                                                   profile::kRos2SensorDataWriter);
    ros2_diagnostics_ = create_writer<DiagnosticsWriter>(participant, ros2_dds_topic(ros2_.diagnostics_topic),
                                                         profile::kRos2DefaultWriter);
    if (ros2_.enu_origin_llh.size() == 3) {
      constexpr double kRadPerDeg = std::numbers::pi / 180.0;
      enu_origin_ = core::Geodetic{ros2_.enu_origin_llh[0] * kRadPerDeg, ros2_.enu_origin_llh[1] * kRadPerDeg,
                                   ros2_.enu_origin_llh[2]};
    }
  }
  if (config.publish_observations) {
    observations_ = create_writer<ObservationWriter>(participant, "canyon/observations", profile::kStageWriter);
  }
  if (config.publish_stages) {
    prior_ = create_writer<PriorWriter>(participant, "canyon/prior", profile::kStageWriter);
    float_ = create_writer<FloatWriter>(participant, "canyon/float", profile::kStageWriter);
    if (config.estimator.mode == config::ProcessMode::Fusion) {
      bridged_ = create_writer<BridgedWriter>(participant, "canyon/bridged", profile::kStageWriter);
      alignment_ = create_writer<AlignmentWriter>(participant, "canyon/alignment", profile::kStageWriter);
    }
  }
  if (!config.record.empty()) start_recording(config);
}

template <typename Writer>
void RoverOutputs::record(Writer* writer, const std::string& topic) {
  if (writer == nullptr) return;
  writer->record_to(*recorder_, value_or_throw(recorder_->channel(topic, writer->type_name()), kExitRuntime));
}

void RoverOutputs::start_recording(const config::RoverConfig& config) {
  recorder_ = value_or_throw(SessionRecorder::create(config.record, {}), kExitRuntime);
  record(solution_.get(), config.solution_topic);
  record(timing_.get(), config.timing_topic);
  record(observations_.get(), "canyon/observations");
  record(prior_.get(), "canyon/prior");
  record(float_.get(), "canyon/float");
  record(bridged_.get(), "canyon/bridged");
  record(alignment_.get(), "canyon/alignment");
  record(ros2_fix_.get(), ros2_dds_topic(ros2_.fix_topic));
  record(ros2_odometry_.get(), ros2_dds_topic(ros2_.odometry_topic));
  record(ros2_diagnostics_.get(), ros2_dds_topic(ros2_.diagnostics_topic));
}

Status RoverOutputs::close_record(double process_cpu_s) {
  if (!recorder_) return Ok{};
  const std::int64_t start = thread_cpu_ns();
  Status closed = recorder_->close();  // the last chunk is compressed here
  recorder_->add_cpu_ns(thread_cpu_ns() - start);
  const double cpu_s = 1e-9 * static_cast<double>(recorder_->cpu_ns());
  spdlog::info(
      "recorded {} messages ({} bytes) to {}; recording took {:.3f} s of CPU, {:.2f} % of the rover's {:.2f} s",
      recorder_->messages(), recorder_->bytes(), recorder_->path(), cpu_s,
      process_cpu_s > 0.0 ? 100.0 * cpu_s / process_cpu_s : 0.0, process_cpu_s);
  return closed;
}

RoverOutputs::~RoverOutputs() = default;

void RoverOutputs::set_sources(const pipeline::RoverIngest& source, const pipeline::LiveVio* live_vio,
                               const pipeline::EpochPipeline& pipeline) {
  source_ = &source;
  live_vio_ = live_vio;
  pipeline_ = &pipeline;
}

pipeline::EpochSink RoverOutputs::sink() {
  return [this](const pipeline::SolvedEpoch& solved) { return write_epoch(solved); };
}

pipeline::StageObserver RoverOutputs::observer() {
  pipeline::StageObserver observer;
  observer.solved = [this](const pipeline::SolvedEpoch& solved) { take_solved(solved); };
  observer.handed_on = [this](pipeline::Stage stage) { handed_on(stage); };
  return observer;
}

Status RoverOutputs::write_epoch(const pipeline::SolvedEpoch& item) {
  ++epochs_;
  if (item.output) {
    ++solved_;
    if (item.output->solution.status == core::SolutionStatus::Fixed) ++fixed_;
    if (gga_link_) gga_link_->set_gga(io::format_gga(item.output->solution));  // uploaded at the link's interval
    if (pos_) return pos_->write(item.output->solution);
  }
  return Ok{};
}

void RoverOutputs::update_context(const pipeline::SolvedEpoch& item) {
  context_.rover_id = rover_id_;
  if (source_ != nullptr) context_.base_late = source_->base_late();
  context_.malformed_samples = malformed_payloads();
  if (live_vio_ != nullptr) {
    const pipeline::LiveVioCounts vio = live_vio_->counts();
    context_.vio_dropped = vio.dropped;
    context_.vio_late = vio.late_epochs;
  }
  if (pipeline_ != nullptr) {
    context_.queue_depth = pipeline_->queue_depths();
    context_.queue_full_waits = pipeline_->stats().full_waits;
  }
  context_.alignment_rmse_m = std::numeric_limits<double>::quiet_NaN();
  if (item.output && item.output->alignment) {
    context_.alignment_rmse_m = item.output->alignment->rmse_m;
    context_.alignment_eigen_ratio = item.output->alignment->first_eigenvalue_ratio;
    context_.lever_arm_m = item.output->alignment->t_IA_m;
  }
}

void RoverOutputs::take_solved(const pipeline::SolvedEpoch& item) {
  update_context(item);
  auto solution = to_msg_solution(item, context_);
  if (!solution_->write(solution)) refused_.fetch_add(1);
  if (observations_) {
    const pipeline::IngestedEpoch& epoch = item.epoch();
    auto observations = to_msg(epoch.rover, observations_sent_++, rover_id_, epoch.arrival_ns);
    if (!observations_->write(observations)) refused_.fetch_add(1);
  }
  timing_pending_ = to_msg_timing(item, context_);
  if (prior_) {
    prior_pending_ = to_msg_prior(item);
    float_pending_ = to_msg_float(item);
  }
  if (bridged_) bridged_pending_ = to_msg_bridged(item);
  if (alignment_) alignment_pending_ = to_msg_alignment(item);
  if (ros2_fix_) take_solved_ros2(item);
}

void RoverOutputs::take_solved_ros2(const pipeline::SolvedEpoch& item) {
  const core::Solution* solution = item.output ? &item.output->solution : nullptr;
  auto fix = to_navsatfix(item.epoch().rover.time, solution, navsat_service(item.epoch().rover), ros2_, leaps_);
  if (!ros2_fix_->write(fix)) refused_.fetch_add(1);
  const bool gnss = fix.status().status() >= sensor_msgs::msg::NavSatStatus_Constants::STATUS_FIX;
  if (!enu_origin_ && gnss && solution != nullptr) enu_origin_ = core::ecef_to_geodetic(solution->p_E_m);
  if (solution != nullptr && enu_origin_) odometry_pending_ = to_odometry(*solution, *enu_origin_, ros2_, leaps_);
  diagnostics_pending_ = to_diagnostics(*timing_pending_, solution, leaps_);
}

void RoverOutputs::handed_on(pipeline::Stage stage) {
  if (stage != pipeline::Stage::Ambiguity) return;
  write_pending(timing_, timing_pending_, refused_);
  write_pending(bridged_, bridged_pending_, refused_);
  write_pending(prior_, prior_pending_, refused_);
  write_pending(float_, float_pending_, refused_);
  write_pending(alignment_, alignment_pending_, refused_);
  write_pending(ros2_odometry_, odometry_pending_, refused_);
  write_pending(ros2_diagnostics_, diagnostics_pending_, refused_);
}

Status RoverOutputs::close_pos() {
  if (!pos_) return Ok{};
  return pos_->close();
}

bool RoverOutputs::wait_for_acknowledgments(double timeout_s) {
  return solution_->wait_for_acknowledgments(timeout_s) && timing_->wait_for_acknowledgments(timeout_s);
}

}  // namespace canyon::dds
