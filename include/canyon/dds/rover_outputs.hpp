#pragma once
// The rover's per-epoch outputs: the one place where canyon rover meets the pipeline's stage messages
// (pipeline::SolvedEpoch, pipeline::StageObserver, pipeline::EpochSink) besides the conversions of rover_msgs.hpp.
//   - sink(): the epoch's solution to the .pos (estimator.out) and, for an NTRIP base, as the GGA the link uploads;
//     the epoch counts;
//   - observer(): the solution is published the moment the ambiguity stage has it. The stage outputs (canyon/bridged,
//     /prior, /float, /alignment: every stage's output is still in the epoch then) and the timing are taken then too
//     and written once the epoch has moved on (StageObserver::handed_on): their DDS writes delay no epoch and, in the
//     threaded pipeline, no other stage's thread (on two cores a write on the time bridge's thread held up the next
//     stage's wake-up). The pending messages belong to the ambiguity stage's thread.
// It owns the rover's writers (the solution and timing topics; with dds.publish_stages the stage outputs; with
// ros2.enabled the ROS 2 topics: NavSatFix at once, Odometry and DiagnosticArray with the timing).

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>

#include "canyon/config/rover_config.hpp"
#include "canyon/dds/dds.hpp"
#include "canyon/dds/observation_msgs.hpp"
#include "canyon/dds/ros2_msgs.hpp"
#include "canyon/dds/rover_msgs.hpp"
#include "canyon/io/pos_file.hpp"
#include "canyon/pipeline/byte_link.hpp"
#include "canyon/pipeline/epoch_pipeline.hpp"
#include "canyon/pipeline/live_vio.hpp"
#include "canyon/pipeline/rover_ingest.hpp"

namespace canyon::dds {

class RoverOutputs {
 public:
  /// The solution and timing writers, and with dds.publish_stages the stage writers (canyon/bridged and
  /// canyon/alignment in fusion mode only); AppError if one cannot be created.
  RoverOutputs(DdsParticipant& participant, const config::RoverConfig& config);
  ~RoverOutputs();
  RoverOutputs(const RoverOutputs&) = delete;
  RoverOutputs& operator=(const RoverOutputs&) = delete;

  /// The .pos the sink writes (estimator.out).
  void set_pos(io::PosWriter pos) { pos_.emplace(std::move(pos)); }
  /// The link that uploads the rover's latest solution as GGA (input.ntrip_gga_interval_s > 0).
  void set_gga_link(std::shared_ptr<pipeline::ByteLink> link) { gga_link_ = std::move(link); }
  /// What the messages carry besides the epoch: late base epochs, the live VIO's counts (may be null), the queues.
  void set_sources(const pipeline::RoverIngest& source, const pipeline::LiveVio* live_vio,
                   const pipeline::EpochPipeline& pipeline);

  [[nodiscard]] pipeline::EpochSink sink();
  [[nodiscard]] pipeline::StageObserver observer();

  /// Closes the .pos, if any (a write error that happened on the way).
  Status close_pos();
  /// Closes the in-process recording (dds.record), if any, and logs what it held and cost: its thread CPU time against
  /// `process_cpu_s`, the rover's; a write error that happened on the way.
  Status close_record(double process_cpu_s);
  /// Readers matched now of the solution topic and, with ros2.enabled, of the three ROS 2 topics, counted together.
  [[nodiscard]] int solution_readers() const {
    int readers = solution_->matched();
    if (ros2_fix_) readers += ros2_fix_->matched() + ros2_odometry_->matched() + ros2_diagnostics_->matched();
    return readers;
  }
  /// Waits until the solution and timing readers acknowledged every sample, at most timeout_s each.
  bool wait_for_acknowledgments(double timeout_s);
  /// Samples the writers refused (history full).
  [[nodiscard]] std::uint64_t refused() const { return refused_.load(); }
  [[nodiscard]] std::uint64_t epochs() const { return epochs_; }
  [[nodiscard]] std::uint64_t solved() const { return solved_; }
  [[nodiscard]] std::uint64_t fixed() const { return fixed_; }

 private:
  Status write_epoch(const pipeline::SolvedEpoch& item);
  void take_solved(const pipeline::SolvedEpoch& item);
  void handed_on(pipeline::Stage stage);
  void update_context(const pipeline::SolvedEpoch& item);
  /// The ROS 2 messages of the epoch: NavSatFix written now, Odometry and DiagnosticArray pending.
  void take_solved_ros2(const pipeline::SolvedEpoch& item);
  void start_recording(const config::RoverConfig& config);
  template <typename Writer>
  void record(Writer* writer, const std::string& topic);

  std::string rover_id_;
  std::unique_ptr<SolutionWriter> solution_;
  std::unique_ptr<TimingWriter> timing_;
  std::unique_ptr<BridgedWriter> bridged_;
  std::unique_ptr<AlignmentWriter> alignment_;
  std::unique_ptr<PriorWriter> prior_;
  std::unique_ptr<FloatWriter> float_;
  std::unique_ptr<ObservationWriter> observations_;  ///< dds.publish_observations only
  std::unique_ptr<SessionRecorder> recorder_;        ///< dds.record only
  std::uint64_t observations_sent_ = 0;
  config::Ros2Options ros2_;
  core::LeapSecondTable leaps_;
  std::unique_ptr<NavSatFixWriter> ros2_fix_;
  std::unique_ptr<OdometryWriter> ros2_odometry_;
  std::unique_ptr<DiagnosticsWriter> ros2_diagnostics_;
  std::optional<core::Geodetic> enu_origin_;  // ros2.enu_origin_llh, else the first GNSS fix
  std::optional<io::PosWriter> pos_;
  std::shared_ptr<pipeline::ByteLink> gga_link_;
  const pipeline::RoverIngest* source_ = nullptr;
  const pipeline::LiveVio* live_vio_ = nullptr;
  const pipeline::EpochPipeline* pipeline_ = nullptr;
  // The sink's thread.
  std::uint64_t epochs_ = 0, solved_ = 0, fixed_ = 0;
  // The ambiguity stage's thread.
  EpochContext context_;
  std::optional<msg::BridgedEpoch> bridged_pending_;
  std::optional<msg::Prior> prior_pending_;
  std::optional<msg::FloatSolution> float_pending_;
  std::optional<msg::Alignment> alignment_pending_;
  std::optional<msg::StageTiming> timing_pending_;
  std::optional<nav_msgs::msg::dds_::Odometry_> odometry_pending_;
  std::optional<diagnostic_msgs::msg::dds_::DiagnosticArray_> diagnostics_pending_;
  std::atomic<std::uint64_t> refused_{0};  // the time bridge's and the ambiguity stage's threads publish
};

}  // namespace canyon::dds
