// Timing of mlambda (decorrelation + search for the 2 best candidates) on GNSS-like single-epoch DD float
// ambiguities (see tests/rtk/gnss_like.hpp). 16 different problems per size are cycled through.

#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "canyon/rtk/lambda.hpp"

#include "rtk/gnss_like.hpp"

namespace {

void BM_Mlambda(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::mt19937_64 rng(42 + static_cast<unsigned>(n));
  std::vector<canyon::rtk::testing::IlsProblem> problems;
  problems.reserve(16);
  for (int i = 0; i < 16; ++i) problems.push_back(canyon::rtk::testing::gnss_like_problem(n, rng));
  std::size_t next = 0;
  std::int64_t nodes = 0;
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    const auto& p = problems[next++ % problems.size()];
    auto result = canyon::rtk::mlambda(p.a_float, p.Q_a);
    if (!result) {
      state.SkipWithError(result.error().message.c_str());
      break;
    }
    nodes += result->search_nodes;
    benchmark::DoNotOptimize(result->candidates.data());
  }
  state.counters["search_nodes"] = benchmark::Counter(static_cast<double>(nodes), benchmark::Counter::kAvgIterations);
}

}  // namespace

BENCHMARK(BM_Mlambda)->Arg(10)->Arg(20)->Arg(30)->Unit(benchmark::kMicrosecond);
