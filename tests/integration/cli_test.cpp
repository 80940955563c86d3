// The `canyon` command run as a real process: exit codes and messages for good and bad input.

#include <fstream>

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

}  // namespace
}  // namespace canyon
