// RTCM 3 and UBX against RTKLIB 2.4.3 (Debian) as a real peer, on the shared datasets:
//  - RINEX -> `canyon convert` (RTCM 3 MSM7, MSM4) -> RTKLIB `convbin` -> RINEX equals the original within the MSM
//    resolution, for every satellite and signal RTCM can name, with the phase up to a constant integer per arc;
//  - RTKLIB `str2str` turns the u-blox logs of m8p-galway-20181004 into RTCM 3 (MSM7, 1005, ephemerides), and
//    canyon's decoding of that stream equals RTKLIB's own conversion of it;
//  - canyon's UBX decoding of those logs gives the observations and ephemerides of the RINEX files RTKLIB made of
//    them.

#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include "canyon/io/gnss_stream.hpp"
#include "canyon/io/rinex_nav.hpp"
#include "canyon/io/rinex_obs.hpp"

#include "obs_compare.hpp"
#include "test_support.hpp"

namespace canyon {
namespace {

namespace fs = std::filesystem;
using test::shared_data;

const std::string kCanyon = CANYON_BINARY;

#define SKIP_WITHOUT(path, what)                                                         \
  if (!fs::exists(path)) {                                                               \
    GTEST_SKIP() << (what) << " not found at " << (path) << " (shared datasets absent)"; \
  }                                                                                      \
  if (test::run_command("command -v convbin && command -v str2str").exit_code != 0) {    \
    GTEST_SKIP() << "RTKLIB (convbin, str2str) not installed: apt-get install rtklib";   \
  }

std::string describe(const test::ObsComparison& c) {
  std::string text = "epochs " + std::to_string(c.epochs_matched) + "/" + std::to_string(c.epochs_a) + " (b has " +
                     std::to_string(c.epochs_b) + "); values";
  for (const auto& [kind, n] : c.values) {
    char buffer[96];
    std::snprintf(buffer, sizeof buffer, " %c %d (max %.5f)", kind, n, c.max_diff.at(kind));
    text += buffer;
  }
  text += "; missing";
  for (const auto& [k, n] : c.missing) text += " [" + k + "] " + std::to_string(n);
  text += "; extra";
  for (const auto& [k, n] : c.extra) text += " [" + k + "] " + std::to_string(n);
  text += "; slips lost " + std::to_string(c.slips_lost) + " added " + std::to_string(c.slips_added) +
          " (first epoch " + std::to_string(c.slips_added_first_epoch) + "), half-cycle mismatches " +
          std::to_string(c.half_cycle_mismatches) + ", arc offset changes " + std::to_string(c.arc_offset_changes);
  for (const std::string& e : c.examples) text += "\n  " + e;
  return text;
}

io::RinexObsFile read_obs(const fs::path& path) {
  auto file = io::read_rinex_obs(path.string());
  EXPECT_TRUE(file.ok()) << (file.ok() ? "" : file.error().to_string());
  return file.ok() ? std::move(file).value() : io::RinexObsFile{};
}

core::NavigationData read_nav(const fs::path& path) {
  auto file = io::read_rinex_nav(path.string());
  EXPECT_TRUE(file.ok()) << (file.ok() ? "" : file.error().to_string());
  return file.ok() ? file->nav : core::NavigationData{};
}

// -------------------------------------------------------------------------------------------------------------------
// RINEX -> canyon RTCM 3 -> RTKLIB convbin -> RINEX.

struct RoundTripCase {
  const char* name;
  const char* obs;
  const char* nav;
  const char* approx_time;  // convbin -tr
  int msm;
};

void PrintTo(const RoundTripCase& c, std::ostream* os) {
  *os << c.name << " MSM" << c.msm;
}

class RinexThroughConvbin : public ::testing::TestWithParam<RoundTripCase> {};

TEST_P(RinexThroughConvbin, EqualsTheOriginalWithinMsmResolution) {
  const RoundTripCase& c = GetParam();
  const fs::path obs = shared_data() / c.obs;
  SKIP_WITHOUT(obs, "observation file");
  const fs::path dir = test::temp_dir(std::string("rtcm_convbin_") + c.name + "_msm" + std::to_string(c.msm));
  const fs::path rtcm = dir / "stream.rtcm3";
  const auto made =
      test::run_command(kCanyon + " convert " + obs.string() + " --nav " + (shared_data() / c.nav).string() +
                        " --out " + rtcm.string() + " --station-id 17 --msm " + std::to_string(c.msm));
  ASSERT_EQ(made.exit_code, 0) << made.output;
  std::cout << "[ canyon   ] " << made.output;
  const auto decoded =
      test::run_command("convbin -r rtcm3 -tr \"" + std::string(c.approx_time) + "\" -v 3.04 -od -os -o " +
                        (dir / "rtklib.obs").string() + " -n " + (dir / "rtklib.nav").string() + " " + rtcm.string());
  ASSERT_EQ(decoded.exit_code, 0) << decoded.output;
  const io::RinexObsFile original = read_obs(obs);
  const io::RinexObsFile back = read_obs(dir / "rtklib.obs");
  test::ObsTolerances tol;
  if (c.msm == 7) {
    // MSM7: pseudorange 2^-29 ms (0.28 mm half step), phase 2^-31 ms, rate 0.1 mm/s, CNR 1/16 dB-Hz; plus the RINEX
    // rounding of the original (0.5 mm, 0.0005 cycle / Hz) and of RTKLIB's file.
    tol.pseudorange_m = 0.0011;
    tol.phase_cyc = 0.0015;
    tol.doppler_hz = 0.0015;
    tol.snr_dbhz = 1.0 / 32 + 0.001;
  } else {
    // MSM4: pseudorange 2^-24 ms (9 mm half step), phase 2^-29 ms (0.28 mm), CNR 1 dB-Hz; no Doppler.
    tol.pseudorange_m = 0.0101;
    tol.phase_cyc = 0.003;
    tol.snr_dbhz = 0.5 + 0.001;
  }
  const test::ObsComparison r = test::compare_obs(original.epochs, back.epochs, tol);
  std::cout << "[ compared ] " << describe(r) << "\n";
  EXPECT_EQ(r.epochs_matched, r.epochs_a);
  EXPECT_EQ(r.epochs_b, r.epochs_a);
  EXPECT_EQ(r.total_out_of_tolerance(), 0);
  EXPECT_EQ(r.arc_offset_changes, 0);
  EXPECT_EQ(r.slips_lost, 0);
  EXPECT_EQ(r.slips_added, 0);  // lock time 0 at a signal's first epoch is a loss of lock for RTKLIB: allowed
  EXPECT_EQ(r.half_cycle_mismatches, 0);
  EXPECT_TRUE(r.extra.empty());
  // Missing: only what RTCM cannot carry (QZSS L1 SAIF "1Z"; the proprietary "X1" type is no signal), MSM4's
  // Doppler, and Doppler values further than 1.6 m/s from the satellite's first signal (MSM7 fine-rate field).
  int doppler_out_of_field = 0;
  for (const auto& [key, n] : r.missing) {
    if (key.find(" 1Z ") != std::string::npos || key.find(" X1") != std::string::npos) continue;
    if (key.back() == 'D') {
      if (c.msm == 7) doppler_out_of_field += n;
      continue;
    }
    ADD_FAILURE() << "missing " << key << ": " << n;
  }
  EXPECT_LE(doppler_out_of_field, 1);
  // Ephemerides: what RTKLIB decoded equals the navigation file's records.
  const core::NavigationData nav_in = read_nav(shared_data() / c.nav);
  const core::NavigationData nav_back = read_nav(dir / "rtklib.nav");
  const test::NavComparison n = test::compare_nav(nav_back, nav_in, 1e-9);
  std::cout << "[ nav      ] RTKLIB decoded " << n.records_a << " ephemerides, " << n.matched << " match the input, "
            << n.mismatched << " differ\n";
  EXPECT_GT(n.records_a, 0);
  EXPECT_EQ(n.matched, n.records_a);
  EXPECT_EQ(n.mismatched, 0);
  for (const auto& e : n.examples) std::cout << "  " << e << "\n";
}

INSTANTIATE_TEST_SUITE_P(
    Datasets, RinexThroughConvbin,
    ::testing::Values(RoundTripCase{"cssrlib_static_base", "cssrlib-static-doy078/3034078M1.21O",
                                    "cssrlib-static-doy078/SEPT078M.21P", "2021/03/19 12:00:00", 7},
                      RoundTripCase{"cssrlib_static_rover", "cssrlib-static-doy078/SEPT078M1.21O",
                                    "cssrlib-static-doy078/SEPT078M.21P", "2021/03/19 12:00:00", 7},
                      RoundTripCase{"matrtklib_base", "matrtklib-static/base.obs", "matrtklib-static/base.nav",
                                    "2024/06/24 08:20:00", 7},
                      RoundTripCase{"matrtklib_rover", "matrtklib-static/rover.obs", "matrtklib-static/base.nav",
                                    "2024/06/24 08:20:00", 7},
                      RoundTripCase{"cssrlib_kinematic_base", "cssrlib-kinematic-doy265/3034265G.21O",
                                    "cssrlib-kinematic-doy265/SEPT2650.21P", "2021/09/22 06:30:00", 7},
                      RoundTripCase{"cssrlib_kinematic_rover", "cssrlib-kinematic-doy265/SEPT265G.21O",
                                    "cssrlib-kinematic-doy265/SEPT2650.21P", "2021/09/22 06:30:00", 7},
                      RoundTripCase{"matrtklib_base", "matrtklib-static/base.obs", "matrtklib-static/base.nav",
                                    "2024/06/24 08:20:00", 4},
                      RoundTripCase{"cssrlib_static_base", "cssrlib-static-doy078/3034078M1.21O",
                                    "cssrlib-static-doy078/SEPT078M.21P", "2021/03/19 12:00:00", 4}),
    [](const ::testing::TestParamInfo<RoundTripCase>& info) {
      return std::string(info.param.name) + "_msm" + std::to_string(info.param.msm);
    });

// -------------------------------------------------------------------------------------------------------------------
// u-blox logs: canyon's UBX decoding against RTKLIB's RINEX of them, and str2str's RTCM 3 of them.

const char* const kM8p = "m8p-galway-20181004";

struct UbxLog {
  const char* name;
  const char* ubx;
  const char* obs;
  const char* nav;
};
const UbxLog kRover{"rover", "20181004_rover-20181004-1532.ubx.gz", "rinex/20181004_rover-20181004-1532.obs",
                    "rinex/20181004_rover-20181004-1532.nav"};
const UbxLog kBase{"base", "20181004_base-20181004-1452.ubx.gz", "rinex/20181004_base-20181004-1452.obs",
                   "rinex/20181004_base-20181004-1452.nav"};

struct Decoded {
  std::vector<core::ObsEpoch> epochs;
  core::NavigationData nav;
  io::GnssStreamStats stats;
};

Decoded decode_file(const fs::path& path, io::StreamFormat format, const core::GpsTime& approx) {
  Decoded d;
  auto bytes = io::read_binary_file(path.string());
  EXPECT_TRUE(bytes.ok()) << (bytes.ok() ? "" : bytes.error().to_string());
  if (!bytes) return d;
  io::GnssStreamOptions o;
  o.format = format;
  o.rtcm3.reference_time = approx;
  io::GnssStreamDecoder decoder(o);
  decoder.push(*bytes);
  decoder.finish();
  while (auto e = format == io::StreamFormat::Ubx ? decoder.pop_ubx_epoch() : decoder.pop_rtcm3_epoch()) {
    d.epochs.push_back(std::move(*e));
  }
  d.nav = decoder.navigation();
  d.stats = decoder.stats();
  return d;
}

const core::GpsTime kM8pTime{2021, 4 * 86400.0 + 15.5 * 3600.0};  // 2018-10-04 15:30 GPST

TEST(UbxRtklib, RoverLogDecodesToRtklibsRinex) {
  const fs::path dir = shared_data() / kM8p;
  SKIP_WITHOUT(dir / kRover.ubx, "u-blox log");
  const Decoded d = decode_file(dir / kRover.ubx, io::StreamFormat::Ubx, kM8pTime);
  const io::RinexObsFile rtklib = read_obs(dir / kRover.obs);
  test::ObsTolerances tol;
  tol.pseudorange_m = tol.phase_cyc = tol.doppler_hz = tol.snr_dbhz = 0.0006;  // RINEX rounding only
  tol.phase_integer_per_arc = false;
  const test::ObsComparison r = test::compare_obs(rtklib.epochs, d.epochs, tol);
  std::cout << "[ compared ] " << describe(r) << "\n";
  EXPECT_EQ(r.epochs_matched, 1180);
  EXPECT_EQ(r.epochs_b, 1180);
  EXPECT_EQ(r.total_out_of_tolerance(), 0);
  EXPECT_TRUE(r.missing.empty());
  EXPECT_TRUE(r.extra.empty());
  EXPECT_EQ(r.slips_lost + r.slips_added + r.slips_added_first_epoch + r.half_cycle_mismatches, 0);
  const test::NavComparison n = test::compare_nav(read_nav(dir / kRover.nav), d.nav);
  std::cout << "[ nav      ] RTKLIB " << n.records_a << " ephemerides, canyon " << n.records_b << ", matched "
            << n.matched << ", differing " << n.mismatched << "\n";
  EXPECT_EQ(n.records_a, n.records_b);
  EXPECT_EQ(n.matched, n.records_a);
  EXPECT_EQ(n.mismatched, 0);
  // The ionosphere of subframe 4 page 18, in RTKLIB's navigation header.
  const core::NavigationData rtklib_nav = read_nav(dir / kRover.nav);
  ASSERT_TRUE(rtklib_nav.gps_klobuchar && d.nav.gps_klobuchar);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(d.nav.gps_klobuchar->alpha[i], rtklib_nav.gps_klobuchar->alpha[i],
                1e-3 * std::abs(rtklib_nav.gps_klobuchar->alpha[i]));  // RTKLIB prints 4 digits
    EXPECT_NEAR(d.nav.gps_klobuchar->beta[i], rtklib_nav.gps_klobuchar->beta[i],
                1e-3 * std::abs(rtklib_nav.gps_klobuchar->beta[i]));
  }
}

TEST(UbxRtklib, CorruptBaseLogDecodesEveryRtklibEpochAndMore) {
  const fs::path dir = shared_data() / kM8p;
  SKIP_WITHOUT(dir / kBase.ubx, "u-blox log");
  const Decoded d = decode_file(dir / kBase.ubx, io::StreamFormat::Ubx, kM8pTime);
  const io::RinexObsFile rtklib = read_obs(dir / kBase.obs);
  test::ObsTolerances tol;
  tol.pseudorange_m = tol.phase_cyc = tol.doppler_hz = tol.snr_dbhz = 0.0006;
  tol.phase_integer_per_arc = false;
  const test::ObsComparison r = test::compare_obs(rtklib.epochs, d.epochs, tol);
  std::cout << "[ compared ] " << describe(r) << "\n";
  const auto& f = d.stats.framing;
  std::cout << "[ framing  ] " << f.ubx_packets << " UBX packets, " << f.ubx_bad_checksum << " bad checksums, "
            << f.garbage_bytes << " garbage bytes of " << f.bytes << "\n";
  // The log is corrupt (logging gaps, broken packets): canyon resynchronises at the byte after a failed checksum and
  // so finds packets RTKLIB skips; every epoch RTKLIB has is among canyon's, with the same values.
  EXPECT_EQ(r.epochs_matched, r.epochs_a);
  EXPECT_EQ(r.epochs_a, 763);
  EXPECT_GT(r.epochs_b, r.epochs_a);
  EXPECT_EQ(r.total_out_of_tolerance(), 0);
  EXPECT_TRUE(r.missing.empty());
  EXPECT_TRUE(r.extra.empty());
  EXPECT_GT(f.ubx_bad_checksum, 0U);
  // Loss of lock over the windows between RTKLIB's epochs: every slip RTKLIB flags, canyon flags in the same
  // window; canyon flags more only where it has epochs RTKLIB lost (it saw the lock time drop there).
  const test::SlipWindows w = test::compare_slip_windows(rtklib.epochs, d.epochs);
  std::cout << "[ slips    ] windows " << w.windows << ", agree " << w.agree << ", lost " << w.lost
            << ", added where canyon has more epochs " << w.added_seen_in_extra_epochs << ", added " << w.added << "\n";
  EXPECT_EQ(w.lost, 0);
  // One window with the same epochs where canyon flags a slip RTKLIB does not: R11 at 15:51:09.991 returns after a
  // gap with a u-blox lock time of 2.2 s, shorter than its lock time before the gap.
  EXPECT_LE(w.added, 1);
  const test::NavComparison n = test::compare_nav(read_nav(dir / kBase.nav), d.nav);
  std::cout << "[ nav      ] RTKLIB " << n.records_a << " ephemerides, canyon " << n.records_b << ", matched "
            << n.matched << ", differing " << n.mismatched << "\n";
  EXPECT_EQ(n.matched, n.records_a);
  EXPECT_EQ(n.mismatched, 0);
}

/// Runs str2str on a u-blox log until it has read all of it; the RTCM 3 stream (messages `msg`) it wrote.
fs::path str2str_rtcm(const fs::path& ubx_gz, const fs::path& dir,
                      const std::string& msg = "1077,1087,1117,1005(10),1019,1020,1044") {
  auto bytes = io::read_binary_file(ubx_gz.string());
  EXPECT_TRUE(bytes.ok());
  const fs::path ubx = dir / "log.ubx";
  std::ofstream(ubx, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes->data()), static_cast<std::streamsize>(bytes->size()));
  fs::path out = dir / "str2str.rtcm3";
  const fs::path log = dir / "str2str.log";
  fs::remove(log);  // polled below: a log of an earlier run would stop str2str at once
  // str2str does not exit at the end of a file: stop it once it reports the input ended.
  const std::string command = "bash -c 'str2str -in \"file://" + ubx.string() + "#ubx\" -out \"file://" + out.string() +
                              "#rtcm3\" -msg \"" + msg + "\" -p 53.2804778 -9.0578437 79.05 2> " + log.string() +
                              " & pid=$!; for i in $(seq 1 600); do grep -q \" end\" " + log.string() +
                              " && break; sleep 0.1; done; kill -INT $pid; wait $pid; true'";
  const auto run = test::run_command(command);
  EXPECT_EQ(run.exit_code, 0) << run.output;
  return out;
}

