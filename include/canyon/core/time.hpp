#pragma once
// GNSS time and the pipeline clock.
//
// Two time types and no globals:
//  - GpsTime {week, tow_s}: GNSS time, always on the GPST scale. Other systems' times (GST, BDT, GLONASS, UTC)
//    are converted to and from GPST at the edges (readers, writers); inside canyon everything is GPST.
//  - PipelineNs: the pipeline clock, int64 nanoseconds of a monotonic clock, for latency and ordering.
// Leap seconds come from a LeapSecondTable that is passed in (built from the navigation header or the built-in
// list returned by builtin_leap_seconds()), never from a mutable global.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace canyon::core {

inline constexpr int kSecondsPerWeek = 604800;
inline constexpr int kSecondsPerDay = 86400;
inline constexpr int kGstWeekOffset = 1024;           ///< GPS week of GST week 0 (1999-08-22)
inline constexpr int kBdtWeekOffset = 1356;           ///< GPS week of BDT week 0 (2006-01-01)
inline constexpr double kBdtMinusGpstS = -14.0;       ///< BDT = GPST - 14 s
inline constexpr double kGlonassMinusUtcS = 10800.0;  ///< GLONASS time = UTC(SU) + 3 h

/// Pipeline clock: monotonic nanoseconds (steady clock), only for latency and ordering, never for GNSS time.
using PipelineNs = std::int64_t;
[[nodiscard]] PipelineNs pipeline_now_ns();

/// GNSS time on the GPST scale. `tow_s` is kept in [0, 604800) by normalize().
struct GpsTime {
  int week = 0;        ///< weeks since 1980-01-06 00:00:00 GPST, no rollover
  double tow_s = 0.0;  ///< seconds of week

  /// Same instant with tow_s in [0, 604800).
  [[nodiscard]] GpsTime normalized() const;
  /// Seconds since the GPS epoch (loses sub-microsecond precision after ~2^53 ns; use differences instead).
  [[nodiscard]] double seconds_since_epoch() const { return week * double(kSecondsPerWeek) + tow_s; }

  friend bool operator==(const GpsTime& a, const GpsTime& b) = default;
};

/// a - b in seconds.
[[nodiscard]] inline double operator-(const GpsTime& a, const GpsTime& b) {
  return (a.week - b.week) * double(kSecondsPerWeek) + (a.tow_s - b.tow_s);
}
/// t + dt_s, normalized.
[[nodiscard]] GpsTime operator+(const GpsTime& t, double dt_s);
[[nodiscard]] inline GpsTime operator-(const GpsTime& t, double dt_s) {
  return t + (-dt_s);
}
[[nodiscard]] inline bool operator<(const GpsTime& a, const GpsTime& b) {
  return (a - b) < 0.0;
}

/// Broken-down calendar time in whatever scale the caller says (GPST, UTC, GLONASS Moscow time...).
struct CalendarTime {
  int year = 1980;
  int month = 1;
  int day = 6;
  int hour = 0;
  int minute = 0;
  double second = 0.0;

  friend bool operator==(const CalendarTime& a, const CalendarTime& b) = default;
};

/// Days since 1970-01-01 of a proleptic Gregorian date (negative before).
[[nodiscard]] std::int64_t days_from_civil(int year, int month, int day);
/// Day of year, 1..366.
[[nodiscard]] int day_of_year(int year, int month, int day);
/// True if the fields are a valid calendar time (second in [0, 61) to allow a leap second label).
[[nodiscard]] bool is_valid(const CalendarTime& c);

/// Calendar time read on the GPST scale -> GpsTime, and back.
[[nodiscard]] GpsTime calendar_to_gps(const CalendarTime& c);
[[nodiscard]] CalendarTime gps_to_calendar(const GpsTime& t);
/// "2021-03-19 12:00:00", "2021/03/19 12:00:00" or a date alone ("2021-03-19", midnight), read as GPST; nullopt
/// if malformed.
[[nodiscard]] std::optional<GpsTime> parse_gps_calendar(const std::string& text);

