// The staged pipeline (pipeline/epoch_pipeline.hpp):
//  - threaded and sequential `canyon process` give the same .pos byte for byte: rtk on instinct-spirent-rtk-sim
//    (shared data; skipped when absent) and fusion on a generated urban-severe scenario with VIO;
//  - queues: a full queue blocks its producer (counted, nothing dropped, order kept); empty queues wait;
//  - stop() with epochs in flight: every epoch ingested reaches the sink, run() returns cleanly;
//  - a failing source or sink stops the pipeline with its error, without hanging;
//  - the stage observer's two steps (taken, handed_on), per epoch, on each stage's thread;
//  - pinned stage threads (pipeline.cpu_affinity) run where they are told, and give the same solutions.

#include "canyon/pipeline/epoch_pipeline.hpp"

#include <array>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <sched.h>

#include "canyon/commands/process.hpp"
#include "canyon/commands/simulate.hpp"
#include "canyon/config/process_config.hpp"
#include "canyon/config/scenario_config.hpp"
#include "canyon/pipeline/cpu_affinity.hpp"

#include "pipeline/fake_epochs.hpp"

namespace canyon::pipeline {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path temp_dir(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("canyon_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

/// The report without its CPU-time figures (they differ from run to run).
std::vector<std::string> without_cpu_times(std::vector<std::string> lines) {
  const std::regex cpu("[0-9.]+ s CPU");
  for (std::string& line : lines) line = std::regex_replace(line, cpu, "_ s CPU");
  return lines;
}

/// Six threads, ingest and the time bridge on the first CPU this process may use, the estimator's four stages on
/// its last (the same CPU on a one-CPU machine).
PipelineOptions pinned_threaded() {
  PipelineOptions options{true, 4};
  const std::vector<int> cpus = allowed_cpus();
  for (std::size_t s = 0; s < kNumStages; ++s) {
    options.cpu_affinity[s] = {s <= static_cast<std::size_t>(Stage::TimeBridge) ? cpus.front() : cpus.back()};
  }
  return options;
}

/// The layouts: one thread, two (ingest and time bridge ahead), six threads, six threads pinned to CPUs.
const std::vector<std::pair<std::string, PipelineOptions>>& layouts() {
  static const std::vector<std::pair<std::string, PipelineOptions>> all{
      {"sequential", PipelineOptions{false, 64}},
      {"bridge-ahead", PipelineOptions{false, 4, true}},
      {"threaded", PipelineOptions{true, 4}},
      {"threaded-pinned", pinned_threaded()},
  };
  return all;
}

/// Runs `config` in every layout; returns the sequential .pos file's contents and the others' (bridge-ahead,
/// threaded) after checking that their counts and reports equal the sequential run's.
std::pair<std::string, std::vector<std::string>> every_way(config::ProcessConfig config, const fs::path& dir) {
  std::optional<commands::ProcessSummary> sequential;
  std::vector<std::string> others;
  for (const auto& [name, options] : layouts()) {
    config.out = (dir / (name + ".pos")).string();
    auto run = commands::run_process(config, {}, options);
    EXPECT_TRUE(run) << name << ": " << (run ? "" : run.error().to_string());
    if (!run) continue;
    if (!sequential) {
      sequential = *run;
      continue;
    }
    EXPECT_EQ(sequential->epochs, run->epochs) << name;
    EXPECT_EQ(sequential->fixed, run->fixed) << name;
    EXPECT_EQ(without_cpu_times(sequential->report), without_cpu_times(run->report)) << name;
    others.push_back(slurp(config.out));
  }
  return {slurp(dir / "sequential.pos"), others};
}

TEST(EpochPipeline, EveryLayoutEqualsSequentialRtkInstinct) {
  const fs::path data = fs::path(CANYON_SHARED_DATA_DIR) / "instinct-spirent-rtk-sim";
  if (!fs::exists(data)) GTEST_SKIP() << "shared data absent: " << data;
  const fs::path dir = temp_dir("pipeline-rtk");
  auto config = config::load_process_config(std::string(CANYON_SOURCE_DIR) + "/config/rtk.yaml");
  ASSERT_TRUE(config);
  config->rover_obs = (data / "iono-Klob_tropo-Saast/Rover-dynamic_MO_Spirent.obs").string();
  config->base_obs = (data / "iono-Klob_tropo-Saast/Base-static_MO_Spirent.obs").string();
  config->nav = {(data / "RINEX_GN_Spirent.23N").string()};
  const auto [seq, others] = every_way(*config, dir);
  EXPECT_GT(seq.size(), 10000U);
  ASSERT_EQ(others.size(), 3U);
  EXPECT_TRUE(seq == others[0]) << "bridge-ahead .pos differs from sequential";
  EXPECT_TRUE(seq == others[1]) << "threaded .pos differs from sequential";
  EXPECT_TRUE(seq == others[2]) << "pinned threaded .pos differs from sequential";
}

TEST(EpochPipeline, EveryLayoutEqualsSequentialFusionUrbanSevere) {
  const fs::path dir = temp_dir("pipeline-fusion");
  auto scenario = config::load_scenario(std::string(CANYON_SOURCE_DIR) + "/config/scenarios/urban-severe.yaml");
  ASSERT_TRUE(scenario) << scenario.error().to_string();
  scenario->duration_s = 60.0;
  auto sim = commands::run_simulate(*scenario, dir.string());
  ASSERT_TRUE(sim) << sim.error().to_string();
  auto config = config::load_process_config(std::string(CANYON_SOURCE_DIR) + "/config/fusion.yaml");
  ASSERT_TRUE(config);
  config->rover_obs = (dir / "rover.obs").string();
  config->base_obs = (dir / "base.obs").string();
  config->nav = {(dir / "nav.rnx").string()};
  config->vio = (dir / "vio.csv").string();
  config->timesync = (dir / "timesync.csv").string();
  const auto [seq, others] = every_way(*config, dir);
  EXPECT_GT(seq.size(), 10000U);
  ASSERT_EQ(others.size(), 3U);
  EXPECT_TRUE(seq == others[0]) << "bridge-ahead .pos differs from sequential";
  EXPECT_TRUE(seq == others[1]) << "threaded .pos differs from sequential";
  EXPECT_TRUE(seq == others[2]) << "pinned threaded .pos differs from sequential";
}

// ---- Queues and shutdown, with a fake source and estimator ----

core::ObsEpoch epoch_at(double tow_s) {
  core::ObsEpoch e;
  e.time = core::GpsTime{2300, tow_s};
  return e;
}

/// `n` epochs (or endless with n < 0), each after `delay`.
class CountingSource final : public EpochSource {
 public:
  CountingSource(int n, std::chrono::microseconds delay) : n_(n), delay_(delay) {}
  Result<std::optional<IngestedEpoch>> next() override {
    if (n_ >= 0 && produced_.load() >= n_) return std::optional<IngestedEpoch>{};
    if (fail_at_ >= 0 && produced_.load() == fail_at_) return Error{"source broke"};
    std::this_thread::sleep_for(delay_);
    std::optional<IngestedEpoch> item(std::in_place);
    item->rover = epoch_at(produced_.load());
    produced_.fetch_add(1);
    return item;
  }
  std::atomic<int> produced_{0};
  int fail_at_ = -1;

 private:
  int n_;
  std::chrono::microseconds delay_;
};

using testing::bridged_without_geometry;

/// Records the order in which each stage saw epochs; resolve() makes the output.
class RecordingEstimator final : public EpochEstimator {
 public:
  [[nodiscard]] BridgedEpoch bridge(IngestedEpoch epoch) const override {
    return bridged_without_geometry(std::move(epoch));
  }
  [[nodiscard]] AlignedEpoch align(BridgedEpoch epoch) override {
    check(epoch.epoch, in_align_);
    return AlignedEpoch{std::move(epoch)};
  }
  [[nodiscard]] PredictedEpoch predict(AlignedEpoch epoch) override {
    check(epoch.bridged.epoch, in_predict_);
    return PredictedEpoch{std::move(epoch), true};
  }
  [[nodiscard]] UpdatedEpoch update(PredictedEpoch epoch) override { return UpdatedEpoch{std::move(epoch), true}; }
  [[nodiscard]] SolvedEpoch resolve(UpdatedEpoch epoch) override {
    // The token: alignment of epoch k+1 never runs before the ambiguity stage finished epoch k.
    EXPECT_EQ(busy_.exchange(false), true);
    SolvedEpoch solved{std::move(epoch)};
    EpochOutput out;
    out.solution.time = solved.epoch().rover.time;
    out.solution.status = core::SolutionStatus::Fixed;
    solved.output = out;
    return solved;
  }
  void finish() override { finished = true; }
  bool finished = false;

 private:
  void check(const IngestedEpoch& item, std::uint64_t& next) {
    EXPECT_EQ(item.seq, next);
    ++next;
    if (&next == &in_align_) {
      EXPECT_EQ(busy_.exchange(true), false);
    }
  }
  std::uint64_t in_align_ = 0, in_predict_ = 0;
  std::atomic<bool> busy_{false};
};

void expect_full_queues_block_and_drop_nothing(const PipelineOptions& options) {
  SCOPED_TRACE(options.threaded ? "threaded" : "bridge-ahead");
  CountingSource source(200, std::chrono::microseconds(0));
  RecordingEstimator estimator;
  std::vector<double> seen;
  const auto slow_sink = [&seen](const SolvedEpoch& item) -> Status {
    std::this_thread::sleep_for(std::chrono::microseconds(200));
    seen.push_back(item.output->solution.time.tow_s);
    return Ok{};
  };
  EpochPipeline pipeline(source, estimator, slow_sink, options);
  ASSERT_TRUE(pipeline.run().ok());
  ASSERT_EQ(seen.size(), 200U);
  for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], static_cast<double>(i));
  const PipelineStats stats = pipeline.stats();
  EXPECT_EQ(stats.epochs, 200U);
  // Threaded: ingest's queue; bridge-ahead: the one queue, after the time bridge.
  EXPECT_GT(stats.full_waits[options.threaded ? 0 : 1], 0U) << "the producer never found its queue full";
  EXPECT_TRUE(estimator.finished);
  for (const std::size_t depth : pipeline.queue_depths()) EXPECT_EQ(depth, 0U);
}

TEST(EpochPipeline, FullQueuesBlockTheProducerAndDropNothing) {
  for (const PipelineOptions& options : {PipelineOptions{true, 1}, PipelineOptions{false, 1, true}}) {
    expect_full_queues_block_and_drop_nothing(options);
  }
}

/// Counts the epochs between the time bridge and the ambiguity stage; add_navigation() must find none.
class InFlightEstimator final : public EpochEstimator {
 public:
  [[nodiscard]] BridgedEpoch bridge(IngestedEpoch epoch) const override {
    in_flight_.fetch_add(1);
    return bridged_without_geometry(std::move(epoch));
  }
  [[nodiscard]] AlignedEpoch align(BridgedEpoch epoch) override { return AlignedEpoch{std::move(epoch)}; }
  [[nodiscard]] PredictedEpoch predict(AlignedEpoch epoch) override { return PredictedEpoch{std::move(epoch), true}; }
  [[nodiscard]] UpdatedEpoch update(PredictedEpoch epoch) override { return UpdatedEpoch{std::move(epoch), true}; }
  [[nodiscard]] SolvedEpoch resolve(UpdatedEpoch epoch) override {
    std::this_thread::sleep_for(std::chrono::microseconds(100));  // the later stages lag: epochs pile up
    SolvedEpoch solved{std::move(epoch)};
    solved.output = EpochOutput{};
    in_flight_.fetch_sub(1);
    return solved;
  }
  void finish() override {}
  void add_navigation(const core::NavigationData& fresh) override {
    EXPECT_EQ(in_flight_.load(), 0) << "ephemerides added while a stage may read them";
    added += fresh.kepler.size();
  }
  std::size_t added = 0;

