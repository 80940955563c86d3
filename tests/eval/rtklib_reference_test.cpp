// RTKLIB 2.4.3's own results shipped with the shared datasets (../shared/data/*/rtklib/*.pos), scored against the
// truths their READMEs give: the evaluator must reproduce the READMEs' figures (rounded to the millimetre there).

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "canyon/eval/metrics.hpp"
#include "canyon/io/pos_file.hpp"

namespace canyon::eval {
namespace {

namespace fs = std::filesystem;

const fs::path kData = CANYON_SHARED_DATA_DIR;
constexpr double kHalfMillimetreM = 0.0005;  // the READMEs round to the millimetre

// Truths from the READMEs.
constexpr const char* kCssrlibStaticTruth = "ecef:-3962108.673,3381309.574,3668678.638";
constexpr const char* kMatrtklibTruth = "llh:35.13469901,136.97757549,104.8626";
constexpr const char* kInstinctStatic2kmTruth = "ecef:4156857.1195929,673209.028774142,4774767.03105544";

struct Case {
  const char* pos;    // relative to the shared data folder
  const char* truth;  // a truth spec; a relative file name is taken in the shared data folder
  int epochs;
  int fixed;
  double horizontal_rmse_m;
  double rmse_3d_m;
  double max_3d_m;
};

std::string resolve_truth(const std::string& spec) {
  if (spec.find(':') != std::string::npos) return spec;
  return (kData / spec).string();
}

class RtklibReference : public testing::TestWithParam<Case> {};

TEST_P(RtklibReference, ReproducesTheReadmeFigures) {
  if (!fs::is_directory(kData)) GTEST_SKIP() << "shared datasets not found at " << kData << " (CANYON_SHARED_DATA_DIR)";
  const Case& c = GetParam();
  const auto solutions = io::read_pos_file((kData / c.pos).string());
  ASSERT_TRUE(solutions.ok()) << solutions.error().to_string();
  const auto truth = parse_truth_spec(resolve_truth(c.truth));
  ASSERT_TRUE(truth.ok()) << truth.error().to_string();
  const auto stats = evaluate(*solutions, *truth);
  ASSERT_TRUE(stats.ok()) << stats.error().to_string();
  EXPECT_EQ(stats->epochs_with_solution, c.epochs);
  EXPECT_EQ(stats->epochs_with_truth, c.epochs);
  EXPECT_EQ(stats->fixed().epochs, c.fixed);
  EXPECT_NEAR(stats->overall.horizontal_rmse_m, c.horizontal_rmse_m, kHalfMillimetreM);
  EXPECT_NEAR(stats->overall.rmse_3d_m, c.rmse_3d_m, kHalfMillimetreM);
  EXPECT_NEAR(stats->overall.max_3d_m, c.max_3d_m, kHalfMillimetreM);
  EXPECT_EQ(stats->wrong_fixes, 0);
  std::cout << format_stats(*stats, c.pos);
}

constexpr const char* kInstinctTruth = "instinct-spirent-rtk-sim/Rover-dynamic_PVA_Spirent.csv";

INSTANTIATE_TEST_SUITE_P(
    Readmes, RtklibReference,
    testing::Values(
        Case{"cssrlib-static-doy078/rtklib/rtk_kinematic.pos", kCssrlibStaticTruth, 60, 60, 0.001, 0.003, 0.006},
        Case{"cssrlib-static-doy078/rtklib/rtk_kinematic_inst.pos", kCssrlibStaticTruth, 60, 60, 0.001, 0.003, 0.006},
        Case{"cssrlib-static-doy078/rtklib/rtk_kinematic_withqzss.pos", kCssrlibStaticTruth, 60, 60, 0.001, 0.003,
             0.006},
        Case{"matrtklib-static/rtklib/rtk_kinematic.pos", kMatrtklibTruth, 301, 301, 0.001, 0.002, 0.004},
        Case{"matrtklib-static/rtklib/rtk_kinematic_fixhold.pos", kMatrtklibTruth, 301, 301, 0.001, 0.002, 0.004},
        Case{"matrtklib-static/rtklib/rtk_kinematic_inst.pos", kMatrtklibTruth, 301, 301, 0.001, 0.002, 0.004},
        Case{"instinct-spirent-rtk-sim/rtklib/iono-Klob_tropo-Saast_dynamic_rtk_kinematic.pos", kInstinctTruth, 601,
             601, 0.000, 0.000, 0.001},
        Case{"instinct-spirent-rtk-sim/rtklib/iono-Klob_tropo-Saast_dynamic_rtk_kinematic_fixhold.pos",
             "instinct-spirent-rtk-sim/truth_rover_dynamic_ecef_10Hz.pos", 601, 601, 0.000, 0.000, 0.001},
        Case{"instinct-spirent-rtk-sim/rtklib/iono-Klob_tropo-Saast_dynamic_rtk_kinematic_inst.pos", kInstinctTruth,
             601, 601, 0.000, 0.000, 0.001},
        Case{"instinct-spirent-rtk-sim/rtklib/iono-Klob_tropo-Saast_static2km_rtk_kinematic.pos",
             kInstinctStatic2kmTruth, 601, 601, 0.001, 0.002, 0.002},
        Case{"instinct-spirent-rtk-sim/rtklib/iono-none_tropo-none_dynamic_rtk_kinematic.pos", kInstinctTruth, 601, 601,
             0.001, 0.021, 0.087},
        Case{"instinct-spirent-rtk-sim/rtklib/iono-none_tropo-none_static2km_rtk_kinematic_inst.pos",
             kInstinctStatic2kmTruth, 465, 465, 0.002, 0.019, 0.093}));

// cssrlib-kinematic has no truth: RTKLIB's continuous-AR run against its own combined fix-and-hold pseudo-reference
// (fixed epochs only, so no interpolation across the gaps), and the agreement of the two on epochs both fixed.
TEST(RtklibReferenceKinematic, AgainstThePseudoReference) {
  if (!fs::is_directory(kData)) GTEST_SKIP() << "shared datasets not found at " << kData << " (CANYON_SHARED_DATA_DIR)";
  const std::string reference = (kData / "cssrlib-kinematic-doy265/rtklib/pseudo_ref_fixed_only.pos").string();
  const auto solutions = io::read_pos_file((kData / "cssrlib-kinematic-doy265/rtklib/rtk_kinematic.pos").string());
  ASSERT_TRUE(solutions.ok()) << solutions.error().to_string();
  TruthOptions exact_epochs_only;
  exact_epochs_only.max_gap_s = 0.5;
  exact_epochs_only.max_extrapolation_s = 0.0;
  const auto truth = read_truth_pos(reference, exact_epochs_only);
  ASSERT_TRUE(truth.ok()) << truth.error().to_string();
  const auto stats = evaluate(*solutions, *truth);
  ASSERT_TRUE(stats.ok());
  EXPECT_EQ(stats->epochs_with_solution, 360);
  EXPECT_EQ(stats->fixed().epochs, 82);
  EXPECT_EQ(stats->floating().epochs, 278);
  EXPECT_NEAR(100.0 * stats->fixed().fraction_of_solved, 22.8, 0.05);
  EXPECT_EQ(stats->epochs_with_truth, 216);
  EXPECT_NEAR(stats->overall.horizontal_rmse_m, 0.062, kHalfMillimetreM);
  EXPECT_NEAR(stats->overall.rmse_3d_m, 0.084, kHalfMillimetreM);
  EXPECT_NEAR(stats->overall.max_3d_m, 0.176, kHalfMillimetreM);

  const auto pseudo_reference = io::read_pos_file(reference);
  ASSERT_TRUE(pseudo_reference.ok());
  const auto agreement = compare(*solutions, *pseudo_reference);
  ASSERT_TRUE(agreement.ok());
  EXPECT_EQ(agreement->both_fixed, 82);  // README: "fixed epochs identical to ref"
  EXPECT_LT(agreement->max_distance_fixed_m, 0.001);
}

TEST(RtklibReferenceKinematic, QzssRunsAndTheL1OnlyRun) {
  if (!fs::is_directory(kData)) GTEST_SKIP() << "shared datasets not found at " << kData << " (CANYON_SHARED_DATA_DIR)";
  struct Counts {
    const char* pos;
    int solved;
    int fixed;
  };
  for (const Counts& c : {Counts{"cssrlib-kinematic-doy265/rtklib/rtk_kinematic_inst.pos", 360, 327},
                          Counts{"cssrlib-kinematic-doy265/rtklib/rtk_kinematic_withqzss.pos", 356, 46},
                          Counts{"cssrlib-kinematic-doy265/rtklib/rtk_kinematic_inst_withqzss.pos", 356, 234},
                          Counts{"m8p-galway-20181004/rtklib/20181004_run2_rtk_kinematic.pos", 1155, 39}}) {
    const auto solutions = io::read_pos_file((kData / c.pos).string());
    ASSERT_TRUE(solutions.ok()) << solutions.error().to_string();
    const auto stats = evaluate(*solutions, nullptr);
    ASSERT_TRUE(stats.ok()) << c.pos << ": " << stats.error().to_string();
    EXPECT_EQ(stats->epochs_with_solution, c.solved) << c.pos;
    EXPECT_EQ(stats->fixed().epochs, c.fixed) << c.pos;
  }
}

TEST(EvaluateFiles, ReportForTheCli) {
  if (!fs::is_directory(kData)) GTEST_SKIP() << "shared datasets not found at " << kData << " (CANYON_SHARED_DATA_DIR)";
  const std::string pos = (kData / "matrtklib-static/rtklib/rtk_kinematic.pos").string();
  const std::string other = (kData / "matrtklib-static/rtklib/rtk_kinematic_inst.pos").string();
  const auto report = evaluate_files(pos, kMatrtklibTruth, {}, other);
  ASSERT_TRUE(report.ok()) << report.error().to_string();
  EXPECT_NE(report->find("epochs in 301, with solution 301, with truth 301"), std::string::npos) << *report;
  EXPECT_NE(report->find("fixed in both 301"), std::string::npos) << *report;
  const auto missing = evaluate_files((kData / "nonexistent.pos").string(), kMatrtklibTruth);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().file.find("nonexistent.pos"), std::string::npos);
  const auto bad_truth = evaluate_files(pos, "ecef:1,2");
  EXPECT_FALSE(bad_truth.ok());
}

}  // namespace
}  // namespace canyon::eval
