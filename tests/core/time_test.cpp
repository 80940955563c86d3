#include "canyon/core/time.hpp"

#include <ctime>
#include <random>

#include <gtest/gtest.h>

namespace canyon::core {
namespace {

constexpr double kMaxTimeErrorS = 1e-9;

struct CalendarCase {
  CalendarTime calendar;
  int week;
  double tow_s;
};

// Table: calendar dates on the GPST scale and their GPS week / time of week.
const CalendarCase kCalendarCases[] = {
    {{1980, 1, 6, 0, 0, 0.0}, 0, 0.0},
    {{1999, 8, 21, 23, 59, 47.0}, 1023, 604787.0},  // last GPS week before the first rollover
    {{1999, 8, 22, 0, 0, 0.0}, 1024, 0.0},          // first rollover; also GST week 0
    {{2005, 4, 2, 0, 0, 0.0}, 1316, 518400.0},      // rtklib-test-gsi-2005 first epoch
    {{2006, 1, 1, 0, 0, 0.0}, 1356, 0.0},           // BDT week 0
    {{2019, 4, 7, 0, 0, 0.0}, 2048, 0.0},           // second rollover
    {{2021, 9, 22, 6, 30, 0.0}, 2176, 282600.0},    // cssrlib-kinematic-doy265
    {{2023, 1, 8, 10, 0, 0.0}, 2244, 36000.0},      // instinct-spirent-rtk-sim
    {{2024, 2, 29, 12, 0, 0.5}, 2303, 388800.5},    // leap day
};

TEST(CalendarTest, ConvertsTableBothWays) {
  for (const auto& c : kCalendarCases) {
    const GpsTime t = calendar_to_gps(c.calendar);
    EXPECT_EQ(t.week, c.week) << format_calendar(c.calendar);
    EXPECT_NEAR(t.tow_s, c.tow_s, kMaxTimeErrorS) << format_calendar(c.calendar);
    const CalendarTime back = gps_to_calendar(t);
    EXPECT_EQ(format_calendar(back, 6), format_calendar(c.calendar, 6));
  }
}

TEST(CalendarTest, DayOfYear) {
  EXPECT_EQ(day_of_year(2021, 9, 22), 265);
  EXPECT_EQ(day_of_year(2021, 3, 19), 78);
  EXPECT_EQ(day_of_year(2024, 12, 31), 366);
  EXPECT_EQ(day_of_year(2023, 12, 31), 365);
}

TEST(CalendarTest, ValidatesFields) {
  EXPECT_TRUE(is_valid({2024, 2, 29, 0, 0, 0.0}));
  EXPECT_FALSE(is_valid({2023, 2, 29, 0, 0, 0.0}));
  EXPECT_FALSE(is_valid({2023, 13, 1, 0, 0, 0.0}));
  EXPECT_FALSE(is_valid({2023, 1, 1, 24, 0, 0.0}));
  EXPECT_FALSE(is_valid({2023, 1, 1, 0, 60, 0.0}));
  EXPECT_FALSE(is_valid({2023, 1, 1, 0, 0, -1.0}));
}

TEST(CalendarTest, RandomRoundTrips) {
  std::mt19937_64 rng(42);
  std::uniform_int_distribution<int> week(0, 5000);
  std::uniform_real_distribution<double> tow(0.0, kSecondsPerWeek);
  for (int i = 0; i < 20000; ++i) {
    const GpsTime t{week(rng), tow(rng)};
    const GpsTime back = calendar_to_gps(gps_to_calendar(t));
    EXPECT_NEAR(back - t, 0.0, 1e-6) << t.week << " " << t.tow_s;
  }
}

TEST(GpsTimeTest, ArithmeticNormalizesAcrossWeeks) {
  const GpsTime t{2000, 604799.5};
  const GpsTime u = t + 1.0;
  EXPECT_EQ(u.week, 2001);
  EXPECT_NEAR(u.tow_s, 0.5, kMaxTimeErrorS);
  EXPECT_NEAR(u - t, 1.0, kMaxTimeErrorS);
  const GpsTime v = GpsTime{2001, 0.25} - 0.5;
  EXPECT_EQ(v.week, 2000);
  EXPECT_NEAR(v.tow_s, 604799.75, kMaxTimeErrorS);
  EXPECT_TRUE(t < u);
  EXPECT_EQ((GpsTime{10, -kSecondsPerWeek * 2.5}).normalized().week, 7);
}

TEST(LeapSecondTest, BuiltinTable) {
  const LeapSecondTable leaps = builtin_leap_seconds();
  EXPECT_EQ(leaps.gps_minus_utc_at_utc({1980, 1, 6, 0, 0, 0.0}), 0);
  EXPECT_EQ(leaps.gps_minus_utc_at_utc({2005, 4, 2, 0, 0, 0.0}), 13);
  EXPECT_EQ(leaps.gps_minus_utc_at_utc({2016, 12, 31, 23, 59, 59.0}), 17);
  EXPECT_EQ(leaps.gps_minus_utc_at_utc({2017, 1, 1, 0, 0, 0.0}), 18);
  EXPECT_EQ(leaps.gps_minus_utc_at_utc({2026, 11, 22, 0, 0, 0.0}), 18);
  // On the GPST scale the step happens 18 s after the UTC label.
  const GpsTime step = calendar_to_gps({2017, 1, 1, 0, 0, 0.0});
  EXPECT_EQ(leaps.gps_minus_utc_at_gps(step + 17.5), 17);
  EXPECT_EQ(leaps.gps_minus_utc_at_gps(step + 18.0), 18);
}

TEST(LeapSecondTest, TablePassedInIsUsedAndExtendable) {
  const LeapSecondTable custom({{{2030, 1, 1, 0, 0, 0.0}, 19}, {{2017, 1, 1, 0, 0, 0.0}, 18}});
  EXPECT_EQ(custom.gps_minus_utc_at_utc({2029, 6, 1, 0, 0, 0.0}), 18);
  EXPECT_EQ(custom.gps_minus_utc_at_utc({2030, 6, 1, 0, 0, 0.0}), 19);
  const LeapSecondTable extended = builtin_leap_seconds().with_entry({{2031, 1, 1, 0, 0, 0.0}, 19});
  EXPECT_EQ(extended.gps_minus_utc_at_utc({2031, 1, 2, 0, 0, 0.0}), 19);
  EXPECT_EQ(builtin_leap_seconds().gps_minus_utc_at_utc({2031, 1, 2, 0, 0, 0.0}), 18);  // builtin unchanged
}

TEST(TimeSystemTest, UtcRoundTripsAndOffsets) {
  const LeapSecondTable leaps = builtin_leap_seconds();
  const GpsTime t = utc_to_gps({2021, 9, 22, 6, 29, 42.0}, leaps);
  EXPECT_EQ(t.week, 2176);
  EXPECT_NEAR(t.tow_s, 282600.0, kMaxTimeErrorS);
  EXPECT_EQ(format_calendar(gps_to_utc(t, leaps)), "2021-09-22 06:29:42.000");
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int> week(1000, 3000);
  std::uniform_real_distribution<double> tow(0.0, kSecondsPerWeek);
  for (int i = 0; i < 5000; ++i) {
    const GpsTime g{week(rng), tow(rng)};
    EXPECT_NEAR(utc_to_gps(gps_to_utc(g, leaps), leaps) - g, 0.0, 1e-6);
    EXPECT_NEAR(glonass_to_gps(gps_to_glonass(g, leaps), leaps) - g, 0.0, 1e-6);
  }
}

TEST(TimeSystemTest, GalileoAndBeiDou) {
  const GpsTime gst = gst_to_gps(1152, 282600.0);
  EXPECT_EQ(gst.week, 2176);
  EXPECT_NEAR(gst.tow_s, 282600.0, kMaxTimeErrorS);
  const GpsTime bdt = bdt_to_gps(820, 282586.0);  // BDT = GPST - 14 s
  EXPECT_EQ(bdt.week, 2176);
  EXPECT_NEAR(bdt.tow_s, 282600.0, kMaxTimeErrorS);
  const WeekTow b = gps_to_bdt(GpsTime{1356, 10.0});  // 4 s before BDT week 0 began
  EXPECT_EQ(b.week, -1);
  EXPECT_NEAR(b.tow_s, 604796.0, kMaxTimeErrorS);
  const WeekTow b2 = gps_to_bdt(GpsTime{1356, 14.0});
  EXPECT_EQ(b2.week, 0);
  EXPECT_NEAR(b2.tow_s, 0.0, kMaxTimeErrorS);
  const WeekTow g = gps_to_gst(GpsTime{2176, 5.0});
  EXPECT_EQ(g.week, 1152);
}

TEST(TimeSystemTest, GlonassIsUtcPlusThreeHours) {
  const LeapSecondTable leaps = builtin_leap_seconds();
  const GpsTime t = glonass_to_gps({2024, 6, 24, 11, 20, 0.0}, leaps);
  const CalendarTime utc = gps_to_utc(t, leaps);
  EXPECT_EQ(format_calendar(utc), "2024-06-24 08:20:00.000");
}

TEST(WeekRolloverTest, ResolvesTruncatedWeeks) {
  EXPECT_EQ(resolve_week_rollover(128, 10, 2176), 2176);
  EXPECT_EQ(resolve_week_rollover(1023, 10, 2048), 2047);
  EXPECT_EQ(resolve_week_rollover(0, 10, 2047), 2048);
  EXPECT_EQ(resolve_week_rollover(292, 10, 1300), 1316);
  EXPECT_EQ(resolve_week_rollover(1152, 12, 1150), 1152);
  EXPECT_EQ(resolve_week_rollover(820, 13, 800), 820);
}

TEST(WeekRolloverTest, NearestTimeOfWeek) {
  const GpsTime ref{2000, 10.0};
  const GpsTime t = nearest_gps_time(604790.0, ref);
  EXPECT_EQ(t.week, 1999);
  const GpsTime u = nearest_gps_time(20.0, GpsTime{2000, 604790.0});
  EXPECT_EQ(u.week, 2001);
}

TEST(PipelineClockTest, IsMonotonic) {
  const PipelineNs a = pipeline_now_ns();
  const PipelineNs b = pipeline_now_ns();
  EXPECT_LE(a, b);
}

TEST(FormatGpst, WeekAndTimeOfWeekNormalised) {
  EXPECT_EQ(format_gpst(GpsTime{2175, 369000.04}), "GPST 2175 369000.0");
  EXPECT_EQ(format_gpst(GpsTime{2175, 604800.5}, 3), "GPST 2176 0.500");
  EXPECT_EQ(format_gpst(GpsTime{2176, -1.25}, 2), "GPST 2175 604798.75");
}

TEST(SystemClockGps, IsTheClockOnTheGpstScale) {
  const LeapSecondTable leaps = builtin_leap_seconds();
  const auto seconds_since_1970 = [](const GpsTime& t) {
    // GPST 0 is 1980-01-06 00:00:00 UTC, 315964800 s after 1970; GPST - UTC is 18 s since 2017.
    return static_cast<double>(t.week) * 604800.0 + t.tow_s + 315964800.0 - 18.0;
  };
  const double before = static_cast<double>(std::time(nullptr));
  const double now = seconds_since_1970(system_clock_gps(leaps));
  const double after = static_cast<double>(std::time(nullptr));
  EXPECT_GE(now, before);
  EXPECT_LE(now, after);
}

}  // namespace
}  // namespace canyon::core
