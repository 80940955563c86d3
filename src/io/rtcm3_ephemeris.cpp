// RTCM 3 ephemeris messages: 1019 GPS, 1020 GLONASS, 1042 BeiDou, 1044 QZSS, 1045 Galileo F/NAV, 1046 Galileo
// I/NAV (RTCM 10403.3 tables 3.5-21, 3.5-22, and the 1042/1044/1045/1046 tables of amendments 1-2).
// Angles are sent in semicircles: converted with the ICD's pi (kGpsPi).

#include <algorithm>
#include <array>
#include <cmath>

#include "canyon/io/bits.hpp"
#include "canyon/io/rtcm3.hpp"

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

double p2(int e) {
  return std::ldexp(1.0, e);
}

/// Writes scaled fields and keeps the first range error, naming the field.
class FieldWriter {
 public:
  FieldWriter(std::vector<std::uint8_t>& out, int number) : w_(out), number_(number) {}

  void raw(std::uint64_t value, unsigned bits) { w_.u(value, bits); }
  /// Unsigned integer field.
  void uint(long long value, unsigned bits, const char* name) {
    if (value < 0 || value >= (1LL << bits)) {
      fail(name);
      value = 0;
    }
    w_.u(static_cast<std::uint64_t>(value), bits);
  }
  /// round(value / lsb) as an unsigned field.
  void uscaled(double value, double lsb, unsigned bits, const char* name) {
    const double q = std::round(value / lsb);
    if (!(q >= 0.0 && q < std::ldexp(1.0, static_cast<int>(bits)))) {
      fail(name);
      w_.u(0, bits);
      return;
    }
    w_.u(static_cast<std::uint64_t>(q), bits);
  }
  /// round(value / lsb) as a two's complement field.
  void sscaled(double value, double lsb, unsigned bits, const char* name) {
    const double q = std::round(value / lsb);
    const double limit = std::ldexp(1.0, static_cast<int>(bits) - 1);
    if (!(q >= -limit && q < limit)) {
      fail(name);
      w_.u(0, bits);
      return;
    }
    w_.s(static_cast<std::int64_t>(q), bits);
  }
  /// round(value / lsb) as a sign-magnitude field (GLONASS).
  void smscaled(double value, double lsb, unsigned bits, const char* name) {
    const double q = std::round(value / lsb);
    const double limit = std::ldexp(1.0, static_cast<int>(bits) - 1);
    if (!(q > -limit && q < limit)) {
      fail(name);
      w_.u(0, bits);
      return;
    }
    w_.sm(static_cast<std::int64_t>(q), bits);
  }
  [[nodiscard]] Status status() const {
    if (error_.empty()) return Ok{};
    return Error{error_};
  }

 private:
  void fail(const char* name) {
    if (error_.empty())
      error_ = "RTCM 3 message " + std::to_string(number_) + ": " + name + " out of its field's range";
  }
  BitWriter w_;
  int number_;
  std::string error_;
};

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

