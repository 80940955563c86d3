// NMEA GGA: checksums of sentences written by hand from the NMEA 0183 GGA layout, formatting corner cases
// (minutes rounding to 60, southern and western hemispheres, time carry), parser errors, round trips, the writer.

#include "canyon/io/nmea.hpp"

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"

namespace canyon::io {
namespace {

// GPST week 2318, Monday 09:00:18 GPST = 09:00:00 UTC (GPST - UTC = 18 s since 2017).
const core::GpsTime kMonday0900Utc{2318, 86400.0 + 9 * 3600.0 + 18.0};
constexpr double kMinuteResolutionDeg = 1e-7 / 60.0;

core::Solution solution_at(double lat_deg, double lon_deg, double height_m, core::SolutionStatus status) {
  core::Solution s;
  s.time = kMonday0900Utc;
  s.status = status;
  s.p_E_m = core::geodetic_to_ecef({lat_deg * core::kDegToRad, lon_deg * core::kDegToRad, height_m});
  s.num_satellites = 12;
  s.age_s = 1.0;
  return s;
}

TEST(NmeaChecksum, KnownSentences) {
  // The GGA example of the NMEA 0183 documentation, checksum 47.
  EXPECT_EQ(nmea_checksum("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"), 0x47);
  EXPECT_EQ(nmea_checksum(""), 0);
  EXPECT_EQ(nmea_checksum("A"), 0x41);
  EXPECT_EQ(nmea_checksum("AA"), 0);
  EXPECT_TRUE(parse_gga("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47").ok());
}

TEST(FormatGga, FixedSolutionFieldByField) {
  const core::Solution s = solution_at(35.13469901, 136.97757549, 104.8626, core::SolutionStatus::Fixed);
  GgaOptions options;
  options.hdop = 0.8;
  options.station_id = 0;
  // 0.13469901 deg = 8.0819406', 0.97757549 deg = 58.6545294'; checksum: XOR of the body, 0x74.
  EXPECT_EQ(format_gga(s, core::builtin_leap_seconds(), options),
            "$GPGGA,090000.00,3508.0819406,N,13658.6545294,E,4,12,0.8,104.863,M,0.000,M,1.0,0000*74");
}

TEST(FormatGga, QualityPerStatus) {
  EXPECT_EQ(gga_quality(core::SolutionStatus::Fixed), 4);
  EXPECT_EQ(gga_quality(core::SolutionStatus::Float), 5);
  EXPECT_EQ(gga_quality(core::SolutionStatus::Single), 1);
  EXPECT_EQ(gga_quality(core::SolutionStatus::VioFillIn), 6);
  EXPECT_EQ(gga_quality(core::SolutionStatus::None), 0);
  // Single point and VIO fill-in carry no age or station id; no HDOP when none is given.
  core::Solution single = solution_at(35.13469901, 136.97757549, 104.8626, core::SolutionStatus::Single);
  single.num_satellites = 7;
  GgaOptions with_station;
  with_station.station_id = 5;
  const std::string text = format_gga(single, core::builtin_leap_seconds(), with_station);
  EXPECT_NE(text.find(",E,1,07,,104.863,M,0.000,M,,*"), std::string::npos) << text;
}

TEST(FormatGga, NoSolutionHasEmptyPosition) {
  core::Solution none = solution_at(0, 0, 0, core::SolutionStatus::None);
  EXPECT_EQ(format_gga(none), "$GPGGA,090000.00,,,,,0,00,,,,,,,*41");
  EXPECT_TRUE(parse_gga(format_gga(none)).ok());
}

TEST(FormatGga, SouthernAndWesternHemispheres) {
  const core::Solution s = solution_at(-33.5, -0.5, -20.0, core::SolutionStatus::Float);
  const std::string text = format_gga(s);
  EXPECT_NE(text.find(",3330.0000000,S,00030.0000000,W,5,12,,-20.000,M,"), std::string::npos) << text;
  const auto parsed = parse_gga(text);
  ASSERT_TRUE(parsed.ok()) << parsed.error().to_string();
  EXPECT_NEAR(*parsed->lat_deg, -33.5, kMinuteResolutionDeg);
  EXPECT_NEAR(*parsed->lon_deg, -0.5, kMinuteResolutionDeg);
}

TEST(FormatGga, MinutesNeverRoundTo60) {
  // 59.99999999' rounds to the next whole degree, not to "60.0000000".
  const double just_below_deg = 10.0 + 59.99999999 / 60.0;
  const core::Solution s = solution_at(just_below_deg, -(100.0 + 59.99999999 / 60.0), 0.0, core::SolutionStatus::Fixed);
  const std::string text = format_gga(s);
  EXPECT_NE(text.find(",1100.0000000,N,10100.0000000,W,"), std::string::npos) << text;
  // A tiny negative latitude that rounds to zero is written as north, not as "0000.0000000,S".
  const core::Solution equator = solution_at(-1e-12, 1e-12, 0.0, core::SolutionStatus::Fixed);
  EXPECT_NE(format_gga(equator).find(",0000.0000000,N,00000.0000000,E,"), std::string::npos) << format_gga(equator);
}

TEST(FormatGga, TimeRoundsWithCarryAndUsesTheLeapTable) {
  core::Solution s = solution_at(35.0, 135.0, 0.0, core::SolutionStatus::Fixed);
  s.time = kMonday0900Utc - 0.004;  // 08:59:59.996 UTC
  EXPECT_EQ(format_gga(s).substr(0, 17), "$GPGGA,090000.00,");
  s.time = kMonday0900Utc + 0.123;
  EXPECT_EQ(format_gga(s).substr(0, 17), "$GPGGA,090000.12,");
  const core::LeapSecondTable no_leaps({{core::CalendarTime{1980, 1, 6, 0, 0, 0.0}, 0}});
  s.time = kMonday0900Utc;
  EXPECT_EQ(format_gga(s, no_leaps).substr(0, 17), "$GPGGA,090018.00,");
}

TEST(ParseGga, RoundTripOfRandomSolutions) {
  std::mt19937 rng(20240624);
  std::uniform_real_distribution<double> lat(-89.9, 89.9);
  std::uniform_real_distribution<double> lon(-179.9, 179.9);
  std::uniform_real_distribution<double> height(-100.0, 5000.0);
  const core::SolutionStatus statuses[] = {core::SolutionStatus::Fixed, core::SolutionStatus::Float,
                                           core::SolutionStatus::Single, core::SolutionStatus::VioFillIn};
  for (int i = 0; i < 1000; ++i) {
    const double lat_deg = lat(rng);
    const double lon_deg = lon(rng);
    const double height_m = height(rng);
    core::Solution s = solution_at(lat_deg, lon_deg, height_m, statuses[i % 4]);
    s.time = kMonday0900Utc + 0.01 * i;
    s.age_s = 0.1 * (i % 30);
    GgaOptions options;
    options.hdop = 0.1 * (i % 50);
    options.station_id = i % 1024;
    const std::string text = format_gga(s, core::builtin_leap_seconds(), options);
    const auto parsed = parse_gga(text + "\r\n");
    ASSERT_TRUE(parsed.ok()) << text << ": " << parsed.error().to_string();
    EXPECT_EQ(parsed->talker, "GP");
    EXPECT_NEAR(*parsed->lat_deg, lat_deg, kMinuteResolutionDeg) << text;
    EXPECT_NEAR(*parsed->lon_deg, lon_deg, kMinuteResolutionDeg) << text;
    EXPECT_NEAR(*parsed->altitude_m + *parsed->geoid_separation_m, height_m, 0.0005 + 1e-9) << text;
    EXPECT_EQ(parsed->quality, gga_quality(s.status));
    EXPECT_EQ(parsed->num_satellites, 12);
    EXPECT_NEAR(*parsed->hdop, *options.hdop, 0.05 + 1e-9);
    EXPECT_NEAR(parsed->utc_seconds_of_day, 9 * 3600.0 + 0.01 * i, 0.005 + 1e-9);
    const bool differential = s.status == core::SolutionStatus::Fixed || s.status == core::SolutionStatus::Float;
    EXPECT_EQ(parsed->age_s.has_value(), differential);
    EXPECT_EQ(parsed->station_id.has_value(), differential);
    if (differential) {
      EXPECT_EQ(*parsed->station_id, i % 1024);
    }
  }
}

TEST(ParseGga, AcceptsOtherTalkersAndEmptyFields) {
  const auto parsed = parse_gga("$GNGGA,000001.5,,,,,0,,,,,,,,*62");
  ASSERT_TRUE(parsed.ok()) << parsed.error().to_string();
  EXPECT_EQ(parsed->talker, "GN");
  EXPECT_DOUBLE_EQ(parsed->utc_seconds_of_day, 1.5);
  EXPECT_FALSE(parsed->lat_deg.has_value());
  EXPECT_FALSE(parsed->hdop.has_value());
}

TEST(ParseGga, Errors) {
  const auto error_of = [](std::string_view text) {
    const auto parsed = parse_gga(text);
    return parsed.ok() ? std::string("ok") : parsed.error().message;
  };
  EXPECT_NE(error_of("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*48").find("computed 47"),
            std::string::npos);
  EXPECT_NE(error_of("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,").find("missing checksum"),
            std::string::npos);
  EXPECT_NE(error_of("GPGGA,123519*00").find("'$'"), std::string::npos);
  EXPECT_NE(error_of("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*4G").find("hexadecimal"),
            std::string::npos);
  // Correct checksums over bad content (computed for each body).
  const auto with_checksum = [](const std::string& body) {
    char suffix[4];
    std::snprintf(suffix, sizeof suffix, "*%02X", nmea_checksum(body));
    return "$" + body + suffix;
  };
  EXPECT_NE(error_of(with_checksum("GPRMC,123519,A")).find("not a GGA"), std::string::npos);
  EXPECT_NE(error_of(with_checksum("GPGGA,123519,4807.038,N")).find("fields"), std::string::npos);
  EXPECT_NE(error_of(with_checksum("GPGGA,123519,4867.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,")).find("latitude"),
            std::string::npos);
  EXPECT_NE(error_of(with_checksum("GPGGA,123519,4807.038,X,01131.000,E,1,08,0.9,545.4,M,46.9,M,,")).find("hemisphere"),
            std::string::npos);
  EXPECT_NE(error_of(with_checksum("GPGGA,253519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,")).find("UTC time"),
            std::string::npos);
  EXPECT_NE(error_of(with_checksum("GPGGA,123519,4807.038,N,01131.000,E,9,08,0.9,545.4,M,46.9,M,,")).find("quality"),
            std::string::npos);
  EXPECT_NE(error_of(with_checksum("GPGGA,123519,4807.038,N,01131.000,E,1,08,x,545.4,M,46.9,M,,")).find("HDOP"),
            std::string::npos);
  EXPECT_NE(error_of(with_checksum("GPGGA,123519,4807.038,N,01131.000,E,4,08,0.9,545.4,M,46.9,M,1.0,2000"))
                .find("station id"),
            std::string::npos);
}

TEST(NmeaWriter, WritesOneSentencePerSolutionWithCrLf) {
  const auto path = (std::filesystem::temp_directory_path() / "canyon_nmea_test" / "out.nmea").string();
  GgaOptions options;
  options.station_id = 12;
  auto writer = NmeaWriter::create(path, core::builtin_leap_seconds(), options);
  ASSERT_TRUE(writer.ok()) << writer.error().to_string();
  const core::Solution fixed = solution_at(35.13469901, 136.97757549, 104.8626, core::SolutionStatus::Fixed);
  ASSERT_TRUE(writer->write(fixed, 0.8).ok());
  ASSERT_TRUE(writer->write(solution_at(-1.0, -2.0, 3.0, core::SolutionStatus::Single)).ok());
  ASSERT_TRUE(writer->close().ok());
  std::ifstream in(path, std::ios::binary);
  std::stringstream content;
  content << in.rdbuf();
  const std::string text = content.str();
  EXPECT_EQ(text.substr(0, text.find('\n') + 1),
            "$GPGGA,090000.00,3508.0819406,N,13658.6545294,E,4,12,0.8,104.863,M,0.000,M,1.0,0012*77\r\n");
  std::istringstream lines(text);
  std::string line;
  int count = 0;
  while (std::getline(lines, line)) {
    ASSERT_FALSE(line.empty());
    EXPECT_EQ(line.back(), '\r');
    EXPECT_TRUE(parse_gga(line).ok()) << line;
    ++count;
  }
  EXPECT_EQ(count, 2);
  EXPECT_FALSE(NmeaWriter::create("/proc/canyon_nmea_test/a.nmea").ok());
}

}  // namespace
}  // namespace canyon::io
