#include "canyon/core/satellite.hpp"

#include <set>

#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"

namespace canyon::core {
namespace {

TEST(SatelliteTest, ParsesAndFormats) {
  struct Case {
    const char* text;
    const char* expected;
  };
  const Case cases[] = {{"G05", "G05"}, {"G 5", "G05"}, {" 5", "G05"},  {"12", "G12"},   {"R24", "R24"},
                        {"E36", "E36"}, {"C63", "C63"}, {"J01", "J01"}, {"J193", "J01"}, {"J 2", "J02"}};
  for (const auto& c : cases) {
    const auto sat = parse_satellite(c.text);
    ASSERT_TRUE(sat.has_value()) << c.text;
    EXPECT_EQ(sat->to_string(), c.expected);
  }
  for (const char* bad : {"", "X01", "G00", "G33", "R28", "G1x", "G-1", "S20", "Gab"}) {
    EXPECT_FALSE(parse_satellite(bad).has_value()) << bad;
  }
}

TEST(SatelliteTest, IndexIsDenseAndInvertible) {
  std::set<int> seen;
  for (int i = 0; i < kMaxSatellites; ++i) {
    const SatelliteId sat = satellite_from_index(i);
    ASSERT_TRUE(sat.valid()) << i;
    EXPECT_EQ(sat.index(), i);
    seen.insert(sat.index());
  }
  EXPECT_EQ(static_cast<int>(seen.size()), kMaxSatellites);
}

TEST(SignalTest, FrequenciesAndWavelengths) {
  struct Case {
    Constellation system;
    const char* code;
    int channel;
    double mhz;
  };
  const Case cases[] = {
      {Constellation::Gps, "1C", kNoGlonassChannel, 1575.42},
      {Constellation::Gps, "2W", kNoGlonassChannel, 1227.60},
      {Constellation::Gps, "5Q", kNoGlonassChannel, 1176.45},
      {Constellation::Galileo, "7Q", kNoGlonassChannel, 1207.14},
      {Constellation::Galileo, "8X", kNoGlonassChannel, 1191.795},
      {Constellation::BeiDou, "2I", kNoGlonassChannel, 1561.098},
      {Constellation::BeiDou, "6I", kNoGlonassChannel, 1268.52},
      {Constellation::Qzss, "2L", kNoGlonassChannel, 1227.60},
      {Constellation::Glonass, "1C", -7, 1598.0625},
      {Constellation::Glonass, "1C", 6, 1605.375},
      {Constellation::Glonass, "2C", 1, 1246.4375},
      {Constellation::Glonass, "3X", kNoGlonassChannel, 1202.025},
  };
  for (const auto& c : cases) {
    const auto f = carrier_frequency_hz(c.system, *parse_signal(c.code), c.channel);
    ASSERT_TRUE(f.has_value()) << c.code;
    EXPECT_NEAR(*f, c.mhz * 1e6, 1e-3) << c.code;
    EXPECT_NEAR(*wavelength_m(c.system, *parse_signal(c.code), c.channel), kSpeedOfLightMps / (c.mhz * 1e6), 1e-12);
  }
  EXPECT_NEAR(*wavelength_m(Constellation::Gps, {'1', 'C'}), 0.190293672798, 1e-11);
  EXPECT_FALSE(carrier_frequency_hz(Constellation::Glonass, {'1', 'C'}).has_value());  // needs the channel
  EXPECT_FALSE(carrier_frequency_hz(Constellation::Gps, {'7', 'Q'}).has_value());
  EXPECT_FALSE(parse_signal("C1").has_value());
  EXPECT_FALSE(parse_signal("1").has_value());
}

TEST(SignalTest, FrequencyRanks) {
  EXPECT_EQ(frequency_rank(Constellation::Gps, '2'), 1);
  EXPECT_EQ(frequency_rank(Constellation::Galileo, '7'), 1);
  EXPECT_EQ(frequency_rank(Constellation::Galileo, '5'), 2);
  EXPECT_EQ(frequency_rank(Constellation::BeiDou, '2'), 0);
  EXPECT_FALSE(frequency_rank(Constellation::Gps, '7').has_value());
}

}  // namespace
}  // namespace canyon::core

namespace canyon::core {
namespace {

TEST(ConstellationFlagsTest, LettersRoundTripAndRejectUnknown) {
  ConstellationFlags flags;
  EXPECT_EQ(flags.letters(), (std::vector<std::string>{"G", "R", "E", "C", "J"}));
  ASSERT_TRUE(flags.set_from_letters({"E", "G"}));
  EXPECT_TRUE(flags.uses(Constellation::Gps));
  EXPECT_TRUE(flags.uses(Constellation::Galileo));
  EXPECT_FALSE(flags.uses(Constellation::Glonass));
  EXPECT_EQ(flags.letters(), (std::vector<std::string>{"G", "E"}));
  std::string bad;
  EXPECT_FALSE(flags.set_from_letters({"G", "S"}, &bad));
  EXPECT_EQ(bad, "S");
  EXPECT_EQ(flags.letters(), (std::vector<std::string>{"G", "E"}));  // unchanged on error
  EXPECT_FALSE(flags.set_from_letters({"GR"}));
  ASSERT_TRUE(flags.set_from_letters({}));
  EXPECT_FALSE(flags.any());
}

}  // namespace
}  // namespace canyon::core