TEST(Str2strRtklib, UbxLogThroughStr2strDecodesLikeConvbin) {
  const fs::path dir = shared_data() / kM8p;
  SKIP_WITHOUT(dir / kRover.ubx, "u-blox log");
  const fs::path tmp = test::temp_dir("str2str_rover");
  const fs::path rtcm = str2str_rtcm(dir / kRover.ubx, tmp);
  ASSERT_GT(fs::file_size(rtcm), 100000U);
  // RTKLIB's own conversion of the stream, and canyon's (through the command, which dates the stream from its GPS
  // ephemerides: no --time).
  const auto rtk =
      test::run_command("convbin -r rtcm3 -tr \"2018/10/04 15:30:00\" -v 3.04 -od -os -o " +
                        (tmp / "rtklib.obs").string() + " -n " + (tmp / "rtklib.nav").string() + " " + rtcm.string());
  ASSERT_EQ(rtk.exit_code, 0) << rtk.output;
  const auto can = test::run_command(kCanyon + " convert " + rtcm.string() + " --obs-out " +
                                     (tmp / "canyon.obs").string() + " --nav-out " + (tmp / "canyon.nav").string());
  ASSERT_EQ(can.exit_code, 0) << can.output;
  std::cout << "[ canyon   ] " << can.output;
  const io::RinexObsFile rtklib = read_obs(tmp / "rtklib.obs");
  const io::RinexObsFile canyon = read_obs(tmp / "canyon.obs");
  test::ObsTolerances tol;
  tol.pseudorange_m = tol.phase_cyc = tol.doppler_hz = 0.0011;  // last printed digit
  tol.snr_dbhz = 0.0011;
  tol.phase_integer_per_arc = false;
  // RTKLIB 2.4.3 writes LLI = loss of lock + 3 when an MSM cell's half-cycle bit is set (3: half cycle only, 4 or 5:
  // both): compare the half-cycle bit here, and the loss of lock against the receiver's own log below.
  const auto rtklib_lli = [](std::uint8_t lli) -> std::uint8_t {
    return lli >= 3 ? core::kLliHalfCycle : static_cast<std::uint8_t>(lli & 1);
  };
  std::vector<core::ObsEpoch> rtklib_epochs = rtklib.epochs;
  for (auto& e : rtklib_epochs) {
    for (auto& s : e.sats) {
      for (auto& g : s.signals) g.lli = rtklib_lli(g.lli);
    }
  }
  std::vector<core::ObsEpoch> canyon_half_only = canyon.epochs;
  for (auto& e : canyon_half_only) {
    for (auto& s : e.sats) {
      for (auto& g : s.signals) g.lli &= core::kLliHalfCycle;
    }
  }
  for (auto& e : rtklib_epochs) {
    for (auto& s : e.sats) {
      for (auto& g : s.signals) g.lli &= core::kLliHalfCycle;
    }
  }
  const test::ObsComparison r = test::compare_obs(rtklib_epochs, canyon_half_only, tol);
  std::cout << "[ compared ] " << describe(r) << "\n";
  EXPECT_EQ(r.epochs_matched, 1180);
  EXPECT_EQ(r.epochs_b, 1180);
  EXPECT_EQ(r.total_out_of_tolerance(), 0);
  EXPECT_TRUE(r.missing.empty());
  EXPECT_TRUE(r.extra.empty());
  EXPECT_EQ(r.half_cycle_mismatches, 0);
  // Loss of lock against the receiver: RTKLIB's RINEX of the UBX log that str2str read.
  const io::RinexObsFile receiver = read_obs(dir / kRover.obs);
  test::ObsTolerances loose;
  loose.pseudorange_m = loose.doppler_hz = loose.snr_dbhz = 1.0;
  loose.phase_cyc = 0.01;
  const test::ObsComparison slips = test::compare_obs(receiver.epochs, canyon.epochs, loose);
  std::cout << "[ slips    ] vs the receiver log: lost " << slips.slips_lost << ", added " << slips.slips_added
            << " of " << slips.values.at('L') << " phases\n";
  EXPECT_EQ(slips.slips_lost, 0);
  EXPECT_EQ(slips.slips_added, 0);
  // Ephemerides: the same records as RTKLIB's conversion.
  const test::NavComparison n = test::compare_nav(read_nav(tmp / "rtklib.nav"), read_nav(tmp / "canyon.nav"));
  std::cout << "[ nav      ] RTKLIB " << n.records_a << " ephemerides, canyon " << n.records_b << ", matched "
            << n.matched << ", differing " << n.mismatched << "\n";
  EXPECT_GT(n.records_a, 0);
  EXPECT_EQ(n.records_a, n.records_b);
  EXPECT_EQ(n.matched, n.records_a);
  EXPECT_EQ(n.mismatched, 0);
  // RTKLIB 2.4.3 b34's str2str writes no 1005 from a UBX input (-p, -px and -sta tried): 1005 is checked against
  // the standard's example (tests/io) and the receiver's own 1005 below.
}