std::string short_text(int number, std::size_t bytes, unsigned bits) {
  return "RTCM 3 message " + std::to_string(number) + ": " + std::to_string(bytes) + " bytes, needs " +
         std::to_string((bits + 7) / 8);
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
  const double sc = kGpsPi;  // radians per semicircle
  FieldWriter w(out, number);
  w.raw(static_cast<std::uint64_t>(number), 12);
  const double toc_s = system_sow(e.toc, e.sat.system);
  switch (number) {
    case 1019: {
      w.uint(e.sat.prn, 6, "satellite id");
      w.raw(static_cast<std::uint64_t>(e.toe.week % 1024), 10);
      w.uint(ura_index(e.accuracy_m), 4, "URA");
      w.raw(static_cast<std::uint64_t>(e.data_source & 3), 2);
      w.sscaled(e.idot_radps / sc, p2(-43), 14, "IDOT");
      w.uint(e.iode, 8, "IODE");
      w.uscaled(toc_s, 16.0, 16, "toc");
      w.sscaled(e.af2_sps2, p2(-55), 8, "af2");
      w.sscaled(e.af1_sps, p2(-43), 16, "af1");
      w.sscaled(e.af0_s, p2(-31), 22, "af0");
      w.uint(e.iodc, 10, "IODC");
      w.sscaled(e.crs_m, p2(-5), 16, "Crs");
      w.sscaled(e.delta_n_radps / sc, p2(-43), 16, "delta n");
      w.sscaled(e.m0_rad / sc, p2(-31), 32, "M0");
      w.sscaled(e.cuc_rad, p2(-29), 16, "Cuc");
      w.uscaled(e.e, p2(-33), 32, "e");
      w.sscaled(e.cus_rad, p2(-29), 16, "Cus");
      w.uscaled(e.sqrt_a_sqrtm, p2(-19), 32, "sqrt A");
      w.uscaled(e.toe_sow_s, 16.0, 16, "toe");
      w.sscaled(e.cic_rad, p2(-29), 16, "Cic");
      w.sscaled(e.omega0_rad / sc, p2(-31), 32, "OMEGA0");
      w.sscaled(e.cis_rad, p2(-29), 16, "Cis");
      w.sscaled(e.i0_rad / sc, p2(-31), 32, "i0");
      w.sscaled(e.crc_m, p2(-5), 16, "Crc");
      w.sscaled(e.omega_rad / sc, p2(-31), 32, "omega");
      w.sscaled(e.omega_dot_radps / sc, p2(-43), 24, "OMEGADOT");
      w.sscaled(e.tgd_s[0], p2(-31), 8, "TGD");
      w.uint(e.health, 6, "health");
      w.raw(0, 1);  // L2 P data flag: not kept by canyon
      w.raw(e.fit_interval_h > 4.0 ? 1 : 0, 1);
      break;
    }
    case 1044: {
      w.uint(e.sat.prn, 4, "satellite id");
      w.uscaled(toc_s, 16.0, 16, "toc");
      w.sscaled(e.af2_sps2, p2(-55), 8, "af2");
      w.sscaled(e.af1_sps, p2(-43), 16, "af1");
      w.sscaled(e.af0_s, p2(-31), 22, "af0");
      w.uint(e.iode, 8, "IODE");
      w.sscaled(e.crs_m, p2(-5), 16, "Crs");
      w.sscaled(e.delta_n_radps / sc, p2(-43), 16, "delta n");
      w.sscaled(e.m0_rad / sc, p2(-31), 32, "M0");
      w.sscaled(e.cuc_rad, p2(-29), 16, "Cuc");
      w.uscaled(e.e, p2(-33), 32, "e");
      w.sscaled(e.cus_rad, p2(-29), 16, "Cus");
      w.uscaled(e.sqrt_a_sqrtm, p2(-19), 32, "sqrt A");
      w.uscaled(e.toe_sow_s, 16.0, 16, "toe");
      w.sscaled(e.cic_rad, p2(-29), 16, "Cic");
      w.sscaled(e.omega0_rad / sc, p2(-31), 32, "OMEGA0");
      w.sscaled(e.cis_rad, p2(-29), 16, "Cis");
      w.sscaled(e.i0_rad / sc, p2(-31), 32, "i0");
      w.sscaled(e.crc_m, p2(-5), 16, "Crc");
      w.sscaled(e.omega_rad / sc, p2(-31), 32, "omega");
      w.sscaled(e.omega_dot_radps / sc, p2(-43), 24, "OMEGADOT");
      w.sscaled(e.idot_radps / sc, p2(-43), 14, "IDOT");
      w.raw(static_cast<std::uint64_t>(e.data_source & 3), 2);
      w.raw(static_cast<std::uint64_t>(e.toe.week % 1024), 10);
      w.uint(ura_index(e.accuracy_m), 4, "URA");
      w.uint(e.health, 6, "health");
      w.sscaled(e.tgd_s[0], p2(-31), 8, "TGD");
      w.uint(e.iodc, 10, "IODC");
      w.raw(e.fit_interval_h > 4.0 ? 1 : 0, 1);
      break;
    }
    case 1042: {
      w.uint(e.sat.prn, 6, "satellite id");
      w.raw(static_cast<std::uint64_t>(core::gps_to_bdt(e.toe).week % 8192), 13);
      w.uint(ura_index(e.accuracy_m), 4, "URAI");
      w.sscaled(e.idot_radps / sc, p2(-43), 14, "IDOT");
      w.uint(e.iode, 5, "AODE");
      w.uscaled(toc_s, 8.0, 17, "toc");
      w.sscaled(e.af2_sps2, p2(-66), 11, "a2");
      w.sscaled(e.af1_sps, p2(-50), 22, "a1");
      w.sscaled(e.af0_s, p2(-33), 24, "a0");
      w.uint(e.iodc, 5, "AODC");
      w.sscaled(e.crs_m, p2(-6), 18, "Crs");
      w.sscaled(e.delta_n_radps / sc, p2(-43), 16, "delta n");
      w.sscaled(e.m0_rad / sc, p2(-31), 32, "M0");
      w.sscaled(e.cuc_rad, p2(-31), 18, "Cuc");
      w.uscaled(e.e, p2(-33), 32, "e");
      w.sscaled(e.cus_rad, p2(-31), 18, "Cus");
      w.uscaled(e.sqrt_a_sqrtm, p2(-19), 32, "sqrt A");
      w.uscaled(e.toe_sow_s, 8.0, 17, "toe");
      w.sscaled(e.cic_rad, p2(-31), 18, "Cic");
      w.sscaled(e.omega0_rad / sc, p2(-31), 32, "OMEGA0");
      w.sscaled(e.cis_rad, p2(-31), 18, "Cis");
      w.sscaled(e.i0_rad / sc, p2(-31), 32, "i0");
      w.sscaled(e.crc_m, p2(-6), 18, "Crc");
      w.sscaled(e.omega_rad / sc, p2(-31), 32, "omega");
      w.sscaled(e.omega_dot_radps / sc, p2(-43), 24, "OMEGADOT");
      w.sscaled(e.tgd_s[0], 1e-10, 10, "TGD1");
      w.sscaled(e.tgd_s[1], 1e-10, 10, "TGD2");
      w.uint(e.health & 1, 1, "health");
      break;
    }
    case 1045:
    case 1046: {
      w.uint(e.sat.prn, 6, "satellite id");
      w.raw(static_cast<std::uint64_t>(core::gps_to_gst(e.toe).week % 4096), 12);
      w.uint(e.iode, 10, "IODnav");
      w.uint(sisa_index(e.accuracy_m), 8, "SISA");
      w.sscaled(e.idot_radps / sc, p2(-43), 14, "IDOT");
      w.uscaled(toc_s, 60.0, 14, "toc");
      w.sscaled(e.af2_sps2, p2(-59), 6, "af2");
      w.sscaled(e.af1_sps, p2(-46), 21, "af1");
      w.sscaled(e.af0_s, p2(-34), 31, "af0");
      w.sscaled(e.crs_m, p2(-5), 16, "Crs");
      w.sscaled(e.delta_n_radps / sc, p2(-43), 16, "delta n");
      w.sscaled(e.m0_rad / sc, p2(-31), 32, "M0");
      w.sscaled(e.cuc_rad, p2(-29), 16, "Cuc");
      w.uscaled(e.e, p2(-33), 32, "e");
      w.sscaled(e.cus_rad, p2(-29), 16, "Cus");
      w.uscaled(e.sqrt_a_sqrtm, p2(-19), 32, "sqrt A");
      w.uscaled(e.toe_sow_s, 60.0, 14, "toe");
      w.sscaled(e.cic_rad, p2(-29), 16, "Cic");
      w.sscaled(e.omega0_rad / sc, p2(-31), 32, "OMEGA0");
      w.sscaled(e.cis_rad, p2(-29), 16, "Cis");
      w.sscaled(e.i0_rad / sc, p2(-31), 32, "i0");
      w.sscaled(e.crc_m, p2(-5), 16, "Crc");
      w.sscaled(e.omega_rad / sc, p2(-31), 32, "omega");
      w.sscaled(e.omega_dot_radps / sc, p2(-43), 24, "OMEGADOT");
      w.sscaled(e.tgd_s[0], p2(-32), 10, "BGD E5a/E1");
      // RINEX health bits: 0 E1-B DVS, 1-2 E1-B HS, 3 E5a DVS, 4-5 E5a HS, 6 E5b DVS, 7-8 E5b HS.
      if (number == 1045) {
        w.raw(static_cast<std::uint64_t>((e.health >> 4) & 3), 2);
        w.raw(static_cast<std::uint64_t>((e.health >> 3) & 1), 1);
        w.raw(0, 7);
      } else {
        w.sscaled(e.tgd_s[1], p2(-32), 10, "BGD E5b/E1");
        w.raw(static_cast<std::uint64_t>((e.health >> 7) & 3), 2);
        w.raw(static_cast<std::uint64_t>((e.health >> 6) & 1), 1);
        w.raw(static_cast<std::uint64_t>((e.health >> 1) & 3), 2);
        w.raw(static_cast<std::uint64_t>(e.health & 1), 1);
        w.raw(0, 2);
      }
      break;
    }
    default: break;
  }
  return w.status();
}

