// RTCM 3: CRC-24Q known vectors, bit packing round trips, framing with resynchronisation, every message type
// encoded and decoded back, MSM resolutions, lock time indicators, epoch times and the stream codecs.

#include "canyon/io/rtcm3.hpp"

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"
#include "canyon/io/bits.hpp"
#include "canyon/io/rtcm3_codec.hpp"
#include "canyon/io/rtcm3_fields.hpp"
#include "canyon/io/stream_framer.hpp"

namespace canyon::io {
namespace {

using core::Constellation;
using core::GpsTime;

std::vector<std::uint8_t> bytes_of(std::initializer_list<int> values) {
  std::vector<std::uint8_t> out;
  for (const int v : values) out.push_back(static_cast<std::uint8_t>(v));
  return out;
}

TEST(Crc24q, KnownVectors) {
  const std::string check = "123456789";
  EXPECT_EQ(crc24q({reinterpret_cast<const std::uint8_t*>(check.data()), check.size()}), 0xCDE703U);
  EXPECT_EQ(crc24q({}), 0U);
  // The 1005 example of RTCM 10403.3 (station 2003): header and payload, then its CRC 36 0B 98.
  const auto frame = bytes_of({0xD3, 0x00, 0x13, 0x3E, 0xD7, 0xD3, 0x02, 0x02, 0x98, 0x0E, 0xDE, 0xEF, 0x34,
                               0xB4, 0xBD, 0x62, 0xAC, 0x09, 0x41, 0x98, 0x6F, 0x33, 0x36, 0x0B, 0x98});
  EXPECT_EQ(crc24q({frame.data(), frame.size() - 3}), 0x360B98U);
}

TEST(Rtcm3Station, DecodesTheStandardExample) {
  const auto frame = bytes_of({0xD3, 0x00, 0x13, 0x3E, 0xD7, 0xD3, 0x02, 0x02, 0x98, 0x0E, 0xDE, 0xEF, 0x34,
                               0xB4, 0xBD, 0x62, 0xAC, 0x09, 0x41, 0x98, 0x6F, 0x33, 0x36, 0x0B, 0x98});
  const auto station = rtcm3::decode_station_position({frame.data() + 3, 19});
  ASSERT_TRUE(station.ok()) << station.error().to_string();
  EXPECT_EQ(station->station_id, 2003);
  EXPECT_NEAR(station->arp_E_m.x(), 1114104.5999, 1e-4);
  EXPECT_NEAR(station->arp_E_m.y(), -4850729.7108, 1e-4);
  EXPECT_NEAR(station->arp_E_m.z(), 3975521.4643, 1e-4);
  // Encoding it again gives the same bytes.
  std::vector<std::uint8_t> payload;
  ASSERT_TRUE(rtcm3::append_station_position(*station, payload).ok());
  auto framed = rtcm3::frame_rtcm3(payload);
  ASSERT_TRUE(framed.ok());
  EXPECT_EQ(*framed, frame);
}

TEST(Bits, RandomFieldsRoundTrip) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<std::uint8_t> buffer;
    BitWriter w(buffer);
    struct Field {
      unsigned n;
      std::int64_t value;
      int kind;  // 0 unsigned, 1 signed, 2 sign-magnitude
    };
    std::vector<Field> fields;
    for (int i = 0; i < 40; ++i) {
      const unsigned n = 2 + static_cast<unsigned>(rng() % 63);
      const int kind = static_cast<int>(rng() % 3);
      std::int64_t v = 0;
      if (kind == 0) {
        v = static_cast<std::int64_t>(rng() & ((n == 64 ? ~0ULL : (1ULL << n) - 1) >> 1));
        w.u(static_cast<std::uint64_t>(v), n);
      } else if (kind == 1) {
        const std::int64_t half = n >= 63 ? (1LL << 61) : (1LL << (n - 1));
        v = static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(2 * half)) - half;
        w.s(v, n);
      } else {
        const std::int64_t max = n >= 63 ? (1LL << 61) : (1LL << (n - 1)) - 1;
        v = static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(max + 1)) * ((rng() & 1) != 0 ? -1 : 1);
        w.sm(v, n);
      }
      fields.push_back({n, v, kind});
    }
    w.flush();
    BitReader r(buffer);
    for (const Field& f : fields) {
      const std::int64_t got = f.kind == 0 ? static_cast<std::int64_t>(r.u(f.n)) : (f.kind == 1 ? r.s(f.n) : r.sm(f.n));
      ASSERT_EQ(got, f.value) << "width " << f.n << " kind " << f.kind;
    }
  }
}

TEST(Rtcm3Lock, IndicatorsMapToMinimumLockTimes) {
  // MSM4 (DF402): 0 -> 0, k -> 2^(k+4) ms.
  EXPECT_EQ(rtcm3::msm_lock_time_ms(0, false), 0.0);
  EXPECT_EQ(rtcm3::msm_lock_time_ms(1, false), 32.0);
  EXPECT_EQ(rtcm3::msm_lock_time_ms(15, false), 524288.0);
  // MSM7 (DF407) anchors from the table of RTCM 10403.3.
  EXPECT_EQ(rtcm3::msm_lock_time_ms(63, true), 63.0);
  EXPECT_EQ(rtcm3::msm_lock_time_ms(64, true), 64.0);
  EXPECT_EQ(rtcm3::msm_lock_time_ms(95, true), 2 * 95 - 64.0);
  EXPECT_EQ(rtcm3::msm_lock_time_ms(96, true), 4 * 96 - 256.0);
  EXPECT_EQ(rtcm3::msm_lock_time_ms(300, true), 256 * 300 - 65536.0);
  EXPECT_EQ(rtcm3::msm_lock_time_ms(703, true), 1048576.0 * 703 - 671088640.0);
  EXPECT_EQ(rtcm3::msm_lock_time_ms(704, true), 67108864.0);
  for (const bool extended : {false, true}) {
    const int max = extended ? 704 : 15;
    double previous = -1.0;
    for (int i = 0; i <= max; ++i) {
      const double t = rtcm3::msm_lock_time_ms(i, extended);
      EXPECT_GT(t, previous);
      previous = t;
      EXPECT_EQ(rtcm3::msm_lock_indicator(t, extended), i) << i;
      if (i < max) {
        EXPECT_EQ(rtcm3::msm_lock_indicator(rtcm3::msm_lock_time_ms(i + 1, extended) - 0.5, extended), i);
      }
    }
  }
}

TEST(Rtcm3Msm, SignalIdsAreConsistent) {
  for (const Constellation c : {Constellation::Gps, Constellation::Glonass, Constellation::Galileo, Constellation::Qzss,
                                Constellation::BeiDou}) {
    for (int id = 1; id <= 32; ++id) {
      const auto code = rtcm3::msm_signal_code(c, id);
      if (code) {
        EXPECT_EQ(rtcm3::msm_signal_id(c, *code), id);
      }
    }
  }
  EXPECT_EQ(rtcm3::msm_signal_id(Constellation::Gps, {'1', 'C'}), 2);
  EXPECT_EQ(rtcm3::msm_signal_id(Constellation::Gps, {'2', 'W'}), 10);
  EXPECT_EQ(rtcm3::msm_signal_id(Constellation::Galileo, {'7', 'Q'}), 15);
  EXPECT_EQ(rtcm3::msm_signal_id(Constellation::BeiDou, {'2', 'I'}), 2);
  EXPECT_FALSE(rtcm3::msm_signal_id(Constellation::Qzss, {'1', 'Z'}));
  EXPECT_EQ(rtcm3::msm_message_number(Constellation::Qzss, 7), 1117);
  EXPECT_EQ(rtcm3::msm_kind(1127)->system, Constellation::BeiDou);
  EXPECT_FALSE(rtcm3::msm_kind(1107));  // SBAS: not supported
}

