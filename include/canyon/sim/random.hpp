#pragma once
// Deterministic random numbers for the scenario generator.
//
// std::mt19937_64 is specified exactly by the C++ standard, but std::uniform_real_distribution and
// std::normal_distribution are not (each standard library implements them differently). Rng therefore draws its
// doubles and Gaussians from the raw 64-bit engine output with algorithms written here: the same seed gives the same
// numbers with any conforming standard library. Results that pass through libm (sin, log, sqrt of the Gaussian
// transform) are identical on one toolchain and libm; a different libm may change the last bit of some values.
//
// Streams: Rng::stream(seed, a, b, c) derives an independent generator for one purpose (one channel of one receiver,
// the city, the route...) so that adding a satellite or a signal does not shift the numbers every other part draws.

#include <cstdint>
#include <random>

namespace canyon::sim {

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}

  /// Generator for one purpose, derived from the scenario seed and up to three identifiers by SplitMix64 mixing.
  [[nodiscard]] static Rng stream(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0, std::uint64_t c = 0);

  /// Uniform in [0, 1), 53 random bits.
  double uniform();
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Standard normal (Marsaglia's polar method; the second value of each pair is kept for the next call).
  double normal();
  double normal(double mean, double sigma) { return mean + sigma * normal(); }
  /// Uniform integer in [lo, hi] (inclusive), without modulo bias (rejection sampling).
  std::int64_t integer(std::int64_t lo, std::int64_t hi);
  /// True with probability p.
  bool bernoulli(double p) { return uniform() < p; }

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace canyon::sim
