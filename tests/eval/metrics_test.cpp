// Metrics on hand-made solution sets whose answers are worked out by hand; each metric has a case that fails if
// it is computed wrongly.

#include "canyon/eval/metrics.hpp"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"

namespace canyon::eval {
namespace {

constexpr double kTolM = 1e-9;
const core::Geodetic kOrigin{45.0 * core::kDegToRad, 10.0 * core::kDegToRad, 100.0};
const core::GpsTime kT0{2244, 36000.0};

core::Solution at_enu(double t_offset_s, core::SolutionStatus status, const Eigen::Vector3d& d_N_m) {
  core::Solution s;
  s.time = kT0 + t_offset_s;
  s.status = status;
  s.p_E_m = core::geodetic_to_ecef(kOrigin) + core::enu_to_ecef(d_N_m, kOrigin);
  return s;
}

using core::SolutionStatus;

// Fixed errors (ENU, m): (0.03, 0.04, 0), (0, 0, 0.12), 0, (0.6, 0, 0.8): 3D 0.05, 0.12, 0, 1.0.
std::vector<core::Solution> mixed_set() {
  return {
      at_enu(0, SolutionStatus::Single, {1.0, 0.0, 0.0}),    at_enu(1, SolutionStatus::Float, {0.0, 0.2, 0.0}),
      at_enu(2, SolutionStatus::Fixed, {0.03, 0.04, 0.0}),   at_enu(3, SolutionStatus::Fixed, {0.0, 0.0, 0.12}),
      at_enu(4, SolutionStatus::None, {0.0, 0.0, 0.0}),      at_enu(5, SolutionStatus::Fixed, {0.0, 0.0, 0.0}),
      at_enu(6, SolutionStatus::Fixed, {0.6, 0.0, 0.8}),     at_enu(7, SolutionStatus::Float, {0.0, 0.0, -0.4}),
      at_enu(8, SolutionStatus::VioFillIn, {0.3, 0.4, 0.0}), at_enu(9, SolutionStatus::Float, {0.0, 0.0, 0.0}),
  };
}

TEST(Evaluate, CountsAndRatesPerStatus) {
  const auto stats = evaluate(mixed_set(), nullptr);
  ASSERT_TRUE(stats.ok()) << stats.error().to_string();
  EXPECT_EQ(stats->epochs_in, 10);
  EXPECT_EQ(stats->epochs_with_solution, 9);
  EXPECT_EQ(stats->fixed().epochs, 4);
  EXPECT_EQ(stats->floating().epochs, 3);
  EXPECT_EQ(stats->of(StatusClass::Single).epochs, 1);
  EXPECT_EQ(stats->of(StatusClass::VioFillIn).epochs, 1);
  EXPECT_EQ(stats->of(StatusClass::Other).epochs, 0);
  EXPECT_DOUBLE_EQ(stats->fixed().fraction_of_solved, 4.0 / 9.0);
  EXPECT_DOUBLE_EQ(stats->fixed().fraction_of_epochs_in, 0.4);
  EXPECT_FALSE(stats->has_truth);
  EXPECT_EQ(stats->overall.count, 0);
}

TEST(Evaluate, EpochsInFromTheCaller) {
  EvalOptions options;
  options.epochs_in = 20;
  const auto stats = evaluate(mixed_set(), nullptr, options);
  ASSERT_TRUE(stats.ok());
  EXPECT_EQ(stats->epochs_in, 20);
  EXPECT_DOUBLE_EQ(stats->fixed().fraction_of_epochs_in, 0.2);
  EXPECT_DOUBLE_EQ(stats->fixed().fraction_of_solved, 4.0 / 9.0);
}

TEST(Evaluate, ErrorsOfFixedEpochsInEnuAtTheTruth) {
  const Truth truth = Truth::constant(core::geodetic_to_ecef(kOrigin));
  const auto stats = evaluate(mixed_set(), truth);
  ASSERT_TRUE(stats.ok());
  const ErrorStats& e = stats->fixed().error;
  EXPECT_EQ(e.count, 4);
  EXPECT_NEAR(e.horizontal_rmse_m, std::sqrt((0.05 * 0.05 + 0.6 * 0.6) / 4), kTolM);
  EXPECT_NEAR(e.horizontal_max_m, 0.6, kTolM);
  EXPECT_NEAR(e.vertical_rmse_m, std::sqrt((0.12 * 0.12 + 0.8 * 0.8) / 4), kTolM);
  EXPECT_NEAR(e.rmse_3d_m, std::sqrt((0.05 * 0.05 + 0.12 * 0.12 + 1.0) / 4), kTolM);
  EXPECT_NEAR(e.max_3d_m, 1.0, kTolM);
  // sorted 3D errors 0, 0.05, 0.12, 1.0; rank 0.95 * 3 = 2.85
  EXPECT_NEAR(e.p95_3d_m, 0.12 + 0.85 * (1.0 - 0.12), kTolM);
}

TEST(Evaluate, ApeDistributionOfFixedEpochs) {
  const Truth truth = Truth::constant(core::geodetic_to_ecef(kOrigin));
  const auto stats = evaluate(mixed_set(), truth);
  ASSERT_TRUE(stats.ok());
  // 3D 0, 0.05, 0.12, 1.0; horizontal 0, 0, 0.05, 0.6
  const ErrorDistribution& d = stats->fixed().error.ape_3d;
  const double mean = (0.05 + 0.12 + 1.0) / 4;
  const double mean_sq = (0.0025 + 0.0144 + 1.0) / 4;
  EXPECT_NEAR(d.mean_m, mean, kTolM);
  EXPECT_NEAR(d.rmse_m, std::sqrt(mean_sq), kTolM);
  EXPECT_NEAR(d.median_m, (0.05 + 0.12) / 2, kTolM);
  EXPECT_NEAR(d.std_m, std::sqrt(mean_sq - mean * mean), kTolM);
  EXPECT_NEAR(d.max_m, 1.0, kTolM);
  EXPECT_NEAR(d.p95_m, stats->fixed().error.p95_3d_m, kTolM);
  const ErrorDistribution& h = stats->fixed().error.ape_horizontal;
  EXPECT_NEAR(h.mean_m, 0.65 / 4, kTolM);
  EXPECT_NEAR(h.median_m, 0.025, kTolM);
  EXPECT_NEAR(h.max_m, 0.6, kTolM);
  EXPECT_NEAR(h.rmse_m, stats->fixed().error.horizontal_rmse_m, kTolM);
  // Epochs without truth: none for a static truth, all without one.
  EXPECT_EQ(stats->epochs_without_truth, 0);
  const auto no_truth = evaluate(mixed_set(), nullptr);
  ASSERT_TRUE(no_truth.ok());
  EXPECT_EQ(no_truth->epochs_without_truth, 0);
}

TEST(Evaluate, ErrorsOfOtherClassesAndOverall) {
  const Truth truth = Truth::constant(core::geodetic_to_ecef(kOrigin));
  const auto stats = evaluate(mixed_set(), truth);
  ASSERT_TRUE(stats.ok());
  const ErrorStats& fl = stats->floating().error;
  EXPECT_EQ(fl.count, 3);
  EXPECT_NEAR(fl.horizontal_rmse_m, std::sqrt(0.04 / 3), kTolM);
  EXPECT_NEAR(fl.vertical_rmse_m, std::sqrt(0.16 / 3), kTolM);
  EXPECT_NEAR(stats->of(StatusClass::Single).error.rmse_3d_m, 1.0, kTolM);
  EXPECT_NEAR(stats->of(StatusClass::VioFillIn).error.rmse_3d_m, 0.5, kTolM);
  EXPECT_EQ(stats->overall.count, 9);
  const double sum_sq = 1.0 + 0.04 + 0.0025 + 0.0144 + 0 + 1.0 + 0.16 + 0.25 + 0;
  EXPECT_NEAR(stats->overall.rmse_3d_m, std::sqrt(sum_sq / 9), kTolM);
  EXPECT_NEAR(stats->overall.max_3d_m, 1.0, kTolM);
  EXPECT_EQ(stats->epochs_with_truth, 9);
}

TEST(Evaluate, WrongFixesAboveTheThreshold) {
  const Truth truth = Truth::constant(core::geodetic_to_ecef(kOrigin));
  const auto default_threshold = evaluate(mixed_set(), truth);
  ASSERT_TRUE(default_threshold.ok());
  EXPECT_EQ(default_threshold->wrong_fixes, 2);  // 0.12 and 1.0 m; float and single epochs never count
  EvalOptions options;
  options.wrong_fix_threshold_m = 0.5;
  const auto loose = evaluate(mixed_set(), truth, options);
  ASSERT_TRUE(loose.ok());
  EXPECT_EQ(loose->wrong_fixes, 1);
}

TEST(Evaluate, HorizontalErrorsBeyondThreeSigmaOfTheirOwnCovariance) {
  // sigma 0.1 m east, 0.01 m north (ECEF covariance from ENU): 0.25 m east is 2.5 sigma, 0.05 m north 5 sigma.
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(kOrigin);
  const Eigen::Matrix3d P_N = Eigen::Vector3d(0.01, 1e-4, 0.04).asDiagonal();
  const auto with_sigma = [&](core::Solution s) {
    s.P_E_m2 = R_NE.transpose() * P_N * R_NE;
    return s;
  };
  std::vector<core::Solution> set = {
      // 2.5 sigma: within (the 0.5 m up is not horizontal)
      with_sigma(at_enu(0, SolutionStatus::Fixed, {0.25, 0.0, 0.5})),
      with_sigma(at_enu(1, SolutionStatus::Float, {0.0, 0.05, 0.0})),  // 5 sigma: beyond
      with_sigma(at_enu(2, SolutionStatus::Float, {0.0, 0.0, 0.0})),
      at_enu(3, SolutionStatus::Single, {5.0, 0.0, 0.0}),  // no covariance: not judged
  };
  const auto stats = evaluate(set, Truth::constant(core::geodetic_to_ecef(kOrigin)));
  ASSERT_TRUE(stats.ok());
  EXPECT_EQ(stats->epochs_with_covariance, 3);
  EXPECT_EQ(stats->beyond_3_sigma_horizontal, 1);
  // The protection level, 6 sigma of the major axis (0.1 m east): 0.6 m. 5 sigma north is within it.
  EXPECT_EQ(stats->beyond_protection_level, 0);
  set.push_back(with_sigma(at_enu(4, SolutionStatus::Fixed, {0.0, 0.61, 0.0})));   // 0.61 m > 0.6 m
  set.push_back(with_sigma(at_enu(5, SolutionStatus::Fixed, {0.42, 0.42, 0.0})));  // 0.594 m: within
  const auto more = evaluate(set, Truth::constant(core::geodetic_to_ecef(kOrigin)));
  ASSERT_TRUE(more.ok());
  EXPECT_EQ(more->beyond_protection_level, 1);
  EXPECT_EQ(more->beyond_3_sigma_horizontal, 3);
}

TEST(Evaluate, TimeToFirstFix) {
  const auto stats = evaluate(mixed_set(), nullptr);
  ASSERT_TRUE(stats.ok());
  ASSERT_TRUE(stats->time_to_first_fix_s.has_value());
  EXPECT_DOUBLE_EQ(*stats->time_to_first_fix_s, 2.0);

  EvalOptions options;
  options.first_epoch = kT0 - 3.0;
  const auto from_start = evaluate(mixed_set(), nullptr, options);
  ASSERT_TRUE(from_start.ok());
  EXPECT_DOUBLE_EQ(*from_start->time_to_first_fix_s, 5.0);

  // Order of records does not matter: time does.
  auto reversed = mixed_set();
  std::reverse(reversed.begin(), reversed.end());
  const auto rev = evaluate(reversed, nullptr);
  ASSERT_TRUE(rev.ok());
  EXPECT_DOUBLE_EQ(*rev->time_to_first_fix_s, 2.0);

  const std::vector<core::Solution> never = {at_enu(0, SolutionStatus::Float, {0, 0, 0})};
  const auto none = evaluate(never, nullptr);
  ASSERT_TRUE(none.ok());
  EXPECT_FALSE(none->time_to_first_fix_s.has_value());
}

TEST(Evaluate, EpochsOutsideTheTruthSpanHaveNoError) {
  const Eigen::Vector3d p0 = core::geodetic_to_ecef(kOrigin);
  auto truth = Truth::from_samples({{kT0, p0}, {kT0 + 1.0, p0}});
  ASSERT_TRUE(truth.ok());
  const auto stats = evaluate(mixed_set(), *truth);
  ASSERT_TRUE(stats.ok());
  EXPECT_EQ(stats->epochs_with_solution, 9);
  EXPECT_EQ(stats->epochs_with_truth, 2);  // t0 (single) and t0 + 1 (float)
  EXPECT_EQ(stats->epochs_without_truth, 7);
  EXPECT_EQ(stats->fixed().error.count, 0);
}

TEST(Evaluate, RejectsDuplicateTimesAndBadOptions) {
  auto twice = mixed_set();
  twice.push_back(at_enu(3.004, SolutionStatus::Fixed, {0, 0, 0}));
  EXPECT_FALSE(evaluate(twice, nullptr).ok());
  EvalOptions bad;
  bad.wrong_fix_threshold_m = 0.0;
  const auto result = evaluate(mixed_set(), nullptr, bad);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().message.find("wrong_fix_threshold_m"), std::string::npos);
}

TEST(Compare, MatchesEpochsWithinTheToleranceAndMeasuresFixedDistances) {
  // b's tags 4 ms after a's (as a rover/base pair 5 ms apart would carry), except one 6 ms off: not the same epoch.
  const std::vector<core::Solution> a = {
      at_enu(0, SolutionStatus::Fixed, {0, 0, 0}), at_enu(1, SolutionStatus::Fixed, {0, 0, 0}),
      at_enu(2, SolutionStatus::Fixed, {0, 0, 0}), at_enu(3, SolutionStatus::Float, {0, 0, 0}),
      at_enu(4, SolutionStatus::Fixed, {0, 0, 0}), at_enu(5, SolutionStatus::None, {0, 0, 0}),
      at_enu(6, SolutionStatus::Fixed, {0, 0, 0}),
  };
  const std::vector<core::Solution> b = {
      at_enu(0.004, SolutionStatus::Fixed, {0.03, 0, 0}), at_enu(1.004, SolutionStatus::Fixed, {0, 0.04, 0}),
      at_enu(2.006, SolutionStatus::Fixed, {5, 0, 0}),    at_enu(3.004, SolutionStatus::Fixed, {0, 0, 2}),
      at_enu(4.004, SolutionStatus::Float, {0, 0, 0.5}),  at_enu(5.004, SolutionStatus::Fixed, {0, 0, 0}),
      at_enu(5.996, SolutionStatus::Fixed, {0, 0, 0}),
  };
  const auto agreement = compare(a, b);
  ASSERT_TRUE(agreement.ok()) << agreement.error().to_string();
  EXPECT_EQ(agreement->epochs_a, 6);
  EXPECT_EQ(agreement->epochs_b, 7);
  EXPECT_EQ(agreement->matched, 5);  // t 0, 1, 3, 4, 6 (2 is 6 ms off, 5 unsolved in a)
  EXPECT_EQ(agreement->both_fixed, 3);
  EXPECT_EQ(agreement->only_a_fixed, 1);
  EXPECT_EQ(agreement->only_b_fixed, 1);
  EXPECT_NEAR(agreement->max_distance_fixed_m, 0.04, 1e-6);
  EXPECT_NEAR(agreement->rms_distance_fixed_m, std::sqrt((0.03 * 0.03 + 0.04 * 0.04) / 3), 1e-6);
  EXPECT_NEAR(agreement->max_distance_matched_m, 2.0, 1e-6);

  const auto strict = compare(a, b, 0.003);
  ASSERT_TRUE(strict.ok());
  EXPECT_EQ(strict->matched, 0);
  EXPECT_FALSE(compare(a, b, 0.0).ok());
}

TEST(Format, TableNamesEveryFigure) {
  const Truth truth = Truth::constant(core::geodetic_to_ecef(kOrigin));
  const auto stats = evaluate(mixed_set(), truth);
  ASSERT_TRUE(stats.ok());
  const std::string table = format_stats(*stats, "mixed");
  EXPECT_NE(table.find("epochs in 10, with solution 9"), std::string::npos) << table;
  EXPECT_NE(table.find("fixed         4    44.4    40.0      4    0.301    0.404    0.504    1.000    0.868"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("wrong fixes (3D error > 0.100 m): 2 of 4 fixed"), std::string::npos) << table;
  EXPECT_NE(table.find("time to first fix: 2.0 s"), std::string::npos) << table;
  const std::string kv = format_key_values(*stats, std::nullopt);
  EXPECT_EQ(kv,
            "epochs_in=10 solved=9 fixed=4 float=3 fixed_pct=40.0 float_pct=30.0 rmse_3d_m=0.5235 wrong_fixes=2 "
            "ttff_s=2.0");
}

}  // namespace
}  // namespace canyon::eval
