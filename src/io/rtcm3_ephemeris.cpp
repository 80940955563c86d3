// RTCM 3 ephemeris messages: 1019 GPS, 1020 GLONASS, 1042 BeiDou, 1044 QZSS, 1045 Galileo F/NAV, 1046 Galileo
// I/NAV (RTCM 10403.3 tables 3.5-21, 3.5-22, and the 1042/1044/1045/1046 tables of amendments 1-2). Their fields are
// laid out in rtcm3_fields.hpp; here are the truncated weeks, accuracy indices, health bits and GLONASS times.

#include <algorithm>
#include <array>
#include <cmath>

#include "canyon/io/bits.hpp"
#include "canyon/io/rtcm3.hpp"
#include "canyon/io/rtcm3_fields.hpp"

namespace canyon::io::rtcm3 {
namespace {

using core::Constellation;
using core::GpsTime;

// URA index N (IS-GPS-200 20.3.3.3.1.3): upper bounds of the accuracy ranges (encoding: the first range that holds
// the value) and the nominal values X the ICD gives users (decoding; RINEX writers, RTKLIB's too, write these).
constexpr std::array<double, 15> kUraUpperM = {2.4,  3.4,   4.85,  6.85,  9.65,   13.65,  24.0,  48.0,
                                               96.0, 192.0, 384.0, 768.0, 1536.0, 3072.0, 6144.0};
constexpr std::array<double, 16> kUraNominalM = {2.0,  2.8,   4.0,   5.7,   8.0,    11.3,   16.0,   32.0,
                                                 64.0, 128.0, 256.0, 512.0, 1024.0, 2048.0, 4096.0, 8192.0};

/// Seconds of week of a GPST instant in a system's time (BDT for BeiDou).
double system_sow(const GpsTime& t, Constellation system) {
  return system == Constellation::BeiDou ? core::gps_to_bdt(t).tow_s : t.normalized().tow_s;
}

/// `t` moved by one week towards `reference` when it is more than half a week (and less than a week and a half) away:
/// a message's week may be that of its transmission rather than of toe. Farther is a date question the week number
/// answers, not this.
GpsTime nearest_week(GpsTime t, const GpsTime& reference) {
  const double d = t - reference;
  constexpr double kHalf = core::kSecondsPerWeek / 2.0;
  if (d > kHalf && d < 3 * kHalf) return t - double(core::kSecondsPerWeek);
  if (d < -kHalf && d > -3 * kHalf) return t + double(core::kSecondsPerWeek);
  return t;
}

std::string short_text(int number, std::size_t bytes, std::size_t bits) {
  return "RTCM 3 message " + std::to_string(number) + ": " + std::to_string(bytes) + " bytes, needs " +
         std::to_string((bits + 7) / 8);
}

/// What message `number` carries of `e` in another form than KeplerEphemeris.
fields::KeplerWire kepler_wire(const core::KeplerEphemeris& e, int number) {
  fields::KeplerWire w;
  w.number = number;
  w.prn = e.sat.prn;
  w.toc_s = system_sow(e.toc, e.sat.system);
  switch (number) {
    case 1019:
    case 1044:
      w.week = e.toe.week % 1024;
      w.accuracy = ura_index(e.accuracy_m);
      w.l2_codes = e.data_source & 3;
      w.fit_interval = e.fit_interval_h > 4.0 ? 1 : 0;
      break;
    case 1042:
      w.week = core::gps_to_bdt(e.toe).week % 8192;
      w.accuracy = ura_index(e.accuracy_m);
      w.health = e.health & 1;
      break;
    default:  // 1045, 1046
      w.week = core::gps_to_gst(e.toe).week % 4096;
      w.accuracy = sisa_index(e.accuracy_m);
      // RINEX health bits: 0 E1-B DVS, 1-2 E1-B HS, 3 E5a DVS, 4-5 E5a HS, 6 E5b DVS, 7-8 E5b HS.
      w.e5a_health = (e.health >> 4) & 3;
      w.e5a_validity = (e.health >> 3) & 1;
      w.e5b_health = (e.health >> 7) & 3;
      w.e5b_validity = (e.health >> 6) & 1;
      w.e1b_health = (e.health >> 1) & 3;
      w.e1b_validity = e.health & 1;
      break;
  }
  return w;
}

/// The rest of a decoded Kepler ephemeris from what its message `w` carried: satellite, times, accuracy, health.
Status complete_kepler(core::KeplerEphemeris& e, const fields::KeplerWire& w, const GpsTime& reference) {
  Constellation system = Constellation::Gps;
  switch (w.number) {
    case 1044: system = Constellation::Qzss; break;
    case 1042: system = Constellation::BeiDou; break;
    case 1045:
    case 1046: system = Constellation::Galileo; break;
    default: break;
  }
  e.sat = core::SatelliteId{system, static_cast<std::uint8_t>(w.prn)};
  if (!e.sat.valid()) {
    return Error{"RTCM 3 message " + std::to_string(w.number) + ": satellite id " + std::to_string(w.prn) +
                 " not valid for " + std::string(core::constellation_name(system))};
  }
  const double week_s = core::kSecondsPerWeek;
  switch (system) {
    case Constellation::BeiDou: {
      const int bdt_week = core::resolve_week_rollover(w.week, 13, core::gps_to_bdt(reference).week);
      e.accuracy_m = ura_m(w.accuracy);
      e.health = w.health;
      e.toe = nearest_week(core::bdt_to_gps(bdt_week, e.toe_sow_s), reference);
      break;
    }
    case Constellation::Galileo: {
      const int gst_week = core::resolve_week_rollover(w.week, 12, core::gps_to_gst(reference).week);
      e.accuracy_m = sisa_m(w.accuracy);
      if (w.number == 1045) {
        e.health = (w.e5a_health << 4) | (w.e5a_validity << 3);
        e.data_source = 0x102;  // F/NAV E5a-I, clock for E5a,E1
      } else {
        e.health = (w.e5b_health << 7) | (w.e5b_validity << 6) | (w.e1b_health << 1) | w.e1b_validity;
        e.data_source = 0x205;  // I/NAV E1-B and E5b-I, clock for E5b,E1
      }
      e.toe = nearest_week(GpsTime{gst_week + core::kGstWeekOffset, e.toe_sow_s}, reference);
      break;
    }
    default: {  // GPS, QZSS
      const int week = core::resolve_week_rollover(w.week, 10, reference.week);
      e.accuracy_m = ura_m(w.accuracy);
      e.data_source = w.l2_codes;
      e.fit_interval_h = w.fit_interval != 0 ? 6.0 : 4.0;
      e.toe = nearest_week(GpsTime{week, e.toe_sow_s}, reference);
      break;
    }
  }
  e.toc = e.toe + std::remainder(w.toc_s - e.toe_sow_s, week_s);
  e.transmission_time = e.toe;
  return Ok{};
}

}  // namespace

double ura_m(int index) {
  return kUraNominalM[static_cast<std::size_t>(std::clamp(index, 0, 15))];
}

int ura_index(double accuracy_m) {
  for (std::size_t i = 0; i < kUraUpperM.size(); ++i) {
    if (kUraUpperM[i] >= accuracy_m) return static_cast<int>(i);
  }
  return 15;
}

double sisa_m(int index) {
  if (index < 0 || index > 125) return -1.0;
  if (index <= 49) return index * 0.01;
  if (index <= 74) return 0.5 + (index - 50) * 0.02;
  if (index <= 99) return 1.0 + (index - 75) * 0.04;
  return 2.0 + (index - 100) * 0.16;
}

int sisa_index(double accuracy_m) {
  if (!(accuracy_m >= 0.0) || accuracy_m > 6.0) return 255;
  if (accuracy_m <= 0.5) return static_cast<int>(std::lround(accuracy_m / 0.01));
  if (accuracy_m <= 1.0) return static_cast<int>(std::lround((accuracy_m - 0.5) / 0.02)) + 50;
  if (accuracy_m <= 2.0) return static_cast<int>(std::lround((accuracy_m - 1.0) / 0.04)) + 75;
  return static_cast<int>(std::lround((accuracy_m - 2.0) / 0.16)) + 100;
}

int ephemeris_message_number(const core::KeplerEphemeris& eph) {
  switch (eph.sat.system) {
    case Constellation::Gps: return 1019;
    case Constellation::Qzss: return 1044;
    case Constellation::BeiDou: return 1042;
    case Constellation::Galileo: return (eph.data_source & 0x2) != 0 ? 1045 : 1046;
    case Constellation::Glonass: return 1020;
  }
  return 0;
}

Status append_kepler_ephemeris(const core::KeplerEphemeris& e, std::vector<std::uint8_t>& out) {
  const int number = ephemeris_message_number(e);
  if (number == 1020) return Error{"a GLONASS satellite has no Keplerian ephemeris"};
  fields::KeplerWire wire = kepler_wire(e, number);
  BitWriter bits(out);
  fields::FieldWriter w(bits, number);
  fields::kepler_ephemeris_fields(w, e, wire);
  return w.status();
}

Result<core::KeplerEphemeris> decode_kepler_ephemeris(std::span<const std::uint8_t> payload, const GpsTime& reference) {
  fields::KeplerWire wire;
  wire.number = message_number(payload);
  core::KeplerEphemeris e;
  fields::FieldCounter needed;
  if (!fields::kepler_ephemeris_fields(needed, e, wire)) {
    return Error{"RTCM 3 message " + std::to_string(wire.number) + " is not a Keplerian ephemeris"};
  }
  if (8 * payload.size() < needed.bits()) return Error{short_text(wire.number, payload.size(), needed.bits())};
  fields::FieldReader r(payload);
  fields::kepler_ephemeris_fields(r, e, wire);
  if (Status s = complete_kepler(e, wire, reference); !s.ok()) return s.error();
  return e;
}

// ---------------------------------------------------------------------------------------------------------------
// GLONASS 1020.

namespace {

/// Moscow time (UTC + 3 h) minus GPST at `t`, seconds.
double msk_minus_gps_s(const GpsTime& t, const core::LeapSecondTable& leaps) {
  return core::kGlonassMinusUtcS - leaps.gps_minus_utc_at_gps(t);
}

/// Seconds of the Moscow day of a GPST instant.
double msk_time_of_day(const GpsTime& t, const core::LeapSecondTable& leaps) {
  const GpsTime msk = t + msk_minus_gps_s(t, leaps);
  return std::fmod(msk.tow_s, double(core::kSecondsPerDay));
}

/// What 1020 carries of `g` in another form than GlonassEphemeris.
fields::GlonassWire glonass_wire(const core::GlonassEphemeris& g, const core::LeapSecondTable& leaps) {
  fields::GlonassWire w;
  w.slot = g.sat.prn;
  w.channel = g.frequency_channel + 7;
  const auto tk_s = static_cast<long long>(std::floor(msk_time_of_day(g.frame_time, leaps) + 0.5));
  w.tk_hours = tk_s / 3600;
  w.tk_minutes = (tk_s % 3600) / 60;
  w.tk_half_minute = (tk_s % 60) >= 30 ? 1 : 0;
  w.bn_msb = g.health != 0 ? 1 : 0;
  w.tb = static_cast<long long>(std::lround(msk_time_of_day(g.toe, leaps) / 900.0)) % 96;
  w.tb_odd = w.tb & 1;
  // N_T: day number within the four-year interval starting with a leap year (Moscow date of tb).
  const core::CalendarTime msk = core::gps_to_calendar(g.toe + msk_minus_gps_s(g.toe, leaps));
  const int first_year = msk.year - ((msk.year - 1996) % 4 + 4) % 4;
  w.day_number = core::days_from_civil(msk.year, msk.month, msk.day) - core::days_from_civil(first_year, 1, 1) + 1;
  return w;
}

}  // namespace

Status append_glonass_ephemeris(const core::GlonassEphemeris& g, const core::LeapSecondTable& leaps,
                                std::vector<std::uint8_t>& out) {
  fields::GlonassWire wire = glonass_wire(g, leaps);
  BitWriter bits(out);
  fields::FieldWriter w(bits, 1020);
  fields::glonass_ephemeris_fields(w, g, wire);
  return w.status();
}

Result<core::GlonassEphemeris> decode_glonass_ephemeris(std::span<const std::uint8_t> payload, const GpsTime& reference,
                                                        const core::LeapSecondTable& leaps) {
  const int number = message_number(payload);
  if (number != 1020) return Error{"RTCM 3 message " + std::to_string(number) + " is not 1020"};
  core::GlonassEphemeris g;
  fields::GlonassWire w;
  fields::FieldCounter needed;
  fields::glonass_ephemeris_fields(needed, g, w);
  if (8 * payload.size() < needed.bits()) return Error{short_text(number, payload.size(), needed.bits())};
  fields::FieldReader r(payload);
  fields::glonass_ephemeris_fields(r, g, w);
  g.sat = core::SatelliteId{Constellation::Glonass, static_cast<std::uint8_t>(w.slot)};
  if (!g.sat.valid()) return Error{"RTCM 3 message 1020: GLONASS slot " + std::to_string(w.slot) + " not valid"};
  g.frequency_channel = w.channel - 7;
  if (g.frequency_channel > 6) {
    return Error{"RTCM 3 message 1020: frequency channel " + std::to_string(g.frequency_channel) + " outside -7..6"};
  }
  g.health = w.bn_msb;
  if (w.tb >= 96 || w.tk_hours >= 24 || w.tk_minutes >= 60) {
    return Error{"RTCM 3 message 1020: time field out of range (tb " + std::to_string(w.tb) + ", tk " +
                 std::to_string(w.tk_hours) + ":" + std::to_string(w.tk_minutes) + ")"};
  }
  // Times of day in Moscow time; the day is the one that puts tb nearest the reference.
  const double offset_s = msk_minus_gps_s(reference, leaps);
  const GpsTime ref_msk = reference + offset_s;
  const GpsTime day_start = ref_msk - std::fmod(ref_msk.tow_s, double(core::kSecondsPerDay));
  GpsTime toe_msk = day_start + w.tb * 900.0;
  toe_msk = toe_msk + std::round((ref_msk - toe_msk) / core::kSecondsPerDay) * core::kSecondsPerDay;
  const double tk_s = w.tk_hours * 3600.0 + w.tk_minutes * 60.0 + w.tk_half_minute * 30.0;
  GpsTime tk_msk = toe_msk - std::fmod(toe_msk.tow_s, double(core::kSecondsPerDay)) + tk_s;
  tk_msk = tk_msk + std::round((toe_msk - tk_msk) / core::kSecondsPerDay) * core::kSecondsPerDay;
  g.toe = toe_msk - offset_s;
  g.frame_time = tk_msk - offset_s;
  return g;
}

}  // namespace canyon::io::rtcm3
