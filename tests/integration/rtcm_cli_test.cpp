// `canyon convert` and `canyon base` on bad input: every failure names what and where, exits non-zero, never hangs.

#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "test_support.hpp"

namespace canyon {
namespace {

namespace fs = std::filesystem;

const std::string kCanyon = CANYON_BINARY;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(RtcmCli, ConvertRefusesWhatItCannotRead) {
  const fs::path dir = test::temp_dir("rtcm_cli");
  // A missing file.
  auto missing = test::run_command(kCanyon + " convert " + (dir / "nope.rtcm3").string());
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_TRUE(contains(missing.output, "nope.rtcm3: cannot open file")) << missing.output;
  // Garbage: nothing decodable, counted.
  {
    std::ofstream garbage(dir / "garbage.bin", std::ios::binary);
    for (int i = 0; i < 100000; ++i) garbage.put(static_cast<char>((i * 7919 + 13) % 251));
  }
  auto garbage = test::run_command(kCanyon + " convert " + (dir / "garbage.bin").string());
  EXPECT_EQ(garbage.exit_code, 1) << garbage.output;
  EXPECT_TRUE(contains(garbage.output, "garbage.bin: no observations or ephemerides found (100000 bytes"))
      << garbage.output;
  // A dead address: the error names it, within a few seconds.
  auto dead = test::run_command(kCanyon + " convert tcp://127.0.0.1:1 --idle-timeout 1");
  EXPECT_EQ(dead.exit_code, 1) << dead.output;
  EXPECT_TRUE(contains(dead.output, "cannot connect to 127.0.0.1:1")) << dead.output;
  // Malformed URLs and options.
  auto url = test::run_command(kCanyon + " convert ntrip://host-without-port/MOUNT");
  EXPECT_EQ(url.exit_code, 1) << url.output;
  EXPECT_TRUE(contains(url.output, "is not tcp://HOST:PORT or ntrip://")) << url.output;
  auto time = test::run_command(kCanyon + " convert x.rtcm3 --time yesterday");
  EXPECT_EQ(time.exit_code, 2) << time.output;
  EXPECT_TRUE(contains(time.output, "--time must be 'YYYY-MM-DD HH:MM:SS'")) << time.output;
  auto rinex_stdin = test::run_command(kCanyon + " convert - --from rinex < /dev/null");
  EXPECT_EQ(rinex_stdin.exit_code, 2) << rinex_stdin.output;
}

TEST(RtcmCli, ConvertCutGzipKeepsWhatIsThere) {
  const fs::path log = test::shared_data() / "m8p-galway-20181004/20181004_rover-20181004-1532.ubx.gz";
  if (!fs::exists(log)) GTEST_SKIP() << "shared datasets not found at " << test::shared_data();
  const fs::path dir = test::temp_dir("rtcm_cli_cut");
  // The first 300 kB of the compressed log: gzip cut short, the last UBX packet cut too.
  {
    std::ifstream in(log, std::ios::binary);
    std::ofstream out(dir / "cut.ubx.gz", std::ios::binary);
    std::vector<char> buffer(300000);
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    out.write(buffer.data(), in.gcount());
  }
  auto r = test::run_command(kCanyon + " convert " + (dir / "cut.ubx.gz").string() + " --obs-out " +
                             (dir / "cut.obs").string() + " --nav-out " + (dir / "cut.nav").string() + " -v");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "compressed stream ended unexpectedly")) << r.output;
  EXPECT_TRUE(fs::exists(dir / "cut.obs"));
}

TEST(RtcmCli, BaseRefusesBadConfigurationAndMissingInput) {
  const fs::path dir = test::temp_dir("rtcm_cli_base");
  std::ofstream(dir / "typo.yaml") << "station:\n  id: 5\noutputs:\n  ntrip:\n    mountpont: X\n";
  auto typo = test::run_command(kCanyon + " base --config " + (dir / "typo.yaml").string());
  EXPECT_EQ(typo.exit_code, 2) << typo.output;
  EXPECT_TRUE(contains(typo.output, "typo.yaml:5: unknown key 'outputs.ntrip.mountpont'")) << typo.output;
  std::ofstream(dir / "rule.yaml") << "station: {id: 99999}\n";
  auto rule = test::run_command(kCanyon + " base --config " + (dir / "rule.yaml").string());
  EXPECT_EQ(rule.exit_code, 2) << rule.output;
  EXPECT_TRUE(contains(rule.output, "station.id must be within 0-4095")) << rule.output;
  std::ofstream(dir / "missing.yaml") << "input: {kind: rinex, path: nowhere.obs}\n"
                                      << "outputs: {dds: {enabled: false}, ntrip: {port: 0}}\n";
  auto missing = test::run_command(kCanyon + " base --config " + (dir / "missing.yaml").string());
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_TRUE(contains(missing.output, "nowhere.obs: cannot open file")) << missing.output;
}

}  // namespace
}  // namespace canyon