rtcm3::MsmMessage random_msm(std::mt19937_64& rng, Constellation system, int type, int nsat, int nsig) {
  std::uniform_real_distribution<double> range(2.0e7, 3.8e7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  rtcm3::MsmMessage m;
  m.header.system = system;
  m.header.type = type;
  m.header.station_id = 1234;
  m.header.epoch_time = 123456789;
  m.header.multiple_message = true;
  m.header.iods = 5;
  m.header.clock_steering = 1;
  const std::vector<int> ids = {2, 8, 15, 22, 3, 9};
  for (int s = 0; s < nsat; ++s) {
    rtcm3::MsmSatellite sat;
    sat.satellite_id = 1 + s * 2;
    sat.extended_info = type == 5 || type == 7 ? static_cast<int>(rng() % 14) : 0;
    const double pr = range(rng);
    const double rate = 800.0 * unit(rng);
    for (int g = 0; g < nsig; ++g) {
      if (s % 3 == 1 && g == 1) continue;  // a missing cell
      rtcm3::MsmCell c;
      c.signal_id = ids[static_cast<std::size_t>(g)];
      c.pseudorange_m = pr + 20.0 * unit(rng);
      c.phase_range_m = pr + 500.0 * unit(rng);
      if (type == 5 || type == 7) c.phase_range_rate_mps = rate + 0.5 * unit(rng);
      c.cnr_dbhz = 30.0 + 20.0 * std::abs(unit(rng));
      c.lock_time_ms = rtcm3::msm_lock_time_ms(static_cast<int>(rng() % (type >= 6 ? 700 : 15)), type >= 6);
      c.half_cycle = (rng() & 1) != 0;
      sat.cells.push_back(c);
    }
    m.satellites.push_back(sat);
  }
  return m;
}

TEST(Rtcm3Msm, EncodeDecodeWithinResolution) {
  std::mt19937_64 rng(7);
  for (const int type : {4, 5, 6, 7}) {
    const bool high = type >= 6;
    // Rounding of the rough range (2^-10 ms) is absorbed by the fine field: errors stay at the fine resolution.
    const double pr_tol_m = (high ? std::ldexp(1.0, -29) : std::ldexp(1.0, -24)) * rtcm3::kRangeMsM / 2 + 1e-9;
    const double ph_tol_m = (high ? std::ldexp(1.0, -31) : std::ldexp(1.0, -29)) * rtcm3::kRangeMsM / 2 + 1e-9;
    const double cnr_tol = high ? 1.0 / 32 : 0.5;
    for (const Constellation c : {Constellation::Gps, Constellation::Glonass, Constellation::Galileo,
                                  Constellation::Qzss, Constellation::BeiDou}) {
      const rtcm3::MsmMessage in = random_msm(rng, c, type, 16, 4);
      std::vector<std::uint8_t> payload;
      auto report = rtcm3::append_msm(in, payload);
      ASSERT_TRUE(report.ok()) << report.error().to_string();
      EXPECT_EQ(report->invalid_values, 0);
      auto out = rtcm3::decode_msm(payload);
      ASSERT_TRUE(out.ok()) << out.error().to_string();
      EXPECT_EQ(out->header.station_id, 1234);
      EXPECT_EQ(out->header.epoch_time, 123456789U);
      EXPECT_TRUE(out->header.multiple_message);
      EXPECT_EQ(out->header.iods, 5);
      EXPECT_EQ(out->header.clock_steering, 1);
      ASSERT_EQ(out->satellites.size(), in.satellites.size());
      for (std::size_t s = 0; s < in.satellites.size(); ++s) {
        const auto& a = in.satellites[s];
        const auto& b = out->satellites[s];
        EXPECT_EQ(a.satellite_id, b.satellite_id);
        if (type == 5 || type == 7) {
          EXPECT_EQ(a.extended_info, b.extended_info);
        }
        ASSERT_EQ(a.cells.size(), b.cells.size());
        // Cells come back in signal id order.
        auto sorted = a.cells;
        std::sort(sorted.begin(), sorted.end(), [](const auto& x, const auto& y) { return x.signal_id < y.signal_id; });
        for (std::size_t k = 0; k < sorted.size(); ++k) {
          const auto& x = sorted[k];
          const auto& y = b.cells[k];
          EXPECT_EQ(x.signal_id, y.signal_id);
          EXPECT_NEAR(x.pseudorange_m, y.pseudorange_m, pr_tol_m);
          EXPECT_NEAR(x.phase_range_m, y.phase_range_m, ph_tol_m);
          EXPECT_NEAR(x.cnr_dbhz, y.cnr_dbhz, cnr_tol);
          EXPECT_EQ(x.lock_time_ms, y.lock_time_ms);
          EXPECT_EQ(x.half_cycle, y.half_cycle);
          if (type == 5 || type == 7) {
            EXPECT_NEAR(x.phase_range_rate_mps, y.phase_range_rate_mps, 0.5e-4 + 1e-9);
          } else {
            EXPECT_FALSE(core::has_value(y.phase_range_rate_mps));
          }
        }
      }
    }
  }
}

TEST(Rtcm3Msm, MissingAndOutOfRangeValuesAreInvalid) {
  rtcm3::MsmMessage m;
  m.header.type = 7;
  rtcm3::MsmSatellite s;
  s.satellite_id = 5;
  rtcm3::MsmCell a;
  a.signal_id = 2;
  a.pseudorange_m = 2.2e7;
  rtcm3::MsmCell b;
  b.signal_id = 8;
  b.pseudorange_m = 2.2e7 + 5000.0;  // too far from the rough range of the first signal
  b.phase_range_m = 2.2e7 + 2.0;
  s.cells = {a, b};
  m.satellites = {s};
  std::vector<std::uint8_t> payload;
  auto report = rtcm3::append_msm(m, payload);
  ASSERT_TRUE(report.ok());
  EXPECT_EQ(report->invalid_values, 1);
  auto out = rtcm3::decode_msm(payload);
  ASSERT_TRUE(out.ok());
  const auto& cells = out->satellites.at(0).cells;
  ASSERT_EQ(cells.size(), 2U);
  EXPECT_FALSE(core::has_value(cells[0].phase_range_m));
  EXPECT_FALSE(core::has_value(cells[0].cnr_dbhz));
  EXPECT_FALSE(core::has_value(cells[1].pseudorange_m));
  EXPECT_NEAR(cells[1].phase_range_m, 2.2e7 + 2.0, 1e-3);
}

TEST(Rtcm3Msm, RejectsTooManyCellsAndShortPayloads) {
  std::mt19937_64 rng(3);
  const rtcm3::MsmMessage big = random_msm(rng, Constellation::Gps, 7, 17, 4);  // 68 cells
  std::vector<std::uint8_t> payload;
  auto report = rtcm3::append_msm(big, payload);
  ASSERT_FALSE(report.ok());
  EXPECT_NE(report.error().message.find("64-cell"), std::string::npos);

  const rtcm3::MsmMessage ok = random_msm(rng, Constellation::Gps, 7, 10, 4);
  ASSERT_TRUE(rtcm3::append_msm(ok, payload).ok());
  for (std::size_t cut = 0; cut < payload.size(); cut += 7) {
    auto decoded = rtcm3::decode_msm({payload.data(), cut});
    if (cut < 2) continue;
    EXPECT_FALSE(decoded.ok()) << "cut at " << cut;
  }
  payload[0] = 0x43;  // message 1074 -> 1076? no: 0x430 = 1072, MSM2
  payload[1] = static_cast<std::uint8_t>((payload[1] & 0x0F) | 0x00);
  auto msm2 = rtcm3::decode_msm(payload);
  ASSERT_FALSE(msm2.ok());
}

TEST(Rtcm3Msm, EpochTimesOfEverySystem) {
  const core::LeapSecondTable leaps = core::builtin_leap_seconds();
  const GpsTime reference{2176, 282600.0};
  for (const Constellation c : {Constellation::Gps, Constellation::Glonass, Constellation::Galileo, Constellation::Qzss,
                                Constellation::BeiDou}) {
    for (const double tow : {0.0, 0.001, 10799.0, 10800.0, 10818.0, 86399.999, 282600.0, 604799.0}) {
      for (const int dweek : {-1, 0}) {
        const GpsTime t{reference.week + dweek, tow};
        const std::uint32_t field = rtcm3::msm_epoch_field(c, t, leaps);
        const GpsTime back = rtcm3::msm_epoch_time(c, field, t + 3600.0, leaps);
        EXPECT_NEAR(back - t, 0.0, 1e-9) << core::constellation_name(c) << " tow " << tow;
      }
    }
  }
  // GLONASS: day of week and Moscow time of day.
  const GpsTime t{2176, 3 * 86400.0 + 100.0};  // Wednesday 00:01:40 GPST = 03:01:22 Moscow
  const std::uint32_t field = rtcm3::msm_epoch_field(Constellation::Glonass, t, leaps);
  EXPECT_EQ(field >> 27, 3U);
  EXPECT_EQ(field & ((1U << 27) - 1), (3 * 3600 + 60 + 22) * 1000U);
}

TEST(Rtcm3Station, RoundTrips) {
  rtcm3::StationPosition s;
  s.station_id = 4095;
  s.itrf_year = 20;
  s.galileo = false;
  s.arp_E_m = {-3959400.6312, 3385704.5331, 3667523.1109};
  s.quarter_cycle = 2;
  s.antenna_height_m = 1.2345;
  std::vector<std::uint8_t> payload;
  ASSERT_TRUE(rtcm3::append_station_position(s, payload).ok());
  EXPECT_EQ(payload.size(), 21U);
  auto d = rtcm3::decode_station_position(payload);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->station_id, 4095);
  EXPECT_EQ(d->itrf_year, 20);
  EXPECT_FALSE(d->galileo);
  EXPECT_EQ(d->quarter_cycle, 2);
  EXPECT_NEAR((d->arp_E_m - s.arp_E_m).norm(), 0.0, 1e-4);
  EXPECT_NEAR(*d->antenna_height_m, 1.2345, 1e-9);

  rtcm3::AntennaInfo a;
  a.station_id = 17;
  a.antenna_descriptor = "TRM59800.00     SCIS";
  a.antenna_setup_id = 3;
  a.antenna_serial = "12345";
  a.receiver_type = "canyon";
  a.receiver_firmware = "0.1.0";
  a.receiver_serial = "X1";
  payload.clear();
  ASSERT_TRUE(rtcm3::append_antenna_info(a, payload).ok());
  auto da = rtcm3::decode_antenna_info(payload);
  ASSERT_TRUE(da.ok());
  EXPECT_EQ(da->antenna_descriptor, a.antenna_descriptor);
  EXPECT_EQ(da->antenna_setup_id, 3);
  EXPECT_EQ(da->antenna_serial, a.antenna_serial);
  EXPECT_EQ(da->receiver_type, a.receiver_type);
  EXPECT_EQ(da->receiver_firmware, a.receiver_firmware);
  EXPECT_EQ(da->receiver_serial, a.receiver_serial);
  EXPECT_FALSE(rtcm3::decode_antenna_info({payload.data(), payload.size() - 2}).ok());
  a.antenna_descriptor = std::string(40, 'A');
  EXPECT_FALSE(rtcm3::append_antenna_info(a, payload).ok());

  rtcm3::GlonassBiases b;
  b.station_id = 9;
  b.aligned = true;
  b.bias_m = {1.22, std::nullopt, -3.5, 0.0};
  payload.clear();
  ASSERT_TRUE(rtcm3::append_glonass_biases(b, payload).ok());
  auto db = rtcm3::decode_glonass_biases(payload);
  ASSERT_TRUE(db.ok());
  EXPECT_TRUE(db->aligned);
  EXPECT_NEAR(*db->bias_m[0], 1.22, 1e-9);
  EXPECT_FALSE(db->bias_m[1]);
  EXPECT_NEAR(*db->bias_m[2], -3.5, 1e-9);
  EXPECT_NEAR(*db->bias_m[3], 0.0, 1e-9);
}

