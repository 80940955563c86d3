// The deterministic generator: fixed sequences, distributions, independent streams.

#include "canyon/sim/random.hpp"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace canyon::sim {
namespace {

TEST(RngTest, SameSeedSameNumbers) {
  Rng a(42), b(42), c(43);
  for (int i = 0; i < 100; ++i) {
    const double x = a.normal();
    EXPECT_EQ(x, b.normal());
    EXPECT_NE(x, c.normal());
  }
}

TEST(RngTest, UniformAndNormalMoments) {
  constexpr int kSamples = 200000;
  Rng rng(7);
  double sum_u = 0.0, sum_n = 0.0, sum_n2 = 0.0;
  for (int i = 0; i < kSamples; ++i) {
    const double u = rng.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum_u += u;
    const double n = rng.normal();
    sum_n += n;
    sum_n2 += n * n;
  }
  // Bounds of about 5 standard errors.
  EXPECT_NEAR(sum_u / kSamples, 0.5, 5.0 * std::sqrt(1.0 / 12.0 / kSamples));
  EXPECT_NEAR(sum_n / kSamples, 0.0, 5.0 / std::sqrt(kSamples));
  EXPECT_NEAR(sum_n2 / kSamples, 1.0, 5.0 * std::sqrt(2.0 / kSamples));
}

TEST(RngTest, IntegersCoverTheInclusiveRangeEvenly) {
  Rng rng(11);
  std::vector<int> counts(7, 0);
  constexpr int kSamples = 70000;
  for (int i = 0; i < kSamples; ++i) {
    const std::int64_t k = rng.integer(-3, 3);
    ASSERT_GE(k, -3);
    ASSERT_LE(k, 3);
    ++counts[static_cast<std::size_t>(k + 3)];
  }
  for (const int c : counts) EXPECT_NEAR(c, kSamples / 7.0, 5.0 * std::sqrt(kSamples / 7.0));
  EXPECT_EQ(rng.integer(5, 5), 5);
}

TEST(RngTest, StreamsAreIndependentOfEachOther) {
  Rng a = Rng::stream(1, 10, 2), b = Rng::stream(1, 10, 3), a2 = Rng::stream(1, 10, 2);
  const double x = a.uniform();
  EXPECT_NE(x, b.uniform());
  EXPECT_EQ(x, a2.uniform());
}

}  // namespace
}  // namespace canyon::sim
