#include "canyon/core/statistics.hpp"

#include <array>
#include <vector>

#include <gtest/gtest.h>

namespace canyon::core {
namespace {

TEST(StatisticsTest, MedianOfOddAndEvenSizes) {
  std::vector<double> odd{5.0, 1.0, 3.0};
  EXPECT_DOUBLE_EQ(median_in_place(odd), 3.0);
  std::vector<double> even{4.0, 1.0, 3.0, 2.0};
  EXPECT_DOUBLE_EQ(median_in_place(even), 2.5);
}

TEST(StatisticsTest, NormalUpperQuantilesMatchTheTables) {
  EXPECT_NEAR(normal_upper_quantile(0.5), 0.0, 1e-9);
  EXPECT_NEAR(normal_upper_quantile(0.05), 1.644854, 1e-6);
  EXPECT_NEAR(normal_upper_quantile(0.001), 3.090232, 1e-6);
  EXPECT_NEAR(normal_upper_quantile(0.975), -1.959964, 1e-6);
}

TEST(StatisticsTest, ChiSquareUpperQuantilesAreWithinTheirStatedAccuracy) {
  // (degrees of freedom, 0.999 quantile from the tables)
  constexpr std::array<std::array<double, 2>, 6> kTable{
      {{1.0, 10.828}, {4.0, 18.467}, {10.0, 29.588}, {20.0, 45.315}, {30.0, 59.703}, {60.0, 99.607}}};
  const double z = normal_upper_quantile(0.001);
  for (const auto& [dof, quantile] : kTable) {
    const double tolerance = dof >= 4.0 ? 0.015 : 0.031;
    EXPECT_NEAR(chi_square_upper_quantile(dof, z), quantile, tolerance * quantile) << dof;
  }
  // The median of chi-square(n) is about n (1 - 2 / (9 n))^3.
  EXPECT_NEAR(chi_square_upper_quantile(10.0, 0.0), 9.342, 0.01);
}

}  // namespace
}  // namespace canyon::core