core::KeplerEphemeris typical_kepler(core::SatelliteId sat, const GpsTime& toe) {
  core::KeplerEphemeris e;
  e.sat = sat;
  e.toe = toe;
  e.toc = toe;
  e.transmission_time = toe;
  e.toe_sow_s = sat.system == Constellation::BeiDou ? core::gps_to_bdt(toe).tow_s : toe.tow_s;
  e.af0_s = -1.2345678e-4;
  e.af1_sps = 3.4e-12;
  e.af2_sps2 = sat.system == Constellation::Galileo ? 0.0 : 1e-19;
  e.sqrt_a_sqrtm = 5153.6789;
  e.e = 0.0123456;
  e.i0_rad = 0.9712345;
  e.omega0_rad = -2.1234567;
  e.omega_rad = 1.2345678;
  e.m0_rad = 0.5432109;
  e.delta_n_radps = 4.5e-9;
  e.omega_dot_radps = -8.1e-9;
  e.idot_radps = 2.1e-10;
  e.cuc_rad = 1.5e-6;
  e.cus_rad = -2.5e-6;
  e.crc_m = 250.125;
  e.crs_m = -45.5;
  e.cic_rad = 1.1e-7;
  e.cis_rad = -9.3e-8;
  e.tgd_s = {-1.1641532e-8, sat.system == Constellation::Gps || sat.system == Constellation::Qzss ? 0.0 : 2.3e-9};
  e.iode = sat.system == Constellation::BeiDou ? 17 : 77;
  e.iodc = sat.system == Constellation::BeiDou ? 9 : 333;
  e.health = 0;
  e.accuracy_m = sat.system == Constellation::Galileo ? 3.12 : 2.0;
  e.data_source = sat.system == Constellation::Galileo ? 0x205 : 1;
  e.fit_interval_h = 4.0;
  return e;
}