/// Leap seconds: GPST - UTC, from a table of the UTC instants at which each new value took effect.
class LeapSecondTable {
 public:
  struct Entry {
    CalendarTime utc_effective;  ///< first UTC instant at which `gps_minus_utc_s` holds
    int gps_minus_utc_s = 0;
  };
  LeapSecondTable() = default;
  /// Entries in any order; they are sorted by time.
  explicit LeapSecondTable(std::vector<Entry> entries);

  /// GPST - UTC (s) at a UTC instant; 0 before the first entry (1980).
  [[nodiscard]] int gps_minus_utc_at_utc(const CalendarTime& utc) const;
  /// GPST - UTC (s) at a GPST instant.
  [[nodiscard]] int gps_minus_utc_at_gps(const GpsTime& gpst) const;
  /// Copy with one more entry: how a RINEX "LEAP SECONDS" header newer than the table extends it.
  [[nodiscard]] LeapSecondTable with_entry(const Entry& entry) const;
  [[nodiscard]] const std::vector<Entry>& entries() const { return entries_; }

 private:
  std::vector<Entry> entries_;  // sorted by utc_effective
};

/// The leap seconds known when this build was made (up to 2017-01-01, GPST - UTC = 18 s).
[[nodiscard]] LeapSecondTable builtin_leap_seconds();

// Conversions between GPST and the other time scales.
[[nodiscard]] GpsTime utc_to_gps(const CalendarTime& utc, const LeapSecondTable& leaps);
[[nodiscard]] CalendarTime gps_to_utc(const GpsTime& gpst, const LeapSecondTable& leaps);
/// Galileo System Time: same second as GPST, week numbered from 1999-08-22.
[[nodiscard]] GpsTime gst_to_gps(int gst_week, double tow_s);
/// BeiDou Time: GPST - 14 s, week numbered from 2006-01-01.
[[nodiscard]] GpsTime bdt_to_gps(int bdt_week, double sow_s);
/// (BDT week, BDT seconds of week) of a GPST instant.
struct WeekTow {
  int week = 0;
  double tow_s = 0.0;
};
[[nodiscard]] WeekTow gps_to_bdt(const GpsTime& gpst);
[[nodiscard]] WeekTow gps_to_gst(const GpsTime& gpst);
/// GLONASS time (Moscow, UTC + 3 h) <-> GPST.
[[nodiscard]] GpsTime glonass_to_gps(const CalendarTime& glonass_time, const LeapSecondTable& leaps);
[[nodiscard]] CalendarTime gps_to_glonass(const GpsTime& gpst, const LeapSecondTable& leaps);

/// Full week number from a week number truncated to `bits` bits (10 for GPS LNAV, 12 for GST, 13 for BDT...),
/// choosing the candidate closest to `reference_week` (a full week, e.g. from the file date or the clock).
[[nodiscard]] int resolve_week_rollover(int truncated_week, int bits, int reference_week);

/// Nearest time of week to `reference` for a time of week `tow_s` that is known only modulo a week
/// (e.g. an ephemeris toe or a transmission time near a week boundary).
[[nodiscard]] GpsTime nearest_gps_time(double tow_s, const GpsTime& reference);

/// "2021-09-22 06:30:00.000" (scale as the caller knows it).
[[nodiscard]] std::string format_calendar(const CalendarTime& c, int decimals = 3);

/// "GPST 2175 369000.0": week and time of week (normalised), as logs name an epoch.
[[nodiscard]] std::string format_gpst(const GpsTime& t, int decimals = 1);

/// The system clock's time now, on the GPST scale (whole seconds; `leaps` for GPST - UTC). For a reference time
/// near the data (RTCM 3 and week rollovers) when the data carries none.
[[nodiscard]] GpsTime system_clock_gps(const LeapSecondTable& leaps);

}  // namespace canyon::core
