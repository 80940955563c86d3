// Timing of mlambda (decorrelation + search for the 2 best candidates).
//
// BM_Mlambda/n/k (the default, realistic case): what an RTK engine feeds MLAMBDA, the DD-ambiguity covariance of a
//   static-baseline EKF after k epochs of dual-frequency DD code (0.3 m at zenith) and phase (3 mm at zenith),
//   elevation weighted, slowly moving sky; n = 2 (satellites - 1); a_float = integers + a draw from Q_a
//   (tests/rtk/gnss_like.hpp, ekf_ambiguity_covariance). Float ambiguity sigmas at n = 30: k = 1: 0.4-3 cycles,
//   k = 5: 0.1-1 cycle, k = 20: 0.02-0.3 cycle.
// BM_MlambdaSingleEpochWorstCase/n: the labelled worst case, one epoch of single-frequency code and phase
//   (gnss_like_covariance): three loose directions at code level, so the search visits far more nodes.
//
// Each repetition cycles through 64 fixed problems; "Time" is the mean over them, aggregated over 15 repetitions
// (the _median row is what we quote). per_problem_median_us is the median time of a single call over the problems.
//
// Reproduce (Release, idle machine, 2 cores, Debian 12, g++ 12):
//   cmake -S . -B build -DCMAKE_BUILD_TYPE=Release && make -C build -j2 bench_lambda
//   build/tests/bench/bench_lambda          (rows ending in _median; --benchmark_filter=BM_Mlambda/n:30 for one size)
// Results (median of 15 repetitions, us; shared 2-core machine, run-to-run cv 2-18 %, so treat +-20 % as noise):
//                          n = 10   n = 20   n = 30
//   realistic k = 1          3.5     18.2     24.3   (before the reduction resumed at k + 1 and Z became optional: 35)
//   realistic k = 5          3.2     15.8     30.3   (44)
//   realistic k = 20         3.7     11.9     19.2   (34)
//   single-epoch worst       5.7     49.0      821   (41k search nodes at n = 30: the search dominates)
// Before the rewrite of the reduction (commit 888f135): realistic n = 30 k = 1 / 5 / 20: 82 / 79 / 42, single-epoch
// n = 30: 993.

#include <algorithm>
#include <chrono>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "canyon/rtk/lambda.hpp"

#include "rtk/gnss_like.hpp"

namespace {

using canyon::rtk::testing::IlsProblem;

constexpr int kProblemsPerCase = 64;
constexpr int kRepetitions = 15;

/// With `warm`, the problems are a sequence (each an epoch after the last) searched with the decorrelation carried.
void time_mlambda(benchmark::State& state, const std::vector<IlsProblem>& problems,
                  canyon::rtk::MlambdaWarmStart* warm = nullptr) {
  std::size_t next = 0;
  std::int64_t nodes = 0;
  std::vector<double> call_us;
  call_us.reserve(1u << 16);
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    const auto& p = problems[next++ % problems.size()];
    const auto start = std::chrono::steady_clock::now();
    auto result = canyon::rtk::mlambda(p.a_float, p.Q_a, canyon::rtk::MlambdaOptions{}, warm);
    benchmark::DoNotOptimize(result);
    const auto stop = std::chrono::steady_clock::now();
    if (!result) {
      state.SkipWithError(result.error().message.c_str());
      break;
    }
    if (call_us.size() < call_us.capacity())
      call_us.push_back(std::chrono::duration<double, std::micro>(stop - start).count());
    nodes += result->search_nodes;
  }
  state.counters["search_nodes"] = benchmark::Counter(static_cast<double>(nodes), benchmark::Counter::kAvgIterations);
  if (!call_us.empty()) {
    auto middle = call_us.begin() + static_cast<std::ptrdiff_t>(call_us.size() / 2);
    std::nth_element(call_us.begin(), middle, call_us.end());
    state.counters["per_problem_median_us"] = *middle;
  }
}

void BM_Mlambda(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  canyon::rtk::testing::EkfAmbiguityOptions options;
  options.num_satellites = n / 2 + 1;
  options.num_epochs = static_cast<int>(state.range(1));
  std::mt19937_64 rng(42 + static_cast<unsigned>(n) * 100 + static_cast<unsigned>(options.num_epochs));
  std::vector<IlsProblem> problems;
  problems.reserve(kProblemsPerCase);
  for (int i = 0; i < kProblemsPerCase; ++i)
    problems.push_back(canyon::rtk::testing::ekf_ambiguity_problem(options, rng));
  time_mlambda(state, problems);
}

void BM_MlambdaSingleEpochWorstCase(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::mt19937_64 rng(42 + static_cast<unsigned>(n));
  std::vector<IlsProblem> problems;
  problems.reserve(kProblemsPerCase);
  for (int i = 0; i < kProblemsPerCase; ++i) problems.push_back(canyon::rtk::testing::gnss_like_problem(n, rng));
  time_mlambda(state, problems);
}

/// EKF ambiguities epoch after epoch (tests/rtk/gnss_like.hpp ekf_ambiguity_sequence), searched cold (warm = 0) or with
/// the decorrelation carried from each search to the next (warm = 1), as canyon's RTK engine does for an unchanged
/// set of ambiguities.
void BM_MlambdaSequence(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  canyon::rtk::testing::EkfAmbiguityOptions options;
  options.num_satellites = n / 2 + 1;
  options.num_epochs = 5;
  const auto problems =
      canyon::rtk::testing::ekf_ambiguity_sequence(options, 7 + static_cast<unsigned>(n), kProblemsPerCase);
  canyon::rtk::MlambdaWarmStart warm;
  time_mlambda(state, problems, state.range(1) != 0 ? &warm : nullptr);
}

}  // namespace

BENCHMARK(BM_MlambdaSequence)
    ->ArgNames({"n", "warm"})
    ->ArgsProduct({{10, 20, 30}, {0, 1}})
    ->Repetitions(kRepetitions)
    ->ReportAggregatesOnly(true)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Mlambda)
    ->ArgNames({"n", "epochs"})
    ->ArgsProduct({{10, 20, 30}, {1, 5, 20}})
    ->Repetitions(kRepetitions)
    ->ReportAggregatesOnly(true)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_MlambdaSingleEpochWorstCase)
    ->ArgNames({"n"})
    ->Arg(10)
    ->Arg(20)
    ->Arg(30)
    ->Repetitions(kRepetitions)
    ->ReportAggregatesOnly(true)
    ->Unit(benchmark::kMicrosecond);