Result<core::KeplerEphemeris> decode_kepler_ephemeris(std::span<const std::uint8_t> payload, const GpsTime& reference) {
  const int number = message_number(payload);
  unsigned needed = 0;
  switch (number) {
    case 1019: needed = 488; break;
    case 1044: needed = 485; break;
    case 1042: needed = 511; break;
    case 1045: needed = 496; break;
    case 1046: needed = 504; break;
    default: return Error{"RTCM 3 message " + std::to_string(number) + " is not a Keplerian ephemeris"};
  }
  BitReader r(payload);
  if (r.bits_left() < needed) return Error{short_text(number, payload.size(), needed)};
  r.skip(12);
  const double sc = kGpsPi;
  core::KeplerEphemeris e;
  double toc_s = 0.0;
  int week = 0;
  auto sat = [&](Constellation system, std::uint64_t prn) -> Status {
    e.sat = core::SatelliteId{system, static_cast<std::uint8_t>(prn)};
    if (!e.sat.valid()) {
      return Error{"RTCM 3 message " + std::to_string(number) + ": satellite id " + std::to_string(prn) +
                   " not valid for " + std::string(core::constellation_name(system))};
    }
    return Ok{};
  };
  switch (number) {
    case 1019: {
      if (Status s = sat(Constellation::Gps, r.u(6)); !s.ok()) return s.error();
      week = core::resolve_week_rollover(static_cast<int>(r.u(10)), 10, reference.week);
      e.accuracy_m = ura_m(static_cast<int>(r.u(4)));
      e.data_source = static_cast<int>(r.u(2));
      e.idot_radps = static_cast<double>(r.s(14)) * p2(-43) * sc;
      e.iode = static_cast<int>(r.u(8));
      toc_s = static_cast<double>(r.u(16)) * 16.0;
      e.af2_sps2 = static_cast<double>(r.s(8)) * p2(-55);
      e.af1_sps = static_cast<double>(r.s(16)) * p2(-43);
      e.af0_s = static_cast<double>(r.s(22)) * p2(-31);
      e.iodc = static_cast<int>(r.u(10));
      e.crs_m = static_cast<double>(r.s(16)) * p2(-5);
      e.delta_n_radps = static_cast<double>(r.s(16)) * p2(-43) * sc;
      e.m0_rad = static_cast<double>(r.s(32)) * p2(-31) * sc;
      e.cuc_rad = static_cast<double>(r.s(16)) * p2(-29);
      e.e = static_cast<double>(r.u(32)) * p2(-33);
      e.cus_rad = static_cast<double>(r.s(16)) * p2(-29);
      e.sqrt_a_sqrtm = static_cast<double>(r.u(32)) * p2(-19);
      e.toe_sow_s = static_cast<double>(r.u(16)) * 16.0;
      e.cic_rad = static_cast<double>(r.s(16)) * p2(-29);
      e.omega0_rad = static_cast<double>(r.s(32)) * p2(-31) * sc;
      e.cis_rad = static_cast<double>(r.s(16)) * p2(-29);
      e.i0_rad = static_cast<double>(r.s(32)) * p2(-31) * sc;
      e.crc_m = static_cast<double>(r.s(16)) * p2(-5);
      e.omega_rad = static_cast<double>(r.s(32)) * p2(-31) * sc;
      e.omega_dot_radps = static_cast<double>(r.s(24)) * p2(-43) * sc;
      e.tgd_s[0] = static_cast<double>(r.s(8)) * p2(-31);
      e.health = static_cast<int>(r.u(6));
      r.skip(1);
      e.fit_interval_h = r.u(1) != 0 ? 6.0 : 4.0;
      break;
    }
    case 1044: {
      if (Status s = sat(Constellation::Qzss, r.u(4)); !s.ok()) return s.error();
      toc_s = static_cast<double>(r.u(16)) * 16.0;
      e.af2_sps2 = static_cast<double>(r.s(8)) * p2(-55);
      e.af1_sps = static_cast<double>(r.s(16)) * p2(-43);
      e.af0_s = static_cast<double>(r.s(22)) * p2(-31);
      e.iode = static_cast<int>(r.u(8));
      e.crs_m = static_cast<double>(r.s(16)) * p2(-5);
      e.delta_n_radps = static_cast<double>(r.s(16)) * p2(-43) * sc;
      e.m0_rad = static_cast<double>(r.s(32)) * p2(-31) * sc;
      e.cuc_rad = static_cast<double>(r.s(16)) * p2(-29);
      e.e = static_cast<double>(r.u(32)) * p2(-33);
      e.cus_rad = static_cast<double>(r.s(16)) * p2(-29);
      e.sqrt_a_sqrtm = static_cast<double>(r.u(32)) * p2(-19);
      e.toe_sow_s = static_cast<double>(r.u(16)) * 16.0;
      e.cic_rad = static_cast<double>(r.s(16)) * p2(-29);
      e.omega0_rad = static_cast<double>(r.s(32)) * p2(-31) * sc;
      e.cis_rad = static_cast<double>(r.s(16)) * p2(-29);
      e.i0_rad = static_cast<double>(r.s(32)) * p2(-31) * sc;
      e.crc_m = static_cast<double>(r.s(16)) * p2(-5);
      e.omega_rad = static_cast<double>(r.s(32)) * p2(-31) * sc;
      e.omega_dot_radps = static_cast<double>(r.s(24)) * p2(-43) * sc;
      e.idot_radps = static_cast<double>(r.s(14)) * p2(-43) * sc;
      e.data_source = static_cast<int>(r.u(2));
      week = core::resolve_week_rollover(static_cast<int>(r.u(10)), 10, reference.week);
      e.accuracy_m = ura_m(static_cast<int>(r.u(4)));
      e.health = static_cast<int>(r.u(6));
      e.tgd_s[0] = static_cast<double>(r.s(8)) * p2(-31);
      e.iodc = static_cast<int>(r.u(10));
      e.fit_interval_h = r.u(1) != 0 ? 6.0 : 4.0;
      break;
    }
    case 1042: {
      if (Status s = sat(Constellation::BeiDou, r.u(6)); !s.ok()) return s.error();
      const int bdt_week = core::resolve_week_rollover(static_cast<int>(r.u(13)), 13, core::gps_to_bdt(reference).week);
      e.accuracy_m = ura_m(static_cast<int>(r.u(4)));
      e.idot_radps = static_cast<double>(r.s(14)) * p2(-43) * sc;
      e.iode = static_cast<int>(r.u(5));
      toc_s = static_cast<double>(r.u(17)) * 8.0;
      e.af2_sps2 = static_cast<double>(r.s(11)) * p2(-66);
      e.af1_sps = static_cast<double>(r.s(22)) * p2(-50);
      e.af0_s = static_cast<double>(r.s(24)) * p2(-33);
      e.iodc = static_cast<int>(r.u(5));
      e.crs_m = static_cast<double>(r.s(18)) * p2(-6);
      e.delta_n_radps = static_cast<double>(r.s(16)) * p2(-43) * sc;
      e.m0_rad = static_cast<double>(r.s(32)) * p2(-31) * sc;
      e.cuc_rad = static_cast<double>(r.s(18)) * p2(-31);
      e.e = static_cast<double>(r.u(32)) * p2(-33);
      e.cus_rad = static_cast<double>(r.s(18)) * p2(-31);
      e.sqrt_a_sqrtm = static_cast<double>(r.u(32)) * p2(-19);
      e.toe_sow_s = static_cast<double>(r.u(17)) * 8.0;
      e.cic_rad = static_cast<double>(r.s(18)) * p2(-31);
      e.omega0_rad = static_cast<double>(r.s(32)) * p2(-31) * sc;
      e.cis_rad = static_cast<double>(r.s(18)) * p2(-31);
      e.i0_rad = static_cast<double>(r.s(32)) * p2(-31) * sc;
      e.crc_m = static_cast<double>(r.s(18)) * p2(-6);
      e.omega_rad = static_cast<double>(r.s(32)) * p2(-31) * sc;
      e.omega_dot_radps = static_cast<double>(r.s(24)) * p2(-43) * sc;
      e.tgd_s[0] = static_cast<double>(r.s(10)) * 1e-10;
      e.tgd_s[1] = static_cast<double>(r.s(10)) * 1e-10;
      e.health = static_cast<int>(r.u(1));
      e.toe = nearest_week(core::bdt_to_gps(bdt_week, e.toe_sow_s), reference);
      e.toc = e.toe + (std::remainder(toc_s - e.toe_sow_s, double(core::kSecondsPerWeek)));
      e.transmission_time = e.toe;
      return e;
    }
    case 1045:
    case 1046: {
      if (Status s = sat(Constellation::Galileo, r.u(6)); !s.ok()) return s.error();
      const int gst_week = core::resolve_week_rollover(static_cast<int>(r.u(12)), 12, core::gps_to_gst(reference).week);
      week = gst_week + core::kGstWeekOffset;
      e.iode = static_cast<int>(r.u(10));
      e.accuracy_m = sisa_m(static_cast<int>(r.u(8)));
      e.idot_radps = static_cast<double>(r.s(14)) * p2(-43) * sc;
      toc_s = static_cast<double>(r.u(14)) * 60.0;
      e.af2_sps2 = static_cast<double>(r.s(6)) * p2(-59);
      e.af1_sps = static_cast<double>(r.s(21)) * p2(-46);
      e.af0_s = static_cast<double>(r.s(31)) * p2(-34);
      e.crs_m = static_cast<double>(r.s(16)) * p2(-5);
      e.delta_n_radps = static_cast<double>(r.s(16)) * p2(-43) * sc;
      e.m0_rad = static_cast<double>(r.s(32)) * p2(-31) * sc;
      e.cuc_rad = static_cast<double>(r.s(16)) * p2(-29);
      e.e = static_cast<double>(r.u(32)) * p2(-33);
      e.cus_rad = static_cast<double>(r.s(16)) * p2(-29);
      e.sqrt_a_sqrtm = static_cast<double>(r.u(32)) * p2(-19);
      e.toe_sow_s = static_cast<double>(r.u(14)) * 60.0;
      e.cic_rad = static_cast<double>(r.s(16)) * p2(-29);
      e.omega0_rad = static_cast<double>(r.s(32)) * p2(-31) * sc;
      e.cis_rad = static_cast<double>(r.s(16)) * p2(-29);
      e.i0_rad = static_cast<double>(r.s(32)) * p2(-31) * sc;
      e.crc_m = static_cast<double>(r.s(16)) * p2(-5);
      e.omega_rad = static_cast<double>(r.s(32)) * p2(-31) * sc;
      e.omega_dot_radps = static_cast<double>(r.s(24)) * p2(-43) * sc;
      e.tgd_s[0] = static_cast<double>(r.s(10)) * p2(-32);
      if (number == 1045) {
        const auto e5a_hs = static_cast<int>(r.u(2));
        const auto e5a_dvs = static_cast<int>(r.u(1));
        e.health = (e5a_hs << 4) | (e5a_dvs << 3);
        e.data_source = 0x102;  // F/NAV E5a-I, clock for E5a,E1
      } else {
        e.tgd_s[1] = static_cast<double>(r.s(10)) * p2(-32);
        const auto e5b_hs = static_cast<int>(r.u(2));
        const auto e5b_dvs = static_cast<int>(r.u(1));
        const auto e1_hs = static_cast<int>(r.u(2));
        const auto e1_dvs = static_cast<int>(r.u(1));
        e.health = (e5b_hs << 7) | (e5b_dvs << 6) | (e1_hs << 1) | e1_dvs;
        e.data_source = 0x205;  // I/NAV E1-B and E5b-I, clock for E5b,E1
      }
      break;
    }
    default: break;
  }
  e.toe = nearest_week(GpsTime{week, e.toe_sow_s}, reference);
  e.toc = e.toe + std::remainder(toc_s - e.toe_sow_s, double(core::kSecondsPerWeek));
  e.transmission_time = e.toe;
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

}  // namespace