 private:
  mutable std::atomic<int> in_flight_{0};
};

// Ephemerides that arrive with an epoch are handed to the estimator once every earlier epoch has left the last
// stage, in every layout, each once.
TEST(EpochPipeline, EphemeridesAreAddedWhileNoStageRuns) {
  for (const auto& [name, options] : layouts()) {
    CountingSource counting(200, std::chrono::microseconds(0));
    struct WithNavigation final : EpochSource {
      explicit WithNavigation(CountingSource& s) : source(s) {}
      Result<std::optional<IngestedEpoch>> next() override {
        auto item = source.next();
        if (item && *item && source.produced_.load() % 10 == 0) {
          auto nav = std::make_shared<core::NavigationData>();
          nav->kepler.resize(2);
          (*item)->navigation = std::move(nav);
        }
        return item;
      }
      CountingSource& source;
    } source(counting);
    InFlightEstimator estimator;
    std::size_t solved = 0;
    EpochPipeline pipeline(
        source, estimator,
        [&solved](const SolvedEpoch&) -> Status {
          ++solved;
          return Ok{};
        },
        options);
    ASSERT_TRUE(pipeline.run().ok()) << name;
    EXPECT_EQ(solved, 200U) << name;
    EXPECT_EQ(estimator.added, 40U) << name;  // 20 epochs with 2 records each
  }
}

TEST(EpochPipeline, EmptyQueuesWaitForASlowSource) {
  CountingSource source(20, std::chrono::milliseconds(2));
  RecordingEstimator estimator;
  int sunk = 0;
  EpochPipeline pipeline(
      source, estimator,
      [&sunk](const SolvedEpoch& solved) -> Status {
        EXPECT_TRUE(solved.output.ok());
        // Every stage stamped the epoch, in order, after its arrival.
        const StageClock& clock = solved.epoch().clock;
        for (std::size_t s = 0; s < kNumStages; ++s) {
          EXPECT_LE(clock.enter_ns[s], clock.exit_ns[s]);
          if (s > 0) {
            EXPECT_LE(clock.exit_ns[s - 1], clock.enter_ns[s]);
          }
        }
        EXPECT_LE(solved.epoch().arrival_ns, clock.exit_ns[kNumStages - 1]);
        ++sunk;
        return Ok{};
      },
      PipelineOptions{true, 8});
  ASSERT_TRUE(pipeline.run().ok());
  EXPECT_EQ(sunk, 20);
  for (const auto w : pipeline.stats().full_waits) EXPECT_EQ(w, 0U);
}

// The stage observer: per stage and epoch, taken() right after the stage (its exit stamped), then handed_on() on the
// same thread before the stage takes its next epoch; the ambiguity stage's handed_on() comes after the epoch's sink.
TEST(EpochPipeline, ObserverTakesThenHandsOnEachEpochOnItsStageThread) {
  for (const auto& [name, options] : layouts()) {
    constexpr int kEpochs = 50;
    CountingSource source(kEpochs, std::chrono::microseconds(0));
    RecordingEstimator estimator;
    struct StageLog {
      std::vector<char> events;  // 't' taken, 'h' handed on
      std::vector<std::uint64_t> taken_seq;
      std::set<std::thread::id> threads;
      std::vector<int> sunk_when_handed_on;
    };
    std::array<StageLog, kNumStages> logs;  // each written by its stage's thread only
    std::atomic<int> sunk{0};
    StageObserver observer;
    observer.taken = [&logs](Stage stage, const IngestedEpoch& item) {
      StageLog& log = logs[static_cast<std::size_t>(stage)];
      EXPECT_GT(item.clock.exit_ns[static_cast<std::size_t>(stage)], 0);
      log.events.push_back('t');
      log.taken_seq.push_back(item.seq);
      log.threads.insert(std::this_thread::get_id());
    };
    observer.handed_on = [&logs, &sunk](Stage stage) {
      StageLog& log = logs[static_cast<std::size_t>(stage)];
      log.events.push_back('h');
      log.threads.insert(std::this_thread::get_id());
      log.sunk_when_handed_on.push_back(sunk.load());
    };
    EpochPipeline pipeline(
        source, estimator,
        [&sunk](const SolvedEpoch&) -> Status {
          sunk.fetch_add(1);
          return Ok{};
        },
        options, observer);
    ASSERT_TRUE(pipeline.run().ok()) << name;
    ASSERT_EQ(sunk.load(), kEpochs) << name;
    for (std::size_t s = 0; s < kNumStages; ++s) {
      const StageLog& log = logs[s];
      const char* stage = stage_name(static_cast<Stage>(s));
      ASSERT_EQ(log.events.size(), 2U * kEpochs) << name << " " << stage;
      for (std::size_t k = 0; k < log.events.size(); ++k) {
        EXPECT_EQ(log.events[k], k % 2 == 0 ? 't' : 'h') << name << " " << stage << " event " << k;
      }
      for (std::size_t k = 0; k < log.taken_seq.size(); ++k) EXPECT_EQ(log.taken_seq[k], k) << name << " " << stage;
      EXPECT_EQ(log.threads.size(), 1U) << name << " " << stage;
    }
    const StageLog& last = logs[static_cast<std::size_t>(Stage::Ambiguity)];
    for (std::size_t k = 0; k < last.sunk_when_handed_on.size(); ++k) {
      EXPECT_GE(last.sunk_when_handed_on[k], static_cast<int>(k) + 1) << name << ": handed on before its sink";
    }
  }
}

// pipeline.cpu_affinity: each stage's thread runs on its CPUs only; the caller's thread (which runs the ambiguity
// stage) gets its CPUs back; a CPU the process may not use is refused before any epoch is read.
TEST(EpochPipeline, PinnedStageThreadsRunOnTheirCpus) {
  const PipelineOptions options = pinned_threaded();
  const std::vector<int> caller_before = this_thread_cpus();
  CountingSource source(50, std::chrono::microseconds(0));
  RecordingEstimator estimator;
  std::array<std::set<int>, kNumStages> cpus_seen;  // each written by its stage's thread only
  StageObserver observer;
  observer.taken = [&cpus_seen](Stage stage, const IngestedEpoch&) {
    cpus_seen[static_cast<std::size_t>(stage)].insert(sched_getcpu());
  };
  EpochPipeline pipeline(
      source, estimator, [](const SolvedEpoch&) -> Status { return Ok{}; }, options, observer);
  ASSERT_TRUE(pipeline.run().ok());
  for (std::size_t s = 0; s < kNumStages; ++s) {
    const std::set<int> pinned(options.cpu_affinity[s].begin(), options.cpu_affinity[s].end());
    EXPECT_EQ(cpus_seen[s], pinned) << stage_name(static_cast<Stage>(s));
  }
  EXPECT_EQ(this_thread_cpus(), caller_before);

  PipelineOptions far{true, 4};
  far.cpu_affinity[static_cast<std::size_t>(Stage::Update)] = {max_cpu_number()};
  ASSERT_EQ(far.validate(), "");
  CountingSource unread(5, std::chrono::microseconds(0));
  EpochPipeline refused(
      unread, estimator, [](const SolvedEpoch&) -> Status { return Ok{}; }, far);
  const Status s = refused.run();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("pipeline: cpu_affinity.update: CPU 1023 is not one this process may run on"),
            std::string::npos)
      << s.error().message;
  EXPECT_EQ(unread.produced_.load(), 0);
}

