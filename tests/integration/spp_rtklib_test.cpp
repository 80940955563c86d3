// Single-point positioning end to end on the real shared datasets, with RTKLIB 2.4.3 (`rnx2rtkp -p 0`) run as a
// real peer on the same files and options.

#include <iostream>

#include <gtest/gtest.h>

#include "canyon/commands/process.hpp"
#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/io/rinex_obs.hpp"

#include "test_support.hpp"

namespace canyon {
namespace {

namespace fs = std::filesystem;
using test::shared_data;

constexpr double kMaxMedianDistanceToRtklibM = 0.5;
constexpr double kMaxInstinctRms3dM = 1.0;

struct Dataset {
  const char* name;
  const char* rover;
  std::vector<const char*> nav;
  const char* systems;  // RTKLIB -sys; canyon uses the same
};

const Dataset kDatasets[] = {
    {"rtklib-test-gsi-2005", "rtklib-test-gsi-2005/07590920.05o", {"rtklib-test-gsi-2005/07590920.05n"}, "G"},
    {"cssrlib-static-doy078", "cssrlib-static-doy078/SEPT078M1.21O", {"cssrlib-static-doy078/SEPT078M.21P"}, "G,E,J"},
    {"cssrlib-kinematic-doy265",
     "cssrlib-kinematic-doy265/SEPT265G.21O",
     {"cssrlib-kinematic-doy265/SEPT2650.21P"},
     "G,E,J"},
    {"matrtklib-static", "matrtklib-static/rover.obs", {"matrtklib-static/base.nav"}, "G,R,E,C,J"},
    {"m8p-galway-20181004",
     "m8p-galway-20181004/rinex/20181004_rover-20181004-1532.obs",
     {"m8p-galway-20181004/rinex/20181004_rover-20181004-1532.nav"},
     "G,R,J"},
    {"instinct-spirent-rtk-sim",
     "instinct-spirent-rtk-sim/iono-Klob_tropo-Saast/Rover-dynamic_MO_Spirent.obs",
     {"instinct-spirent-rtk-sim/RINEX_GN_Spirent.23N", "instinct-spirent-rtk-sim/RINEX_EN_Spirent.23L"},
     "G,E"},
};

config::ProcessConfig canyon_config(const Dataset& d, const fs::path& out) {
  config::ProcessConfig c;
  c.rover_obs = (shared_data() / d.rover).string();
  for (const char* n : d.nav) c.nav.push_back((shared_data() / n).string());
  c.out = out.string();
  const std::string systems = d.systems;
  c.spp.use_gps = systems.find('G') != std::string::npos;
  c.spp.use_glonass = systems.find('R') != std::string::npos;
  c.spp.use_galileo = systems.find('E') != std::string::npos;
  c.spp.use_beidou = systems.find('C') != std::string::npos;
  c.spp.use_qzss = systems.find('J') != std::string::npos;
  return c;
}

/// Runs canyon and RTKLIB on a dataset; returns both solution lists.
struct BothSolutions {
  std::vector<core::Solution> canyon;
  std::vector<core::Solution> rtklib;
  commands::ProcessSummary summary;
};

std::optional<BothSolutions> run_both(const Dataset& d) {
  const fs::path dir = test::temp_dir(std::string("spp_") + d.name);
  const config::ProcessConfig config = canyon_config(d, dir / "canyon.pos");
  auto summary = commands::run_process(config);
  EXPECT_TRUE(summary.ok()) << summary.error().to_string();
  if (!summary) return std::nullopt;
  const fs::path conf = test::write_rtklib_spp_conf(dir, d.systems);
  std::string command =
      "rnx2rtkp -k " + conf.string() + " -o " + (dir / "rtklib.pos").string() + " " + config.rover_obs;
  for (const auto& n : config.nav) command += " " + n;
  const auto rtklib_run = test::run_command(command);
  EXPECT_EQ(rtklib_run.exit_code, 0) << command;
  auto canyon = io::read_pos_file(config.out);
  auto rtklib = io::read_pos_file((dir / "rtklib.pos").string());
  EXPECT_TRUE(canyon.ok() && rtklib.ok());
  if (!canyon || !rtklib) return std::nullopt;
  return BothSolutions{std::move(*canyon), std::move(*rtklib), std::move(*summary)};
}

class SppAgainstRtklib : public ::testing::TestWithParam<Dataset> {};

TEST_P(SppAgainstRtklib, MedianDistanceToRtklibIsSmall) {
  const Dataset& d = GetParam();
  if (!fs::exists(shared_data() / d.rover)) GTEST_SKIP() << "shared dataset not present: " << shared_data() / d.rover;
  if (!test::have_rtklib()) GTEST_SKIP() << "RTKLIB rnx2rtkp not installed (scripts/setup.sh installs it)";
  const auto both = run_both(d);
  ASSERT_TRUE(both.has_value());
  std::vector<double> distances;
  for (const auto& r : both->rtklib) {
    if (const core::Solution* c = test::nearest(both->canyon, r.time, 0.01)) {
      distances.push_back((c->p_E_m - r.p_E_m).norm());
    }
  }
  ASSERT_GT(distances.size(), both->rtklib.size() * 9 / 10) << "too few common epochs";
  const double median = test::median(distances);
  std::cout << "[ SPP      ] " << d.name << ": canyon " << both->canyon.size() << " solutions / "
            << both->summary.epochs << " epochs, RTKLIB " << both->rtklib.size() << ", common " << distances.size()
            << ", median distance " << median << " m\n";
  RecordProperty("median_distance_m", std::to_string(median));
  EXPECT_LT(median, kMaxMedianDistanceToRtklibM);
  EXPECT_GE(both->canyon.size(), both->rtklib.size()) << "canyon solves fewer epochs than RTKLIB";
}

INSTANTIATE_TEST_SUITE_P(SharedDatasets, SppAgainstRtklib, ::testing::ValuesIn(kDatasets), [](const auto& info) {
  std::string name = info.param.name;
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
});

TEST(SppAccuracy, GsiStaticIsAtLeastAsAccurateAsRtklib) {
  const Dataset& d = kDatasets[0];
  if (!fs::exists(shared_data() / d.rover)) GTEST_SKIP() << "shared dataset not present";
  if (!test::have_rtklib()) GTEST_SKIP() << "RTKLIB rnx2rtkp not installed";
  auto header = io::RinexObsReader::open((shared_data() / d.rover).string());
  ASSERT_TRUE(header.ok());
  ASSERT_TRUE(header->header().receiver.approx_position_E_m.has_value());
  const Eigen::Vector3d truth = *header->header().receiver.approx_position_E_m;
  const auto both = run_both(d);
  ASSERT_TRUE(both.has_value());
  std::vector<double> canyon_err;
  std::vector<double> rtklib_err;
  for (const auto& s : both->canyon) canyon_err.push_back((s.p_E_m - truth).norm());
  for (const auto& s : both->rtklib) rtklib_err.push_back((s.p_E_m - truth).norm());
  const double canyon_rms = test::rms(canyon_err);
  const double rtklib_rms = test::rms(rtklib_err);
  std::cout << "[ SPP      ] gsi-2005 3D RMS vs header: canyon " << canyon_rms << " m (" << canyon_err.size()
            << " epochs), RTKLIB " << rtklib_rms << " m (" << rtklib_err.size() << " epochs)\n";
  EXPECT_LE(canyon_rms, rtklib_rms);
  EXPECT_EQ(canyon_err.size(), rtklib_err.size());  // 5 of 120 epochs have GDOP > 30 in both
}

TEST(SppAccuracy, InstinctSimulatorWithinOneMetre) {
  const Dataset& d = kDatasets[5];
  const fs::path truth_file = shared_data() / "instinct-spirent-rtk-sim/truth_rover_dynamic_ecef_10Hz.pos";
  if (!fs::exists(truth_file)) GTEST_SKIP() << "shared dataset not present: " << truth_file;
  const fs::path dir = test::temp_dir("spp_instinct");
  auto summary = commands::run_process(canyon_config(d, dir / "canyon.pos"));
  ASSERT_TRUE(summary.ok()) << summary.error().to_string();
  auto sols = io::read_pos_file((dir / "canyon.pos").string());
  auto truth = io::read_pos_file(truth_file.string());
  ASSERT_TRUE(sols.ok() && truth.ok());
  std::vector<double> errors;
  for (const auto& s : *sols) {
    // Truth at 10 Hz: interpolate linearly between the two samples around the solution time.
    auto after = std::find_if(truth->begin(), truth->end(), [&](const auto& t) { return s.time - t.time <= 0; });
    if (after == truth->end()) continue;
    if (after == truth->begin()) ++after;  // at or before the first sample: extrapolate from the first two
    const auto before = after - 1;
    const double f = (s.time - before->time) / (after->time - before->time);
    const Eigen::Vector3d p_true = before->p_E_m + f * (after->p_E_m - before->p_E_m);
    errors.push_back((s.p_E_m - p_true).norm());
  }
  const double rms = test::rms(errors);
  std::cout << "[ SPP      ] instinct Klobuchar+Saastamoinen dynamic: 3D RMS " << rms << " m over " << errors.size()
            << " epochs\n";
  EXPECT_EQ(errors.size(), 601U);
  EXPECT_LE(rms, kMaxInstinctRms3dM);
}

TEST(SppProcess, EpochsWithTooFewSatellitesAreSkippedAndProcessingGoesOn) {
  const Dataset& d = kDatasets[0];
  if (!fs::exists(shared_data() / d.rover)) GTEST_SKIP() << "shared dataset not present";
  const fs::path dir = test::temp_dir("spp_few");
  config::ProcessConfig config = canyon_config(d, dir / "x.pos");
  config.spp.elevation_mask_rad = 60.0 * core::kDegToRad;  // leaves 0-4 satellites per epoch
  auto summary = commands::run_process(config);
  ASSERT_TRUE(summary.ok()) << summary.error().to_string();
  EXPECT_EQ(summary->epochs, 120);
  EXPECT_LT(summary->solved, 120);
  ASSERT_FALSE(summary->epoch_notes.empty());
  EXPECT_NE(summary->epoch_notes.front().find("no solution: too few satellites"), std::string::npos)
      << summary->epoch_notes.front();
}

}  // namespace
}  // namespace canyon
