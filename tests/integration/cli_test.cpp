// The `canyon` command run as a real process: exit codes and messages for good and bad input, including a rover
// file with one corrupt epoch in the middle (issue 3: a clear message, the epoch handled, processing continues).

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.hpp"

namespace canyon {
namespace {

namespace fs = std::filesystem;

test::CommandResult canyon(const std::string& args) {
  return test::run_command(std::string(CANYON_BINARY) + " " + args);
}

const fs::path kGsiRover = test::shared_data() / "rtklib-test-gsi-2005/07590920.05o";
const fs::path kGsiNav = test::shared_data() / "rtklib-test-gsi-2005/07590920.05n";
// 60 epochs at 1 Hz from 12:00:00 GPST; epoch i's line is 33 + 24 i (23 satellites each).
const fs::path kStaticDir = test::shared_data() / "cssrlib-static-doy078";
const fs::path kStaticRover = kStaticDir / "SEPT078M1.21O";
const fs::path kStaticBase = kStaticDir / "3034078M1.21O";
const fs::path kStaticNav = kStaticDir / "SEPT078M.21P";

TEST(CanyonCli, NoSubcommandIsAUsageError) {
  const auto r = canyon("");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("subcommand"), std::string::npos) << r.output;
}

TEST(CanyonCli, UnknownOptionIsAUsageError) {
  const auto r = canyon("process --bogus 3");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--bogus"), std::string::npos) << r.output;
}

TEST(CanyonCli, MissingInputsAreNamed) {
  const auto r = canyon("process --rover /nonexistent/rover.obs --nav /nonexistent/nav.n --out /tmp/x.pos");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("/nonexistent/nav.n"), std::string::npos) << r.output;
  const auto no_out = canyon("process --rover a.obs --nav b.nav");
  EXPECT_EQ(no_out.exit_code, 2);
  EXPECT_NE(no_out.output.find("solution file is required"), std::string::npos) << no_out.output;
}

TEST(CanyonCli, TopicToolsAreOneExecutableThatTheNameSelects) {
  // canyon-record and canyon-echo are links to canyon-monitor; each name gets its own options, any other is refused.
  const fs::path monitor = fs::path(CANYON_BINARY).parent_path() / "canyon-monitor";
  if (!fs::exists(monitor)) GTEST_SKIP() << monitor << " not built (a build without Fast DDS)";
  const auto record = canyon("record --help");
  EXPECT_EQ(record.exit_code, 0) << record.output;
  EXPECT_NE(record.output.find("--out"), std::string::npos) << record.output;
  const auto echo = canyon("echo --help");
  EXPECT_EQ(echo.exit_code, 0) << echo.output;
  EXPECT_NE(echo.output.find("topic"), std::string::npos) << echo.output;
  EXPECT_EQ(echo.output.find("--out"), std::string::npos) << echo.output;
  const auto monitor_help = canyon("monitor --help");
  EXPECT_EQ(monitor_help.exit_code, 0) << monitor_help.output;
  EXPECT_NE(monitor_help.output.find("--json"), std::string::npos) << monitor_help.output;
  const fs::path other = test::temp_dir("cli") / "canyon-bogus";
  fs::remove(other);
  fs::create_symlink(monitor, other);
  const auto refused = test::run_command(other.string() + " --help");
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("run this executable as canyon-record, canyon-echo or canyon-monitor"),
            std::string::npos)
      << refused.output;
}

TEST(CanyonCli, BadConfigKeyNamesFileAndLine) {
  const fs::path config = test::temp_dir("cli") / "bad.yaml";
  std::ofstream(config) << "mode: spp\nspp:\n  elevation_mask: 10\n";
  const auto r = canyon("process --config " + config.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find(config.string() + ":3: unknown key 'spp.elevation_mask'"), std::string::npos) << r.output;
}

TEST(CanyonCli, PrintConfigShowsEffectiveOptions) {
  const auto r = canyon("process --print-config --elevation-mask-deg 10 --coordinates ecef");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.output.find("elevation_mask_deg: 10"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("coordinates: ecef"), std::string::npos) << r.output;
}

