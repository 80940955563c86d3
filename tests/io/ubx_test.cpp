// u-blox UBX: RXM-RAWX measurements and their loss-of-lock rules, RXM-SFRBX navigation words of Galileo (I/NAV
// pages with CRC) and BeiDou (D1 subframes) built here from the ICD layouts and decoded into ephemerides, NAV-PVT,
// NAV-TIMEGPS, and a mixed stream with NMEA, RTCM 3 and garbage. (GPS LNAV and GLONASS strings are checked against
// RTKLIB on the real u-blox logs in tests/integration.)

#include "canyon/io/ubx.hpp"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "canyon/io/bits.hpp"
#include "canyon/io/gnss_stream.hpp"
#include "canyon/io/rtcm3.hpp"

namespace canyon::io {
namespace {

using core::Constellation;
using core::GpsTime;

constexpr double kSc = rtcm3::kGpsPi;

ubx::RawxMeasurement measurement(int gnss, int sv, double pr, double cp, int lock_ms, std::uint8_t trk) {
  ubx::RawxMeasurement m;
  m.gnss_id = gnss;
  m.sv_id = sv;
  m.pseudorange_m = pr;
  m.carrier_phase_cyc = cp;
  m.doppler_hz = -1234.5;
  m.cno_dbhz = 44;
  m.lock_time_ms = lock_ms;
  m.cp_stdev = 2;
  m.trk_stat = trk;
  m.freq_id = gnss == 6 ? 3 : 0;  // GLONASS channel -4
  return m;
}

TEST(Ubx, RawxRoundTripsAndFollowsTheLockRules) {
  UbxDecoder decoder;
  auto epoch = [&](double tow, std::vector<ubx::RawxMeasurement> m) {
    ubx::Rawx r;
    r.rcv_tow_s = tow;
    r.week = 2021;
    r.leap_s = 18;
    r.measurements = std::move(m);
    const auto payload = ubx::encode_rawx(r);
    auto decoded = ubx::decode_rawx(payload);
    EXPECT_TRUE(decoded.ok());
    EXPECT_EQ(decoded->measurements.size(), r.measurements.size());
    auto msg = decoder.decode(ubx::kClassRxm, ubx::kIdRxmRawx, payload);
    EXPECT_TRUE(msg.ok());
    return *decoder.pop_epoch();
  };
  // trkStat: 1 pr valid, 2 cp valid, 4 half cycle valid, 8 half cycle subtracted.
  auto e1 =
      epoch(399000.5, {measurement(0, 5, 2.1e7, 1.1e8, 5000, 1 | 2 | 4), measurement(6, 7, 2.0e7, 1.0e8, 100, 1 | 2)});
  ASSERT_EQ(e1.sats.size(), 2U);
  EXPECT_EQ(e1.time, (GpsTime{2021, 399000.5}));
  const core::SignalObs& g = e1.sats[0].signals.at(0);
  EXPECT_EQ(e1.sats[0].sat, (core::SatelliteId{Constellation::Gps, 5}));
  EXPECT_EQ(g.code, (core::SignalCode{'1', 'C'}));
  EXPECT_DOUBLE_EQ(g.pseudorange_m, 2.1e7);
  EXPECT_DOUBLE_EQ(g.carrier_phase_cyc, 1.1e8);
  EXPECT_NEAR(g.doppler_hz, -1234.5, 1e-3);
  EXPECT_EQ(g.snr_dbhz, 44.0);
  EXPECT_EQ(g.lli, core::kLliLossOfLock);  // first epoch of the signal
  const core::SignalObs& r = e1.sats[1].signals.at(0);
  EXPECT_EQ(r.lli, core::kLliLossOfLock | core::kLliHalfCycle);  // half cycle not resolved
  EXPECT_EQ(decoder.glonass_channels().at(0), (std::pair<int, int>{7, -4}));
  // Lock continues: no flag; lock time down: loss of lock; phase invalid: the slip waits for the next valid phase.
  auto e2 = epoch(399001.5, {measurement(0, 5, 2.1e7, 1.1e8, 6000, 1 | 2 | 4), measurement(6, 7, 2.0e7, 1.0e8, 50, 1)});
  EXPECT_EQ(e2.sats[0].signals[0].lli, 0);
  EXPECT_FALSE(core::has_value(e2.sats[1].signals[0].carrier_phase_cyc));
  auto e3 = epoch(399002.5, {measurement(0, 5, 2.1e7, 1.1e8, 7000, 1 | 2 | 4 | 8),
                             measurement(6, 7, 2.0e7, 1.0e8, 1050, 1 | 2 | 4)});
  EXPECT_EQ(e3.sats[0].signals[0].lli, core::kLliLossOfLock);  // half-cycle subtraction changed
  EXPECT_EQ(e3.sats[1].signals[0].lli, core::kLliLossOfLock);  // the slip seen while the phase was invalid
  // Malformed payloads.
  EXPECT_FALSE(ubx::decode_rawx(std::vector<std::uint8_t>(10)).ok());
  auto payload = ubx::encode_rawx(ubx::Rawx{});
  payload[11] = 3;  // announces 3 measurements, has none
  auto bad = ubx::decode_rawx(payload);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("16 bytes for 3 measurements"), std::string::npos);
}

TEST(Ubx, NavPvtAndTimeGps) {
  std::vector<std::uint8_t> pvt(92, 0);
  auto put4 = [&](std::size_t at, std::int32_t v) {
    for (int k = 0; k < 4; ++k) pvt[at + static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(v >> (8 * k));
  };
  put4(0, 399000000);
  pvt[20] = 3;
  pvt[21] = 0x81;  // fix OK, fixed carrier solution
  pvt[23] = 17;
  put4(24, -90578437);
  put4(28, 532804778);
  put4(32, 61857);
  UbxDecoder decoder;
  ASSERT_TRUE(decoder.decode(ubx::kClassNav, ubx::kIdNavPvt, pvt).ok());
  ASSERT_TRUE(decoder.nav_pvt());
  EXPECT_EQ(decoder.nav_pvt()->fix_type, 3);
  EXPECT_EQ(decoder.nav_pvt()->num_sv, 17);
  EXPECT_NEAR(decoder.nav_pvt()->lat_deg, 53.2804778, 1e-9);
  EXPECT_NEAR(decoder.nav_pvt()->lon_deg, -9.0578437, 1e-9);
  EXPECT_NEAR(decoder.nav_pvt()->height_m, 61.857, 1e-9);
  EXPECT_FALSE(ubx::decode_nav_pvt(std::vector<std::uint8_t>(50)).ok());
  // iTOW 399000000 ms, fTOW 10000 ns, week 2021, leap 18 s, all valid.
  std::vector<std::uint8_t> t = {0xC0, 0x41, 0xC8, 0x17, 0x10, 0x27, 0x00, 0x00, 0xE5, 0x07, 18, 0x07, 0, 0, 0, 0};
  auto m = decoder.decode(ubx::kClassNav, ubx::kIdNavTimeGps, t);
  ASSERT_TRUE(m.ok());
  ASSERT_TRUE(m->time);
  EXPECT_EQ(m->time->week, 2021);
  EXPECT_NEAR(m->time->tow_s, 399000.0 + 10000e-9, 1e-9);
  EXPECT_EQ(decoder.nav_timegps()->leap_s, 18);
}

core::KeplerEphemeris reference_ephemeris(Constellation system, int prn, const GpsTime& toe, double toe_sow_s) {
  core::KeplerEphemeris e;
  e.sat = core::SatelliteId{system, static_cast<std::uint8_t>(prn)};
  e.toe = toe;
  e.toe_sow_s = toe_sow_s;
  e.sqrt_a_sqrtm = 5440.618;
  e.e = 0.000210181926;
  e.i0_rad = 0.978439028;
  e.omega0_rad = 1.79156968;
  e.omega_rad = 0.603366068;
  e.m0_rad = 1.78232728;
  e.delta_n_radps = 2.9451e-9;
  e.omega_dot_radps = -5.5927e-9;
  e.idot_radps = 2.107e-11;
  e.cuc_rad = 6.2063e-6;
  e.cus_rad = 5.7946e-6;
  e.crc_m = 223.75;
  e.crs_m = 137.5;
  e.cic_rad = -3.7252e-9;
  e.cis_rad = -1.8626e-9;
  e.af0_s = -1.0687820613e-3;
  e.af1_sps = -7.9865e-12;
  e.af2_sps2 = 0.0;
  e.tgd_s = {2.3283e-9, 2.561e-9};
  return e;
}

/// round(value / lsb) into a signed field.
void put(BitWriter& w, double value, double lsb, unsigned bits) {
  w.s(static_cast<std::int64_t>(std::llround(value / lsb)), bits);
}
void putu(BitWriter& w, double value, double lsb, unsigned bits) {
  w.u(static_cast<std::uint64_t>(std::llround(value / lsb)), bits);
}
double p2(int e) {
  return std::ldexp(1.0, e);
}

/// Galileo I/NAV words 1-5 (OS SIS ICD tables 40-44), 128 bits each.
std::vector<std::vector<std::uint8_t>> galileo_words(const core::KeplerEphemeris& e, int iod, int gst_week,
                                                     double tow_s, double toc_s) {
  std::vector<std::vector<std::uint8_t>> words(5);
  {
    BitWriter w(words[0]);
    w.u(1, 6);
    w.u(static_cast<std::uint64_t>(iod), 10);
    putu(w, e.toe_sow_s, 60, 14);
    put(w, e.m0_rad / kSc, p2(-31), 32);
    putu(w, e.e, p2(-33), 32);
    putu(w, e.sqrt_a_sqrtm, p2(-19), 32);
    w.u(0, 2);
  }
  {
    BitWriter w(words[1]);
    w.u(2, 6);
    w.u(static_cast<std::uint64_t>(iod), 10);
    put(w, e.omega0_rad / kSc, p2(-31), 32);
    put(w, e.i0_rad / kSc, p2(-31), 32);
    put(w, e.omega_rad / kSc, p2(-31), 32);
    put(w, e.idot_radps / kSc, p2(-43), 14);
    w.u(0, 2);
  }
  {
    BitWriter w(words[2]);
    w.u(3, 6);
    w.u(static_cast<std::uint64_t>(iod), 10);
    put(w, e.omega_dot_radps / kSc, p2(-43), 24);
    put(w, e.delta_n_radps / kSc, p2(-43), 16);
    put(w, e.cuc_rad, p2(-29), 16);
    put(w, e.cus_rad, p2(-29), 16);
    put(w, e.crc_m, p2(-5), 16);
    put(w, e.crs_m, p2(-5), 16);
    w.u(107, 8);  // SISA index: 3.12 m
  }
  {
    BitWriter w(words[3]);
    w.u(4, 6);
    w.u(static_cast<std::uint64_t>(iod), 10);
    w.u(e.sat.prn, 6);
    put(w, e.cic_rad, p2(-29), 16);
    put(w, e.cis_rad, p2(-29), 16);
    putu(w, toc_s, 60, 14);
    put(w, e.af0_s, p2(-34), 31);
    put(w, e.af1_sps, p2(-46), 21);
    put(w, e.af2_sps2, p2(-59), 6);
    w.u(0, 2);
  }
  {
    BitWriter w(words[4]);
    w.u(5, 6);
    w.u(0, 11 + 11 + 14 + 5);  // ionosphere
    put(w, e.tgd_s[0], p2(-32), 10);
    put(w, e.tgd_s[1], p2(-32), 10);
    w.u(0, 2 + 2 + 1 + 1);  // healthy, data valid
    w.u(static_cast<std::uint64_t>(gst_week), 12);
    putu(w, tow_s, 1, 20);
    w.u(0, 23);
  }
  return words;
}

/// An E1-B nominal page pair holding `word`, as a u-blox receiver hands it over (8 words).
std::vector<std::uint32_t> inav_pages(const std::vector<std::uint8_t>& word) {
  std::vector<std::uint8_t> bits;
  BitWriter w(bits);
  w.u(0, 1);  // even
  w.u(0, 1);  // nominal
  for (std::size_t i = 0; i < 112; ++i) w.u(get_bits(word.data(), word.size(), i, 1), 1);
  w.u(0, 6 + 8);  // tail, pad to 128
  w.u(1, 1);      // odd
  w.u(0, 1);
  for (std::size_t i = 112; i < 128; ++i) w.u(get_bits(word.data(), word.size(), i, 1), 1);
  w.u(0, 64);  // reserved, SAR, spare
  w.flush();
  // CRC-24Q over 4 zero bits, the even part's 114 bits and the odd part's 82 bits.
  std::vector<std::uint8_t> crc_in;
  {
    BitWriter c(crc_in);
    c.u(0, 4);
    for (std::size_t i = 0; i < 114; ++i) c.u(get_bits(bits.data(), bits.size(), i, 1), 1);
    for (std::size_t i = 128; i < 210; ++i) c.u(get_bits(bits.data(), bits.size(), i, 1), 1);
  }
  const std::uint32_t crc = crc24q(crc_in);
  std::vector<std::uint8_t> page(32, 0);
  std::copy(bits.begin(), bits.end(), page.begin());
  for (int i = 0; i < 24; ++i) {
    const std::size_t pos = 210 + static_cast<std::size_t>(i);
    if (((crc >> (23 - i)) & 1) != 0) page[pos / 8] = static_cast<std::uint8_t>(page[pos / 8] | (0x80 >> (pos % 8)));
  }
  std::vector<std::uint32_t> words;
  for (std::size_t k = 0; k < 8; ++k) {
    words.push_back((std::uint32_t{page[4 * k]} << 24) | (std::uint32_t{page[4 * k + 1]} << 16) |
                    (std::uint32_t{page[4 * k + 2]} << 8) | page[4 * k + 3]);
  }
  return words;
}

TEST(Ubx, GalileoInavWordsDecodeIntoTheEphemeris) {
  const GpsTime toe{2149, 477600.0};
  const core::KeplerEphemeris in = reference_ephemeris(Constellation::Galileo, 11, toe, 477600.0);
  const auto words = galileo_words(in, 83, 2149 - 1024, 476400.0, 477600.0);
  UbxDecoderOptions o;
  o.reference_time = GpsTime{2149, 476400.0};
  UbxDecoder decoder(o);
  for (const auto& word : words) {
    ubx::Sfrbx s;
    s.gnss_id = 2;
    s.sv_id = 11;
    s.sig_id = 1;
    s.words = inav_pages(word);
    auto m = decoder.decode(ubx::kClassRxm, ubx::kIdRxmSfrbx, ubx::encode_sfrbx(s));
    ASSERT_TRUE(m.ok()) << m.error().to_string();
  }
  EXPECT_EQ(decoder.rejected_words(), 0U) << (decoder.warnings().empty() ? "" : decoder.warnings().front());
  ASSERT_EQ(decoder.navigation().kepler.size(), 1U);
  const core::KeplerEphemeris& e = decoder.navigation().kepler.front();
  EXPECT_EQ(e.sat, in.sat);
  EXPECT_EQ(e.iode, 83);
  EXPECT_NEAR(e.toe - toe, 0.0, 1e-9);
  EXPECT_NEAR(e.toc - toe, 0.0, 1e-9);
  EXPECT_NEAR(e.sqrt_a_sqrtm, in.sqrt_a_sqrtm, p2(-19));
  EXPECT_NEAR(e.e, in.e, p2(-33));
  EXPECT_NEAR(e.m0_rad, in.m0_rad, p2(-31) * kSc);
  EXPECT_NEAR(e.omega0_rad, in.omega0_rad, p2(-31) * kSc);
  EXPECT_NEAR(e.i0_rad, in.i0_rad, p2(-31) * kSc);
  EXPECT_NEAR(e.omega_dot_radps, in.omega_dot_radps, p2(-43) * kSc);
  EXPECT_NEAR(e.crc_m, in.crc_m, p2(-5));
  EXPECT_NEAR(e.af0_s, in.af0_s, p2(-34));
  EXPECT_NEAR(e.tgd_s[1], in.tgd_s[1], p2(-32));
  EXPECT_NEAR(e.accuracy_m, 3.12, 1e-9);
  EXPECT_EQ(e.data_source, 0x205);
  // A corrupted page pair fails its CRC and is counted, not decoded.
  ubx::Sfrbx s;
  s.gnss_id = 2;
  s.sv_id = 11;
  s.words = inav_pages(words[0]);
  s.words[2] ^= 0x00010000;
  ASSERT_TRUE(decoder.decode(ubx::kClassRxm, ubx::kIdRxmSfrbx, ubx::encode_sfrbx(s)).ok());
  EXPECT_EQ(decoder.rejected_words(), 1U);
}

/// BeiDou D1 subframes 1-3 (ICD B1I 5.2.4): 224 data bits each, placed into 10 words of 30 bits (26 + 4 parity,
/// then 22 + 8), parity bits left zero.
std::vector<std::vector<std::uint32_t>> beidou_subframes(const core::KeplerEphemeris& e, int bdt_week, double sow,
                                                         double toc_s) {
  std::vector<std::vector<std::uint8_t>> data(3);
  for (int id = 1; id <= 3; ++id) {
    BitWriter w(data[static_cast<std::size_t>(id - 1)]);
    w.u(0x712, 11);
    w.u(0, 4);
    w.u(static_cast<std::uint64_t>(id), 3);
    putu(w, sow + 6.0 * (id - 1), 1, 20);
    if (id == 1) {
      w.u(0, 1);  // SatH1
      w.u(9, 5);  // AODC
      w.u(2, 4);  // URAI
      w.u(static_cast<std::uint64_t>(bdt_week), 13);
      putu(w, toc_s, 8, 17);
      put(w, e.tgd_s[0], 1e-10, 10);
      put(w, e.tgd_s[1], 1e-10, 10);
      w.u(0, 64);  // ionosphere
      put(w, e.af2_sps2, p2(-66), 11);
      put(w, e.af0_s, p2(-33), 24);
      put(w, e.af1_sps, p2(-50), 22);
      w.u(17, 5);  // AODE
    } else if (id == 2) {
      put(w, e.delta_n_radps / kSc, p2(-43), 16);
      put(w, e.cuc_rad, p2(-31), 18);
      put(w, e.m0_rad / kSc, p2(-31), 32);
      putu(w, e.e, p2(-33), 32);
      put(w, e.cus_rad, p2(-31), 18);
      put(w, e.crc_m, p2(-6), 18);
      put(w, e.crs_m, p2(-6), 18);
      putu(w, e.sqrt_a_sqrtm, p2(-19), 32);
      w.u(static_cast<std::uint64_t>(std::llround(e.toe_sow_s / 8)) >> 15, 2);
    } else {
      w.u(static_cast<std::uint64_t>(std::llround(e.toe_sow_s / 8)) & 0x7FFF, 15);
      put(w, e.i0_rad / kSc, p2(-31), 32);
      put(w, e.cic_rad, p2(-31), 18);
      put(w, e.omega_dot_radps / kSc, p2(-43), 24);
      put(w, e.cis_rad, p2(-31), 18);
      put(w, e.idot_radps / kSc, p2(-43), 14);
      put(w, e.omega0_rad / kSc, p2(-31), 32);
      put(w, e.omega_rad / kSc, p2(-31), 32);
      w.u(0, 1);
    }
  }
  std::vector<std::vector<std::uint32_t>> subframes;
  for (const auto& d : data) {
    std::vector<std::uint32_t> words;
    words.push_back(static_cast<std::uint32_t>(get_bits(d.data(), d.size(), 0, 26)) << 4);
    for (std::size_t k = 0; k < 9; ++k) {
      words.push_back(static_cast<std::uint32_t>(get_bits(d.data(), d.size(), 26 + 22 * k, 22)) << 8);
    }
    subframes.push_back(words);
  }
  return subframes;
}

TEST(Ubx, BeidouD1SubframesDecodeIntoTheEphemeris) {
  const GpsTime toe = core::bdt_to_gps(793, 345600.0);
  core::KeplerEphemeris in = reference_ephemeris(Constellation::BeiDou, 30, toe, 345600.0);
  in.af0_s = -5.0e-4;  // the 24-bit a0 field holds +-0.98 ms
  UbxDecoderOptions o;
  o.reference_time = toe;
  UbxDecoder decoder(o);
  for (const auto& words : beidou_subframes(in, 793, 345000.0, 345600.0)) {
    ubx::Sfrbx s;
    s.gnss_id = 3;
    s.sv_id = 30;
    s.words = words;
    ASSERT_TRUE(decoder.decode(ubx::kClassRxm, ubx::kIdRxmSfrbx, ubx::encode_sfrbx(s)).ok());
  }
  EXPECT_EQ(decoder.rejected_words(), 0U) << (decoder.warnings().empty() ? "" : decoder.warnings().front());
  ASSERT_EQ(decoder.navigation().kepler.size(), 1U);
  const core::KeplerEphemeris& e = decoder.navigation().kepler.front();
  EXPECT_EQ(e.sat, in.sat);
  EXPECT_EQ(e.iode, 17);
  EXPECT_EQ(e.iodc, 9);
  EXPECT_NEAR(e.toe - toe, 0.0, 1e-9);
  EXPECT_NEAR(e.toe_sow_s, 345600.0, 1e-9);
  EXPECT_NEAR(e.toc - toe, 0.0, 1e-9);
  EXPECT_NEAR(e.sqrt_a_sqrtm, in.sqrt_a_sqrtm, p2(-19));
  EXPECT_NEAR(e.e, in.e, p2(-33));
  EXPECT_NEAR(e.m0_rad, in.m0_rad, p2(-31) * kSc);
  EXPECT_NEAR(e.omega0_rad, in.omega0_rad, p2(-31) * kSc);
  EXPECT_NEAR(e.omega_rad, in.omega_rad, p2(-31) * kSc);
  EXPECT_NEAR(e.idot_radps, in.idot_radps, p2(-43) * kSc);
  EXPECT_NEAR(e.crs_m, in.crs_m, p2(-6));
  EXPECT_NEAR(e.cuc_rad, in.cuc_rad, p2(-31));
  EXPECT_NEAR(e.af0_s, in.af0_s, p2(-33));
  EXPECT_NEAR(e.af1_sps, in.af1_sps, p2(-50));
  EXPECT_NEAR(e.tgd_s[0], in.tgd_s[0], 0.5e-10);
  EXPECT_NEAR(e.accuracy_m, 4.0, 1e-9);  // URAI 2
  // A GEO satellite (D2) is not decoded, and says so.
  ubx::Sfrbx geo;
  geo.gnss_id = 3;
  geo.sv_id = 3;
  geo.words.assign(10, 0);
  ASSERT_TRUE(decoder.decode(ubx::kClassRxm, ubx::kIdRxmSfrbx, ubx::encode_sfrbx(geo)).ok());
  EXPECT_EQ(decoder.navigation().kepler.size(), 1U);
  EXPECT_NE(decoder.warnings().back().find("D2"), std::string::npos);
}

TEST(Ubx, MixedStreamWithGarbageDecodesEveryIntactPacket) {
  // RAWX epochs between NMEA sentences, RTCM 3 frames, garbage and broken UBX packets, fed a byte at a time.
  std::vector<std::uint8_t> stream;
  int intact = 0;
  for (int k = 0; k < 20; ++k) {
    ubx::Rawx r;
    r.rcv_tow_s = 399000.0 + k;
    r.week = 2021;
    r.measurements = {measurement(0, 5 + k % 3, 2.1e7 + k, 1.1e8 + k, 1000 * (k + 1), 7)};
    auto packet = ubx::frame_ubx(ubx::kClassRxm, ubx::kIdRxmRawx, ubx::encode_rawx(r));
    if (k % 5 == 3) packet[packet.size() / 2] ^= 0xFF;  // broken checksum
    if (k % 5 != 3) ++intact;
    stream.insert(stream.end(), packet.begin(), packet.end());
    const std::string nmea = "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n";
    stream.insert(stream.end(), nmea.begin(), nmea.end());
    for (int g = 0; g < 7 * k; ++g) stream.push_back(static_cast<std::uint8_t>((g * 131 + k) & 0xFF));
    std::vector<std::uint8_t> payload(19, 0);
    payload[0] = 0x3E;
    payload[1] = 0xD0;
    const auto rtcm = *rtcm3::frame_rtcm3(payload);
    stream.insert(stream.end(), rtcm.begin(), rtcm.end());
  }
  stream.resize(stream.size() - 3);  // the last frame cut short
  GnssStreamDecoder decoder(GnssStreamOptions{});
  for (const std::uint8_t b : stream) decoder.push({&b, 1});
  decoder.finish();
  int epochs = 0;
  while (decoder.pop_ubx_epoch()) ++epochs;
  EXPECT_EQ(epochs, intact);
  const GnssStreamStats s = decoder.stats();
  EXPECT_EQ(s.framing.ubx_bad_checksum, 4U);
  EXPECT_EQ(s.framing.nmea_sentences, 20U);
  EXPECT_EQ(s.framing.rtcm3_frames, 19U);
  EXPECT_EQ(s.framing.truncated, 1U);
  EXPECT_GT(s.framing.garbage_bytes, 0U);
  EXPECT_EQ(s.rtcm3_decode_errors, 0U);  // the frames are 1005 (0x3ED) with a zero position
}

}  // namespace
}  // namespace canyon::io
