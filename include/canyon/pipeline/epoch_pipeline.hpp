#pragma once
// The estimation as six stages, run in order on one thread, in order with ingest and the time bridge on a second
// thread running ahead (`canyon process`), or as six threads joined by bounded lock-free single-producer/single-
// consumer queues (`canyon rover`). All three modes call the same stage functions on the same engine in the same
// order, so they give the same solutions (tests/pipeline/epoch_pipeline_test). The messages between the stages are
// typed per stage (stage_messages.hpp): IngestedEpoch, BridgedEpoch, AlignedEpoch, PredictedEpoch, UpdatedEpoch,
// SolvedEpoch.
//
//   ingest ──▶ time bridge ──▶ alignment ──▶ prediction ──▶ update ──▶ ambiguity resolution ──▶ sink
//      │  rover epoch + base   epoch geometry pending T_EO /  VIO increment  gated DD EKF   MLAMBDA, ratio, pruning,
//      │  epoch (BaseCursor    (+ C/N0), VIO  t_IA fit, VIO   as aiding, RTK  (RtkEngine::  float validation, fill-in,
//      │  or DDS), stamped     pose at the    segment book-   time update,    update)       output (finish_epoch)
//      │  on arrival           epoch's GPST   keeping         single diffs
//
// What each stage does is the engine's own code (rtk::RtkEngine and fusion::FusionEngine expose their stages; see
// their headers); rtk mode has no VIO: its time bridge builds the epoch's geometry only, its alignment stage passes
// epochs through.
//
// Honest about the parallelism: ingest (file parsing, base matching) and the time bridge (the epoch's geometry:
// satellite states, single point, base zero differences, slip scan, C/N0 screen; the read-only VIO track) run
// ahead freely. Alignment, prediction, update and ambiguity resolution share one estimator state and epoch k+1's
// alignment needs epoch k's solution (the filter is recursive), so a token returned by the last stage admits one
// epoch at a time into the alignment stage: those four stages overlap with ingest and the time bridge but not with
// each other. The bridge-ahead mode keeps just that overlap with two threads and hands epochs over in batches, for
// throughput, not latency (an epoch may wait for its batch): on cssrlib-kinematic-doy265 rtk it takes
// `canyon process` from about 37 to 28 ms on the 2-core development VM, where six threads are slower than one.
//
// Queue policy: GNSS epochs are never dropped. A full queue blocks its producer (back-pressure up to ingest, which
// then reads its input later) until the consumer has taken it down to half (core::SpscHandoff); each time a producer
// finds its queue full is counted (PipelineStats::full_waits). PipelineOptions::cpu_affinity pins stage threads.
// Stop (stop()): ingest stops reading; every epoch already ingested goes through every stage and reaches the sink.
// Ephemerides that arrive while running (IngestedEpoch::navigation, rare: a satellite's new ephemeris every hour or
// two) drain the pipeline: that epoch enters the time bridge once every earlier epoch has left the last stage.

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "canyon/core/ephemeris.hpp"
#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/core/solution.hpp"
#include "canyon/core/spsc_handoff.hpp"
#include "canyon/fusion/fusion_engine.hpp"
#include "canyon/fusion/fusion_geometry.hpp"
#include "canyon/fusion/vio_track.hpp"
#include "canyon/pipeline/link_counts.hpp"
#include "canyon/pipeline/stage_messages.hpp"
#include "canyon/rtk/engine.hpp"