// Without --config a mode runs its recommended set-up: the shipped file of that mode, key for key.
TEST(CanyonCli, ModeWithoutConfigIsTheShippedFile) {
  for (const std::string mode : {"rtk", "fusion"}) {
    const auto defaults = canyon("process --mode " + mode + " --print-config");
    const auto shipped =
        canyon("process --config " + std::string(CANYON_SOURCE_DIR) + "/config/" + mode + ".yaml --print-config");
    EXPECT_EQ(defaults.exit_code, 0) << defaults.output;
    EXPECT_EQ(shipped.exit_code, 0) << shipped.output;
    EXPECT_EQ(defaults.output, shipped.output) << mode;
  }
  const auto fusion = canyon("process --mode fusion --print-config");
  EXPECT_NE(fusion.output.find("ar_mode: fix_and_hold"), std::string::npos) << fusion.output;
  const auto described = canyon("process --mode fusion --describe-config");
  EXPECT_NE(described.output.find("defaults of mode fusion"), std::string::npos) << described.output;
}

// check-fixes on the open-sky kinematic drive: every fix survives leaving the most-observed satellite out (all 1,080
// epochs fixed in both agreed within 2.6 cm when the check was written), and canyon fixes more than RTKLIB.
TEST(CanyonCli, CheckFixesAgreesOnAnOpenSkyDrive) {
  const fs::path dir = test::shared_data() / "cssrlib-kinematic-doy265";
  if (!fs::exists(dir)) GTEST_SKIP() << "shared dataset not present: " << dir;
  const fs::path out = test::temp_dir("check-fixes") / "kinematic.pos";
  const auto r = canyon("check-fixes --mode rtk --rover " + (dir / "SEPT265G.21O").string() + " --base " +
                        (dir / "3034265G.21O").string() + " --nav " + (dir / "SEPT2650.21P").string() + " --out " +
                        out.string() + " --leave-out 1 --reference " + (dir / "rtklib/rtk_kinematic.pos").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("1 left out: consistent"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("times as many"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(test::temp_dir("check-fixes") / "kinematic.leave-out-1.pos"));
}

TEST(CanyonCli, CheckFixesNamesBadInput) {
  const auto spp = canyon("check-fixes --mode spp --rover a.obs --nav b.nav --out /tmp/x.pos");
  EXPECT_EQ(spp.exit_code, 1) << spp.output;
  EXPECT_NE(spp.output.find("mode spp has no fixes"), std::string::npos) << spp.output;
  const auto missing = canyon(
      "check-fixes --mode rtk --rover /nonexistent/rover.obs --base /nonexistent/base.obs "
      "--nav /nonexistent/nav.n --out /tmp/x.pos");
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_NE(missing.output.find("/nonexistent/"), std::string::npos) << missing.output;
}

TEST(CanyonCli, ProcessesRealDataAndSummarises) {
  if (!fs::exists(kGsiRover)) GTEST_SKIP() << "shared dataset not present: " << kGsiRover;
  const fs::path out = test::temp_dir("cli") / "gsi.pos";
  const auto r = canyon("process --mode spp --rover " + kGsiRover.string() + " --nav " + kGsiNav.string() + " --out " +
                        out.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("120 epochs, 115 solved"), std::string::npos) << r.output;  // 5 have GDOP > 30
  std::ifstream in(out);
  std::string line;
  int records = 0;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] != '%') ++records;
  }
  EXPECT_EQ(records, 115);
}

/// Per record of a .pos file: "week tow" -> number of satellites (column 7 of a week/tow llh record).
std::map<std::string, int> satellites_per_epoch(const fs::path& pos, std::string* header) {
  std::map<std::string, int> out;
  std::ifstream in(pos);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] == '%') {
      *header += line + "\n";
      continue;
    }
    std::istringstream fields(line);
    std::string week;
    std::string tow;
    double lat = 0;
    double lon = 0;
    double h = 0;
    int q = 0;
    int ns = 0;
    if (fields >> week >> tow >> lat >> lon >> h >> q >> ns) {
      std::string key = week;
      key += ' ';
      key += tow;
      out[key] = ns;
    }
  }
  return out;
}

