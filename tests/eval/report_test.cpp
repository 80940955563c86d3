// evaluate_report on a constructed case whose figures are worked out by hand below: a truth trajectory with a gap,
// two solutions with known errors in ENU at the truth point; rover epoch counting; the table, Markdown and JSON.

#include "canyon/eval/report.hpp"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"

namespace canyon::eval {
namespace {

using core::SolutionStatus;

constexpr double kTolM = 1e-9;
const core::Geodetic kStart{35.0 * core::kDegToRad, 139.0 * core::kDegToRad, 50.0};
const core::GpsTime kT0{2244, 36000.0};

/// Truth at t = 0..9 s walking east at 1 m/s, without the samples at 6 and 7 s: a 3 s gap (> max_gap_s 2 s).
Truth gapped_truth() {
  std::vector<TruthSample> samples;
  for (int k = 0; k < 10; ++k) {
    if (k == 6 || k == 7) continue;
    samples.push_back({kT0 + k, core::geodetic_to_ecef(kStart) + core::enu_to_ecef({1.0 * k, 0.0, 0.0}, kStart)});
  }
  return *Truth::from_samples(std::move(samples));
}

/// A solution at truth(t) + d_N (ENU at the truth point); at 6 and 7 s (no truth) at the walked point.
core::Solution at(const Truth& truth, int t_s, SolutionStatus status, const Eigen::Vector3d& d_N_m) {
  core::Solution s;
  s.time = kT0 + t_s;
  s.status = status;
  const auto p = truth.position_at(s.time);
  const Eigen::Vector3d p_E = p ? *p : core::geodetic_to_ecef(kStart) + core::enu_to_ecef({1.0 * t_s, 0, 0}, kStart);
  s.p_E_m = p_E + core::enu_to_ecef(d_N_m, core::ecef_to_geodetic(p_E));
  return s;
}

// A: 10 epochs. 3D errors with truth: 5, 0.3, 0.05, 0.02, 0.15, 0, -, -, 1.0, 0.01.
std::vector<core::Solution> solution_a(const Truth& truth) {
  return {
      at(truth, 0, SolutionStatus::Single, {3.0, 4.0, 0.0}),
      at(truth, 1, SolutionStatus::Float, {0.0, 0.0, 0.3}),
      at(truth, 2, SolutionStatus::Fixed, {0.03, 0.04, 0.0}),
      at(truth, 3, SolutionStatus::Fixed, {0.0, 0.0, 0.02}),
      at(truth, 4, SolutionStatus::Fixed, {0.12, 0.0, 0.09}),
      at(truth, 5, SolutionStatus::Fixed, {0.0, 0.0, 0.0}),
      at(truth, 6, SolutionStatus::Fixed, {0.0, 0.0, 0.0}),
      at(truth, 7, SolutionStatus::VioFillIn, {0.0, 0.0, 0.0}),
      at(truth, 8, SolutionStatus::VioFillIn, {0.6, 0.8, 0.0}),
      at(truth, 9, SolutionStatus::Fixed, {0.0, 0.01, 0.0}),
  };
}

// B: float at 1 s, fixed 1 cm up at 2..5, 8, 9 s; nothing at 0, 6, 7 s.
std::vector<core::Solution> solution_b(const Truth& truth) {
  std::vector<core::Solution> b = {at(truth, 1, SolutionStatus::Float, {0.2, 0.0, 0.0})};
  for (const int t : {2, 3, 4, 5, 8, 9}) b.push_back(at(truth, t, SolutionStatus::Fixed, {0.0, 0.0, 0.01}));
  return b;
}

Result<EvaluationReport> report_ab(const Truth& truth, const ReportOptions& options = {}) {
  return evaluate_report({{"A", "a.pos", solution_a(truth)}, {"B", "b.pos", solution_b(truth)}}, truth, "truth.csv",
                         options);
}

TEST(Report, RatesOfAllRoverEpochs) {
  const Truth truth = gapped_truth();
  const auto report = report_ab(truth);
  ASSERT_TRUE(report.ok()) << report.error().to_string();
  // 8 truth epochs in the span 0..9 s joined with the solutions' 0..9 s: 10.
  EXPECT_EQ(report->epochs.epochs, 10);
  EXPECT_EQ(report->epochs.source, EpochSource::TruthEpochs);
  ASSERT_EQ(report->solutions.size(), 2u);
  const SolutionStats& a = report->solutions[0].stats;
  EXPECT_EQ(a.epochs_in, 10);
  EXPECT_EQ(a.epochs_with_solution, 10);
  EXPECT_DOUBLE_EQ(a.fixed().fraction_of_epochs_in, 0.6);
  EXPECT_DOUBLE_EQ(a.floating().fraction_of_epochs_in, 0.1);
  EXPECT_DOUBLE_EQ(a.of(StatusClass::Single).fraction_of_epochs_in, 0.1);
  EXPECT_DOUBLE_EQ(a.of(StatusClass::VioFillIn).fraction_of_epochs_in, 0.2);
  EXPECT_EQ(a.epochs_with_truth, 8);
  EXPECT_EQ(a.epochs_without_truth, 2);  // 6 and 7 s, in the truth's gap
  EXPECT_EQ(a.wrong_fixes, 1);           // 0.15 m at 4 s
  ASSERT_TRUE(report->solutions[0].wrong_fix_rate.has_value());
  EXPECT_DOUBLE_EQ(*report->solutions[0].wrong_fix_rate, 1.0 / 5.0);  // of 5 fixed epochs with truth
  ASSERT_TRUE(a.time_to_first_fix_s.has_value());
  EXPECT_DOUBLE_EQ(*a.time_to_first_fix_s, 2.0);

  const SolutionStats& b = report->solutions[1].stats;
  EXPECT_EQ(b.epochs_with_solution, 7);
  EXPECT_DOUBLE_EQ(b.fixed().fraction_of_epochs_in, 0.6);
  EXPECT_EQ(b.epochs_without_truth, 0);
  EXPECT_EQ(b.wrong_fixes, 0);
  EXPECT_DOUBLE_EQ(*b.time_to_first_fix_s, 2.0);  // from the first rover epoch (A's at 0 s)
  ASSERT_EQ(report->warnings.size(), 1u);
  EXPECT_NE(report->warnings[0].find("a.pos: 2 of 10 solved epochs have no truth"), std::string::npos);
}

TEST(Report, ApeStatisticsOfFixedEpochs) {
  const auto report = report_ab(gapped_truth());
  ASSERT_TRUE(report.ok());
  const ErrorStats& e = report->solutions[0].stats.fixed().error;
  ASSERT_EQ(e.count, 5);
  // 3D: 0.05, 0.02, 0.15, 0, 0.01 -> sorted 0, 0.01, 0.02, 0.05, 0.15
  const double mean_3d = (0.05 + 0.02 + 0.15 + 0.0 + 0.01) / 5.0;
  const double ms_3d = (0.0025 + 0.0004 + 0.0225 + 0.0 + 0.0001) / 5.0;
  EXPECT_NEAR(e.ape_3d.mean_m, mean_3d, kTolM);
  EXPECT_NEAR(e.ape_3d.rmse_m, std::sqrt(ms_3d), kTolM);
  EXPECT_NEAR(e.ape_3d.median_m, 0.02, kTolM);
  EXPECT_NEAR(e.ape_3d.std_m, std::sqrt(ms_3d - mean_3d * mean_3d), kTolM);
  EXPECT_NEAR(e.ape_3d.max_m, 0.15, kTolM);
  EXPECT_NEAR(e.ape_3d.p95_m, 0.05 + 0.8 * (0.15 - 0.05), kTolM);  // rank 0.95 * 4 = 3.8
  // Horizontal: 0.05, 0, 0.12, 0, 0.01 -> sorted 0, 0, 0.01, 0.05, 0.12
  const double mean_h = (0.05 + 0.12 + 0.01) / 5.0;
  const double ms_h = (0.0025 + 0.0144 + 0.0001) / 5.0;
  EXPECT_NEAR(e.ape_horizontal.mean_m, mean_h, kTolM);
  EXPECT_NEAR(e.ape_horizontal.rmse_m, std::sqrt(ms_h), kTolM);
  EXPECT_NEAR(e.ape_horizontal.median_m, 0.01, kTolM);
  EXPECT_NEAR(e.ape_horizontal.std_m, std::sqrt(ms_h - mean_h * mean_h), kTolM);
  EXPECT_NEAR(e.ape_horizontal.max_m, 0.12, kTolM);
  EXPECT_NEAR(e.ape_horizontal.p95_m, 0.05 + 0.8 * (0.12 - 0.05), kTolM);
}

TEST(Report, ApeStatisticsOverallAndOfOtherClasses) {
  const auto report = report_ab(gapped_truth());
  ASSERT_TRUE(report.ok());
  const SolutionStats& a = report->solutions[0].stats;
  // All 8 epochs with truth: sorted 0, 0.01, 0.02, 0.05, 0.15, 0.3, 1.0, 5.0
  const ErrorDistribution& d = a.overall.ape_3d;
  EXPECT_EQ(a.overall.count, 8);
  EXPECT_NEAR(d.mean_m, (0.01 + 0.02 + 0.05 + 0.15 + 0.3 + 1.0 + 5.0) / 8.0, kTolM);
  EXPECT_NEAR(d.median_m, 0.5 * (0.05 + 0.15), kTolM);    // rank 3.5
  EXPECT_NEAR(d.p95_m, 1.0 + 0.65 * (5.0 - 1.0), kTolM);  // rank 6.65
  EXPECT_NEAR(d.max_m, 5.0, kTolM);
  EXPECT_NEAR(a.overall.ape_horizontal.max_m, 5.0, kTolM);
  EXPECT_NEAR(a.of(StatusClass::VioFillIn).error.ape_3d.rmse_m, 1.0, kTolM);  // only 8 s has truth
  EXPECT_EQ(a.of(StatusClass::VioFillIn).error.count, 1);
  EXPECT_NEAR(a.floating().error.ape_3d.median_m, 0.3, kTolM);
  EXPECT_NEAR(a.floating().error.ape_horizontal.max_m, 0.0, kTolM);
  // B: six fixed epochs all 1 cm off: std 0.
  const ErrorStats& bf = report->solutions[1].stats.fixed().error;
  EXPECT_NEAR(bf.ape_3d.rmse_m, 0.01, kTolM);
  EXPECT_NEAR(bf.ape_3d.std_m, 0.0, 1e-9);
}

TEST(Report, EpochCountRules) {
  const Truth truth = gapped_truth();
  // Given: rates over the given count; fewer than solved is an error naming the file.
  ReportOptions given;
  given.epochs = EpochCount{20, EpochSource::Given, std::nullopt};
  const auto r20 = report_ab(truth, given);
  ASSERT_TRUE(r20.ok());
  EXPECT_DOUBLE_EQ(r20->solutions[0].stats.fixed().fraction_of_epochs_in, 0.3);
  given.epochs->epochs = 9;
  const auto r9 = report_ab(truth, given);
  ASSERT_FALSE(r9.ok());
  EXPECT_EQ(r9.error().file, "a.pos");
  EXPECT_NE(r9.error().message.find("10 solved epochs, but only 9 rover epochs"), std::string::npos);

  // A static truth has no epochs: the union of the solutions' epochs (B's 7 are all among A's 10).
  const Truth fixed_point = Truth::constant(truth.samples().front().p_E_m);
  const auto union_count = count_epochs(fixed_point, {solution_a(truth), solution_b(truth)}, 0.005);
  EXPECT_EQ(union_count.epochs, 10);
  EXPECT_EQ(union_count.source, EpochSource::SolutionEpochs);
  // Tags within the tolerance are one epoch.
  auto shifted = solution_b(truth);
  for (auto& s : shifted) s.time = s.time + 0.004;
  EXPECT_EQ(count_epochs(fixed_point, {solution_a(truth), shifted}, 0.005).epochs, 10);
  EXPECT_EQ(count_epochs(fixed_point, {solution_a(truth), shifted}, 0.003).epochs, 17);
  // Trajectory truth: only its epochs within the solutions' span count (B spans 1..9 s: truth 1-5, 8, 9).
  EXPECT_EQ(count_epochs(truth, {solution_b(truth)}, 0.005).epochs, 7);
  EXPECT_EQ(count_epochs(truth, {solution_b(truth)}, 0.005).first, kT0 + 1.0);
}

TEST(Report, TruthThatDoesNotOverlapIsAnError) {
  const Truth truth = gapped_truth();
  std::vector<core::Solution> later = solution_b(truth);
  for (auto& s : later) s.time = s.time + 3600.0;
  const auto report = evaluate_report({{"late", "late.pos", later}}, truth, "truth.csv");
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.error().file, "late.pos");
  EXPECT_NE(report.error().message.find("no solved epoch has truth"), std::string::npos) << report.error().message;
  EXPECT_NE(report.error().message.find("2023-01-08 11:00:01.000 - 2023-01-08 11:00:09.000 GPST"), std::string::npos)
      << report.error().message;
  EXPECT_NE(report.error().message.find("truth (truth.csv) 2023-01-08 10:00:00.000 - 2023-01-08 10:00:09.000 GPST"),
            std::string::npos)
      << report.error().message;
}

TEST(Report, EmptySolutionAndDenserTruthAreWarnings) {
  const Truth truth = gapped_truth();
  // Solutions every 2 s against a 1 s truth.
  std::vector<core::Solution> sparse;
  for (const int t : {0, 2, 4, 8}) sparse.push_back(at(truth, t, SolutionStatus::Fixed, {0, 0, 0}));
  const auto report = evaluate_report({{"sparse", "s.pos", sparse}, {"empty", "e.pos", {}}}, truth, "truth.csv");
  ASSERT_TRUE(report.ok()) << report.error().to_string();
  ASSERT_EQ(report->warnings.size(), 2u);
  EXPECT_EQ(report->warnings[0], "e.pos: no solutions");
  EXPECT_NE(report->warnings[1].find("the truth is sampled every 1 s, the solutions every 2 s"), std::string::npos)
      << report->warnings[1];
  EXPECT_EQ(report->solutions[1].stats.epochs_with_solution, 0);
  EXPECT_FALSE(report->solutions[1].wrong_fix_rate.has_value());
}

TEST(Report, TextTableSideBySide) {
  const auto report = report_ab(gapped_truth());
  ASSERT_TRUE(report.ok());
  const std::string table = format_text_table(*report);
  EXPECT_NE(table.find("truth: truth.csv (trajectory, 8 samples)"), std::string::npos) << table;
  EXPECT_NE(table.find("rover epochs: 10 (truth epochs within the solutions' span"), std::string::npos) << table;
  EXPECT_NE(table.find("                                             A :         B\n"
                       "epochs                                      10 :        10\n"
                       "solved (availability %)            10 (100.00) : 7 (70.00)\n"
                       "fixed (%)                            6 (60.00) : 6 (60.00)\n"
                       "float (%)                            1 (10.00) : 1 (10.00)\n"
                       "single (%)                           1 (10.00) :  0 (0.00)\n"
                       "fill-in (%)                          2 (20.00) :  0 (0.00)\n"
                       "wrong fixes > 0.10 m (% of fixed)    1 (20.00) :  0 (0.00)\n"
                       "correct fixes <= 0.10 m (%)          4 (40.00) : 6 (60.00)\n"
                       "horizontal error > 3 sigma (%)        0 (0.00) :  0 (0.00)\n"
                       "horizontal error > HPL (%)            0 (0.00) :  0 (0.00)\n"
                       "epochs without truth                         2 :         0\n"
                       "time to first fix (s)                      2.0 :       2.0\n"
                       "APE 3D, all epochs (m)\n"
                       "  epochs                                     8 :         7\n"
                       "  RMSE                                   1.807 :     0.076\n"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("APE 3D, fixed (m)\n"
                       "  epochs                                     5 :         6\n"
                       "  RMSE                                   0.071 :     0.010\n"
                       "  mean                                   0.046 :     0.010\n"
                       "  median                                 0.020 :     0.010\n"
                       "  std                                    0.055 :     0.000\n"
                       "  max                                    0.150 :     0.010\n"
                       "  p95                                    0.130 :     0.010\n"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("APE 3D, fill-in (m)\n"
                       "  epochs                                     1 :         0\n"
                       "  RMSE                                   1.000 :         -\n"),
            std::string::npos)
      << table;
  EXPECT_EQ(table.find("other (%)"), std::string::npos) << table;  // no other status anywhere
}

TEST(Report, MarkdownAndJson) {
  const auto report = report_ab(gapped_truth());
  ASSERT_TRUE(report.ok());
  const std::string md = format_markdown(*report);
  EXPECT_NE(md.find("| | A | B |\n|---|---:|---:|\n"), std::string::npos) << md;
  EXPECT_NE(md.find("| fixed (%) | 6 (60.00) | 6 (60.00) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| **APE 3D, all epochs (m)** | | |"), std::string::npos) << md;
  const std::string json = format_json(*report);
  for (const char* expected :
       {"\"format\": \"canyon-evaluate/1\"", "\"kind\": \"trajectory\", \"samples\": 8",
        "\"epochs\": {\"count\": 10, \"source\": \"truth+solutions\"}", "\"label\": \"A\"",
        "\"fixed\": {\"epochs\": 6, \"rate\": 0.6}", "\"fill_in\": {\"epochs\": 2, \"rate\": 0.2}",
        "\"wrong_fixes\": 1", "\"wrong_fix_rate\": 0.2", "\"correct_fixes\": 4", "\"correct_fix_rate\": 0.4",
        "\"epochs_without_truth\": 2", "\"time_to_first_fix_s\": 2",
        "\"other\": {\"epochs\": 0, \"3d\": null, \"horizontal\": null, \"vertical_rmse_m\": null}",
        "\"max_m\": 0.15, \"p95_m\": 0.13"}) {
    EXPECT_NE(json.find(expected), std::string::npos) << expected << "\n" << json;
  }
}

}  // namespace
}  // namespace canyon::eval
