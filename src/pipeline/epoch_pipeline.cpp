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
/// from `filter` (rtk mode: the epoch itself; fusion: its RTK engine's epoch, FusionEpoch::rtk).
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

/// The prediction stage's verdict (either engine's predict()) into the epoch.
void record_prediction(EpochItem& item, const Result<bool>& more) {
  if (more) {
    item.to_update = *more;
  } else {
    item.error = more.error();
  }
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

void RtkEstimator::bridge(EpochItem& item) const {
  if (item.base_position_E_m) geometry_.set_base_position(*item.base_position_E_m);
  item.geometry.emplace(geometry_.build(item.rover, item.base ? &*item.base : nullptr));
}

void RtkEstimator::predict(EpochItem& item) {
  if (item.base_position_E_m) engine_.set_base_position(*item.base_position_E_m);
  const core::ObsEpoch* base = item.base ? &*item.base : nullptr;
  record_prediction(item, engine_.predict(item.rover, base, nullptr, item.geometry ? &*item.geometry : nullptr));
}

void RtkEstimator::update(EpochItem& item) {
  if (item.to_update) item.to_resolve = engine_.update();
}

void RtkEstimator::resolve(EpochItem& item) {
  if (item.error) return;
  if (item.to_resolve) engine_.resolve();
  rtk::RtkEpoch epoch = engine_.take_epoch();
  item.output = output_of(epoch, epoch);
}

void FusionEstimator::bridge(EpochItem& item) const {
  if (item.base_position_E_m) geometry_.set_base_position(*item.base_position_E_m);
  item.fusion_geometry.emplace(geometry_.build(item.rover, item.base ? &*item.base : nullptr));
  if (live_vio_ != nullptr) live_vio_->await(item.rover.time);
  item.pose = engine_.bridge(item.rover.time);
}

void FusionEstimator::align(EpochItem& item) {
  engine_.align(item.rover.time, item.pose);
}

void FusionEstimator::predict(EpochItem& item) {
  if (item.base_position_E_m) engine_.set_base_position(*item.base_position_E_m);
  const core::ObsEpoch* base = item.base ? &*item.base : nullptr;
  record_prediction(
      item, engine_.predict(item.rover, base, item.pose, item.fusion_geometry ? &*item.fusion_geometry : nullptr));
}

void FusionEstimator::update(EpochItem& item) {
  if (item.to_update) item.to_resolve = engine_.update();
}

void FusionEstimator::resolve(EpochItem& item) {
  if (item.error) return;
  if (item.to_resolve) engine_.resolve();
  fusion::FusionEpoch epoch = engine_.finish_epoch();
  EpochOutput out = output_of(epoch, epoch.rtk);
  out.aided = epoch.aided;
  if (!engine_.stats().alignment.events.empty()) {
    const fusion::AlignmentEvent& a = engine_.stats().alignment.events.back();
    out.alignment = EpochOutput::Alignment{a.kind, a.rmse_m, a.first_eigenvalue_ratio, engine_.lever_arm_m()};
  }
  item.output = std::move(out);
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

using ItemPtr = std::unique_ptr<EpochItem>;  // nullptr: end of the stream
/// Epochs per hand-over in the bridge-ahead pipeline.
constexpr std::size_t kBridgeAheadBatch = 4;
using ItemQueue = core::SpscHandoff<ItemPtr>;

struct EpochPipeline::Queues {
  explicit Queues(std::size_t capacity) {
    for (auto& q : between) q = std::make_unique<ItemQueue>(capacity);
  }
  std::array<std::unique_ptr<ItemQueue>, kNumStages - 1> between;  // stage i -> stage i + 1
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
  std::array<std::size_t, kNumStages - 1> depths{};
  if (!queues_) return depths;
  for (std::size_t i = 0; i < depths.size(); ++i) depths[i] = queues_->between[i]->size_approx();
  return depths;
}

PipelineStats EpochPipeline::stats() const {
  PipelineStats s;
  s.epochs = epochs_.load();
  for (std::size_t i = 0; i < s.full_waits.size(); ++i) s.full_waits[i] = full_waits_[i].load();
  return s;
}

/// One stage (not ingest) on one epoch, with its enter and exit times.
void EpochPipeline::run_stage(Stage stage, EpochItem& item) {
  const auto i = static_cast<std::size_t>(stage);
  item.enter_ns[i] = monotonic_ns();
  switch (stage) {
    case Stage::Ingest: break;
    case Stage::TimeBridge:
      if (item.navigation) add_navigation(item);
      estimator_.bridge(item);
      break;
    case Stage::Alignment: estimator_.align(item); break;
    case Stage::Prediction: estimator_.predict(item); break;
    case Stage::Update:
      if (!item.error) estimator_.update(item);
      break;
    case Stage::Ambiguity: estimator_.resolve(item); break;
  }
  item.exit_ns[i] = monotonic_ns();
  if (observer_.taken) observer_.taken(stage, item);
}

Status EpochPipeline::run() {
  if (const std::string e = options_.validate(); !e.empty()) return Error{"pipeline: " + e};
  Status s = options_.threaded ? run_threaded() : options_.bridge_ahead ? run_bridge_ahead() : run_sequential();
  if (!s) return s;
  const std::lock_guard lock(error_mutex_);
  if (failed_.load()) return error_;
  return Ok{};
}

void EpochPipeline::ingested(EpochItem& item, std::uint64_t seq, std::int64_t enter_ns) {
  item.seq = seq;
  if (item.arrival_ns == 0) item.arrival_ns = enter_ns;
  item.enter_ns[0] = item.arrival_ns;
  item.exit_ns[0] = monotonic_ns();
  if (observer_.taken) observer_.taken(Stage::Ingest, item);
}

std::unique_ptr<EpochItem> EpochPipeline::ingest_next(std::uint64_t seq) {
  const std::int64_t enter = monotonic_ns();
  auto next = source_.next();
  if (!next) {
    fail(next.error());
    return nullptr;
  }
  if (!*next) return nullptr;
  auto item = std::make_unique<EpochItem>(std::move(**next));
  ingested(*item, seq, enter);
  return item;
}

void EpochPipeline::add_navigation(const EpochItem& item) {
  // Every earlier epoch has left the last stage (sequential: always so), then no stage reads the ephemerides.
  while (epochs_.load() < item.seq) std::this_thread::sleep_for(std::chrono::microseconds(50));
  estimator_.add_navigation(*item.navigation);
}

Status EpochPipeline::run_sequential() {
  for (std::uint64_t seq = 0; !stop_.load(); ++seq) {
    const std::int64_t enter = monotonic_ns();
    auto next = source_.next();
    if (!next) return next.error();
    if (!*next) break;
    EpochItem& item = **next;
    ingested(item, seq, enter);
    for (std::size_t s = 1; s < kNumStages; ++s) run_stage(static_cast<Stage>(s), item);
    ++epochs_;
    Status w = sink_(item);
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
  core::BatchQueue<ItemPtr> ready(options_.queue_capacity, kBridgeAheadBatch);
  std::mutex spent_mutex;
  std::vector<ItemPtr> spent;  // under spent_mutex: epochs past the sink, for the ingest thread to free
  std::thread ahead([this, &ready, &spent_mutex, &spent] {
    std::vector<ItemPtr> to_free;
    for (std::uint64_t seq = 0; !stop_.load(); ++seq) {
      {
        const std::lock_guard lock(spent_mutex);
        to_free.swap(spent);
      }
      to_free.clear();
      ItemPtr item = ingest_next(seq);
      if (!item) break;
      // Fresh ephemerides wait for every earlier epoch to leave the last stage: those still batched must go first.
      if (item->navigation && !ready.flush()) break;
      run_stage(Stage::TimeBridge, *item);
      if (!ready.push(std::move(item))) break;
      handed_on(Stage::Ingest);
      handed_on(Stage::TimeBridge);
    }
    ready.close();
  });
  while (std::optional<ItemPtr> item = ready.pop()) {
    EpochItem& epoch = **item;
    for (std::size_t s = static_cast<std::size_t>(Stage::Alignment); s < kNumStages; ++s) {
      run_stage(static_cast<Stage>(s), epoch);
    }
    ++epochs_;
    // After a failure (source or sink) the epochs already bridged still go through, as in run_threaded().
    if (!failed_.load()) {
      if (Status w = sink_(epoch); !w) fail(w.error());
    }
    for (std::size_t s = static_cast<std::size_t>(Stage::Alignment); s < kNumStages; ++s) {
      handed_on(static_cast<Stage>(s));
    }
    epoch.output.reset();  // this thread's allocations: freed here
    epoch.error.reset();
    const std::lock_guard lock(spent_mutex);
    spent.push_back(std::move(*item));
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

Status EpochPipeline::run_threaded() {
  if (const std::string e = options_.unavailable_cpu(); !e.empty()) return Error{"pipeline: " + e};
  const std::vector<int> caller_cpus = this_thread_cpus();  // this thread runs the last stage, then gets them back
  Queues& q = *queues_;
  const auto push = [this, &q](std::size_t i, ItemPtr item) {
    if (q.between[i]->push(std::move(item))) ++full_waits_[i];  // never drops: back-pressure
  };

  // Ingest.
  std::thread ingest([this, &push] {
    pin(Stage::Ingest);
    for (std::uint64_t seq = 0; !stop_.load(); ++seq) {
      ItemPtr item = ingest_next(seq);
      if (!item) break;
      push(0, std::move(item));
      handed_on(Stage::Ingest);
    }
    push(0, nullptr);
  });

  // Middle stages: time bridge, alignment (waits for the token), prediction, update.
  const auto middle = [this, &q, &push](Stage stage) {
    const auto in = static_cast<std::size_t>(stage) - 1;
    pin(stage);
    bool first = true;
    for (;;) {
      ItemPtr item = q.between[in]->pop();
      if (!item) break;
      if (stage == Stage::Alignment) {
        if (!first) (void)q.tokens.pop();
        first = false;
      }
      run_stage(stage, *item);
      push(in + 1, std::move(item));
      handed_on(stage);
    }
    push(in + 1, nullptr);
  };
  std::thread bridge(middle, Stage::TimeBridge);
  std::thread align(middle, Stage::Alignment);
  std::thread predict(middle, Stage::Prediction);
  std::thread update(middle, Stage::Update);

  // Ambiguity resolution and the sink, on this thread.
  pin(Stage::Ambiguity);
  for (;;) {
    ItemPtr item = q.between[kNumStages - 2]->pop();
    if (!item) break;
    run_stage(Stage::Ambiguity, *item);
    (void)q.tokens.push(true);  // the estimator is free for the next epoch's alignment
    ++epochs_;
    if (!failed_.load()) {
      if (Status w = sink_(*item); !w) fail(w.error());
    }
    handed_on(Stage::Ambiguity);
  }
  ingest.join();
  bridge.join();
  align.join();
  predict.join();
  update.join();
  if (options_.pinned() && !caller_cpus.empty()) (void)pin_this_thread(caller_cpus);
  estimator_.finish();
  return Ok{};
}

}  // namespace canyon::pipeline