TEST(Rtcm3Ephemeris, KeplerRoundTripsForEverySystem) {
  const GpsTime toe{2176, 288000.0};
  for (const core::SatelliteId sat :
       {core::SatelliteId{Constellation::Gps, 5}, core::SatelliteId{Constellation::Qzss, 3},
        core::SatelliteId{Constellation::Galileo, 11}, core::SatelliteId{Constellation::BeiDou, 30}}) {
    for (const int source : {0x205, 0x102}) {
      if (source == 0x102 && sat.system != Constellation::Galileo) continue;
      // BeiDou toe and toc are multiples of 8 s of BDT (GPST - 14 s).
      core::KeplerEphemeris in = typical_kepler(sat, sat.system == Constellation::BeiDou ? toe + 14.0 : toe);
      in.data_source = sat.system == Constellation::Galileo ? source : in.data_source;
      std::vector<std::uint8_t> payload;
      ASSERT_TRUE(rtcm3::append_kepler_ephemeris(in, payload).ok());
      const int number = rtcm3::message_number(payload);
      EXPECT_EQ(number, rtcm3::ephemeris_message_number(in));
      auto out = rtcm3::decode_kepler_ephemeris(payload, toe + 7200.0);
      ASSERT_TRUE(out.ok()) << out.error().to_string();
      const core::KeplerEphemeris& e = *out;
      SCOPED_TRACE(sat.to_string() + " message " + std::to_string(number));
      EXPECT_EQ(e.sat, in.sat);
      EXPECT_NEAR(e.toe - in.toe, 0.0, 1e-9);
      EXPECT_NEAR(e.toc - in.toc, 0.0, 1e-9);
      EXPECT_NEAR(e.toe_sow_s, in.toe_sow_s, 1e-9);
      const double sc = rtcm3::kGpsPi;
      EXPECT_NEAR(e.sqrt_a_sqrtm, in.sqrt_a_sqrtm, std::ldexp(1.0, -20));
      EXPECT_NEAR(e.e, in.e, std::ldexp(1.0, -34));
      EXPECT_NEAR(e.i0_rad, in.i0_rad, std::ldexp(sc, -32));
      EXPECT_NEAR(e.omega0_rad, in.omega0_rad, std::ldexp(sc, -32));
      EXPECT_NEAR(e.omega_rad, in.omega_rad, std::ldexp(sc, -32));
      EXPECT_NEAR(e.m0_rad, in.m0_rad, std::ldexp(sc, -32));
      EXPECT_NEAR(e.delta_n_radps, in.delta_n_radps, std::ldexp(sc, -44));
      EXPECT_NEAR(e.omega_dot_radps, in.omega_dot_radps, std::ldexp(sc, -44));
      EXPECT_NEAR(e.idot_radps, in.idot_radps, std::ldexp(sc, -44));
      EXPECT_NEAR(e.crc_m, in.crc_m, std::ldexp(1.0, -6));
      EXPECT_NEAR(e.crs_m, in.crs_m, std::ldexp(1.0, -6));
      EXPECT_NEAR(e.cuc_rad, in.cuc_rad, std::ldexp(1.0, -30));
      EXPECT_NEAR(e.cis_rad, in.cis_rad, std::ldexp(1.0, -30));
      EXPECT_NEAR(e.af0_s, in.af0_s, std::ldexp(1.0, -31));
      EXPECT_NEAR(e.af1_sps, in.af1_sps, std::ldexp(1.0, -43));
      EXPECT_NEAR(e.tgd_s[0], in.tgd_s[0], sat.system == Constellation::BeiDou ? 0.5e-10 : std::ldexp(1.0, -31));
      if (sat.system == Constellation::BeiDou || (sat.system == Constellation::Galileo && source == 0x205)) {
        EXPECT_NEAR(e.tgd_s[1], in.tgd_s[1], sat.system == Constellation::BeiDou ? 0.5e-10 : std::ldexp(1.0, -32));
      }
      EXPECT_EQ(e.iode, in.iode);
      if (sat.system != Constellation::Galileo) {
        EXPECT_EQ(e.iodc, in.iodc);
      }
      EXPECT_NEAR(e.accuracy_m, in.accuracy_m, 1e-9);
      if (sat.system == Constellation::Galileo) {
        EXPECT_EQ(e.data_source, source == 0x205 ? 0x205 : 0x102);
      }
    }
  }
}

TEST(Rtcm3Ephemeris, GlonassRoundTrips) {
  const core::LeapSecondTable leaps = core::builtin_leap_seconds();
  core::GlonassEphemeris g;
  g.sat = core::SatelliteId{Constellation::Glonass, 7};
  g.frequency_channel = -4;
  // tb = 23:45 Moscow on the GPS day before: toe 20:45 UTC + 18 s.
  g.toe = GpsTime{2176, 2 * 86400.0 + 20 * 3600.0 + 45 * 60.0 + 18.0};
  g.frame_time = g.toe - 900.0 + 30.0;
  g.p_E_m = {12345678.9, -19876543.2, 7654321.0};
  g.v_E_mps = {1234.5678, 456.789, -3210.987};
  g.a_E_mps2 = {1.8626e-6, -9.3132e-7, 0.0};
  g.tau_n_s = 2.345e-5;
  g.gamma_n = 1.8190e-12;
  g.delta_tau_n_s = -2.79e-9;
  g.age_days = 3;
  std::vector<std::uint8_t> payload;
  ASSERT_TRUE(rtcm3::append_glonass_ephemeris(g, leaps, payload).ok());
  EXPECT_EQ(payload.size(), 45U);
  for (const double dt : {-40000.0, 0.0, 40000.0}) {
    auto d = rtcm3::decode_glonass_ephemeris(payload, g.toe + dt, leaps);
    ASSERT_TRUE(d.ok()) << d.error().to_string();
    EXPECT_EQ(d->sat, g.sat);
    EXPECT_EQ(d->frequency_channel, -4);
    EXPECT_NEAR(d->toe - g.toe, 0.0, 1e-9);
    EXPECT_NEAR(d->frame_time - g.frame_time, 0.0, 1e-9);
    EXPECT_NEAR((d->p_E_m - g.p_E_m).norm(), 0.0, std::ldexp(1.0, -11) * 1e3);
    EXPECT_NEAR((d->v_E_mps - g.v_E_mps).norm(), 0.0, std::ldexp(1.0, -20) * 1e3);
    EXPECT_NEAR((d->a_E_mps2 - g.a_E_mps2).norm(), 0.0, std::ldexp(1.0, -30) * 1e3);
    EXPECT_NEAR(d->tau_n_s, g.tau_n_s, std::ldexp(1.0, -31));
    EXPECT_NEAR(d->gamma_n, g.gamma_n, std::ldexp(1.0, -41));
    EXPECT_NEAR(d->delta_tau_n_s, g.delta_tau_n_s, std::ldexp(1.0, -31));
    EXPECT_EQ(d->age_days, 3);
  }
}

TEST(Rtcm3Ephemeris, AccuracyIndices) {
  for (int i = 0; i < 15; ++i) EXPECT_EQ(rtcm3::ura_index(rtcm3::ura_m(i)), i);
  for (int i = 0; i <= 125; ++i) EXPECT_EQ(rtcm3::sisa_index(rtcm3::sisa_m(i)), i) << i;
  EXPECT_EQ(rtcm3::sisa_index(-1.0), 255);
}