void expect_stop_finishes_the_epochs_in_flight(const PipelineOptions& options) {
  SCOPED_TRACE(options.threaded ? "threaded" : "bridge-ahead");
  CountingSource source(-1, std::chrono::microseconds(50));  // endless
  RecordingEstimator estimator;
  std::atomic<int> sunk{0};
  EpochPipeline* self = nullptr;
  EpochPipeline pipeline(
      source, estimator,
      [&sunk, &self](const SolvedEpoch& /*item*/) -> Status {
        std::this_thread::sleep_for(std::chrono::microseconds(300));  // the queues fill up behind
        if (sunk.fetch_add(1) == 50) self->stop();
        return Ok{};
      },
      options);
  self = &pipeline;
  const auto start = std::chrono::steady_clock::now();
  ASSERT_TRUE(pipeline.run().ok());
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
  EXPECT_GT(sunk.load(), 51) << "the epochs in the queues were not finished";
  EXPECT_EQ(sunk.load(), source.produced_.load()) << "an ingested epoch was lost at shutdown";
  EXPECT_TRUE(estimator.finished);
}

TEST(EpochPipeline, StopFinishesTheEpochsInFlight) {
  for (const PipelineOptions& options : {PipelineOptions{true, 16}, PipelineOptions{false, 16, true}}) {
    expect_stop_finishes_the_epochs_in_flight(options);
  }
}

