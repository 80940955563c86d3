// Broadcast navigation message decoding (see nav_message.hpp).

#include "canyon/io/nav_message.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "canyon/io/bits.hpp"
#include "canyon/io/rtcm3.hpp"

namespace canyon::io::navmsg {
namespace {

using core::Constellation;
using core::GpsTime;

constexpr double kSc = rtcm3::kGpsPi;  // radians per semicircle

double p2(int e) {
  return std::ldexp(1.0, e);
}

template <std::size_t N>
std::uint64_t u(const std::array<std::uint8_t, N>& a, std::size_t pos, unsigned n) {
  return get_bits(a.data(), N, pos, n);
}
template <std::size_t N>
double s(const std::array<std::uint8_t, N>& a, std::size_t pos, unsigned n) {
  return static_cast<double>(get_bits_signed(a.data(), N, pos, n));
}
template <std::size_t N>
double sm(const std::array<std::uint8_t, N>& a, std::size_t pos, unsigned n) {
  return static_cast<double>(get_bits_sign_magnitude(a.data(), N, pos, n));
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

long long toe_key(const GpsTime& toe) {
  return std::llround(toe.seconds_since_epoch());
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
// GPS / QZSS LNAV.

Result<std::optional<core::KeplerEphemeris>> LnavAssembler::add(core::SatelliteId sat, const Subframe& f,
                                                                const GpsTime& reference) {
  if (u(f, 0, 8) != 0x8B) return Error{sat.to_string() + ": LNAV subframe without preamble"};
  const auto id = static_cast<int>(u(f, 43, 3));
  if (id < 1 || id > 5) return Error{sat.to_string() + ": LNAV subframe id " + std::to_string(id) + " not 1-5"};
  if (id == 4 && sat.system == Constellation::Gps && u(f, 50, 6) == 56) {
    // Subframe 4 page 18: ionosphere (IS-GPS-200 20.3.3.5.1.7), seconds per semicircle to the power k.
    core::KlobucharParams k;
    k.alpha = {s(f, 56, 8) * p2(-30), s(f, 64, 8) * p2(-27), s(f, 72, 8) * p2(-24), s(f, 80, 8) * p2(-24)};
    k.beta = {s(f, 88, 8) * p2(11), s(f, 96, 8) * p2(14), s(f, 104, 8) * p2(16), s(f, 112, 8) * p2(16)};
    klobuchar_ = k;
  }
  if (id > 3) return std::optional<core::KeplerEphemeris>{};  // almanac, UTC: not used here
  State& st = state_[sat];
  st.frames[static_cast<std::size_t>(id - 1)] = f;
  st.have[static_cast<std::size_t>(id - 1)] = true;
  if (!st.have[0] || !st.have[1] || !st.have[2]) return std::optional<core::KeplerEphemeris>{};
  const Subframe& f1 = st.frames[0];
  const Subframe& f2 = st.frames[1];
  const Subframe& f3 = st.frames[2];
  const auto iodc = static_cast<int>((u(f1, 70, 2) << 8) | u(f1, 168, 8));
  const auto iode2 = static_cast<int>(u(f2, 48, 8));
  const auto iode3 = static_cast<int>(u(f3, 216, 8));
  if (iode2 != iode3 || (iodc & 0xFF) != iode2) return std::optional<core::KeplerEphemeris>{};

  core::KeplerEphemeris e;
  e.sat = sat;
  const int week = core::resolve_week_rollover(static_cast<int>(u(f1, 48, 10)), 10, reference.week);
  e.data_source = static_cast<int>(u(f1, 58, 2));
  e.accuracy_m = rtcm3::ura_m(static_cast<int>(u(f1, 60, 4)));
  e.health = static_cast<int>(u(f1, 64, 6));
  e.iodc = iodc;
  e.tgd_s[0] = s(f1, 160, 8) * p2(-31);
  const double toc_s = static_cast<double>(u(f1, 176, 16)) * 16.0;
  e.af2_sps2 = s(f1, 192, 8) * p2(-55);
  e.af1_sps = s(f1, 200, 16) * p2(-43);
  e.af0_s = s(f1, 216, 22) * p2(-31);
  e.iode = iode2;
  e.crs_m = s(f2, 56, 16) * p2(-5);
  e.delta_n_radps = s(f2, 72, 16) * p2(-43) * kSc;
  e.m0_rad = s(f2, 88, 32) * p2(-31) * kSc;
  e.cuc_rad = s(f2, 120, 16) * p2(-29);
  e.e = static_cast<double>(u(f2, 136, 32)) * p2(-33);
  e.cus_rad = s(f2, 168, 16) * p2(-29);
  e.sqrt_a_sqrtm = static_cast<double>(u(f2, 184, 32)) * p2(-19);
  e.toe_sow_s = static_cast<double>(u(f2, 216, 16)) * 16.0;
  e.fit_interval_h = u(f2, 232, 1) != 0 ? 6.0 : 4.0;
  e.cic_rad = s(f3, 48, 16) * p2(-29);
  e.omega0_rad = s(f3, 64, 32) * p2(-31) * kSc;
  e.cis_rad = s(f3, 96, 16) * p2(-29);
  e.i0_rad = s(f3, 112, 32) * p2(-31) * kSc;
  e.crc_m = s(f3, 144, 16) * p2(-5);
  e.omega_rad = s(f3, 160, 32) * p2(-31) * kSc;
  e.omega_dot_radps = s(f3, 192, 24) * p2(-43) * kSc;
  e.idot_radps = s(f3, 224, 14) * p2(-43) * kSc;
  // Transmission time: start of subframe 1 (its HOW counts the start of the next subframe in 6 s units).
  const double tow_s = static_cast<double>(u(f1, 24, 17)) * 6.0 - 6.0;
  e.transmission_time = nearest_week(GpsTime{week, tow_s}.normalized(), reference);
  e.toe = nearest_week(GpsTime{week, e.toe_sow_s}, e.transmission_time);
  e.toc = e.toe + std::remainder(toc_s - e.toe_sow_s, double(core::kSecondsPerWeek));
  if (e.iode == st.last_iode && toe_key(e.toe) == st.last_toe) return std::optional<core::KeplerEphemeris>{};
  st.last_iode = e.iode;
  st.last_toe = toe_key(e.toe);
  return std::optional<core::KeplerEphemeris>{e};
}

// ---------------------------------------------------------------------------------------------------------------
// GLONASS.

bool GlonassAssembler::hamming_ok(const String& str) {
  // Bit b_k (k = 85 .. 1) is at index 85 - k. Data bits b9..b85 take the Hamming positions 3, 5, 6, 7, 9, ...
  // (the integers that are not powers of two); check bit beta_k (= b_k, k = 1..7) covers the positions with bit
  // k - 1 set; beta_8 (b8) makes the parity of the whole string even.
  auto bit = [&](int k) {
    return static_cast<unsigned>(get_bits(str.data(), str.size(), static_cast<std::size_t>(85 - k), 1));
  };
  std::array<unsigned, 7> syndrome{};
  for (int k = 1; k <= 7; ++k) syndrome[static_cast<std::size_t>(k - 1)] = bit(k);
  int position = 2;
  unsigned parity = 0;
  for (int k = 1; k <= 85; ++k) parity ^= bit(k);
  for (int b = 9; b <= 85; ++b) {
    ++position;
    while ((position & (position - 1)) == 0) ++position;  // skip powers of two
    const unsigned v = bit(b);
    for (int k = 0; k < 7; ++k) {
      if ((position >> k) & 1) syndrome[static_cast<std::size_t>(k)] ^= v;
    }
  }
  return parity == 0 && std::all_of(syndrome.begin(), syndrome.end(), [](unsigned x) { return x == 0; });
}

Result<std::optional<core::GlonassEphemeris>> GlonassAssembler::add(int slot, int channel, const String& str,
                                                                    const GpsTime& reference,
                                                                    const core::LeapSecondTable& leaps) {
  if (!hamming_ok(str)) return Error{"GLONASS R" + std::to_string(slot) + ": string fails its Hamming code"};
  const auto m = static_cast<int>(u(str, 1, 4));
  if (m < 1 || m > 4) return std::optional<core::GlonassEphemeris>{};
  State& st = state_[slot];
  st.strings[static_cast<std::size_t>(m - 1)] = str;
  st.have[static_cast<std::size_t>(m - 1)] = true;
  st.received[static_cast<std::size_t>(m - 1)] = reference;
  if (!std::all_of(st.have.begin(), st.have.end(), [](bool b) { return b; })) {
    return std::optional<core::GlonassEphemeris>{};
  }
  for (const GpsTime& t : st.received) {
    if (std::abs(t - reference) > 30.0) return std::optional<core::GlonassEphemeris>{};
  }
  const String& s1 = st.strings[0];
  const String& s2 = st.strings[1];
  const String& s3 = st.strings[2];
  const String& s4 = st.strings[3];
  core::GlonassEphemeris g;
  g.sat = core::SatelliteId{Constellation::Glonass, static_cast<std::uint8_t>(slot)};
  g.frequency_channel = channel;
  const auto tk_h = static_cast<int>(u(s1, 9, 5));
  const auto tk_m = static_cast<int>(u(s1, 14, 6));
  const auto tk_30 = static_cast<int>(u(s1, 20, 1));
  Eigen::Vector3d p_km, v_kmps, a_kmps2;
  const std::array<const String*, 3> xyz = {&s1, &s2, &s3};
  for (int i = 0; i < 3; ++i) {
    v_kmps[i] = sm(*xyz[static_cast<std::size_t>(i)], 21, 24) * p2(-20);
    a_kmps2[i] = sm(*xyz[static_cast<std::size_t>(i)], 45, 5) * p2(-30);
    p_km[i] = sm(*xyz[static_cast<std::size_t>(i)], 50, 27) * p2(-11);
  }
  g.health = static_cast<int>(u(s2, 5, 3));  // B_n
  const auto tb = static_cast<int>(u(s2, 9, 7));
  g.gamma_n = sm(s3, 6, 11) * p2(-40);
  g.tau_n_s = -sm(s4, 5, 22) * p2(-30);
  g.delta_tau_n_s = sm(s4, 27, 5) * p2(-30);
  g.age_days = static_cast<int>(u(s4, 32, 5));
  const auto n = static_cast<int>(u(s4, 70, 5));
  if (n != slot || tb >= 96 || tk_h >= 24 || tk_m >= 60) {
    // Strings of different frames or satellites: wait for a consistent set.
    return std::optional<core::GlonassEphemeris>{};
  }
  g.p_E_m = p_km * 1e3;
  g.v_E_mps = v_kmps * 1e3;
  g.a_E_mps2 = a_kmps2 * 1e3;
  const double offset_s = core::kGlonassMinusUtcS - leaps.gps_minus_utc_at_gps(reference);
  const GpsTime ref_msk = reference + offset_s;
  const GpsTime day_start = ref_msk - std::fmod(ref_msk.tow_s, double(core::kSecondsPerDay));
  GpsTime tk_msk = day_start + (tk_h * 3600.0 + tk_m * 60.0 + tk_30 * 30.0);
  tk_msk = tk_msk + std::round((ref_msk - tk_msk) / core::kSecondsPerDay) * core::kSecondsPerDay;
  GpsTime toe_msk = tk_msk - std::fmod(tk_msk.tow_s, double(core::kSecondsPerDay)) + tb * 900.0;
  toe_msk = toe_msk + std::round((tk_msk - toe_msk) / core::kSecondsPerDay) * core::kSecondsPerDay;
  g.frame_time = tk_msk - offset_s;
  g.toe = toe_msk - offset_s;
  // The frame time must lie within the ephemeris validity (tb +- 30 min, and tk within the last interval).
  if (std::abs(g.toe - g.frame_time) > 3600.0) return std::optional<core::GlonassEphemeris>{};
  if (toe_key(g.toe) == st.last_toe) return std::optional<core::GlonassEphemeris>{};
  st.last_toe = toe_key(g.toe);
  return std::optional<core::GlonassEphemeris>{g};
}

// ---------------------------------------------------------------------------------------------------------------
// Galileo I/NAV.

Result<std::optional<GalileoInavAssembler::Word>> GalileoInavAssembler::word_from_pages(
    std::span<const std::uint32_t, 8> page_words) {
  std::array<std::uint8_t, 32> b{};
  for (std::size_t i = 0; i < 8; ++i) {
    for (std::size_t k = 0; k < 4; ++k) b[4 * i + k] = static_cast<std::uint8_t>(page_words[i] >> (24 - 8 * k));
  }
  const auto even_part = u(b, 0, 1);
  const auto even_alert = u(b, 1, 1);
  const auto odd_part = u(b, 128, 1);
  const auto odd_alert = u(b, 129, 1);
  if (even_alert != 0 || odd_alert != 0) return std::optional<Word>{};
  if (even_part != 0 || odd_part != 1) return Error{"Galileo I/NAV page parts out of order"};
  // CRC-24Q over 4 zero bits, the even part's first 114 bits and the odd part's first 82 bits.
  std::array<std::uint8_t, 25> crc_input{};
  {
    std::vector<std::uint8_t> v;
    BitWriter w(v);
    w.u(0, 4);
    for (std::size_t i = 0; i < 114; ++i) w.u(u(b, i, 1), 1);
    for (std::size_t i = 0; i < 82; ++i) w.u(u(b, 128 + i, 1), 1);
    w.flush();
    std::copy(v.begin(), v.end(), crc_input.begin());
  }
  if (crc24q(crc_input) != u(b, 128 + 82, 24)) return Error{"Galileo I/NAV page pair fails its CRC"};
  Word word{};
  std::vector<std::uint8_t> v;
  BitWriter w(v);
  for (std::size_t i = 0; i < 112; ++i) w.u(u(b, 2 + i, 1), 1);
  for (std::size_t i = 0; i < 16; ++i) w.u(u(b, 130 + i, 1), 1);
  w.flush();
  std::copy(v.begin(), v.end(), word.begin());
  return std::optional<Word>{word};
}

Result<std::optional<core::KeplerEphemeris>> GalileoInavAssembler::add(int svid, const Word& word,
                                                                       const GpsTime& reference) {
  const auto type = static_cast<int>(u(word, 0, 6));
  if (type < 1 || type > 5) return std::optional<core::KeplerEphemeris>{};
  State& st = state_[svid];
  st.words[static_cast<std::size_t>(type - 1)] = word;
  st.have[static_cast<std::size_t>(type - 1)] = true;
  if (!std::all_of(st.have.begin(), st.have.end(), [](bool b) { return b; })) {
    return std::optional<core::KeplerEphemeris>{};
  }
  const Word& w1 = st.words[0];
  const Word& w2 = st.words[1];
  const Word& w3 = st.words[2];
  const Word& w4 = st.words[3];
  const Word& w5 = st.words[4];
  const auto iod = static_cast<int>(u(w1, 6, 10));
  if (u(w2, 6, 10) != static_cast<std::uint64_t>(iod) || u(w3, 6, 10) != static_cast<std::uint64_t>(iod) ||
      u(w4, 6, 10) != static_cast<std::uint64_t>(iod)) {
    return std::optional<core::KeplerEphemeris>{};
  }
  if (static_cast<int>(u(w4, 16, 6)) != svid)
    return Error{"Galileo E" + std::to_string(svid) + ": word 4 of another SVID"};
  core::KeplerEphemeris e;
  e.sat = core::SatelliteId{Constellation::Galileo, static_cast<std::uint8_t>(svid)};
  e.iode = iod;
  e.toe_sow_s = static_cast<double>(u(w1, 16, 14)) * 60.0;
  e.m0_rad = s(w1, 30, 32) * p2(-31) * kSc;
  e.e = static_cast<double>(u(w1, 62, 32)) * p2(-33);
  e.sqrt_a_sqrtm = static_cast<double>(u(w1, 94, 32)) * p2(-19);
  e.omega0_rad = s(w2, 16, 32) * p2(-31) * kSc;
  e.i0_rad = s(w2, 48, 32) * p2(-31) * kSc;
  e.omega_rad = s(w2, 80, 32) * p2(-31) * kSc;
  e.idot_radps = s(w2, 112, 14) * p2(-43) * kSc;
  e.omega_dot_radps = s(w3, 16, 24) * p2(-43) * kSc;
  e.delta_n_radps = s(w3, 40, 16) * p2(-43) * kSc;
  e.cuc_rad = s(w3, 56, 16) * p2(-29);
  e.cus_rad = s(w3, 72, 16) * p2(-29);
  e.crc_m = s(w3, 88, 16) * p2(-5);
  e.crs_m = s(w3, 104, 16) * p2(-5);
  e.accuracy_m = rtcm3::sisa_m(static_cast<int>(u(w3, 120, 8)));
  e.cic_rad = s(w4, 22, 16) * p2(-29);
  e.cis_rad = s(w4, 38, 16) * p2(-29);
  const double toc_s = static_cast<double>(u(w4, 54, 14)) * 60.0;
  e.af0_s = s(w4, 68, 31) * p2(-34);
  e.af1_sps = s(w4, 99, 21) * p2(-46);
  e.af2_sps2 = s(w4, 120, 6) * p2(-59);
  e.tgd_s[0] = s(w5, 47, 10) * p2(-32);
  e.tgd_s[1] = s(w5, 57, 10) * p2(-32);
  const auto e5b_hs = static_cast<int>(u(w5, 67, 2));
  const auto e1b_hs = static_cast<int>(u(w5, 69, 2));
  const auto e5b_dvs = static_cast<int>(u(w5, 71, 1));
  const auto e1b_dvs = static_cast<int>(u(w5, 72, 1));
  e.health = (e5b_hs << 7) | (e5b_dvs << 6) | (e1b_hs << 1) | e1b_dvs;
  e.data_source = 0x205;  // I/NAV, E1-B and E5b, clock for E5b,E1
  const int gst_week =
      core::resolve_week_rollover(static_cast<int>(u(w5, 73, 12)), 12, core::gps_to_gst(reference).week);
  const double tow_s = static_cast<double>(u(w5, 85, 20));
  e.transmission_time = core::gst_to_gps(gst_week, tow_s).normalized();
  e.toe = nearest_week(core::gst_to_gps(gst_week, e.toe_sow_s), e.transmission_time);
  e.toc = e.toe + std::remainder(toc_s - e.toe_sow_s, double(core::kSecondsPerWeek));
  if (iod == st.last_iod && toe_key(e.toe) == st.last_toe) return std::optional<core::KeplerEphemeris>{};
  st.last_iod = iod;
  st.last_toe = toe_key(e.toe);
  return std::optional<core::KeplerEphemeris>{e};
}

// ---------------------------------------------------------------------------------------------------------------
// BeiDou D1.

Result<std::optional<core::KeplerEphemeris>> BeidouD1Assembler::add(int prn, const Subframe& f,
                                                                    const GpsTime& reference) {
  // Data bits without parity: word 1 bits 0-25, words 2-10 the first 22 of their 30 bits.
  std::array<std::uint8_t, 28> d{};
  {
    std::vector<std::uint8_t> v;
    BitWriter w(v);
    w.u(get_bits(f.data(), f.size(), 0, 26), 26);
    for (std::size_t k = 1; k < 10; ++k) w.u(get_bits(f.data(), f.size(), 30 * k, 22), 22);
    w.flush();
    std::copy(v.begin(), v.end(), d.begin());
  }
  if (u(d, 0, 11) != 0x712) return Error{"BeiDou C" + std::to_string(prn) + ": D1 subframe without preamble"};
  const auto id = static_cast<int>(u(d, 15, 3));
  if (id < 1 || id > 5) return Error{"BeiDou C" + std::to_string(prn) + ": D1 subframe id " + std::to_string(id)};
  if (id > 3) return std::optional<core::KeplerEphemeris>{};
  State& st = state_[prn];
  st.data[static_cast<std::size_t>(id - 1)] = d;
  st.sow[static_cast<std::size_t>(id - 1)] = static_cast<double>(u(d, 18, 20));
  st.have[static_cast<std::size_t>(id - 1)] = true;
  if (!st.have[0] || !st.have[1] || !st.have[2]) return std::optional<core::KeplerEphemeris>{};
  if (st.sow[1] != st.sow[0] + 6.0 || st.sow[2] != st.sow[0] + 12.0) return std::optional<core::KeplerEphemeris>{};
  const auto& d1 = st.data[0];
  const auto& d2 = st.data[1];
  const auto& d3 = st.data[2];
  core::KeplerEphemeris e;
  e.sat = core::SatelliteId{Constellation::BeiDou, static_cast<std::uint8_t>(prn)};
  e.health = static_cast<int>(u(d1, 38, 1));
  e.iodc = static_cast<int>(u(d1, 39, 5));
  e.accuracy_m = rtcm3::ura_m(static_cast<int>(u(d1, 44, 4)));
  const int bdt_week =
      core::resolve_week_rollover(static_cast<int>(u(d1, 48, 13)), 13, core::gps_to_bdt(reference).week);
  const double toc_s = static_cast<double>(u(d1, 61, 17)) * 8.0;
  e.tgd_s[0] = s(d1, 78, 10) * 1e-10;
  e.tgd_s[1] = s(d1, 88, 10) * 1e-10;
  // 98-161: ionosphere alpha/beta (not kept here).
  e.af2_sps2 = s(d1, 162, 11) * p2(-66);
  e.af0_s = s(d1, 173, 24) * p2(-33);
  e.af1_sps = s(d1, 197, 22) * p2(-50);
  e.iode = static_cast<int>(u(d1, 219, 5));
  e.delta_n_radps = s(d2, 38, 16) * p2(-43) * kSc;
  e.cuc_rad = s(d2, 54, 18) * p2(-31);
  e.m0_rad = s(d2, 72, 32) * p2(-31) * kSc;
  e.e = static_cast<double>(u(d2, 104, 32)) * p2(-33);
  e.cus_rad = s(d2, 136, 18) * p2(-31);
  e.crc_m = s(d2, 154, 18) * p2(-6);
  e.crs_m = s(d2, 172, 18) * p2(-6);
  e.sqrt_a_sqrtm = static_cast<double>(u(d2, 190, 32)) * p2(-19);
  const auto toe_msb = u(d2, 222, 2);
  const auto toe_lsb = u(d3, 38, 15);
  e.toe_sow_s = static_cast<double>((toe_msb << 15) | toe_lsb) * 8.0;
  e.i0_rad = s(d3, 53, 32) * p2(-31) * kSc;
  e.cic_rad = s(d3, 85, 18) * p2(-31);
  e.omega_dot_radps = s(d3, 103, 24) * p2(-43) * kSc;
  e.cis_rad = s(d3, 127, 18) * p2(-31);
  e.idot_radps = s(d3, 145, 14) * p2(-43) * kSc;
  e.omega0_rad = s(d3, 159, 32) * p2(-31) * kSc;
  e.omega_rad = s(d3, 191, 32) * p2(-31) * kSc;
  e.transmission_time = core::bdt_to_gps(bdt_week, st.sow[0]);
  e.toe = nearest_week(core::bdt_to_gps(bdt_week, e.toe_sow_s), e.transmission_time);
  e.toc = e.toe + std::remainder(toc_s - e.toe_sow_s, double(core::kSecondsPerWeek));
  if (e.iode == st.last_iode && toe_key(e.toe) == st.last_toe) return std::optional<core::KeplerEphemeris>{};
  st.last_iode = e.iode;
  st.last_toe = toe_key(e.toe);
  return std::optional<core::KeplerEphemeris>{e};
}

}  // namespace canyon::io::navmsg
