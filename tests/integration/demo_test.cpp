// `canyon demo` end to end (a 2-minute downtown scenario instead of the default 10): every stage runs, RTKLIB
// included, and the table, Markdown, JSON and plots come out; the README's first command runs this with defaults.

#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "test_support.hpp"

namespace canyon {
namespace {

namespace fs = std::filesystem;

test::CommandResult canyon(const std::string& args) {
  return test::run_command(std::string(CANYON_BINARY) + " " + args);
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(DemoCli, SimulatesProcessesRunsRtklibAndEvaluates) {
  const fs::path dir = test::temp_dir("demo") / "run";
  fs::remove_all(dir);
  const auto r = canyon("demo --duration 120 --out " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The table has a column per solution, RTKLIB first as in the paper's tables.
  const std::size_t rtklib = r.output.find("RTKLIB");
  const std::size_t spp = r.output.find("canyon SPP");
  const std::size_t rtk = r.output.find("canyon RTK");
  const std::size_t fusion = r.output.find("canyon fusion");
  ASSERT_NE(rtklib, std::string::npos) << r.output;
  ASSERT_NE(spp, std::string::npos) << r.output;
  ASSERT_NE(rtk, std::string::npos) << r.output;
  ASSERT_NE(fusion, std::string::npos) << r.output;
  EXPECT_LT(rtklib, spp);
  EXPECT_LT(spp, rtk);
  EXPECT_LT(rtk, fusion);
  for (const char* name :
       {"scenario/rover.obs", "scenario/truth.csv", "scenario/city.geojson", "spp.pos", "rtk.pos", "fusion.pos",
        "rtklib.pos", "evaluation.md", "evaluation.json", "trajectory.svg", "ape.svg"}) {
    EXPECT_TRUE(fs::exists(dir / name) && fs::file_size(dir / name) > 0) << name;
  }
  const std::string json = read_file(dir / "evaluation.json");
  EXPECT_NE(json.find("\"label\": \"canyon RTK\""), std::string::npos) << json.substr(0, 2000);
  EXPECT_NE(json.find("\"count\": 601"), std::string::npos) << json.substr(0, 2000);  // 120 s at 5 Hz
  for (const char* svg : {"trajectory.svg", "ape.svg"}) {
    const auto xml = test::run_command("xmllint --noout " + (dir / svg).string());
    EXPECT_EQ(xml.exit_code, 0) << svg << ": " << xml.output;
  }
}

TEST(DemoCli, WithoutRtklibStillEvaluatesCanyonAndSaysWhy) {
  const fs::path dir = test::temp_dir("demo") / "no-rtklib";
  fs::remove_all(dir);
  const auto r = canyon("demo --duration 30 --rtklib-program canyon-no-such-program --out " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("canyon-no-such-program is not installed"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("canyon RTK"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "rtklib.pos"));
}

TEST(DemoCli, FailingRtklibIsAnErrorThatPointsToItsLog) {
  const fs::path dir = test::temp_dir("demo") / "rtklib-fails";
  fs::remove_all(dir);
  const auto r = canyon("demo --duration 10 --rtklib-program false --out " + dir.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("false failed (exit status 1)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find((dir / "rtklib.log").string()), std::string::npos) << r.output;
}

TEST(DemoCli, UnknownScenarioIsAUsageErrorAndUnwritableFolderAnInputError) {
  const auto unknown = canyon("demo --scenario midtown --out /tmp/canyon-demo-unused");
  EXPECT_EQ(unknown.exit_code, 2) << unknown.output;
  EXPECT_NE(unknown.output.find("urban-severe"), std::string::npos) << unknown.output;
  const auto unwritable = canyon("demo --duration 10 --out /proc/canyon-demo");
  EXPECT_EQ(unwritable.exit_code, 1) << unwritable.output;
  EXPECT_NE(unwritable.output.find("/proc/canyon-demo"), std::string::npos) << unwritable.output;
}

}  // namespace
}  // namespace canyon