TEST(Str2strRtklib, LegacyMessagesDecodeLikeConvbin) {
  // 1004 (GPS) and 1012 (GLONASS): the phase-range field wraps by 1500 cycles around the L1 pseudorange.
  const fs::path dir = shared_data() / kM8p;
  SKIP_WITHOUT(dir / kRover.ubx, "u-blox log");
  const fs::path tmp = test::temp_dir("str2str_legacy");
  const fs::path rtcm = str2str_rtcm(dir / kRover.ubx, tmp, "1004,1012,1019,1020");
  const auto rtk =
      test::run_command("convbin -r rtcm3 -tr \"2018/10/04 15:30:00\" -v 3.04 -od -os -o " +
                        (tmp / "rtklib.obs").string() + " -n " + (tmp / "rtklib.nav").string() + " " + rtcm.string());
  ASSERT_EQ(rtk.exit_code, 0) << rtk.output;
  const auto can = test::run_command(kCanyon + " convert " + rtcm.string() + " --obs-out " +
                                     (tmp / "canyon.obs").string() + " --nav-out " + (tmp / "canyon.nav").string());
  ASSERT_EQ(can.exit_code, 0) << can.output;
  std::cout << "[ canyon   ] " << can.output;
  test::ObsTolerances tol;
  tol.pseudorange_m = tol.phase_cyc = tol.doppler_hz = tol.snr_dbhz = 0.0011;
  tol.phase_integer_per_arc = false;  // the same phase, not only up to an integer
  const test::ObsComparison r =
      test::compare_obs(read_obs(tmp / "rtklib.obs").epochs, read_obs(tmp / "canyon.obs").epochs, tol);
  std::cout << "[ compared ] " << describe(r) << "\n";
  EXPECT_EQ(r.epochs_matched, 1180);
  EXPECT_EQ(r.epochs_b, 1180);
  EXPECT_EQ(r.total_out_of_tolerance(), 0);
  EXPECT_TRUE(r.missing.empty());
  EXPECT_TRUE(r.extra.empty());
  EXPECT_EQ(r.slips_lost + r.slips_added + r.slips_added_first_epoch, 0);
}

