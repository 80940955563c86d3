// Saastamoinen and Klobuchar against hand-computed values.

#include "canyon/gnss/atmosphere.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"

namespace canyon::gnss {
namespace {

using core::kDegToRad;

TEST(Saastamoinen, ZenithHydrostaticAtSeaLevel) {
  // Dry zenith delay at 45 deg latitude, sea level, 1013.25 hPa: 0.0022768 * 1013.25 = 2.30697 m.
  const core::Geodetic sea{45.0 * kDegToRad, 0.0, 0.0};
  EXPECT_NEAR(saastamoinen_delay_m(sea, 90.0 * kDegToRad, 0.0), 2.30697, 1e-4);
  // 1 / cos(z) mapping: twice the zenith value at 30 deg elevation.
  EXPECT_NEAR(saastamoinen_delay_m(sea, 30.0 * kDegToRad, 0.0), 2.0 * 2.30697, 2e-4);
  // Wet part, 70 % humidity at 15 C: e = 11.9 hPa, 0.002277 * (1255 / 288.15 + 0.05) * e = 0.119 m.
  const double wet_m = saastamoinen_delay_m(sea, 90.0 * kDegToRad, 0.7) - 2.30697;
  EXPECT_NEAR(wet_m, 0.119, 0.003);
  // 1000 m: pressure 898.7 hPa -> 2.046 m dry.
  const core::Geodetic high{45.0 * kDegToRad, 0.0, 1000.0};
  EXPECT_NEAR(saastamoinen_delay_m(high, 90.0 * kDegToRad, 0.0), 0.0022768 * 898.75 / (1.0 - 0.00028), 2e-3);
}

TEST(Saastamoinen, OutOfRangeIsZero) {
  EXPECT_EQ(saastamoinen_delay_m({0.6, 0.0, 20000.0}, 0.5, 0.7), 0.0);
  EXPECT_EQ(saastamoinen_delay_m({0.6, 0.0, -500.0}, 0.5, 0.7), 0.0);
  EXPECT_EQ(saastamoinen_delay_m({0.6, 0.0, 10.0}, 0.0, 0.7), 0.0);
}

TEST(Klobuchar, NightFloorAndDayPeak) {
  const core::Geodetic rcv{0.0, 0.0, 0.0};
  const core::AzEl zenith{0.0, 90.0 * kDegToRad};
  core::KlobucharParams p;
  p.alpha = {1e-8, 0.0, 0.0, 0.0};
  p.beta = {72000.0, 0.0, 0.0, 0.0};
  // Zenith obliquity F = 1 + 16 (0.53 - 0.5)^3 = 1.000432.
  const double f = 1.0 + 16.0 * std::pow(0.03, 3.0);
  // Midnight local time: only the 5 ns floor.
  EXPECT_NEAR(klobuchar_delay_m({2320, 0.0}, rcv, zenith, p), core::kSpeedOfLightMps * 5e-9 * f, 1e-9);
  // 14:00 local: floor + amplitude.
  EXPECT_NEAR(klobuchar_delay_m({2320, 50400.0}, rcv, zenith, p), core::kSpeedOfLightMps * 15e-9 * f, 1e-9);
  // Low elevation: larger obliquity (5 deg: F = 1 + 16 (0.53 - 0.0278)^3 = 3.026).
  const core::AzEl low{0.0, 5.0 * kDegToRad};
  EXPECT_NEAR(klobuchar_delay_m({2320, 0.0}, rcv, low, p) / (core::kSpeedOfLightMps * 5e-9), 3.026, 0.002);
}

TEST(Klobuchar, DefaultsWhenNoneBroadcast) {
  const core::Geodetic rcv{35.0 * kDegToRad, 137.0 * kDegToRad, 100.0};
  const core::AzEl azel{1.0, 40.0 * kDegToRad};
  const core::GpsTime t{2320, 3.0 * 86400.0 + 5.0 * 3600.0};
  const double with_defaults = klobuchar_delay_m(t, rcv, azel, default_klobuchar());
  EXPECT_DOUBLE_EQ(klobuchar_delay_m(t, rcv, azel, core::KlobucharParams{}), with_defaults);
  EXPECT_GT(with_defaults, 1.0);
  EXPECT_LT(with_defaults, 30.0);
}

}  // namespace
}  // namespace canyon::gnss
