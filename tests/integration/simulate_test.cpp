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
  const auto unknown = canyon("simulate --scenario midtown --out /tmp/x");
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

/// canyon process with the shipped config/rtk-urban.yaml (SNR weighting; the ionosphere estimated at the scenario's
/// 20 km by rtk.yaml's ionosphere: auto) on `dir`.
fs::path run_canyon_rtk(const fs::path& dir) {
  fs::path pos = dir / "canyon.pos";
  const auto r = canyon("process -q --config " + std::string(CANYON_SOURCE_DIR) + "/config/rtk-urban.yaml --rover " +
                        (dir / "rover.obs").string() + " --base " + (dir / "base.obs").string() + " --nav " +
                        (dir / "nav.rnx").string() + " --out " + pos.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return pos;
}

TEST(SimulateCli, CanyonRtkWithTheShippedDefaultsFixesOpenSkyAsRtklibDoes) {
  const fs::path dir = generate("open-sky", "canyon-open-sky");
  const eval::SolutionStats ours = score(run_canyon_rtk(dir), dir);
  const eval::SolutionStats theirs = score(run_rtklib(dir), dir);
  EXPECT_GE(ours.fixed().fraction_of_epochs_in, kMinOpenSkyFixFraction);
  // RTKLIB may take the very first epochs on the ratio test alone where canyon also wants the bootstrapped success
  // rate (0.19 at the first epoch here): up to 1 % of the epochs (the 10-minute figures, 3 seeds, are in the README:
  // canyon's fix rate is RTKLIB's or higher there).
  EXPECT_GE(ours.fixed().epochs, theirs.fixed().epochs - 9);
  EXPECT_LE(ours.fixed().error.rmse_3d_m, kMaxOpenSkyFixedRmseM);
  EXPECT_LE(ours.fixed().error.rmse_3d_m, theirs.fixed().error.rmse_3d_m);
  EXPECT_EQ(ours.wrong_fixes, 0);
  ASSERT_TRUE(ours.time_to_first_fix_s.has_value());
  EXPECT_LE(*ours.time_to_first_fix_s, 2.0);  // partial fixing by the success rate while the float converges
}

TEST(SimulateCli, CanyonRtkNeverFixesWronglyInStreetCanyonsAndStaysCloserThanRtklib) {
  // Float validation keeps fixes away from floats that reflections have corrupted (RTKLIB's fixes there are wrong).
  for (const char* scenario : {"urban-moderate", "urban-severe"}) {
    const fs::path dir = generate(scenario, std::string("canyon-") + scenario);
    const eval::SolutionStats ours = score(run_canyon_rtk(dir), dir);
    const eval::SolutionStats theirs = score(run_rtklib(dir), dir);
    EXPECT_EQ(ours.wrong_fixes, 0) << scenario;
    EXPECT_LE(ours.overall.rmse_3d_m, theirs.overall.rmse_3d_m) << scenario;
    EXPECT_GE(ours.fixed().epochs - ours.wrong_fixes, theirs.fixed().epochs - theirs.wrong_fixes) << scenario;
  }
}

}  // namespace
}  // namespace canyon
