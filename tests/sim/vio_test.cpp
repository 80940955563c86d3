// Simulated VIO: SE(3) helpers, drift after 1 km within the configured rate, errors consistent with the reported
// covariances (NEES within chi-square bounds over seeds), consecutive-pose cross-covariances consistent with the
// relative errors, device clock and time-sync pairs as configured, vio.csv as DESIGN.md describes it.

#include "canyon/sim/vio.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"
#include "canyon/sim/simulator.hpp"

#include "io/rinex_test_util.hpp"

namespace canyon::sim {
namespace {

constexpr int kSeeds = 40;
constexpr double kWalkM = 1000.0;
// Two-sided 99 % bounds of the mean of kSeeds chi-square(6) values: chi2_240(0.005, 0.995) / 40.
constexpr double kNeesLow = 4.63, kNeesHigh = 7.51;

Scenario straight_walk_scenario() {
  Scenario s;
  s.duration_s = kWalkM / s.route.speed_mps + 20.0;
  return s;
}

Trajectory straight_walk(const Scenario& s) {
  return Trajectory(Path::through({{0.0, 0.0}, {0.0, kWalkM + 100.0}}, s.route.turn_radius_m), s.route);
}

const VioSample& sample_at(const VioRun& run, double t_s, const Scenario& s) {
  const auto it = std::lower_bound(run.poses.begin(), run.poses.end(), t_s,
                                   [&](const VioSample& v, double t) { return (v.time - s.start) < t; });
  return it == run.poses.end() ? run.poses.back() : *it;
}

/// Right-perturbation error of the estimate: T_est = T_true Exp(xi).
Vector6d error_of(const VioSample& v) {
  return se3_log(v.T_OI_true.inverse() * v.T_OI);
}

double nees(const Vector6d& xi, const Matrix6d& P) {
  return xi.dot(P.ldlt().solve(xi));
}

TEST(VioTest, Se3ExpLogAndAdjoint) {
  Vector6d xi;
  xi << 1.0, -2.0, 0.5, 0.3, -0.2, 0.9;
  EXPECT_LT((se3_log(se3_exp(xi)) - xi).norm(), 1e-12);
  const Pose T = se3_exp((Vector6d() << 3.0, 1.0, -1.0, -0.4, 0.1, 1.2).finished());
  Vector6d small;
  small << 0.01, 0.02, -0.03, 0.001, -0.002, 0.003;
  const Pose lhs = se3_exp(se3_adjoint(T) * small);
  const Pose rhs = T * se3_exp(small) * T.inverse();
  EXPECT_LT((lhs.p - rhs.p).norm(), 1e-12);
  EXPECT_LT(lhs.q.angularDistance(rhs.q), 1e-12);
}

TEST(VioTest, DriftAfterOneKilometreIsTheConfiguredRate) {
  const Scenario s = straight_walk_scenario();
  const Trajectory walk = straight_walk(s);
  const double t_km_s = kWalkM / s.route.speed_mps;
  double sum_err2 = 0.0, sum_trace = 0.0;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const VioRun run = simulate_vio(s, walk, static_cast<std::uint64_t>(seed));
    const VioSample& v = sample_at(run, t_km_s, s);
    sum_err2 += (v.T_OI.p - v.T_OI_true.p).squaredNorm();
    sum_trace += v.covariance.topLeftCorner<3, 3>().trace();
  }
  const double rms_m = std::sqrt(sum_err2 / kSeeds);
  // Configured: translation random walk plus the lateral error of the heading random walk, sigma_yaw 1 km / sqrt(3).
  const double yaw_rad = s.vio.yaw_drift_deg_per_km * core::kDegToRad;
  const double expected_m =
      std::sqrt(std::pow(s.vio.position_drift_fraction * kWalkM, 2) + std::pow(yaw_rad * kWalkM, 2) / 3.0);
  EXPECT_NEAR(rms_m / expected_m, 1.0, 0.25) << "rms " << rms_m << " m, configured " << expected_m << " m";
  EXPECT_NEAR(std::sqrt(sum_trace / kSeeds) / expected_m, 1.0, 0.05);
  EXPECT_LT(rms_m / kWalkM, 0.0065);  // about 0.5 % of the distance
  std::printf("VIO drift after 1 km: rms %.2f m (%.2f %%), configured %.2f m, reported sigma %.2f m\n", rms_m,
              100.0 * rms_m / kWalkM, expected_m, std::sqrt(sum_trace / kSeeds));
}

TEST(VioTest, ErrorsAreConsistentWithTheCovariances) {
  const Scenario s = straight_walk_scenario();
  const Trajectory walk = straight_walk(s);
  for (const double t_s : {60.0, 300.0, 700.0}) {
    double sum = 0.0;
    for (int seed = 1; seed <= kSeeds; ++seed) {
      const VioRun run = simulate_vio(s, walk, static_cast<std::uint64_t>(seed) + 1000U);
      const VioSample& v = sample_at(run, t_s, s);
      sum += nees(error_of(v), v.covariance);
    }
    const double mean = sum / kSeeds;
    EXPECT_GT(mean, kNeesLow) << "at " << t_s << " s";
    EXPECT_LT(mean, kNeesHigh) << "at " << t_s << " s";
    std::printf("VIO NEES at %.0f s: %.2f (6 expected, 99 %% bounds %.2f..%.2f)\n", t_s, mean, kNeesLow, kNeesHigh);
  }
}

// Real VIO's errors as options: a scale error stretches the walked distance by exactly that fraction (the drift
// around it unchanged), and an over-confident covariance makes the NEES the optimism squared times too large.
TEST(VioTest, ScaleErrorAndOverConfidentCovariance) {
  Scenario s = straight_walk_scenario();
  const Trajectory walk = straight_walk(s);
  const double t_s = 600.0;
  Scenario scaled = s;
  scaled.vio.scale_error = 0.005;
  Scenario optimistic = s;
  optimistic.vio.covariance_optimism = 2.0;
  double sum_nees = 0.0, sum_optimistic_nees = 0.0, sum_stretch = 0.0;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const auto run_seed = static_cast<std::uint64_t>(seed) + 2000U;
    const VioRun honest_run = simulate_vio(s, walk, run_seed);
    const VioRun scaled_run = simulate_vio(scaled, walk, run_seed);
    const VioRun optimistic_run = simulate_vio(optimistic, walk, run_seed);
    const VioSample& v = sample_at(honest_run, t_s, s);
    const VioSample& w = sample_at(scaled_run, t_s, s);
    const VioSample& o = sample_at(optimistic_run, t_s, s);
    // Same drift, stretched: the scaled estimate's distance from the start is 0.5 % longer than the unscaled one's.
    sum_stretch += w.T_OI.p.norm() / v.T_OI.p.norm() - 1.0;
    // The scale error is not in the covariance (which differs only through the longer increments it is propagated
    // with).
    EXPECT_NEAR(w.covariance.trace() / v.covariance.trace(), 1.0, 0.02);
    EXPECT_EQ(o.T_OI.p, v.T_OI.p);  // the same poses ...
    sum_nees += nees(error_of(v), v.covariance);
    sum_optimistic_nees += nees(error_of(o), o.covariance);  // ... reported with a quarter of the covariance
  }
  EXPECT_NEAR(sum_stretch / kSeeds, 0.005, 0.0005);
  EXPECT_NEAR(sum_optimistic_nees / sum_nees, 4.0, 1e-6);
  std::printf("VIO scale error 0.5 %%: distance %.3f %% long; covariance optimism 2: NEES %.2f (honest %.2f)\n",
              100.0 * sum_stretch / kSeeds, sum_optimistic_nees / kSeeds, sum_nees / kSeeds);
}