TEST(Rtcm3Ephemeris, ErrorsNameTheProblem) {
  core::KeplerEphemeris e = typical_kepler({Constellation::Gps, 5}, GpsTime{2176, 288000.0});
  e.e = -0.1;
  std::vector<std::uint8_t> payload;
  auto s = rtcm3::append_kepler_ephemeris(e, payload);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("1019: e out of"), std::string::npos) << s.error().message;
  payload.clear();
  ASSERT_TRUE(
      rtcm3::append_kepler_ephemeris(typical_kepler({Constellation::Gps, 5}, GpsTime{2176, 288000.0}), payload).ok());
  auto d = rtcm3::decode_kepler_ephemeris({payload.data(), 40}, GpsTime{2176, 288000.0});
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.error().message.find("40 bytes, needs 61"), std::string::npos) << d.error().message;
}

// ---------------------------------------------------------------------------------------------------------------
// Field layouts (rtcm3_fields.hpp).

TEST(Rtcm3Fields, LayoutsAddUpToTheMessageLengths) {
  namespace f = rtcm3::fields;
  auto bits = [](auto&& layout) {
    f::FieldCounter counter;
    layout(counter);
    return counter.bits();
  };
  rtcm3::StationPosition station;
  f::StationWire station_wire;
  EXPECT_EQ(bits([&](auto& io) { f::station_position_fields(io, station, station_wire); }), 152U);
  station_wire.number = 1006;
  EXPECT_EQ(bits([&](auto& io) { f::station_position_fields(io, station, station_wire); }), 168U);
  rtcm3::GlonassBiases biases;
  f::GlonassBiasWire bias_wire;
  EXPECT_EQ(bits([&](auto& io) { f::glonass_bias_fields(io, biases, bias_wire); }), 32U);
  bias_wire.mask = 0xF;
  EXPECT_EQ(bits([&](auto& io) { f::glonass_bias_fields(io, biases, bias_wire); }), 32U + 4 * 16);
  rtcm3::AntennaInfo antenna;
  antenna.antenna_descriptor = "ABC";
  for (const auto& [number, expected] :
       {std::pair{1007, 12 + 12 + 8 + 24 + 8}, std::pair{1008, 64 + 8}, std::pair{1033, 72 + 3 * 8}}) {
    int n = number;
    EXPECT_EQ(bits([&](auto& io) { f::antenna_info_fields(io, antenna, n); }), static_cast<std::size_t>(expected));
  }
  core::KeplerEphemeris kepler;
  f::KeplerWire kepler_wire;
  for (const auto& [number, expected] :
       {std::pair{1019, 488}, std::pair{1044, 485}, std::pair{1042, 511}, std::pair{1045, 496}, std::pair{1046, 504}}) {
    kepler_wire.number = number;
    EXPECT_EQ(bits([&](auto& io) { EXPECT_TRUE(f::kepler_ephemeris_fields(io, kepler, kepler_wire)); }),
              static_cast<std::size_t>(expected))
        << number;
  }
  kepler_wire.number = 1020;
  EXPECT_FALSE(f::kepler_ephemeris_fields(*std::make_unique<f::FieldCounter>(), kepler, kepler_wire));
  core::GlonassEphemeris glonass;
  f::GlonassWire glonass_wire;
  EXPECT_EQ(bits([&](auto& io) { f::glonass_ephemeris_fields(io, glonass, glonass_wire); }), 360U);
  // MSM: header, and per satellite / per cell of MSM4-7 (RTCM 10403.3 tables 3.5-78 ff.).
  EXPECT_EQ(f::msm_header_bits(), 169U);
  const std::size_t satellite_bits[] = {18, 36, 18, 36};
  const std::size_t cell_bits[] = {48, 63, 65, 80};
  for (int type = 4; type <= 7; ++type) {
    EXPECT_EQ(f::msm_fields(type).satellite_bits, satellite_bits[type - 4]) << type;
    EXPECT_EQ(f::msm_fields(type).cell_bits, cell_bits[type - 4]) << type;
  }
  rtcm3::LegacyObsMessage legacy;
  f::LegacyWire legacy_wire;
  f::LegacySatelliteWire legacy_sat;
  for (const auto& [number, header, satellite] : {std::tuple{1004, 64, 125}, std::tuple{1012, 61, 130}}) {
    legacy_wire.number = number;
    const bool glonass = number == 1012;
    EXPECT_EQ(bits([&](auto& io) { f::legacy_header_fields(io, legacy, legacy_wire); }),
              static_cast<std::size_t>(header));
    EXPECT_EQ(bits([&](auto& io) { f::legacy_satellite_fields(io, glonass, legacy_sat); }),
              static_cast<std::size_t>(satellite));
  }
}

TEST(Rtcm3Fields, OneFieldListEncodesDecodesAndChecks) {
  namespace f = rtcm3::fields;
  struct Values {
    double angle_rad = 0.0;
    double height_m = 0.0;
    double position_m = 0.0;
    int masked = 0;
    int checked = 0;
    bool flag = false;
    std::string text;
  };
  auto layout = [](auto& io, auto& v) {
    io(f::s(1, 14, f::p2(-43), "angle", f::Unit::Semicircle), v.angle_rad);
    io(f::u(2, 16, 1e-4, "height"), v.height_m);
    io(f::sm(3, 27, f::p2(-11), "position", f::Unit::Kilometre), v.position_m);
    io(f::u(4, 4), v.masked);
    io(f::reserved(3));
    io(f::u(5, 6, "checked"), v.checked);
    io(f::u(6, 1), v.flag);
    io(f::text(7, "text"), v.text);
  };
  Values in;
  in.angle_rad = 2.1e-10;
  in.height_m = 1.23456;
  in.position_m = -19876543.2;
  in.masked = 0x1F;  // 5 bits into 4: its low bits
  in.checked = 63;
  in.flag = true;
  in.text = "canyon";
  std::vector<std::uint8_t> payload;
  {
    BitWriter bits(payload);
    f::FieldWriter w(bits, 999);
    layout(w, in);
    ASSERT_TRUE(w.status().ok());
  }
  f::FieldCounter counter;
  layout(counter, in);
  EXPECT_EQ(payload.size(), (counter.bits() + 7) / 8);
  Values out;
  f::FieldReader<true> r(payload);
  layout(r, out);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(out.angle_rad,
            std::round(in.angle_rad / rtcm3::kGpsPi / std::ldexp(1.0, -43)) * std::ldexp(1.0, -43) * rtcm3::kGpsPi);
  EXPECT_EQ(out.height_m, 12346 * 1e-4);
  EXPECT_EQ(out.position_m, -std::round(19876543.2 * 1e-3 / std::ldexp(1.0, -11)) * std::ldexp(1.0, -11) * 1e3);
  EXPECT_EQ(out.masked, 0xF);
  EXPECT_EQ(out.checked, 63);
  EXPECT_TRUE(out.flag);
  EXPECT_EQ(out.text, "canyon");
  // A checked reader stops at the end of the payload; a named field out of range is an Error naming it.
  f::FieldReader<true> short_reader({payload.data(), payload.size() - 3});
  layout(short_reader, out);
  EXPECT_FALSE(short_reader.ok());
  in.checked = 64;
  payload.clear();
  BitWriter bits(payload);
  f::FieldWriter w(bits, 999);
  layout(w, in);
  ASSERT_FALSE(w.status().ok());
  EXPECT_EQ(w.status().error().message, "RTCM 3 message 999: checked out of its field's range");
}