Status append_glonass_ephemeris(const core::GlonassEphemeris& g, const core::LeapSecondTable& leaps,
                                std::vector<std::uint8_t>& out) {
  FieldWriter w(out, 1020);
  w.raw(1020, 12);
  w.uint(g.sat.prn, 6, "satellite id");
  w.uint(g.frequency_channel + 7, 5, "frequency channel");
  w.raw(0, 1);  // almanac health
  w.raw(0, 1);  // almanac health availability
  w.raw(0, 2);  // P1
  const auto tk_s = static_cast<long long>(std::floor(msk_time_of_day(g.frame_time, leaps) + 0.5));
  w.uint(tk_s / 3600, 5, "tk hours");
  w.uint((tk_s % 3600) / 60, 6, "tk minutes");
  w.uint((tk_s % 60) >= 30 ? 1 : 0, 1, "tk 30 s");
  w.raw(g.health != 0 ? 1 : 0, 1);  // Bn MSB
  const auto tb = static_cast<long long>(std::lround(msk_time_of_day(g.toe, leaps) / 900.0)) % 96;
  w.raw(static_cast<std::uint64_t>(tb & 1), 1);  // P2: oddness of tb
  w.uint(tb, 7, "tb");
  const Eigen::Vector3d p_km = g.p_E_m * 1e-3;
  const Eigen::Vector3d v_kmps = g.v_E_mps * 1e-3;
  const Eigen::Vector3d a_kmps2 = g.a_E_mps2 * 1e-3;
  for (int i = 0; i < 3; ++i) {
    w.smscaled(v_kmps[i], p2(-20), 24, "velocity");
    w.smscaled(p_km[i], p2(-11), 27, "position");
    w.smscaled(a_kmps2[i], p2(-30), 5, "acceleration");
  }
  w.raw(0, 1);  // P3
  w.smscaled(g.gamma_n, p2(-40), 11, "gamma_n");
  w.raw(0, 2);  // P
  w.raw(0, 1);  // ln (third string)
  w.smscaled(-g.tau_n_s, p2(-30), 22, "tau_n");
  w.smscaled(g.delta_tau_n_s, p2(-30), 5, "delta tau_n");
  w.uint(g.age_days, 5, "E_n");
  w.raw(0, 1);  // P4
  w.raw(0, 4);  // F_T
  // N_T: day number within the four-year interval starting with a leap year (Moscow date of tb).
  const core::CalendarTime msk = core::gps_to_calendar(g.toe + msk_minus_gps_s(g.toe, leaps));
  const int first_year = msk.year - ((msk.year - 1996) % 4 + 4) % 4;
  const auto nt = core::days_from_civil(msk.year, msk.month, msk.day) - core::days_from_civil(first_year, 1, 1) + 1;
  w.uint(nt, 11, "N_T");
  w.raw(1, 2);  // M: GLONASS-M
  w.raw(0, 1);  // no additional data (NA, tau_c, N4, tau_GPS) follows as valid
  w.raw(0, 11);
  w.raw(0, 32);
  w.raw(0, 5);
  w.raw(0, 22);
  w.raw(0, 1);
  w.raw(0, 7);
  return w.status();
}