TEST(CanyonCli, ExcludeMostObservedLeavesOutThatManySatellitesEveryEpoch) {
  if (!fs::exists(kGsiRover)) GTEST_SKIP() << "shared dataset not present: " << kGsiRover;
  const fs::path dir = test::temp_dir("cli-most-observed");
  const std::string inputs = " --mode spp --rover " + kGsiRover.string() + " --nav " + kGsiNav.string();
  const auto all = canyon("process" + inputs + " --out " + (dir / "all.pos").string());
  ASSERT_EQ(all.exit_code, 0) << all.output;
  const auto fewer = canyon("process" + inputs + " --exclude-most-observed 2 --out " + (dir / "fewer.pos").string());
  ASSERT_EQ(fewer.exit_code, 0) << fewer.output;
  EXPECT_NE(fewer.output.find("left out the 2 most observed satellites: G"), std::string::npos) << fewer.output;
  std::string header_all;
  std::string header_fewer;
  const auto ns_all = satellites_per_epoch(dir / "all.pos", &header_all);
  const auto ns_fewer = satellites_per_epoch(dir / "fewer.pos", &header_fewer);
  EXPECT_EQ(header_all.find("excl sats"), std::string::npos);
  EXPECT_NE(header_fewer.find("(the 2 most observed)"), std::string::npos) << header_fewer;
  // The two most observed satellites are tracked in (almost) every epoch: most solutions lose exactly two.
  int compared = 0;
  int lost_two = 0;
  for (const auto& [time, ns] : ns_fewer) {
    const auto it = ns_all.find(time);
    if (it == ns_all.end()) continue;
    ++compared;
    EXPECT_GE(it->second - ns, 0) << time;
    EXPECT_LE(it->second - ns, 2) << time;
    if (it->second - ns == 2) ++lost_two;
  }
  EXPECT_GT(compared, 100);
  EXPECT_GT(lost_two, compared * 9 / 10);
  const auto bad = canyon("process" + inputs + " --exclude-most-observed -1 --out " + (dir / "bad.pos").string());
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
}

TEST(CanyonCli, UnwritableOutputIsAnError) {
  if (!fs::exists(kGsiRover)) GTEST_SKIP() << "shared dataset not present";
  const auto r = canyon("process --rover " + kGsiRover.string() + " --nav " + kGsiNav.string() +
                        " --out /proc/canyon-cannot-create/x.pos");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("/proc/canyon-cannot-create/x.pos"), std::string::npos) << r.output;
}

TEST(CanyonCli, NavigationFileGivenAsObservationsIsRejected) {
  if (!fs::exists(kGsiRover)) GTEST_SKIP() << "shared dataset not present";
  const auto r = canyon("process --rover " + kGsiNav.string() + " --nav " + kGsiNav.string() + " --out /tmp/x.pos");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find(kGsiNav.string()), std::string::npos) << r.output;
}

