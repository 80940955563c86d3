// What a thread that sleeps between epochs finds in the caches when it wakes: the time per cache line of a dependent
// walk (pointer chase, random order, so no prefetcher helps) over a working set of W KB, right after sleeping S ms.
// This is the machine, not canyon: the real-time rover sleeps about 200 ms between 5 Hz epochs, and its per-epoch
// stage times at real-time pace are 3-5x those of the same stages run back to back (README, issue 7 latency).
//
// BM_WalkAfterSleep/W/S: "ns_per_line" is the median over the iterations (each: sleep S ms, untimed, then one walk).
//
// Reproduce: build/tests/bench/bench_cache_after_sleep
// Results on the 2-core CI machine (a virtual machine, AMD EPYC), 2026-11-24, ns per cache line (median of 40):
//                    S = 0    S = 1 ms   S = 5 ms   S = 200 ms
//   W = 32 KB          2.7       -          -          118
//   W = 256 KB         4.3       7.3       19          105
// A warm walk costs 3-4 ns per line; after the rover's 200 ms between epochs every line is a DRAM miss (about 110 ns),
// even in 32 KB: the vCPU's caches are lost while it is idle (other work runs on the physical core). A probe that
// spun instead of sleeping for 200 ms found them lost as well (75 ns per line).

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <numeric>
#include <random>
#include <thread>
#include <vector>

#include <benchmark/benchmark.h>

namespace {

constexpr std::size_t kLineBytes = 64;
constexpr std::size_t kSlotsPerLine = kLineBytes / sizeof(std::size_t);

/// next[i * kSlotsPerLine] holds the slot of the line after line i in one random cycle over every line.
std::vector<std::size_t> random_cycle(std::size_t lines) {
  std::vector<std::size_t> order(lines);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::shuffle(order.begin() + 1, order.end(), std::mt19937(7));
  std::vector<std::size_t> next(lines * kSlotsPerLine, 0);
  for (std::size_t i = 0; i < lines; ++i) next[order[i] * kSlotsPerLine] = order[(i + 1) % lines] * kSlotsPerLine;
  return next;
}

void BM_WalkAfterSleep(benchmark::State& state) {
  const auto lines = static_cast<std::size_t>(state.range(0)) * 1024 / kLineBytes;
  const auto sleep = std::chrono::milliseconds(state.range(1));
  const std::vector<std::size_t> next = random_cycle(lines);
  std::vector<double> ns_per_line;
  std::size_t slot = 0;
  for (auto _ : state) {
    state.PauseTiming();
    if (sleep.count() > 0) std::this_thread::sleep_for(sleep);
    state.ResumeTiming();
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < lines; ++i) slot = next[slot];
    const auto t1 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(slot);
    ns_per_line.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count() / static_cast<double>(lines));
  }
  std::nth_element(ns_per_line.begin(), ns_per_line.begin() + static_cast<std::ptrdiff_t>(ns_per_line.size() / 2),
                   ns_per_line.end());
  state.counters["ns_per_line"] = ns_per_line[ns_per_line.size() / 2];
}

BENCHMARK(BM_WalkAfterSleep)
    ->ArgNames({"KB", "sleep_ms"})
    ->Args({32, 0})
    ->Args({32, 200})
    ->Args({256, 0})
    ->Args({256, 1})
    ->Args({256, 5})
    ->Args({256, 200})
    ->Iterations(40)
    ->Unit(benchmark::kMicrosecond);

}  // namespace