TEST(UbxRtklib, BaseReceiversOwnRtcmDecodesLikeConvbin) {
  // The M8P base logged its own RTCM 3 output (1005, 1077, 1087, 1230) between its UBX packets, with corruption.
  const fs::path dir = shared_data() / kM8p;
  SKIP_WITHOUT(dir / kBase.ubx, "u-blox log");
  const fs::path tmp = test::temp_dir("base_rtcm");
  auto bytes = io::read_binary_file((dir / kBase.ubx).string());
  ASSERT_TRUE(bytes.ok());
  const fs::path log = tmp / "base.ubx";
  std::ofstream(log, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes->data()), static_cast<std::streamsize>(bytes->size()));
  const auto rtk =
      test::run_command("convbin -r rtcm3 -tr \"2018/10/04 15:00:00\" -v 3.04 -od -os -o " +
                        (tmp / "rtklib.obs").string() + " -n " + (tmp / "rtklib.nav").string() + " " + log.string());
  ASSERT_EQ(rtk.exit_code, 0) << rtk.output;
  const auto can =
      test::run_command(kCanyon + " convert " + log.string() + " --from rtcm3 --time \"2018-10-04 15:00:00\" " +
                        "--obs-out " + (tmp / "canyon.obs").string() + " --nav-out " + (tmp / "canyon.nav").string());
  ASSERT_EQ(can.exit_code, 0) << can.output;
  std::cout << "[ canyon   ] " << can.output;
  const io::RinexObsFile rtklib = read_obs(tmp / "rtklib.obs");
  const io::RinexObsFile canyon = read_obs(tmp / "canyon.obs");
  // 1005 position.
  ASSERT_TRUE(canyon.header.receiver.approx_position_E_m.has_value());
  ASSERT_TRUE(rtklib.header.receiver.approx_position_E_m.has_value());
  EXPECT_LT((*canyon.header.receiver.approx_position_E_m - *rtklib.header.receiver.approx_position_E_m).norm(), 1e-4);
  test::ObsTolerances tol;
  tol.pseudorange_m = tol.phase_cyc = tol.doppler_hz = tol.snr_dbhz = 0.0011;
  tol.phase_integer_per_arc = false;
  // RTKLIB dates its first epoch a day early (a GLONASS message before any GPS one): leave it out.
  std::vector<core::ObsEpoch> reference(rtklib.epochs.begin() + 1, rtklib.epochs.end());
  const test::ObsComparison r = test::compare_obs(reference, canyon.epochs, tol);
  std::cout << "[ compared ] " << describe(r) << "\n";
  EXPECT_EQ(r.epochs_matched, r.epochs_a);
  EXPECT_GT(r.epochs_b, r.epochs_a);
  EXPECT_EQ(r.total_out_of_tolerance(), 0);
  EXPECT_TRUE(r.missing.empty());
  // Loss of lock is reported, not asserted: RTKLIB misses frames of this corrupt stream and decodes lock times with
  // its own rule (0 twice, or decreasing, including cells without phase).
  const test::SlipWindows w = test::compare_slip_windows(reference, canyon.epochs);
  std::cout << "[ slips    ] windows " << w.windows << ", agree " << w.agree << ", lost " << w.lost
            << ", added where canyon has more epochs " << w.added_seen_in_extra_epochs << ", added " << w.added << "\n";
  EXPECT_EQ(w.lost, 0);
  EXPECT_GT(w.agree, w.windows * 99 / 100);
}

}  // namespace
}  // namespace canyon