namespace canyon::pipeline {

/// The pipeline clock: monotonic nanoseconds (steady_clock).
[[nodiscard]] std::int64_t monotonic_ns();

/// Where epochs come from (the ingest stage): a rover epoch with its base epoch.
class EpochSource {
 public:
  virtual ~EpochSource() = default;
  /// The next epoch (rover, base; seq and times are set by the pipeline); nullopt at the end of the input.
  virtual Result<std::optional<IngestedEpoch>> next() = 0;
};

/// The estimator's stages (see the engines' headers for what each does), each taking its stage's input message and
/// making its output. bridge() is const and may run on another thread than the others; the others run one epoch at
/// a time, in order.
class EpochEstimator {
 public:
  virtual ~EpochEstimator() = default;
  [[nodiscard]] virtual BridgedEpoch bridge(IngestedEpoch epoch) const = 0;
  [[nodiscard]] virtual AlignedEpoch align(BridgedEpoch epoch) = 0;
  [[nodiscard]] virtual PredictedEpoch predict(AlignedEpoch epoch) = 0;
  /// The update, when the prediction's verdict asks for it.
  [[nodiscard]] virtual UpdatedEpoch update(PredictedEpoch epoch) = 0;
  /// Ambiguity resolution (when the update asked for it) and the epoch's output.
  [[nodiscard]] virtual SolvedEpoch resolve(UpdatedEpoch epoch) = 0;
  /// End of the input (a pending alignment).
  virtual void finish() = 0;
  /// Ephemerides that arrived while running (IngestedEpoch::navigation), for the store the stages read. The pipeline
  /// calls it while no stage runs (see IngestedEpoch::navigation). Default: ignored.
  virtual void add_navigation(const core::NavigationData& /*fresh*/) {}
};

/// RTK (rtk::RtkEngine): no VIO and no alignment; the time bridge builds each epoch's geometry (single-point
/// solution, observables, satellite states, cycle-slip scan: rtk/epoch_geometry.hpp) ahead of the filter, and bridges
/// no time.
class RtkEstimator final : public EpochEstimator {
 public:
  explicit RtkEstimator(rtk::RtkEngine& engine)
      : engine_(engine), geometry_(engine.geometry_options(), engine.ephemerides(), engine.base_position_E_m()) {}
  [[nodiscard]] BridgedEpoch bridge(IngestedEpoch epoch) const override;
  [[nodiscard]] AlignedEpoch align(BridgedEpoch epoch) override { return AlignedEpoch{std::move(epoch)}; }
  [[nodiscard]] PredictedEpoch predict(AlignedEpoch epoch) override;
  [[nodiscard]] UpdatedEpoch update(PredictedEpoch epoch) override;
  [[nodiscard]] SolvedEpoch resolve(UpdatedEpoch epoch) override;
  void finish() override {}

 private:
  rtk::RtkEngine& engine_;
  // The bridge's own builder: bridge() runs on one thread, epoch after epoch (const for the interface's sake).
  mutable rtk::EpochGeometryBuilder geometry_;
};

class LiveVio;

/// The paper's fusion (fusion::FusionEngine). The time bridge builds each epoch's geometry (fusion/fusion_geometry.hpp)
/// ahead of the filter, then takes its VIO pose at the epoch's GPST; with a live VIO stream (live_vio.hpp) it waits
/// for the VIO to cover the epoch.
class FusionEstimator final : public EpochEstimator {
 public:
  explicit FusionEstimator(fusion::FusionEngine& engine, LiveVio* live_vio = nullptr)
      : engine_(engine), live_vio_(live_vio), geometry_(engine.make_geometry_builder()) {}
  [[nodiscard]] BridgedEpoch bridge(IngestedEpoch epoch) const override;
  [[nodiscard]] AlignedEpoch align(BridgedEpoch epoch) override;
  [[nodiscard]] PredictedEpoch predict(AlignedEpoch epoch) override;
  [[nodiscard]] UpdatedEpoch update(PredictedEpoch epoch) override;
  [[nodiscard]] SolvedEpoch resolve(UpdatedEpoch epoch) override;
  void finish() override { engine_.flush_alignment(); }

 private:
  fusion::FusionEngine& engine_;
  LiveVio* live_vio_;
  // The bridge's own builder: bridge() runs on one thread, epoch after epoch (const for the interface's sake).
  mutable fusion::FusionGeometryBuilder geometry_;
};

/// Receives each epoch after its last stage (on the ambiguity stage's thread); an error stops the pipeline.
using EpochSink = std::function<Status(const SolvedEpoch&)>;
/// What a stage's output means to the outside (the rover publishes it on DDS), in two steps, both on the stage's
/// thread, each once per epoch and stage:
///  - taken(stage, item): right after the stage, before the epoch moves on. It delays the epoch: keep it quick (take
///    a copy of what a message needs), except for what must leave first (the rover writes the solution here).
///  - handed_on(stage): once the epoch has moved on (threaded: queued for the next stage, or for the ambiguity stage
///    after the sink; bridge-ahead: ingest and time bridge once queued, the others after the sink; sequential: after
///    the epoch's sink, stage by stage). The place for slow work such as DDS
///    writes: it no longer delays this epoch, and in the threaded pipeline it overlaps the next stage.
///  - solved(epoch): the whole epoch right after the ambiguity stage (after its taken()), before the sink.
struct StageObserver {
  std::function<void(Stage, const IngestedEpoch&)> taken;
  std::function<void(const SolvedEpoch&)> solved;
  std::function<void(Stage)> handed_on;
};

struct PipelineOptions {
  bool threaded = false;            ///< six threads and queues; false: the estimator's stages on the caller's thread
  std::size_t queue_capacity = 64;  ///< epochs per queue (threaded, bridge_ahead)
  /// Not threaded: ingest and the time bridge on a second thread, up to queue_capacity epochs ahead of the estimator
  /// stages (which stay on the caller's thread, one after the other), handing the epochs over in batches. Off:
  /// all six stages on the caller's thread.
  bool bridge_ahead = false;
  /// Threaded only: by Stage, the CPUs that stage's thread may run on (empty: wherever the OS schedules it). With
  /// alignment, prediction, update and ambiguity resolution on one CPU, an epoch's hand-offs between them wake a
  /// thread on the same CPU instead of another CPU's.
  std::array<std::vector<int>, kNumStages> cpu_affinity{};
  [[nodiscard]] bool pinned() const;  ///< some stage has CPUs in cpu_affinity
  [[nodiscard]] std::string validate() const;
  /// "" if every CPU of cpu_affinity is one this process may run on (this machine's, and not excluded by taskset or
  /// a container); else which stage names which CPU.
  [[nodiscard]] std::string unavailable_cpu() const;
};

struct PipelineStats {
  std::uint64_t epochs = 0;  ///< epochs that reached the sink
  /// Per queue (ingest->bridge, bridge->alignment, alignment->prediction, prediction->update, update->ambiguity):
  /// times its producer found it full and waited.
  std::array<std::uint64_t, kNumStages - 1> full_waits{};
};

class EpochPipeline {
 public:
  EpochPipeline(EpochSource& source, EpochEstimator& estimator, EpochSink sink, PipelineOptions options,
                StageObserver observer = {});
  ~EpochPipeline();
  EpochPipeline(const EpochPipeline&) = delete;
  EpochPipeline& operator=(const EpochPipeline&) = delete;

