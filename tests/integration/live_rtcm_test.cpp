// Live RTCM 3 over the network with RTKLIB 2.4.3 as the peer, real processes on loopback with free ports:
//  - canyon-base replays a base RINEX and serves it by NTRIP; RTKLIB `str2str` pulls the mount point, and what it
//    pulled decodes with RTKLIB `convbin` to the base's observations (within MSM7 resolution);
//  - RTKLIB `str2str` acts as the NTRIP caster (fed by canyon-base's TCP output) and canyon's NTRIP client
//    (`canyon convert ntrip://...`) pulls from it the same observations;
//  - the RTK solution computed with the base observations that travelled through RTCM equals the one computed from
//    the base RINEX, within 1 mm at every epoch.
// Each test takes a few seconds (the base replays at 20 times real time).

#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include "canyon/io/pos_file.hpp"
#include "canyon/io/rinex_obs.hpp"

#include "obs_compare.hpp"
#include "test_support.hpp"

namespace canyon {
namespace {

namespace fs = std::filesystem;
using test::shared_data;

const std::string kCanyon = CANYON_BINARY;
const std::string kBase = CANYON_BASE_BINARY;
constexpr double kMaxRtkDifferenceM = 0.001;

const char* const kData = "cssrlib-static-doy078";
const char* const kBaseObs = "3034078M1.21O";
const char* const kRoverObs = "SEPT078M1.21O";
const char* const kNav = "SEPT078M.21P";

#define SKIP_WITHOUT_PEERS()                                                           \
  if (!fs::exists(shared_data() / kData / kBaseObs)) {                                 \
    GTEST_SKIP() << "shared datasets not found at " << shared_data();                  \
  }                                                                                    \
  if (test::run_command("command -v convbin && command -v str2str").exit_code != 0) {  \
    GTEST_SKIP() << "RTKLIB (convbin, str2str) not installed: apt-get install rtklib"; \
  }

/// A base configuration replaying the dataset's base at 20x, NTRIP on a free port, TCP optional, no DDS.
fs::path write_base_config(const fs::path& dir, bool tcp) {
  const fs::path data = shared_data() / kData;
  fs::path path = dir / "base.yaml";
  std::ofstream(path) << "station: {id: 3034, position: [-3959400.631, 3385704.533, 3667523.111]}\n"
                      << "input: {kind: rinex, source: file, path: " << (data / kBaseObs).string() << ", nav: ["
                      << (data / kNav).string() << "], pace: 20}\n"
                      << "outputs:\n"
                      << "  dds: {enabled: false}\n"
                      << "  ntrip: {enabled: true, bind: 127.0.0.1, port: 0, mountpoint: CANYON}\n"
                      << "  tcp: {enabled: " << (tcp ? "true" : "false") << ", bind: 127.0.0.1, port: 0}\n"
                      << "log: {progress_interval_s: 0}\n";
  return path;
}

/// A free TCP port on loopback (bound and released: a tiny race with other processes, acceptable in tests).
int free_port() {
  const auto r = test::run_command(
      "python3 -c \"import socket; s=socket.socket(); s.bind(('127.0.0.1',0)); print(s.getsockname()[1])\"");
  return std::atoi(r.output.c_str());
}

/// Runs a bash script (written to DIR/run.sh: no quoting through the shell of popen).
test::CommandResult run_script(const fs::path& dir, const std::string& script) {
  const fs::path path = dir / "run.sh";
  std::ofstream(path) << script << "\n";
  return test::run_command("bash " + path.string());
}

io::RinexObsFile read_obs(const fs::path& path) {
  auto file = io::read_rinex_obs(path.string());
  EXPECT_TRUE(file.ok()) << (file.ok() ? "" : file.error().to_string());
  return file.ok() ? std::move(file).value() : io::RinexObsFile{};
}

/// The base observations that arrived, against the base RINEX: every epoch, every signal RTCM names, MSM7 resolution.
void expect_base_observations(const fs::path& received) {
  const io::RinexObsFile original = read_obs(shared_data() / kData / kBaseObs);
  const io::RinexObsFile got = read_obs(received);
  test::ObsTolerances tol;
  tol.pseudorange_m = 0.0011;
  tol.phase_cyc = 0.0015;
  tol.doppler_hz = 0.0015;
  tol.snr_dbhz = 1.0 / 32 + 0.001;
  const test::ObsComparison r = test::compare_obs(original.epochs, got.epochs, tol);
  std::cout << "[ received ] epochs " << r.epochs_matched << "/" << r.epochs_a << ", out of tolerance "
            << r.total_out_of_tolerance() << ", slips lost " << r.slips_lost << "\n";
  EXPECT_EQ(r.epochs_matched, r.epochs_a);
  EXPECT_EQ(r.epochs_b, r.epochs_a);
  EXPECT_EQ(r.total_out_of_tolerance(), 0);
  EXPECT_EQ(r.arc_offset_changes, 0);
  EXPECT_EQ(r.slips_lost, 0);
  for (const auto& [key, n] : r.missing) EXPECT_NE(key.find(" 1Z "), std::string::npos) << key << ": " << n;
}

TEST(LiveRtcm, CanyonBaseServesNtripToStr2str) {
  SKIP_WITHOUT_PEERS();
  const fs::path dir = test::temp_dir("live_base_str2str");
  const fs::path config = write_base_config(dir, false);
  const fs::path pulled = dir / "pulled.rtcm3";
  fs::remove(pulled);
  // The script polls base.log for the caster's port: a log left by an earlier run must not answer first (the base's
  // own redirection truncates it only once its process has started).
  fs::remove(dir / "base.log");
  // canyon-base waits for one client, str2str pulls the mount point (NTRIP 1) into a file.
  const std::string script =
      "cd " + dir.string() + "; " + kBase +
      " --config base.yaml --wait-for-clients 1 --wait-timeout 20 > base.log 2>&1 & " +
      "bpid=$!; for i in $(seq 1 100); do grep -q 'NTRIP caster on' base.log && break; sleep 0.1; done; " +
      "port=$(grep -o 'NTRIP caster on [0-9.]*:[0-9]*' base.log | sed 's/.*://'); " +
      "str2str -in ntrip://127.0.0.1:$port/CANYON#rtcm3 -out file://" + pulled.string() + " 2> str2str.log & " +
      "spid=$!; wait $bpid; brc=$?; sleep 0.5; kill -INT $spid; wait $spid; exit $brc";
  const auto run = run_script(dir, script);
  std::ifstream log(dir / "base.log");
  const std::string base_log((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  ASSERT_EQ(run.exit_code, 0) << run.output << base_log;
  EXPECT_NE(base_log.find("connected to /CANYON (NTRIP 1, NTRIP RTKLIB"), std::string::npos) << base_log;
  ASSERT_TRUE(fs::exists(pulled));
  ASSERT_GT(fs::file_size(pulled), 60000U);
  // RTKLIB decodes what it pulled.
  const auto decoded =
      test::run_command("convbin -r rtcm3 -tr \"2021/03/19 12:00:00\" -v 3.04 -od -os -o " +
                        (dir / "rtklib.obs").string() + " -n " + (dir / "rtklib.nav").string() + " " + pulled.string());
  ASSERT_EQ(decoded.exit_code, 0) << decoded.output;
  expect_base_observations(dir / "rtklib.obs");

  // RTK with the base observations that travelled through canyon-base, NTRIP and str2str, decoded by canyon,
  // equals RTK with the base RINEX (GPS + Galileo: QZSS L1 SAIF has no RTCM id).
  const auto converted =
      test::run_command(kCanyon + " convert " + pulled.string() + " --obs-out " + (dir / "base_rtcm.obs").string() +
                        " --nav-out " + (dir / "base_rtcm.nav").string() + " -q");
  ASSERT_EQ(converted.exit_code, 0) << converted.output;
  std::ofstream(dir / "rtk.yaml") << "mode: rtk\nrtk: {systems: [G, E]}\n";
  const fs::path data = shared_data() / kData;
  const std::string common = kCanyon + " process --config " + (dir / "rtk.yaml").string() + " --rover " +
                             (data / kRoverObs).string() + " --nav " + (data / kNav).string() +
                             " --base-pos -3959400.631,3385704.533,3667523.111 --coordinates ecef -q";
  const auto from_rinex =
      test::run_command(common + " --base " + (data / kBaseObs).string() + " --out " + (dir / "rinex.pos").string());
  ASSERT_EQ(from_rinex.exit_code, 0) << from_rinex.output;
  const auto from_rtcm = test::run_command(common + " --base " + (dir / "base_rtcm.obs").string() + " --out " +
                                           (dir / "rtcm.pos").string());
  ASSERT_EQ(from_rtcm.exit_code, 0) << from_rtcm.output;
  auto a = io::read_pos_file((dir / "rinex.pos").string());
  auto b = io::read_pos_file((dir / "rtcm.pos").string());
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->size(), b->size());
  ASSERT_EQ(a->size(), 60U);
  double max_diff_m = 0.0;
  int fixed = 0;
  for (std::size_t k = 0; k < a->size(); ++k) {
    EXPECT_NEAR((*a)[k].time - (*b)[k].time, 0.0, 1e-6);
    EXPECT_EQ((*a)[k].status, (*b)[k].status) << "epoch " << k;
    max_diff_m = std::max(max_diff_m, ((*a)[k].p_E_m - (*b)[k].p_E_m).norm());
    if ((*a)[k].status == core::SolutionStatus::Fixed) ++fixed;
  }
  std::cout << "[ rtk      ] 60 epochs, " << fixed
            << " fixed; largest 3D difference RINEX vs RTCM base: " << max_diff_m * 1000.0
            << " mm (.pos resolution 0.1 mm)\n";
  EXPECT_LE(max_diff_m, kMaxRtkDifferenceM);
  EXPECT_GT(fixed, 50);
}

/// RTK on `rover` with `base` as RINEX and through canyon's RTCM 3 (MSM7; encoded and decoded by canyon): the largest
/// 3D difference of the solutions, and the numbers of epochs and fixes.
struct RtkComparison {
  double max_diff_m = 0.0;
  int epochs = 0;
  int fixed = 0;
  int status_differences = 0;
};
RtkComparison rtk_through_rtcm(const fs::path& dir, const fs::path& rover, const fs::path& base, const fs::path& nav,
                               const std::string& base_pos, const std::string& rtk_yaml) {
  RtkComparison c;
  const auto encoded = test::run_command(kCanyon + " convert " + base.string() + " --nav " + nav.string() + " --out " +
                                         (dir / "base.rtcm3").string() + " -q");
  EXPECT_EQ(encoded.exit_code, 0) << encoded.output;
  const auto decoded =
      test::run_command(kCanyon + " convert " + (dir / "base.rtcm3").string() + " --obs-out " +
                        (dir / "base_rtcm.obs").string() + " --nav-out " + (dir / "base_rtcm.nav").string() + " -q");
  EXPECT_EQ(decoded.exit_code, 0) << decoded.output;
  std::ofstream(dir / "rtk.yaml") << rtk_yaml;
  const std::string common = kCanyon + " process --config " + (dir / "rtk.yaml").string() + " --rover " +
                             rover.string() + " --nav " + nav.string() + " --base-pos " + base_pos +
                             " --coordinates ecef -q";
  const auto a_run = test::run_command(common + " --base " + base.string() + " --out " + (dir / "rinex.pos").string());
  const auto b_run = test::run_command(common + " --base " + (dir / "base_rtcm.obs").string() + " --out " +
                                       (dir / "rtcm.pos").string());
  EXPECT_EQ(a_run.exit_code, 0) << a_run.output;
  EXPECT_EQ(b_run.exit_code, 0) << b_run.output;
  auto a = io::read_pos_file((dir / "rinex.pos").string());
  auto b = io::read_pos_file((dir / "rtcm.pos").string());
  EXPECT_TRUE(a.ok() && b.ok());
  if (!a || !b) return c;
  EXPECT_EQ(a->size(), b->size());
  for (std::size_t k = 0; k < std::min(a->size(), b->size()); ++k) {
    EXPECT_NEAR((*a)[k].time - (*b)[k].time, 0.0, 1e-6);
    if ((*a)[k].status != (*b)[k].status) ++c.status_differences;
    c.max_diff_m = std::max(c.max_diff_m, ((*a)[k].p_E_m - (*b)[k].p_E_m).norm());
    if ((*a)[k].status == core::SolutionStatus::Fixed) ++c.fixed;
    ++c.epochs;
  }
  return c;
}

TEST(LiveRtcm, RtkThroughRtcmEqualsRtkFromRinexOnAMovingRover) {
  // Offline (no network): the kinematic dataset, continuous and instantaneous AR, float epochs included.
  const fs::path data = shared_data() / "cssrlib-kinematic-doy265";
  if (!fs::exists(data / "3034265G.21O")) GTEST_SKIP() << "shared datasets not found at " << shared_data();
  for (const std::string ar : {"continuous", "instantaneous"}) {
    const fs::path dir = test::temp_dir("rtk_through_rtcm_" + ar);
    const RtkComparison c = rtk_through_rtcm(dir, data / "SEPT265G.21O", data / "3034265G.21O", data / "SEPT2650.21P",
                                             "-3959400.631,3385704.533,3667523.111",
                                             "mode: rtk\nrtk: {systems: [G, E], ar_mode: " + ar + "}\n");
    std::cout << "[ rtk      ] " << ar << ": " << c.epochs << " epochs, " << c.fixed
              << " fixed; largest 3D difference RINEX vs RTCM base: " << c.max_diff_m * 1000.0
              << " mm; status differences " << c.status_differences << "\n";
    EXPECT_EQ(c.epochs, 360);
    EXPECT_EQ(c.status_differences, 0);
    EXPECT_LE(c.max_diff_m, kMaxRtkDifferenceM);
  }
  // m8p-galway: L1-only GPS + GLONASS, mostly float solutions (the float filter uses the pseudoranges).
  const fs::path m8p = shared_data() / "m8p-galway-20181004/rinex";
  if (!fs::exists(m8p)) {
    GTEST_SKIP() << "shared dataset not present: " << m8p << " (the L1-only GPS + GLONASS comparison was not made)";
  }
  const fs::path dir = test::temp_dir("rtk_through_rtcm_m8p");
  const RtkComparison c =
      rtk_through_rtcm(dir, m8p / "20181004_rover-20181004-1532.obs", m8p / "20181004_base-20181004-1452.obs",
                       m8p / "20181004_rover-20181004-1532.nav", "3774094.8387,-601664.2944,5089330.8699",
                       "mode: rtk\nrtk: {systems: [G, R], frequencies: 1}\n");
  std::cout << "[ rtk      ] m8p L1: " << c.epochs << " epochs, " << c.fixed
            << " fixed; largest 3D difference RINEX vs RTCM base: " << c.max_diff_m * 1000.0
            << " mm; status differences " << c.status_differences << "\n";
  EXPECT_EQ(c.epochs, 1180);
  EXPECT_EQ(c.status_differences, 0);
  EXPECT_LE(c.max_diff_m, kMaxRtkDifferenceM);
}

TEST(LiveRtcm, CanyonClientPullsFromStr2strCaster) {
  SKIP_WITHOUT_PEERS();
  const fs::path dir = test::temp_dir("live_str2str_caster");
  write_base_config(dir, true);
  const int caster_port = free_port();
  const int tcp_port = free_port();
  ASSERT_GT(caster_port, 0);
  ASSERT_GT(tcp_port, 0);
  // canyon-base (TCP output) -> str2str (TCP client in, NTRIP caster out) -> canyon convert ntrip://. The caster
  // drops what arrives before a client is connected: str2str and canyon's client start first, canyon-base last
  // (it waits for str2str's TCP connection, retried every 200 ms).
  const std::string script =
      "cd " + dir.string() + "; str2str -in tcpcli://127.0.0.1:" + std::to_string(tcp_port) +
      "#rtcm3 -out ntripc://:" + std::to_string(caster_port) + "/RTKLIB -r 200 2> str2str.log & spid=$!; sleep 0.3; " +
      kCanyon + " convert ntrip://127.0.0.1:" + std::to_string(caster_port) +
      "/RTKLIB --ntrip-version 2 --idle-timeout 2 --obs-out canyon.obs --nav-out canyon.nav > convert.log 2>&1 & " +
      "cpid=$!; sleep 1; " + kBase + " --config base.yaml --tcp-port " + std::to_string(tcp_port) +
      " --wait-for-clients 1 --wait-timeout 20 > base.log 2>&1; brc=$?; wait $cpid; crc=$?; kill -INT $spid; " +
      "wait $spid; [ $brc -eq 0 ] && exit $crc; exit $brc";
  const auto run = run_script(dir, script);
  std::ifstream log(dir / "convert.log");
  const std::string convert_log((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  ASSERT_EQ(run.exit_code, 0) << run.output << convert_log;
  std::cout << "[ canyon   ] " << convert_log;
  expect_base_observations(dir / "canyon.obs");
}

}  // namespace
}  // namespace canyon