/// One payload of every message type canyon encodes, from fixed values (MSM cells from a seeded generator).
std::vector<std::pair<std::string, std::vector<std::uint8_t>>> every_message() {
  std::vector<std::pair<std::string, std::vector<std::uint8_t>>> out;
  auto add = [&](const std::string& name, auto&& append) {
    std::vector<std::uint8_t> payload;
    const auto status = append(payload);
    EXPECT_TRUE(status.ok()) << name;
    out.emplace_back(name, std::move(payload));
  };
  rtcm3::StationPosition s;
  s.station_id = 2003;
  s.itrf_year = 20;
  s.glonass = false;
  s.reference_station = true;
  s.arp_E_m = {1114104.5999, -4850729.7108, 3975521.4643};
  s.single_oscillator = true;
  s.quarter_cycle = 1;
  add("1005", [&](auto& p) { return rtcm3::append_station_position(s, p); });
  s.antenna_height_m = 1.2345;
  add("1006", [&](auto& p) { return rtcm3::append_station_position(s, p); });
  rtcm3::AntennaInfo a;
  a.station_id = 17;
  a.antenna_descriptor = "TRM59800.00     SCIS";
  a.antenna_setup_id = 3;
  a.antenna_serial = "12345";
  a.receiver_type = "canyon";
  a.receiver_firmware = "0.1.0";
  a.receiver_serial = "X1";
  add("1033", [&](auto& p) { return rtcm3::append_antenna_info(a, p); });
  rtcm3::GlonassBiases b;
  b.station_id = 9;
  b.aligned = true;
  b.bias_m = {1.22, std::nullopt, -3.5, 0.0};
  add("1230", [&](auto& p) { return rtcm3::append_glonass_biases(b, p); });
  const GpsTime toe{2176, 288000.0};
  for (const core::SatelliteId sat :
       {core::SatelliteId{Constellation::Gps, 5}, core::SatelliteId{Constellation::Qzss, 3},
        core::SatelliteId{Constellation::BeiDou, 30}, core::SatelliteId{Constellation::Galileo, 11}}) {
    for (const int source : {0x205, 0x102}) {
      if (source == 0x102 && sat.system != Constellation::Galileo) continue;
      core::KeplerEphemeris e = typical_kepler(sat, sat.system == Constellation::BeiDou ? toe + 14.0 : toe);
      if (sat.system == Constellation::Galileo) {
        e.data_source = source;
        e.health = 0x1B5;
      }
      if (sat.system == Constellation::Gps) e.fit_interval_h = 6.0;
      add(std::to_string(rtcm3::ephemeris_message_number(e)) + " " + sat.to_string(),
          [&](auto& p) { return rtcm3::append_kepler_ephemeris(e, p); });
    }
  }
  core::GlonassEphemeris g;
  g.sat = core::SatelliteId{Constellation::Glonass, 7};
  g.frequency_channel = -4;
  g.health = 1;
  g.toe = GpsTime{2176, 2 * 86400.0 + 20 * 3600.0 + 45 * 60.0 + 18.0};
  g.frame_time = g.toe - 900.0 + 30.0;
  g.p_E_m = {12345678.9, -19876543.2, 7654321.0};
  g.v_E_mps = {1234.5678, 456.789, -3210.987};
  g.a_E_mps2 = {1.8626e-6, -9.3132e-7, 0.0};
  g.tau_n_s = 2.345e-5;
  g.gamma_n = 1.8190e-12;
  g.delta_tau_n_s = -2.79e-9;
  g.age_days = 3;
  add("1020", [&](auto& p) { return rtcm3::append_glonass_ephemeris(g, core::builtin_leap_seconds(), p); });
  std::mt19937_64 rng(11);
  for (const int type : {4, 5, 6, 7}) {
    for (const Constellation c : {Constellation::Gps, Constellation::Glonass, Constellation::Galileo,
                                  Constellation::Qzss, Constellation::BeiDou}) {
      const rtcm3::MsmMessage m = random_msm(rng, c, type, 12, 4);
      add(std::to_string(rtcm3::msm_message_number(c, type)), [&](auto& p) { return rtcm3::append_msm(m, p); });
    }
  }
  return out;
}

TEST(Rtcm3Fields, EveryMessageEncodesToTheBytesItAlwaysHad) {
  // Size and CRC-24Q of each payload as the encoders wrote them before the layouts were shared (commit 0443c6d).
  struct Recorded {
    const char* name;
    std::size_t size;
    std::uint32_t crc;
  };
  const Recorded recorded[] = {
      {"1005", 19, 0xBC8C12},     {"1006", 21, 0x25EC8E},     {"1033", 47, 0xE6CABF},     {"1230", 10, 0xCD6586},
      {"1019 G05", 61, 0xAF2931}, {"1044 J03", 61, 0x3FD35C}, {"1042 C30", 64, 0x7ED012}, {"1046 E11", 63, 0x729C1E},
      {"1045 E11", 62, 0x1ADA24}, {"1020", 45, 0xE0F94E},     {"1074", 319, 0xB28547},    {"1084", 319, 0x87881B},
      {"1094", 319, 0xFA79B2},    {"1114", 319, 0x5BBE68},    {"1124", 319, 0xEDEE37},    {"1075", 428, 0x9FCC29},
      {"1085", 428, 0x95BC1E},    {"1095", 428, 0x475E2E},    {"1115", 428, 0xCEB256},    {"1125", 428, 0x9CEF53},
      {"1076", 412, 0x40199E},    {"1086", 412, 0xA186B2},    {"1096", 412, 0x34E076},    {"1116", 412, 0x4B4700},
      {"1126", 412, 0xFAA31D},    {"1077", 522, 0xC70941},    {"1087", 522, 0xDA93FE},    {"1097", 522, 0x67A100},
      {"1117", 522, 0xF9D4B8},    {"1127", 522, 0x5C85FC},
  };
  const auto messages = every_message();
  ASSERT_EQ(messages.size(), std::size(recorded));
  for (std::size_t i = 0; i < messages.size(); ++i) {
    const auto& [name, payload] = messages[i];
    EXPECT_EQ(name, recorded[i].name);
    EXPECT_EQ(payload.size(), recorded[i].size) << name;
    EXPECT_EQ(crc24q(payload), recorded[i].crc) << name;
  }
}