TEST(VioTest, CrossCovarianceDescribesConsecutivePoses) {
  // The difference of consecutive errors has covariance P_k + P_k-1 - C - C^T with C = cov(xi_k-1, xi_k).
  Scenario s = straight_walk_scenario();
  s.duration_s = 300.0;
  const Trajectory walk = straight_walk(s);
  const VioRun run = simulate_vio(s, walk, 7);
  double sum = 0.0;
  int n = 0;
  for (std::size_t k = 1; k < run.poses.size(); ++k) {
    const VioSample& a = run.poses[k - 1];
    const VioSample& b = run.poses[k];
    const Matrix6d S = b.covariance + a.covariance - b.cross_previous - b.cross_previous.transpose();
    sum += nees(error_of(b) - error_of(a), S);
    ++n;
  }
  const double mean = sum / n;
  // n is about 3000: the mean of chi-square(6) values is 6 +- 6 sqrt(2 / (6 n)) = 6 +- 0.11 (1 sigma).
  EXPECT_NEAR(mean, 6.0, 0.5);
  std::printf("VIO consecutive-pose NEES: %.2f over %d pairs\n", mean, n);
}

TEST(VioTest, DeviceClockAndTimeSync) {
  Scenario s = straight_walk_scenario();
  s.duration_s = 120.0;
  const VioRun run = simulate_vio(s, straight_walk(s), 3);
  // Poses every 1 / rate of device time, at the configured clock offset and rate.
  ASSERT_GT(run.poses.size(), 1000U);
  for (std::size_t k = 1; k < run.poses.size(); ++k) {
    ASSERT_EQ(run.poses[k].t_ns - run.poses[k - 1].t_ns, 100000000);
  }
  const double scale = 1.0 + s.vio.device_clock_drift_ppm * 1e-6;
  for (const VioSample& v : {run.poses.front(), run.poses.back()}) {
    const double expected_ns = (s.vio.device_clock_offset_s + (v.time - s.start) * scale) * 1e9;
    EXPECT_NEAR(static_cast<double>(v.t_ns), expected_ns, 2.0);
  }
  // Time sync at every GPST second, jitter as configured.
  ASSERT_EQ(run.timesync.size(), 121U);
  double sum2 = 0.0;
  for (const TimeSyncSample& t : run.timesync) {
    EXPECT_EQ(t.time.tow_s, std::round(t.time.tow_s));
    const double expected_ns = (s.vio.device_clock_offset_s + (t.time - s.start) * scale) * 1e9;
    sum2 += std::pow((static_cast<double>(t.t_ns) - expected_ns) * 1e-9, 2);
  }
  EXPECT_NEAR(std::sqrt(sum2 / 121.0) / s.vio.timesync_jitter_s, 1.0, 0.25);
}