std::vector<std::string> read_lines(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

void write_lines(const fs::path& path, const std::vector<std::string>& lines) {
  std::ofstream out(path);
  for (const std::string& line : lines) out << line << "\n";
}

/// Times of week (ms) of the solutions in a .pos file.
std::vector<long> solution_times_ms(const fs::path& pos) {
  auto sols = io::read_pos_file(pos.string());
  EXPECT_TRUE(sols.ok()) << sols.error().to_string();
  std::vector<long> times;
  if (!sols) return times;
  for (const auto& s : *sols) times.push_back(std::lround(s.time.tow_s * 1000.0));
  return times;
}

test::CommandResult process(const std::string& mode, const fs::path& rover, const fs::path& out) {
  return canyon("process -q --mode " + mode + " --rover " + rover.string() + " --base " + kStaticBase.string() +
                " --nav " + kStaticNav.string() + " --out " + out.string());
}

/// An edit of one line of a file: `text` written over it from `column`, or the line cut there if `text` is empty.
struct Corruption {
  const char* name;
  int line;  // 1-based
  std::size_t column;
  std::string text;
  const char* warning;  // expected after "file:line: "
  bool epoch_kept;      // the reader recovers the epoch itself
};

std::string corrupt(const std::string& line, const Corruption& c) {
  if (c.text.empty()) return line.substr(0, c.column);
  std::string out = line;
  out.replace(c.column, c.text.size(), c.text);
  return out;
}

TEST(CanyonCli, CorruptRoverEpochIsSkippedWithAWarningAndEveryOtherEpochSolved) {
  if (!fs::exists(kStaticRover)) GTEST_SKIP() << "shared dataset not present: " << kStaticRover;
  constexpr int kEpochLine = 33 + 24 * 30;  // 12:00:30, the 31st of 60 epochs
  constexpr long kEpochTowMs = 475230000;
  const Corruption corruptions[] = {
      {"garbled_epoch_line", kEpochLine, 16, "x", "bad epoch time", false},  // minute
      {"garbled_observation_value", kEpochLine + 5, 6, "12x45", "bad observation value '212x4552.829' in column 4",
       false},
      {"truncated_satellite_line", kEpochLine + 5, 30, "", "observation value '124140198.' cut short in column 20",
       false},
      {"more_satellites_announced", kEpochLine, 33, "30", "epoch announces 30 satellites, 23 present", true},
  };
  const fs::path dir = test::temp_dir("cli_corrupt");
  for (const char* mode : {"spp", "rtk"}) {
    SCOPED_TRACE(mode);
    const auto original = process(mode, kStaticRover, dir / "original.pos");
    ASSERT_EQ(original.exit_code, 0) << original.output;
    const std::vector<long> all = solution_times_ms(dir / "original.pos");
    ASSERT_EQ(all.size(), 60u);
    ASSERT_EQ(all[30], kEpochTowMs);
    for (const Corruption& c : corruptions) {
      SCOPED_TRACE(c.name);
      std::vector<std::string> lines = read_lines(kStaticRover);
      std::string& line = lines.at(static_cast<std::size_t>(c.line - 1));
      line = corrupt(line, c);
      const fs::path rover = dir / (std::string(c.name) + ".21O");
      write_lines(rover, lines);
      const fs::path out = dir / (std::string(c.name) + "_" + mode + ".pos");
      const auto r = process(mode, rover, out);
      EXPECT_EQ(r.exit_code, 0) << r.output;
      const std::string where = rover.string() + ":" + std::to_string(c.line) + ": ";
      EXPECT_NE(r.output.find("canyon: warning: " + where + c.warning), std::string::npos) << r.output;
      if (!c.epoch_kept) {
        EXPECT_NE(r.output.find("epoch skipped (lines " + std::to_string(kEpochLine) + "-" +
                                std::to_string(kEpochLine + 23) + ")"),
                  std::string::npos)
            << r.output;
      }
      std::vector<long> expected = all;
      if (!c.epoch_kept) expected.erase(expected.begin() + 30);
      EXPECT_EQ(solution_times_ms(out), expected);
    }
  }
}

TEST(CanyonCli, RoverFileWithAHeaderButNoObservationsIsRejected) {
  if (!fs::exists(kStaticRover)) GTEST_SKIP() << "shared dataset not present: " << kStaticRover;
  // The rover's header followed by navigation records: a clear error, not "0 epochs".
  std::vector<std::string> lines = read_lines(kStaticRover);
  lines.resize(32);  // up to END OF HEADER
  const std::vector<std::string> nav = read_lines(kStaticNav);
  lines.insert(lines.end(), nav.begin() + 10, nav.end());
  const fs::path rover = test::temp_dir("cli_corrupt") / "header_and_nav.21O";
  write_lines(rover, lines);
  const auto r = process("spp", rover, test::temp_dir("cli_corrupt") / "x.pos");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(
      r.output.find("canyon: error: " + rover.string() + ":1032: no epoch line in the 1000 lines after the header"),
      std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace canyon