  /// Runs until the source ends, stop() is called, or an error (source, sink). Epochs already ingested are finished
  /// either way. The first error, if any.
  Status run();
  /// Asks ingest to stop reading (thread- and signal-safe: one atomic store).
  void stop() { stop_.store(true); }
  [[nodiscard]] bool stop_requested() const { return stop_.load(); }
  /// Epochs in each queue now (approximate, thread-safe; all zero when sequential).
  [[nodiscard]] std::array<std::size_t, kNumStages - 1> queue_depths() const;
  [[nodiscard]] PipelineStats stats() const;

 private:
  struct Queues;
  Status run_sequential();
  Status run_bridge_ahead();
  Status run_threaded();
  /// A middle stage's thread of the threaded layout: `step` on each epoch from `in`, its output to `out`.
  template <typename In, typename Out, typename Step>
  void stage_thread(Stage stage, core::SpscHandoff<std::optional<In>>& in, core::SpscHandoff<std::optional<Out>>& out,
                    Step step);
  /// Restricts the calling thread to `stage`'s CPUs, if it has any (a refusal by the kernel fails the run).
  void pin(Stage stage);
  /// The ingest stage's bookkeeping for an epoch the source returned: sequence number, arrival and exit times.
  void ingested(IngestedEpoch& epoch, std::uint64_t seq, std::int64_t enter_ns);
  /// The ingest stage of the threaded layouts: the source's next epoch, stamped (ingested()); nullopt at the end of
  /// the input, or after the source's error (recorded by fail()).
  std::optional<IngestedEpoch> ingest_next(std::uint64_t seq);
  // The stages after ingest, each timed in the epoch's clock and observed (taken(); resolve() also solved()).
  BridgedEpoch bridge(IngestedEpoch epoch);
  AlignedEpoch align(BridgedEpoch epoch);
  PredictedEpoch predict(AlignedEpoch epoch);
  UpdatedEpoch update(PredictedEpoch epoch);
  SolvedEpoch resolve(UpdatedEpoch epoch);
  /// Runs `step` on `in` as `stage`: its enter and exit times in the epoch's clock, then taken().
  template <typename Out, typename In, typename Step>
  Out timed(Stage stage, In in, Step step);
  /// An epoch past the last stage: counted and sunk (unless the pipeline failed); an error of the sink fails it.
  void sink(const SolvedEpoch& epoch);
  void handed_on(Stage stage) const {
    if (observer_.handed_on) observer_.handed_on(stage);
  }
  /// Waits until every epoch before `epoch` has left the last stage, then hands its ephemerides to the estimator.
  void add_navigation(const IngestedEpoch& epoch);
  void fail(const Error& error);

  EpochSource& source_;
  EpochEstimator& estimator_;
  EpochSink sink_;
  PipelineOptions options_;
  StageObserver observer_;
  std::unique_ptr<Queues> queues_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> failed_{false};
  std::atomic<std::uint64_t> epochs_{0};
  std::array<std::atomic<std::uint64_t>, kNumStages - 1> full_waits_{};
  std::mutex error_mutex_;
  Error error_;  // the first error (under error_mutex_)
};

}  // namespace canyon::pipeline