TEST(EpochPipeline, SourceAndSinkErrorsStopWithoutHanging) {
  for (const auto& [name, options] : layouts()) {
    CountingSource source(1000, std::chrono::microseconds(0));
    source.fail_at_ = 30;
    RecordingEstimator estimator;
    EpochPipeline pipeline(
        source, estimator, [](const SolvedEpoch&) -> Status { return Ok{}; }, options);
    const Status s = pipeline.run();
    ASSERT_FALSE(s.ok()) << name;
    EXPECT_EQ(s.error().message, "source broke") << name;
  }
  for (const auto& [name, options] : layouts()) {
    CountingSource source(1000, std::chrono::microseconds(0));
    RecordingEstimator estimator;
    int sunk = 0;
    EpochPipeline pipeline(
        source, estimator,
        [&sunk](const SolvedEpoch&) -> Status {
          if (++sunk == 10) return Error{"disk full", "out.pos", 0};
          return Ok{};
        },
        options);
    const Status s = pipeline.run();
    ASSERT_FALSE(s.ok()) << name;
    EXPECT_EQ(s.error().message, "disk full") << name;
    EXPECT_EQ(sunk, 10) << name << ": the sink was called after its error";
    EXPECT_LT(source.produced_.load(), 1000) << name;
  }
  CountingSource source(1, std::chrono::microseconds(0));
  RecordingEstimator estimator;
  EpochPipeline bad(
      source, estimator, [](const SolvedEpoch&) -> Status { return Ok{}; }, PipelineOptions{true, 0});
  const Status s = bad.run();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("queue_capacity"), std::string::npos);
}

}  // namespace
}  // namespace canyon::pipeline
