// The staged estimation pipeline (see epoch_pipeline.hpp).

#include "canyon/pipeline/epoch_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include "canyon/core/batch_queue.hpp"
#include "canyon/core/spsc_handoff.hpp"
#include "canyon/core/time.hpp"
#include "canyon/pipeline/cpu_affinity.hpp"
#include "canyon/pipeline/live_vio.hpp"

namespace canyon::pipeline {
namespace {

/// The output fields both engines' epochs have (rtk::RtkEpoch, fusion::FusionEpoch), with the RTK filter's figures
/// from `filter` (rtk mode: the epoch itself; fusion: its RTK filter's epoch, FusionEpoch::rtk).
template <typename Epoch>
EpochOutput output_of(Epoch& epoch, const rtk::RtkEpoch& filter) {
  EpochOutput out;
  out.has_float = filter.num_dd_measurements > 0;
  out.float_p_E_m = filter.float_p_E_m;
  out.float_P_E_m2 = filter.float_P_E_m2;
  out.dd_phase_rows = filter.num_dd_measurements;
  out.dd_code_rows = filter.num_dd_code_measurements;
  out.max_post_fit_normalised = filter.max_post_fit_normalised;
  out.has_prior = filter.aided;
  out.prior_p_E_m = filter.prior_p_E_m;
  out.prior_P_E_m2 = filter.prior_P_E_m2;
  out.solution = epoch.solution;
  out.hdop = epoch.hdop;
  out.note = std::move(epoch.note);
  out.rejected = std::move(epoch.rejected);
  out.ar_pruned = std::move(epoch.ar_pruned);
  return out;
}

/// A failed prediction is the solved epoch's output (its error); true when it failed, and nothing is left to resolve.
bool prediction_failed(SolvedEpoch& solved) {
  const Result<bool>& verdict = solved.updated.predicted.verdict;
  if (verdict) return false;
  solved.output = verdict.error();
  return true;
}

/// The prediction's verdict: go on to the update.
bool goes_on(const PredictedEpoch& epoch) {
  return epoch.verdict && *epoch.verdict;
}

}  // namespace

const char* stage_name(Stage stage) {
  switch (stage) {
    case Stage::Ingest: return "ingest";
    case Stage::TimeBridge: return "time_bridge";
    case Stage::Alignment: return "alignment";
    case Stage::Prediction: return "prediction";
    case Stage::Update: return "update";
    case Stage::Ambiguity: return "ambiguity";
  }
  return "?";
}

std::int64_t monotonic_ns() {
  return core::pipeline_now_ns();
}

// ---- Estimators: the engines' stages ----

BridgedEpoch RtkEstimator::bridge(IngestedEpoch epoch) const {
  if (epoch.base_position_E_m) geometry_.set_base_position(*epoch.base_position_E_m);
  rtk::EpochGeometry geometry = geometry_.build(epoch.rover, epoch.base_epoch());
  return BridgedEpoch{std::move(epoch), fusion::FusionGeometry{std::move(geometry), std::nullopt, 0}, std::nullopt};
}

PredictedEpoch RtkEstimator::predict(AlignedEpoch epoch) {
  const IngestedEpoch& e = epoch.bridged.epoch;
  if (e.base_position_E_m) engine_.set_base_position(*e.base_position_E_m);
  Result<bool> verdict = engine_.predict(e.rover, e.base_epoch(), nullptr, &epoch.bridged.geometry.rtk);
  return PredictedEpoch{std::move(epoch), std::move(verdict)};
}

UpdatedEpoch RtkEstimator::update(PredictedEpoch epoch) {
  const bool to_resolve = goes_on(epoch) && engine_.update();
  return UpdatedEpoch{std::move(epoch), to_resolve};
}

SolvedEpoch RtkEstimator::resolve(UpdatedEpoch epoch) {
  SolvedEpoch solved{std::move(epoch)};
  if (prediction_failed(solved)) return solved;
  if (solved.updated.to_resolve) engine_.resolve();
  rtk::RtkEpoch result = engine_.take_epoch();
  solved.output = output_of(result, result);
  return solved;
}

BridgedEpoch FusionEstimator::bridge(IngestedEpoch epoch) const {
  if (epoch.base_position_E_m) geometry_.set_base_position(*epoch.base_position_E_m);
  fusion::FusionGeometry geometry = geometry_.build(epoch.rover, epoch.base_epoch());
  if (live_vio_ != nullptr) live_vio_->await(epoch.rover.time);
  std::optional<fusion::VioPoseAt> pose = engine_.bridge(epoch.rover.time);
  return BridgedEpoch{std::move(epoch), std::move(geometry), std::move(pose)};
}

AlignedEpoch FusionEstimator::align(BridgedEpoch epoch) {
  engine_.align(epoch.epoch.rover.time, epoch.pose);
  return AlignedEpoch{std::move(epoch)};
}

PredictedEpoch FusionEstimator::predict(AlignedEpoch epoch) {
  BridgedEpoch& b = epoch.bridged;
  if (b.epoch.base_position_E_m) engine_.set_base_position(*b.epoch.base_position_E_m);
  Result<bool> verdict = engine_.predict(b.epoch.rover, b.epoch.base_epoch(), b.pose, &b.geometry);
  return PredictedEpoch{std::move(epoch), std::move(verdict)};
}

UpdatedEpoch FusionEstimator::update(PredictedEpoch epoch) {
  const bool to_resolve = goes_on(epoch) && engine_.update();
  return UpdatedEpoch{std::move(epoch), to_resolve};
}

SolvedEpoch FusionEstimator::resolve(UpdatedEpoch epoch) {
  SolvedEpoch solved{std::move(epoch)};
  if (prediction_failed(solved)) return solved;
  if (solved.updated.to_resolve) engine_.resolve();
  fusion::FusionEpoch result = engine_.finish_epoch();
  EpochOutput out = output_of(result, result.rtk);
  out.aided = result.aided;
  if (!engine_.stats().alignment.events.empty()) {
    const fusion::AlignmentEvent& a = engine_.stats().alignment.events.back();
    out.alignment = EpochOutput::Alignment{a.kind, a.rmse_m, a.first_eigenvalue_ratio, engine_.lever_arm_m()};
  }
  solved.output = std::move(out);
  return solved;
}

// ---- The pipeline ----

bool PipelineOptions::pinned() const {
  return std::any_of(cpu_affinity.begin(), cpu_affinity.end(), [](const auto& cpus) { return !cpus.empty(); });
}

std::string PipelineOptions::validate() const {
  if (queue_capacity < 1 || queue_capacity > 65536) return "queue_capacity must be in 1..65536";
  // A CPU number out of range is never one the process may use: unavailable_cpu() names it before any thread starts.
  if (pinned() && !threaded) return "cpu_affinity is for the threaded pipeline (threaded: true)";
  return {};
}

std::string PipelineOptions::unavailable_cpu() const {
  if (!pinned()) return {};
  const std::vector<int> allowed = allowed_cpus();
  for (std::size_t s = 0; s < kNumStages; ++s) {
    for (const int cpu : cpu_affinity[s]) {
      if (!std::binary_search(allowed.begin(), allowed.end(), cpu)) {
        return std::string("cpu_affinity.") + stage_name(static_cast<Stage>(s)) + ": CPU " + std::to_string(cpu) +
               " is not one this process may run on (" + cpu_list_text(allowed) + ")";
      }
    }
  }
  return {};
}

/// Epochs per hand-over in the bridge-ahead pipeline.
constexpr std::size_t kBridgeAheadBatch = 4;

/// The queues of the threaded layout: queue i joins stage i to stage i + 1 (nullopt: the end of the stream).
struct EpochPipeline::Queues {
  explicit Queues(std::size_t capacity)
      : ingested(capacity), bridged(capacity), aligned(capacity), predicted(capacity), updated(capacity) {}
  core::SpscHandoff<std::optional<IngestedEpoch>> ingested;
  core::SpscHandoff<std::optional<BridgedEpoch>> bridged;
  core::SpscHandoff<std::optional<AlignedEpoch>> aligned;
  core::SpscHandoff<std::optional<PredictedEpoch>> predicted;
  core::SpscHandoff<std::optional<UpdatedEpoch>> updated;
  core::SpscHandoff<bool> tokens{2};  // ambiguity -> alignment: the estimator state is free for the next epoch
};

EpochPipeline::EpochPipeline(EpochSource& source, EpochEstimator& estimator, EpochSink sink, PipelineOptions options,
                             StageObserver observer)
    : source_(source),
      estimator_(estimator),
      sink_(std::move(sink)),
      options_(std::move(options)),
      observer_(std::move(observer)) {
  for (auto& w : full_waits_) w.store(0);
  if (options_.threaded) queues_ = std::make_unique<Queues>(options_.queue_capacity);
}

EpochPipeline::~EpochPipeline() = default;

void EpochPipeline::fail(const Error& error) {
  const std::lock_guard lock(error_mutex_);
  if (failed_.load()) return;
  error_ = error;
  failed_.store(true);
  stop_.store(true);
}

std::array<std::size_t, kNumStages - 1> EpochPipeline::queue_depths() const {
  if (!queues_) return {};
  const Queues& q = *queues_;
  return {q.ingested.size_approx(), q.bridged.size_approx(), q.aligned.size_approx(), q.predicted.size_approx(),
          q.updated.size_approx()};
}

PipelineStats EpochPipeline::stats() const {
  PipelineStats s;
  s.epochs = epochs_.load();
  for (std::size_t i = 0; i < s.full_waits.size(); ++i) s.full_waits[i] = full_waits_[i].load();
  return s;
}

Status EpochPipeline::run() {
  if (const std::string e = options_.validate(); !e.empty()) return Error{"pipeline: " + e};
  Status s = options_.threaded ? run_threaded() : options_.bridge_ahead ? run_bridge_ahead() : run_sequential();
  if (!s) return s;
  const std::lock_guard lock(error_mutex_);
  if (failed_.load()) return error_;
  return Ok{};
}

// ---- The stages ----

void EpochPipeline::ingested(IngestedEpoch& epoch, std::uint64_t seq, std::int64_t enter_ns) {
  epoch.seq = seq;
  if (epoch.arrival_ns == 0) epoch.arrival_ns = enter_ns;
  epoch.clock.enter_ns[0] = epoch.arrival_ns;
  epoch.clock.exit_ns[0] = monotonic_ns();
  if (observer_.taken) observer_.taken(Stage::Ingest, epoch);
}

std::optional<IngestedEpoch> EpochPipeline::ingest_next(std::uint64_t seq) {
  const std::int64_t enter = monotonic_ns();
  auto next = source_.next();
  if (!next) {
    fail(next.error());
    return std::nullopt;
  }
  if (!*next) return std::nullopt;
  ingested(**next, seq, enter);
  return std::move(*next);
}

template <typename Out, typename In, typename Step>
Out EpochPipeline::timed(Stage stage, In in, Step step) {
  const auto i = static_cast<std::size_t>(stage);
  epoch_of(in).clock.enter_ns[i] = monotonic_ns();
  Out out = step(std::move(in));
  IngestedEpoch& epoch = epoch_of(out);
  epoch.clock.exit_ns[i] = monotonic_ns();
  if (observer_.taken) observer_.taken(stage, epoch);
  return out;
}

BridgedEpoch EpochPipeline::bridge(IngestedEpoch epoch) {
  return timed<BridgedEpoch>(Stage::TimeBridge, std::move(epoch), [this](IngestedEpoch e) {
    if (e.navigation) add_navigation(e);
    return estimator_.bridge(std::move(e));
  });
}

AlignedEpoch EpochPipeline::align(BridgedEpoch epoch) {
  return timed<AlignedEpoch>(Stage::Alignment, std::move(epoch),
                             [this](BridgedEpoch e) { return estimator_.align(std::move(e)); });
}

PredictedEpoch EpochPipeline::predict(AlignedEpoch epoch) {
  return timed<PredictedEpoch>(Stage::Prediction, std::move(epoch),
                               [this](AlignedEpoch e) { return estimator_.predict(std::move(e)); });
}

UpdatedEpoch EpochPipeline::update(PredictedEpoch epoch) {
  return timed<UpdatedEpoch>(Stage::Update, std::move(epoch),
                             [this](PredictedEpoch e) { return estimator_.update(std::move(e)); });
}

SolvedEpoch EpochPipeline::resolve(UpdatedEpoch epoch) {
  SolvedEpoch solved = timed<SolvedEpoch>(Stage::Ambiguity, std::move(epoch),
                                          [this](UpdatedEpoch e) { return estimator_.resolve(std::move(e)); });
  if (observer_.solved) observer_.solved(solved);
  return solved;
}

void EpochPipeline::sink(const SolvedEpoch& epoch) {
  ++epochs_;
  // After a failure (source or sink) the epochs already in the pipeline still go through its stages.
  if (failed_.load()) return;
  if (Status w = sink_(epoch); !w) fail(w.error());
}

void EpochPipeline::add_navigation(const IngestedEpoch& epoch) {
  // Every earlier epoch has left the last stage (sequential: always so), then no stage reads the ephemerides.
  while (epochs_.load() < epoch.seq) std::this_thread::sleep_for(std::chrono::microseconds(50));
  estimator_.add_navigation(*epoch.navigation);
}

// ---- The layouts ----

Status EpochPipeline::run_sequential() {
  for (std::uint64_t seq = 0; !stop_.load(); ++seq) {
    const std::int64_t enter = monotonic_ns();
    auto next = source_.next();
    if (!next) return next.error();
    if (!*next) break;
    ingested(**next, seq, enter);
    const SolvedEpoch solved = resolve(update(predict(align(bridge(std::move(**next))))));
    ++epochs_;
    Status w = sink_(solved);
    for (std::size_t s = 0; s < kNumStages; ++s) handed_on(static_cast<Stage>(s));
    if (!w) return w;
  }
  estimator_.finish();
  return Ok{};
}

Status EpochPipeline::run_bridge_ahead() {
  // Epochs cross from the ingest and time-bridge thread to this one in batches (core::BatchQueue): one lock and at
  // most one wake-up per batch, not per epoch. And they go back to be freed where they were allocated: glibc gives
  // each thread its own heap arena, and this thread freeing the other's blocks contended for that arena's lock on
  // every epoch (about 300 futex waits on cssrlib-kinematic-doy265, which cost more than the second thread saved).
  core::BatchQueue<BridgedEpoch> ready(options_.queue_capacity, kBridgeAheadBatch);
  std::mutex spent_mutex;
  std::vector<SolvedEpoch> spent;  // under spent_mutex: epochs past the sink, for the ingest thread to free
  std::thread ahead([this, &ready, &spent_mutex, &spent] {
    std::vector<SolvedEpoch> to_free;
    for (std::uint64_t seq = 0; !stop_.load(); ++seq) {
      {
        const std::lock_guard lock(spent_mutex);
        to_free.swap(spent);
      }
      to_free.clear();
      std::optional<IngestedEpoch> epoch = ingest_next(seq);
      if (!epoch) break;
      // Fresh ephemerides wait for every earlier epoch to leave the last stage: those still batched must go first.
      if (epoch->navigation && !ready.flush()) break;
      if (!ready.push(bridge(std::move(*epoch)))) break;
      handed_on(Stage::Ingest);
      handed_on(Stage::TimeBridge);
    }
    ready.close();
  });
  while (std::optional<BridgedEpoch> epoch = ready.pop()) {
    SolvedEpoch solved = resolve(update(predict(align(std::move(*epoch)))));
    sink(solved);
    for (std::size_t s = static_cast<std::size_t>(Stage::Alignment); s < kNumStages; ++s) {
      handed_on(static_cast<Stage>(s));
    }
    solved.output = Error{};  // this thread's allocations: freed here
    const std::lock_guard lock(spent_mutex);
    spent.push_back(std::move(solved));
  }
  ahead.join();  // the epochs still in `spent` are freed here, with the vector
  full_waits_[static_cast<std::size_t>(Stage::TimeBridge)] = ready.full_waits();
  estimator_.finish();
  return Ok{};
}

void EpochPipeline::pin(Stage stage) {
  const std::vector<int>& cpus = options_.cpu_affinity[static_cast<std::size_t>(stage)];
  if (cpus.empty()) return;
  if (Status s = pin_this_thread(cpus); !s) {
    fail(Error{std::string("pipeline: the ") + stage_name(stage) + " thread: " + s.error().message});
  }
}

template <typename In, typename Out, typename Step>
void EpochPipeline::stage_thread(Stage stage, core::SpscHandoff<std::optional<In>>& in,
                                 core::SpscHandoff<std::optional<Out>>& out, Step step) {
  const auto out_index = static_cast<std::size_t>(stage);  // queue i joins stage i to stage i + 1
  pin(stage);
  bool first = true;
  for (;;) {
    std::optional<In> epoch = in.pop();
    if (!epoch) break;
    if (stage == Stage::Alignment) {
      if (!first) (void)queues_->tokens.pop();  // the estimator is free: the last epoch left the ambiguity stage
      first = false;
    }
    if (out.push(step(std::move(*epoch)))) ++full_waits_[out_index];  // never drops: back-pressure
    handed_on(stage);
  }
  if (out.push(std::nullopt)) ++full_waits_[out_index];
}

Status EpochPipeline::run_threaded() {
  if (const std::string e = options_.unavailable_cpu(); !e.empty()) return Error{"pipeline: " + e};
  const std::vector<int> caller_cpus = this_thread_cpus();  // this thread runs the last stage, then gets them back
  Queues& q = *queues_;
  std::thread ingest([this, &q] {
    pin(Stage::Ingest);
    for (std::uint64_t seq = 0; !stop_.load(); ++seq) {
      std::optional<IngestedEpoch> epoch = ingest_next(seq);
      if (!epoch) break;
      if (q.ingested.push(std::move(epoch))) ++full_waits_[0];
      handed_on(Stage::Ingest);
    }
    if (q.ingested.push(std::nullopt)) ++full_waits_[0];
  });
  std::thread bridge_thread([this, &q] {
    stage_thread(Stage::TimeBridge, q.ingested, q.bridged, [this](IngestedEpoch e) { return bridge(std::move(e)); });
  });
  std::thread align_thread([this, &q] {
    stage_thread(Stage::Alignment, q.bridged, q.aligned, [this](BridgedEpoch e) { return align(std::move(e)); });
  });
  std::thread predict_thread([this, &q] {
    stage_thread(Stage::Prediction, q.aligned, q.predicted, [this](AlignedEpoch e) { return predict(std::move(e)); });
  });
  std::thread update_thread([this, &q] {
    stage_thread(Stage::Update, q.predicted, q.updated, [this](PredictedEpoch e) { return update(std::move(e)); });
  });
  // Ambiguity resolution and the sink, on this thread.
  pin(Stage::Ambiguity);
  while (std::optional<UpdatedEpoch> epoch = q.updated.pop()) {
    const SolvedEpoch solved = resolve(std::move(*epoch));
    (void)q.tokens.push(true);  // the estimator is free for the next epoch's alignment
    sink(solved);
    handed_on(Stage::Ambiguity);
  }
  ingest.join();
  bridge_thread.join();
  align_thread.join();
  predict_thread.join();
  update_thread.join();
  if (options_.pinned() && !caller_cpus.empty()) (void)pin_this_thread(caller_cpus);
  estimator_.finish();
  return Ok{};
}

}  // namespace canyon::pipeline