TEST(VioTest, FilesFollowTheContract) {
  Scenario s;
  s.duration_s = 20.0;
  io::test::TempDir tmp;
  auto sim = simulate(s, tmp.file("nav.rnx"));
  ASSERT_TRUE(sim.ok()) << sim.error().to_string();
  ASSERT_TRUE(write_simulation(*sim, tmp.file("")).ok());
  std::ifstream vio(tmp.file("vio.csv"));
  std::string line;
  ASSERT_TRUE(std::getline(vio, line));
  EXPECT_EQ(line.rfind("t_ns,px,py,pz,qx,qy,qz,qw,cov_0_0,", 0), 0U);
  std::size_t rows = 0;
  while (std::getline(vio, line)) {
    std::vector<double> values;
    std::stringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) values.push_back(std::stod(field));
    ASSERT_EQ(values.size(), 8U + 21U + 36U);
    const VioSample& v = sim->vio.poses[rows];
    EXPECT_EQ(static_cast<std::int64_t>(values[0]), v.t_ns);
    EXPECT_NEAR(values[1], v.T_OI.p.x(), 1e-6);
    EXPECT_NEAR(values[8], v.covariance(0, 0), 1e-9 * v.covariance(0, 0));
    ++rows;
  }
  EXPECT_EQ(rows, sim->vio.poses.size());
  std::ifstream sync(tmp.file("timesync.csv"));
  ASSERT_TRUE(std::getline(sync, line));
  EXPECT_EQ(line, "t_ns,gps_week,gps_tow_s");
  // The odometry frame maps the VIO's true pose onto the rover antenna truth: p_E_A = T_EO T_OI t_IA.
  const VioSample& v = sim->vio.poses[50];
  const Pose T_EI = sim->vio.T_EO * v.T_OI_true;
  const Eigen::Vector3d p_E_A = T_EI.p + T_EI.q * s.vio.t_IA_m;
  const auto& truth = sim->truth;
  const auto near = std::min_element(truth.begin(), truth.end(), [&](const TruthSample& a, const TruthSample& b) {
    return std::abs(a.time - v.time) < std::abs(b.time - v.time);
  });
  EXPECT_LT((p_E_A - near->p_E_m).norm(), 1.4 * std::abs(near->time - v.time) + 0.03);
}

}  // namespace
}  // namespace canyon::sim
