// Deterministic random numbers (see random.hpp).

#include "canyon/sim/random.hpp"

#include <cmath>

namespace canyon::sim {
namespace {

/// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mix with good avalanche.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30U)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27U)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31U);
}

}  // namespace

Rng Rng::stream(std::uint64_t seed, std::uint64_t a, std::uint64_t b, std::uint64_t c) {
  return Rng(mix(mix(mix(mix(seed) ^ a) ^ b) ^ c));
}

double Rng::uniform() {
  // The top 53 bits as a multiple of 2^-53.
  return static_cast<double>(engine_() >> 11U) * 0x1.0p-53;
}

double Rng::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u = 0.0, v = 0.0, s = 0.0;
  do {
    u = 2.0 * uniform() - 1.0;
    v = 2.0 * uniform() - 1.0;
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double factor = std::sqrt(-2.0 * std::log(s) / s);
  spare_ = v * factor;
  has_spare_ = true;
  return u * factor;
}

std::int64_t Rng::integer(std::int64_t lo, std::int64_t hi) {
  if (hi <= lo) return lo;
  const std::uint64_t range = static_cast<std::uint64_t>(hi) - static_cast<std::uint64_t>(lo) + 1U;
  if (range == 0) return static_cast<std::int64_t>(engine_());  // the whole 64-bit range
  // Largest multiple of `range` that fits: values above it are rejected so that every residue is equally likely.
  const std::uint64_t limit = std::uint64_t(-1) - (std::uint64_t(-1) % range);
  std::uint64_t x = engine_();
  while (x >= limit) x = engine_();
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(lo) + x % range);
}

}  // namespace canyon::sim
