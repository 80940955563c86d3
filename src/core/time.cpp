#include "canyon/core/time.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>

namespace canyon::core {
namespace {

constexpr std::int64_t kGpsEpochDaysFrom1970 = 3657;  // 1980-01-06

bool is_leap_year(int year) {
  return (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
}

int days_in_month(int year, int month) {
  static constexpr std::array<int, 12> kDays = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  return month == 2 && is_leap_year(year) ? 29 : kDays[static_cast<std::size_t>(month - 1)];
}

// Civil date from days since 1970-01-01 (inverse of days_from_civil; H. Hinnant's algorithm).
void civil_from_days(std::int64_t z, int& year, int& month, int& day) {
  z += 719468;
  const std::int64_t era = (z >= 0 ? z : z - 146096) / 146097;
  const auto doe = static_cast<unsigned>(z - era * 146097);
  const unsigned yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const std::int64_t y = static_cast<std::int64_t>(yoe) + era * 400;
  const unsigned doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const unsigned mp = (5 * doy + 2) / 153;
  day = static_cast<int>(doy - (153 * mp + 2) / 5 + 1);
  month = static_cast<int>(mp < 10 ? mp + 3 : mp - 9);
  year = static_cast<int>(y + (month <= 2 ? 1 : 0));
}

// Seconds since 1970-01-01 of a calendar time on its own scale, split into whole days and the rest.
double seconds_of_day(const CalendarTime& c) {
  return c.hour * 3600.0 + c.minute * 60.0 + c.second;
}

}  // namespace

PipelineNs pipeline_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

GpsTime GpsTime::normalized() const {
  GpsTime t = *this;
  if (t.tow_s >= kSecondsPerWeek || t.tow_s < 0.0) {
    const double weeks = std::floor(t.tow_s / kSecondsPerWeek);
    t.week += static_cast<int>(weeks);
    t.tow_s -= weeks * kSecondsPerWeek;
    if (t.tow_s >= kSecondsPerWeek) {  // rounding at the boundary
      t.tow_s -= kSecondsPerWeek;
      ++t.week;
    }
  }
  return t;
}

GpsTime operator+(const GpsTime& t, double dt_s) {
  return GpsTime{t.week, t.tow_s + dt_s}.normalized();
}

std::int64_t days_from_civil(int year, int month, int day) {
  const int y = year - (month <= 2 ? 1 : 0);
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const auto mp = static_cast<unsigned>(month > 2 ? month - 3 : month + 9);
  const unsigned doy = (153 * mp + 2) / 5 + static_cast<unsigned>(day) - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

int day_of_year(int year, int month, int day) {
  return static_cast<int>(days_from_civil(year, month, day) - days_from_civil(year, 1, 1)) + 1;
}

bool is_valid(const CalendarTime& c) {
  return c.month >= 1 && c.month <= 12 && c.day >= 1 && c.day <= days_in_month(c.year, c.month) && c.hour >= 0 &&
         c.hour < 24 && c.minute >= 0 && c.minute < 60 && c.second >= 0.0 && c.second < 61.0;
}

GpsTime calendar_to_gps(const CalendarTime& c) {
  const std::int64_t days = days_from_civil(c.year, c.month, c.day) - kGpsEpochDaysFrom1970;
  const std::int64_t week = days >= 0 ? days / 7 : (days - 6) / 7;
  const std::int64_t day_of_week = days - week * 7;
  return GpsTime{static_cast<int>(week), static_cast<double>(day_of_week * kSecondsPerDay) + seconds_of_day(c)}
      .normalized();
}

CalendarTime gps_to_calendar(const GpsTime& t) {
  const GpsTime n = t.normalized();
  double day_of_week = std::floor(n.tow_s / kSecondsPerDay);
  double sod = n.tow_s - day_of_week * kSecondsPerDay;
  CalendarTime c;
  civil_from_days(kGpsEpochDaysFrom1970 + std::int64_t{n.week} * 7 + static_cast<std::int64_t>(day_of_week), c.year,
                  c.month, c.day);
  c.hour = static_cast<int>(sod / 3600.0);
  sod -= c.hour * 3600.0;
  c.minute = static_cast<int>(sod / 60.0);
  c.second = sod - c.minute * 60.0;
  return c;
}

LeapSecondTable::LeapSecondTable(std::vector<Entry> entries) : entries_(std::move(entries)) {
  std::sort(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) {
    return calendar_to_gps(a.utc_effective) < calendar_to_gps(b.utc_effective);
  });
}

int LeapSecondTable::gps_minus_utc_at_utc(const CalendarTime& utc) const {
  // Compare on a common (leap-free) count of seconds; the table holds UTC labels, so do the same for the query.
  const GpsTime query = calendar_to_gps(utc);
  int value = 0;
  for (const Entry& e : entries_) {
    if (query - calendar_to_gps(e.utc_effective) >= 0.0) {
      value = e.gps_minus_utc_s;
    }
  }
  return value;
}

int LeapSecondTable::gps_minus_utc_at_gps(const GpsTime& gpst) const {
  int value = 0;
  for (const Entry& e : entries_) {
    // The entry takes effect at UTC label `utc_effective`, which is GPST label utc_effective + new value.
    if (gpst - (calendar_to_gps(e.utc_effective) + e.gps_minus_utc_s) >= 0.0) {
      value = e.gps_minus_utc_s;
    }
  }
  return value;
}

LeapSecondTable LeapSecondTable::with_entry(const Entry& entry) const {
  std::vector<Entry> entries = entries_;
  const GpsTime t = calendar_to_gps(entry.utc_effective);
  std::erase_if(entries, [&](const Entry& e) { return std::abs(calendar_to_gps(e.utc_effective) - t) < 1.0; });
  entries.push_back(entry);
  return LeapSecondTable(std::move(entries));
}

LeapSecondTable builtin_leap_seconds() {
  // IERS Bulletin C: UTC dates at which GPST - UTC stepped to the given value.
  static constexpr std::array<std::array<int, 4>, 18> kSteps = {{{1981, 7, 1, 1},
                                                                 {1982, 7, 1, 2},
                                                                 {1983, 7, 1, 3},
                                                                 {1985, 7, 1, 4},
                                                                 {1988, 1, 1, 5},
                                                                 {1990, 1, 1, 6},
                                                                 {1991, 1, 1, 7},
                                                                 {1992, 7, 1, 8},
                                                                 {1993, 7, 1, 9},
                                                                 {1994, 7, 1, 10},
                                                                 {1996, 1, 1, 11},
                                                                 {1997, 7, 1, 12},
                                                                 {1999, 1, 1, 13},
                                                                 {2006, 1, 1, 14},
                                                                 {2009, 1, 1, 15},
                                                                 {2012, 7, 1, 16},
                                                                 {2015, 7, 1, 17},
                                                                 {2017, 1, 1, 18}}};
  std::vector<LeapSecondTable::Entry> entries;
  entries.reserve(kSteps.size());
  for (const auto& s : kSteps) {
    entries.push_back({CalendarTime{s[0], s[1], s[2], 0, 0, 0.0}, s[3]});
  }
  return LeapSecondTable(std::move(entries));
}

GpsTime utc_to_gps(const CalendarTime& utc, const LeapSecondTable& leaps) {
  return calendar_to_gps(utc) + leaps.gps_minus_utc_at_utc(utc);
}

CalendarTime gps_to_utc(const GpsTime& gpst, const LeapSecondTable& leaps) {
  return gps_to_calendar(gpst - leaps.gps_minus_utc_at_gps(gpst));
}

GpsTime gst_to_gps(int gst_week, double tow_s) {
  return GpsTime{gst_week + kGstWeekOffset, tow_s}.normalized();
}

GpsTime bdt_to_gps(int bdt_week, double sow_s) {
  return GpsTime{bdt_week + kBdtWeekOffset, sow_s}.normalized() - kBdtMinusGpstS;
}

WeekTow gps_to_bdt(const GpsTime& gpst) {
  const GpsTime b = gpst + kBdtMinusGpstS;
  return {b.week - kBdtWeekOffset, b.tow_s};
}

WeekTow gps_to_gst(const GpsTime& gpst) {
  const GpsTime n = gpst.normalized();
  return {n.week - kGstWeekOffset, n.tow_s};
}

GpsTime glonass_to_gps(const CalendarTime& glonass_time, const LeapSecondTable& leaps) {
  const CalendarTime utc = gps_to_calendar(calendar_to_gps(glonass_time) - kGlonassMinusUtcS);
  return utc_to_gps(utc, leaps);
}

CalendarTime gps_to_glonass(const GpsTime& gpst, const LeapSecondTable& leaps) {
  return gps_to_calendar(calendar_to_gps(gps_to_utc(gpst, leaps)) + kGlonassMinusUtcS);
}

int resolve_week_rollover(int truncated_week, int bits, int reference_week) {
  const int period = 1 << bits;
  const int base = truncated_week % period;
  int best = base;
  for (int k = 0; k * period + base <= reference_week + period; ++k) {
    const int candidate = k * period + base;
    if (std::abs(candidate - reference_week) < std::abs(best - reference_week)) {
      best = candidate;
    }
  }
  return best;
}

GpsTime nearest_gps_time(double tow_s, const GpsTime& reference) {
  GpsTime t{reference.week, tow_s};
  const double dt = t - reference;
  if (dt > kSecondsPerWeek / 2.0) {
    --t.week;
  } else if (dt < -kSecondsPerWeek / 2.0) {
    ++t.week;
  }
  return t;
}

std::string format_calendar(const CalendarTime& c, int decimals) {
  // Round once at the requested precision so that 59.9996 s prints as the next minute, not "60.000".
  const double scale = std::pow(10.0, decimals);
  GpsTime t = calendar_to_gps(c);
  t.tow_s = std::round(t.tow_s * scale) / scale;
  const CalendarTime r = gps_to_calendar(t.normalized());
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%04d-%02d-%02d %02d:%02d:%0*.*f", r.year, r.month, r.day, r.hour, r.minute,
                decimals > 0 ? decimals + 3 : 2, decimals, r.second);
  return buffer;
}

std::string format_gpst(const GpsTime& t, int decimals) {
  const GpsTime n = t.normalized();
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "GPST %d %.*f", n.week, decimals, n.tow_s);
  return buffer;
}

GpsTime system_clock_gps(const LeapSecondTable& leaps) {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  const CalendarTime c{utc.tm_year + 1900, utc.tm_mon + 1, utc.tm_mday,
                       utc.tm_hour,        utc.tm_min,     static_cast<double>(utc.tm_sec)};
  return utc_to_gps(c, leaps);
}

std::optional<GpsTime> parse_gps_calendar(const std::string& text) {
  CalendarTime c;
  char sep1 = 0;
  char sep2 = 0;
  char tail = 0;
  const int n = std::sscanf(text.c_str(), "%d%c%d%c%d %d:%d:%lf%c", &c.year, &sep1, &c.month, &sep2, &c.day, &c.hour,
                            &c.minute, &c.second, &tail);
  if (n == 5) {
    c.hour = 0;
    c.minute = 0;
    c.second = 0.0;
  } else if (n != 8) {
    return std::nullopt;
  }
  if ((sep1 != '-' && sep1 != '/') || sep2 != sep1 || !is_valid(c)) return std::nullopt;
  return calendar_to_gps(c);
}

}  // namespace canyon::core