Result<core::GlonassEphemeris> decode_glonass_ephemeris(std::span<const std::uint8_t> payload, const GpsTime& reference,
                                                        const core::LeapSecondTable& leaps) {
  const int number = message_number(payload);
  if (number != 1020) return Error{"RTCM 3 message " + std::to_string(number) + " is not 1020"};
  BitReader r(payload);
  if (r.bits_left() < 360) return Error{short_text(number, payload.size(), 360)};
  r.skip(12);
  core::GlonassEphemeris g;
  const auto slot = r.u(6);
  g.sat = core::SatelliteId{Constellation::Glonass, static_cast<std::uint8_t>(slot)};
  if (!g.sat.valid()) return Error{"RTCM 3 message 1020: GLONASS slot " + std::to_string(slot) + " not valid"};
  g.frequency_channel = static_cast<int>(r.u(5)) - 7;
  if (g.frequency_channel > 6) {
    return Error{"RTCM 3 message 1020: frequency channel " + std::to_string(g.frequency_channel) + " outside -7..6"};
  }
  r.skip(1 + 1 + 2);
  const auto tk_h = static_cast<int>(r.u(5));
  const auto tk_m = static_cast<int>(r.u(6));
  const auto tk_30 = static_cast<int>(r.u(1));
  g.health = static_cast<int>(r.u(1));
  r.skip(1);
  const auto tb = static_cast<int>(r.u(7));
  Eigen::Vector3d p_km, v_kmps, a_kmps2;
  for (int i = 0; i < 3; ++i) {
    v_kmps[i] = static_cast<double>(r.sm(24)) * p2(-20);
    p_km[i] = static_cast<double>(r.sm(27)) * p2(-11);
    a_kmps2[i] = static_cast<double>(r.sm(5)) * p2(-30);
  }
  r.skip(1);
  g.gamma_n = static_cast<double>(r.sm(11)) * p2(-40);
  r.skip(2 + 1);
  g.tau_n_s = -static_cast<double>(r.sm(22)) * p2(-30);
  g.delta_tau_n_s = static_cast<double>(r.sm(5)) * p2(-30);
  g.age_days = static_cast<int>(r.u(5));
  g.p_E_m = p_km * 1e3;
  g.v_E_mps = v_kmps * 1e3;
  g.a_E_mps2 = a_kmps2 * 1e3;
  if (tb >= 96 || tk_h >= 24 || tk_m >= 60) {
    return Error{"RTCM 3 message 1020: time field out of range (tb " + std::to_string(tb) + ", tk " +
                 std::to_string(tk_h) + ":" + std::to_string(tk_m) + ")"};
  }
  // Times of day in Moscow time; the day is the one that puts tb nearest the reference.
  const double offset_s = msk_minus_gps_s(reference, leaps);
  const GpsTime ref_msk = reference + offset_s;
  const GpsTime day_start = ref_msk - std::fmod(ref_msk.tow_s, double(core::kSecondsPerDay));
  GpsTime toe_msk = day_start + tb * 900.0;
  toe_msk = toe_msk + std::round((ref_msk - toe_msk) / core::kSecondsPerDay) * core::kSecondsPerDay;
  const double tk_s = tk_h * 3600.0 + tk_m * 60.0 + tk_30 * 30.0;
  GpsTime tk_msk = toe_msk - std::fmod(toe_msk.tow_s, double(core::kSecondsPerDay)) + tk_s;
  tk_msk = tk_msk + std::round((toe_msk - tk_msk) / core::kSecondsPerDay) * core::kSecondsPerDay;
  g.toe = toe_msk - offset_s;
  g.frame_time = tk_msk - offset_s;
  return g;
}

}  // namespace canyon::io::rtcm3
