// `canyon simulate` end to end: the command's errors, its files, and RTKLIB and canyon processing them as they are
// (3-minute scenarios; the 10-minute figures are in the README, from tests/bench/sim_vs_rtklib.sh).

#include <fstream>

#include <gtest/gtest.h>

#include "canyon/eval/metrics.hpp"
#include "canyon/eval/truth.hpp"
#include "canyon/io/pos_file.hpp"

#include "test_support.hpp"

namespace canyon {
namespace {

namespace fs = std::filesystem;

constexpr double kMinOpenSkyFixFraction = 0.95;
constexpr double kMaxOpenSkyFixedRmseM = 0.03;
constexpr double kMaxUrbanFixFraction = 0.5;
constexpr double kMinUrbanMaxErrorM = 1.0;

test::CommandResult canyon(const std::string& args) {
  return test::run_command(std::string(CANYON_BINARY) + " " + args);
}

/// Generates `scenario` for 180 s into a fresh folder of its own (`tag`: tests may run in parallel).
fs::path generate(const std::string& scenario, const std::string& tag) {
  fs::path dir = test::temp_dir("simulate") / tag;
  fs::remove_all(dir);
  const auto r = canyon("simulate -q --scenario " + scenario + " --duration 180 --out " + dir.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return dir;
}

eval::SolutionStats score(const fs::path& pos, const fs::path& dir) {
  auto solutions = io::read_pos_file(pos.string());
  EXPECT_TRUE(solutions.ok()) << solutions.error().to_string();
  auto truth = eval::read_truth_csv((dir / "truth.csv").string());
  EXPECT_TRUE(truth.ok());
  eval::EvalOptions options;
  options.epochs_in = 901;
  auto stats = eval::evaluate(*solutions, *truth, options);
  EXPECT_TRUE(stats.ok());
  return *stats;
}

fs::path run_rtklib(const fs::path& dir) {
  fs::path pos = dir / "rtklib.pos";
  const std::string conf = std::string(CANYON_SOURCE_DIR) + "/config/rtklib/sim.conf";
  const auto r = test::run_command("rnx2rtkp -k " + conf + " -o " + pos.string() + " " + (dir / "rover.obs").string() +
                                   " " + (dir / "base.obs").string() + " " + (dir / "nav.rnx").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return pos;
}

TEST(SimulateCli, UnknownScenarioAndBadFileAreUsageErrors) {
  const auto unknown = canyon("simulate --scenario downtown --out /tmp/x");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.output.find("urban-severe"), std::string::npos) << unknown.output;
  const fs::path bad = test::temp_dir("simulate") / "bad.yaml";
  std::ofstream(bad) << "name: bad\ncity:\n  height_max_m: -81\n";
  const auto r = canyon("simulate --scenario " + bad.string() + " --out /tmp/x");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find(bad.string() + ":3: city.height_max_m"), std::string::npos) << r.output;
}

TEST(SimulateCli, WritesEveryFile) {
  const fs::path dir = generate("urban-severe", "files");
  for (const char* name :
       {"nav.rnx", "rover.obs", "base.obs", "truth.csv", "vio.csv", "timesync.csv", "city.geojson", "scenario.yaml"}) {
    EXPECT_TRUE(fs::exists(dir / name) && fs::file_size(dir / name) > 0) << name;
  }
  // scenario.yaml regenerates the same files.
  const fs::path again = dir.parent_path() / "files-again";
  fs::remove_all(again);
  const auto r = canyon("simulate -q --scenario " + (dir / "scenario.yaml").string() + " --out " + again.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(test::run_command("cmp " + (dir / "rover.obs").string() + " " + (again / "rover.obs").string()).exit_code,
            0);
}

TEST(SimulateCli, RtklibFixesOpenSky) {
  if (!test::have_rtklib()) GTEST_SKIP() << "rnx2rtkp not installed";
  const fs::path dir = generate("open-sky", "rtklib-open-sky");
  const eval::SolutionStats stats = score(run_rtklib(dir), dir);
  EXPECT_GE(stats.fixed().fraction_of_epochs_in, kMinOpenSkyFixFraction);
  EXPECT_LE(stats.fixed().error.rmse_3d_m, kMaxOpenSkyFixedRmseM);
  EXPECT_EQ(stats.wrong_fixes, 0);
}

TEST(SimulateCli, RtklibFailsInTheUrbanCanyon) {
  if (!test::have_rtklib()) GTEST_SKIP() << "rnx2rtkp not installed";
  const fs::path dir = generate("urban-severe", "rtklib-urban-severe");
  const eval::SolutionStats stats = score(run_rtklib(dir), dir);
  EXPECT_LT(stats.fixed().fraction_of_epochs_in, kMaxUrbanFixFraction);
  EXPECT_GT(stats.overall.max_3d_m, kMinUrbanMaxErrorM);
}

TEST(SimulateCli, CanyonRtkWithIonosphereEstimationFixesOpenSky) {
  const fs::path dir = generate("open-sky", "canyon-open-sky");
  const fs::path config = dir / "rtk-iono.yaml";
  std::ofstream(config) << "mode: rtk\nrtk:\n  ionosphere: estimate\n";
  const fs::path pos = dir / "canyon.pos";
  const auto r =
      canyon("process -q --config " + config.string() + " --rover " + (dir / "rover.obs").string() + " --base " +
             (dir / "base.obs").string() + " --nav " + (dir / "nav.rnx").string() + " --out " + pos.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const eval::SolutionStats stats = score(pos, dir);
  EXPECT_GE(stats.fixed().fraction_of_epochs_in, kMinOpenSkyFixFraction);
  EXPECT_LE(stats.fixed().error.rmse_3d_m, kMaxOpenSkyFixedRmseM);
  EXPECT_EQ(stats.wrong_fixes, 0);
}

}  // namespace
}  // namespace canyon