TEST(Rtcm3Fields, EveryMessageDecodesAndEncodesBackToItsBytes) {
  const GpsTime reference{2176, 288000.0 + 7200.0};
  const core::LeapSecondTable leaps = core::builtin_leap_seconds();
  for (const auto& [name, payload] : every_message()) {
    SCOPED_TRACE(name);
    std::vector<std::uint8_t> again;
    const int number = rtcm3::message_number(payload);
    if (number == 1005 || number == 1006) {
      ASSERT_TRUE(rtcm3::append_station_position(*rtcm3::decode_station_position(payload), again).ok());
    } else if (number == 1033) {
      ASSERT_TRUE(rtcm3::append_antenna_info(*rtcm3::decode_antenna_info(payload), again).ok());
    } else if (number == 1230) {
      ASSERT_TRUE(rtcm3::append_glonass_biases(*rtcm3::decode_glonass_biases(payload), again).ok());
    } else if (number == 1020) {
      const auto g = rtcm3::decode_glonass_ephemeris(payload, GpsTime{2176, 2 * 86400.0 + 20 * 3600.0}, leaps);
      ASSERT_TRUE(g.ok()) << g.error().to_string();
      ASSERT_TRUE(rtcm3::append_glonass_ephemeris(*g, leaps, again).ok());
    } else if (rtcm3::msm_kind(number)) {
      const auto m = rtcm3::decode_msm(payload);
      ASSERT_TRUE(m.ok()) << m.error().to_string();
      ASSERT_TRUE(rtcm3::append_msm(*m, again).ok());
    } else {
      const auto e = rtcm3::decode_kepler_ephemeris(payload, reference);
      ASSERT_TRUE(e.ok()) << e.error().to_string();
      ASSERT_TRUE(rtcm3::append_kepler_ephemeris(*e, again).ok());
    }
    EXPECT_EQ(again, payload);
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Framing.

std::vector<std::uint8_t> frame_of(int number, std::size_t payload_bytes, std::uint8_t fill) {
  std::vector<std::uint8_t> payload(payload_bytes, fill);
  payload[0] = static_cast<std::uint8_t>(number >> 4);
  payload[1] = static_cast<std::uint8_t>((number & 0xF) << 4);
  return *rtcm3::frame_rtcm3(payload);
}

TEST(StreamFramer, FindsEveryIntactFrameInGarbageAndCountsTheRest) {
  std::mt19937_64 rng(11);
  std::vector<std::uint8_t> stream;
  std::vector<std::vector<std::uint8_t>> good;
  int bad_crc = 0;
  for (int i = 0; i < 300; ++i) {
    const auto f = frame_of(1001 + i % 200, 5 + rng() % 300, static_cast<std::uint8_t>(rng()));
    const int kind = static_cast<int>(rng() % 5);
    if (kind == 0) {  // garbage, with preamble bytes in it
      for (int k = 0; k < 50; ++k) stream.push_back(static_cast<std::uint8_t>(rng() % 4 == 0 ? 0xD3 : rng()));
    }
    if (kind == 1) {  // truncated frame
      stream.insert(stream.end(), f.begin(), f.begin() + static_cast<std::ptrdiff_t>(f.size() / 2));
      continue;
    }
    if (kind == 2) {  // bad CRC
      auto broken = f;
      broken[broken.size() / 2] ^= 0x10;
      stream.insert(stream.end(), broken.begin(), broken.end());
      ++bad_crc;
      continue;
    }
    stream.insert(stream.end(), f.begin(), f.end());
    good.push_back(f);
  }
  // Fed in random-sized reads.
  StreamFramer framer(StreamFramer::Options{true, false, false});
  std::vector<std::vector<std::uint8_t>> found;
  std::size_t pos = 0;
  while (pos < stream.size()) {
    const std::size_t n = std::min<std::size_t>(1 + rng() % 100, stream.size() - pos);
    framer.push({stream.data() + pos, n});
    pos += n;
    while (auto p = framer.next()) found.emplace_back(p->bytes.begin(), p->bytes.end());
  }
  framer.finish();
  while (auto p = framer.next()) found.emplace_back(p->bytes.begin(), p->bytes.end());
  // Every intact frame, in order; a truncated frame's tail can swallow the start of the next frame only as far as
  // its own announced length reaches, and then the CRC fails and the framer resumes inside it.
  std::size_t k = 0;
  for (const auto& f : found) {
    while (k < good.size() && good[k] != f) ++k;
    ASSERT_LT(k, good.size()) << "a frame that was not sent";
  }
  EXPECT_EQ(found.size(), good.size());
  EXPECT_GE(framer.stats().rtcm3_bad_crc, static_cast<std::uint64_t>(bad_crc));
  EXPECT_GT(framer.stats().garbage_bytes, 0U);
  EXPECT_FALSE(framer.problems().empty());
  EXPECT_NE(framer.problems().front().find("byte "), std::string::npos);
}

TEST(StreamFramer, MixedProtocolsAndPartialReads) {
  std::vector<std::uint8_t> stream;
  const auto rtcm = frame_of(1005, 19, 0x55);
  const std::string nmea = "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n";
  std::vector<std::uint8_t> ubx = {0xB5, 0x62, 0x01, 0x20, 0x02, 0x00, 0xAA, 0xBB};
  std::uint8_t a = 0;
  std::uint8_t b = 0;
  for (std::size_t i = 2; i < ubx.size(); ++i) {
    a = static_cast<std::uint8_t>(a + ubx[i]);
    b = static_cast<std::uint8_t>(b + a);
  }
  ubx.push_back(a);
  ubx.push_back(b);
  stream.insert(stream.end(), rtcm.begin(), rtcm.end());
  stream.insert(stream.end(), nmea.begin(), nmea.end());
  stream.push_back(0x00);
  stream.insert(stream.end(), ubx.begin(), ubx.end());
  const std::string bad_nmea = "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*48\r\n";
  stream.insert(stream.end(), bad_nmea.begin(), bad_nmea.end());
  StreamFramer framer;
  std::vector<Protocol> kinds;
  for (const std::uint8_t byte : stream) {  // one byte at a time
    framer.push({&byte, 1});
    while (auto p = framer.next()) kinds.push_back(p->protocol);
  }
  ASSERT_EQ(kinds.size(), 3U);
  EXPECT_EQ(kinds[0], Protocol::Rtcm3);
  EXPECT_EQ(kinds[1], Protocol::Nmea);
  EXPECT_EQ(kinds[2], Protocol::Ubx);
  EXPECT_EQ(framer.stats().nmea_bad_checksum, 1U);
  EXPECT_EQ(framer.stats().garbage_bytes, 1U + bad_nmea.size());
}

TEST(StreamFramer, TruncatedLastFrameIsCounted) {
  const auto f = frame_of(1077, 200, 0x12);
  StreamFramer framer;
  framer.push({f.data(), f.size() - 10});
  EXPECT_FALSE(framer.next());
  framer.finish();
  EXPECT_FALSE(framer.next());
  EXPECT_EQ(framer.stats().truncated, 1U);
  ASSERT_FALSE(framer.problems().empty());
  EXPECT_NE(framer.problems()[0].find("byte 0: RTCM 3 frame cut short"), std::string::npos) << framer.problems()[0];
}

// ---------------------------------------------------------------------------------------------------------------
// Stream codec: epochs through MSM and back.

core::ObsEpoch synthetic_epoch(const GpsTime& t, double phase_offset_cyc, int nsat_per_system) {
  core::ObsEpoch e;
  e.time = t;
  const std::vector<std::pair<Constellation, std::vector<core::SignalCode>>> plan = {
      {Constellation::Gps, {{'1', 'C'}, {'2', 'W'}, {'2', 'L'}, {'5', 'Q'}, {'1', 'W'}}},
      {Constellation::Glonass, {{'1', 'C'}, {'2', 'C'}}},
      {Constellation::Galileo, {{'1', 'C'}, {'5', 'Q'}, {'7', 'Q'}}},
      {Constellation::BeiDou, {{'2', 'I'}, {'7', 'I'}}},
      {Constellation::Qzss, {{'1', 'C'}, {'2', 'L'}}}};
  for (const auto& [system, codes] : plan) {
    for (int s = 1; s <= nsat_per_system && s <= core::max_prn(system); ++s) {
      core::SatelliteObs so;
      so.sat = core::SatelliteId{system, static_cast<std::uint8_t>(s)};
      const double range = 2.1e7 + 1.0e5 * s + 800.0 * (t.tow_s - 282600.0) * std::sin(s);
      for (const core::SignalCode code : codes) {
        const int channel = system == Constellation::Glonass ? (s % 14) - 7 : core::kNoGlonassChannel;
        const double lambda = *core::wavelength_m(system, code, channel);
        core::SignalObs sig;
        sig.code = code;
        sig.pseudorange_m = range + 3.0 * (code.band - '0');
        sig.carrier_phase_cyc = range / lambda + phase_offset_cyc + 1234567.0 * s;
        sig.doppler_hz = -800.0 * std::sin(s) / lambda;
        sig.snr_dbhz = 40.0 + s % 10;
        so.signals.push_back(sig);
      }
      e.sats.push_back(so);
    }
  }
  return e;
}

TEST(Rtcm3Codec, EpochsRoundTripThroughMsm7AndMsm4) {
  for (const int type : {7, 4}) {
    Rtcm3EncoderOptions eo;
    eo.station_id = 42;
    eo.msm_type = type;
    for (int slot = 1; slot <= 24; ++slot) eo.glonass_channels.emplace_back(slot, (slot % 14) - 7);
    Rtcm3Encoder encoder(eo);
    Rtcm3DecoderOptions dopt;
    dopt.reference_time = GpsTime{2176, 300000.0};
    dopt.glonass_channels = eo.glonass_channels;
    Rtcm3Decoder decoder(dopt);
    std::vector<core::ObsEpoch> in;
    std::vector<core::ObsEpoch> out;
    for (int k = 0; k < 5; ++k) {
      in.push_back(synthetic_epoch(GpsTime{2176, 282600.0 + k}, 0.0, 20));
      if (k == 3) in.back().sats[0].signals[0].lli = core::kLliLossOfLock;  // slip on G01 1C
      if (k == 4) in.back().sats[1].signals[1].lli = core::kLliHalfCycle;
      std::vector<Rtcm3Frame> frames;
      auto report = encoder.encode_epoch(in.back(), frames);
      ASSERT_TRUE(report.ok()) << report.error().to_string();
      EXPECT_EQ(report->invalid_values, 0);
      EXPECT_GT(report->messages, 5);  // GPS: 20 x 5 > 64 cells: split
      StreamFramer framer;
      for (const Rtcm3Frame& f : frames) {
        EXPECT_EQ(f.message_number % 10, type);
        framer.push(f.bytes);
        while (auto p = framer.next()) {
          auto m = decoder.decode(p->payload());
          ASSERT_TRUE(m.ok()) << m.error().to_string();
          EXPECT_EQ(m->station_id, 42);
        }
      }
      auto epoch = decoder.pop_epoch();
      ASSERT_TRUE(epoch) << "epoch " << k << " not complete after its last message";
      out.push_back(*epoch);
      EXPECT_FALSE(decoder.pop_epoch());
    }
    const double pr_tol = type == 7 ? 0.0003 : 0.0092;
    const double ph_tol_m = type == 7 ? 0.0001 : 0.0003;
    for (std::size_t k = 0; k < in.size(); ++k) {
      EXPECT_NEAR(out[k].time - in[k].time, 0.0, 1e-9);
      ASSERT_EQ(out[k].sats.size(), in[k].sats.size());
      for (std::size_t s = 0; s < in[k].sats.size(); ++s) {
        const auto& a = in[k].sats[s];
        const auto* b = &out[k].sats[s];
        ASSERT_EQ(a.sat, b->sat);
        for (const core::SignalObs& x : a.signals) {
          const core::SignalObs* y = b->find(x.code);
          ASSERT_NE(y, nullptr) << a.sat.to_string() << " " << x.code.to_string();
          const int channel = a.sat.system == Constellation::Glonass ? (a.sat.prn % 14) - 7 : core::kNoGlonassChannel;
          const double lambda = *core::wavelength_m(a.sat.system, x.code, channel);
          EXPECT_NEAR(y->pseudorange_m, x.pseudorange_m, pr_tol);
          // Phase: the input minus an integer per arc.
          const double d = x.carrier_phase_cyc - y->carrier_phase_cyc;
          EXPECT_NEAR(d, std::round(d), ph_tol_m / lambda) << a.sat.to_string() << " " << x.code.to_string();
          if (type == 7) {
            EXPECT_NEAR(y->doppler_hz, x.doppler_hz, 0.5e-4 / lambda + 1e-9);
            EXPECT_NEAR(y->snr_dbhz, x.snr_dbhz, 1.0 / 32);
          } else {
            EXPECT_FALSE(core::has_value(y->doppler_hz));
            EXPECT_NEAR(y->snr_dbhz, x.snr_dbhz, 0.5);
          }
          // Loss of lock at the first epoch (lock time 0) and where the input had it.
          const bool slip_in = k == 0 || (x.lli & core::kLliLossOfLock) != 0;
          EXPECT_EQ((y->lli & core::kLliLossOfLock) != 0, slip_in)
              << "epoch " << k << " " << a.sat.to_string() << " " << x.code.to_string();
          EXPECT_EQ((y->lli & core::kLliHalfCycle) != 0, (x.lli & core::kLliHalfCycle) != 0);
        }
      }
    }
    // The integer phase offset stays constant within an arc.
    const core::SignalCode l2w{'2', 'W'};
    const double d1 = in[1].sats[0].find(l2w)->carrier_phase_cyc - out[1].sats[0].find(l2w)->carrier_phase_cyc;
    const double d2 = in[2].sats[0].find(l2w)->carrier_phase_cyc - out[2].sats[0].find(l2w)->carrier_phase_cyc;
    EXPECT_NEAR(d1, d2, 1e-3);
  }
}

TEST(Rtcm3Codec, StationAndEphemerisMessagesThroughTheDecoder) {
  Rtcm3EncoderOptions eo;
  eo.station_id = 7;
  Rtcm3Encoder encoder(eo);
  rtcm3::StationPosition station;
  station.arp_E_m = {3e6, 4e6, 3e6};
  auto f1005 = encoder.encode_station(station);
  ASSERT_TRUE(f1005.ok());
  const GpsTime toe{2176, 288000.0};
  auto f1019 = encoder.encode_ephemeris(typical_kepler({Constellation::Gps, 5}, toe));
  ASSERT_TRUE(f1019.ok());
  Rtcm3DecoderOptions dopt;
  dopt.reference_time = toe;
  Rtcm3Decoder decoder(dopt);
  for (const auto* f : {&*f1005, &*f1019, &*f1019}) {
    StreamFramer framer;
    framer.push(f->bytes);
    auto p = framer.next();
    ASSERT_TRUE(p);
    auto m = decoder.decode(p->payload());
    ASSERT_TRUE(m.ok());
  }
  ASSERT_TRUE(decoder.station());
  EXPECT_EQ(decoder.station()->station_id, 7);
  EXPECT_EQ(decoder.navigation().kepler.size(), 1U);  // the repeated ephemeris is kept once
  EXPECT_EQ(decoder.message_counts().at(1019), 2U);
}

}  // namespace
}  // namespace canyon::io
