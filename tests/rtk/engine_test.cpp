// The RTK engine with an external motion (rtk::ExternalMotion), on a short simulated open-sky scenario: the prior is
// the state plus the increment with the covariance added, revert_to_prior() restores it, a caller that refuses every
// proposed fix gets none, an injected gate rejects rows, an epoch with an external motion is solved without a
// single-point solution, fewer than 4 satellites fix nothing, and a heading error state adds its share to the prior
// coherently and is learnt from the updates.

#include "canyon/rtk/engine.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "canyon/config/scenario_config.hpp"
#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/sim/simulator.hpp"

namespace canyon::rtk {
namespace {

namespace fs = std::filesystem;

/// A gate with a fixed code threshold (m) and a normalised one (|v| <= k sqrt(h P h^T + r)) on every row.
class ThresholdGate final : public InnovationGate {
 public:
  ThresholdGate(double max_code_m, double max_sigmas) : max_code_m_(max_code_m), max_sigmas_(max_sigmas) {}
  [[nodiscard]] bool passes(const DdInnovation& row) const override {
    const double v = std::abs(row.innovation_m());
    if (!row.phase() && v > max_code_m_) return false;
    return v <= max_sigmas_ * std::sqrt(row.predicted_variance_m2() + row.measurement_variance_m2());
  }

 private:
  double max_code_m_;
  double max_sigmas_;
};

class RtkEngineTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto scenario = config::load_scenario((fs::path(CANYON_SOURCE_DIR) / "config/scenarios/open-sky.yaml").string());
    ASSERT_TRUE(scenario.ok()) << scenario.error().to_string();
    scenario->duration_s = 20.0;
    const fs::path dir = fs::temp_directory_path() / ("canyon_rtk_aiding_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    auto sim = sim::simulate(*scenario, (dir / "nav.rnx").string());
    fs::remove_all(dir);
    ASSERT_TRUE(sim.ok()) << sim.error().to_string();
    simulation_ = new sim::Simulation(std::move(*sim));
    ephemerides_ = new gnss::EphemerisStore(simulation_->nav);
  }
  static void TearDownTestSuite() {
    delete ephemerides_;
    delete simulation_;
  }

  static RtkOptions options() {
    RtkOptions o;
    o.ionosphere = IonosphereModel::Estimate;
    return o;
  }
  static const core::ObsEpoch* base_at(const core::GpsTime& t) {
    const core::ObsEpoch* best = nullptr;
    for (const core::ObsEpoch& b : simulation_->base.epochs) {
      if (b.time - t <= 0.05) best = &b;
    }
    return best;
  }
  /// Runs epochs [0, n) unaided.
  static void run(RtkEngine& engine, int n) {
    for (int k = 0; k < n; ++k) {
      const core::ObsEpoch& e = simulation_->rover.epochs[static_cast<std::size_t>(k)];
      ASSERT_TRUE(engine.process(e, base_at(e.time)).ok());
    }
  }
  static ExternalMotion truth_motion(int k, double sigma_m) {
    ExternalMotion a;
    a.delta_p_E_m = simulation_->truth[static_cast<std::size_t>(k)].p_E_m -
                    simulation_->truth[static_cast<std::size_t>(k - 1)].p_E_m;
    a.Q_E_m2 = Eigen::Matrix3d::Identity() * sigma_m * sigma_m;
    return a;
  }

  static sim::Simulation* simulation_;
  static gnss::EphemerisStore* ephemerides_;
};

sim::Simulation* RtkEngineTest::simulation_ = nullptr;
gnss::EphemerisStore* RtkEngineTest::ephemerides_ = nullptr;

TEST_F(RtkEngineTest, PriorIsTheStatePlusTheIncrementAndRevertRestoresIt) {
  RtkEngine engine(options(), *ephemerides_, simulation_->base_p_E_m);
  run(engine, 10);
  const Eigen::Vector3d p_before = engine.position_E_m();
  const Eigen::Matrix3d P_before = engine.position_covariance_E_m2();
  const ExternalMotion aiding = truth_motion(10, 0.01);
  const core::ObsEpoch& e = simulation_->rover.epochs[10];
  auto r = engine.process(e, base_at(e.time), &aiding);
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r->aided);
  EXPECT_LT((r->prior_p_E_m - (p_before + aiding.delta_p_E_m)).norm(), 1e-9);
  EXPECT_LT((r->prior_P_E_m2 - (P_before + aiding.Q_E_m2)).norm(), 1e-12);
  EXPECT_GT(r->num_dd_measurements, 0);
  EXPECT_GT((engine.position_E_m() - r->prior_p_E_m).norm(), 0.0);  // the update moved the state
  EXPECT_LT((r->float_p_E_m - engine.position_E_m()).norm(), 1e-9);
  engine.revert_to_prior();
  EXPECT_LT((engine.position_E_m() - r->prior_p_E_m).norm(), 1e-9);
  EXPECT_LT((engine.position_covariance_E_m2() - r->prior_P_E_m2).norm(), 1e-12);
  ASSERT_TRUE(engine.state_time().has_value());
  EXPECT_DOUBLE_EQ(*engine.state_time() - e.time, 0.0);
}

TEST_F(RtkEngineTest, ACallerThatRefusesEveryProposedFixGetsNone) {
  RtkEngine free_engine(options(), *ephemerides_, simulation_->base_p_E_m);
  RtkEngine refusing(options(), *ephemerides_, simulation_->base_p_E_m);
  run(free_engine, 5);
  run(refusing, 5);
  int fixed_free = 0, fixed_refusing = 0, asked = 0;
  for (int k = 5; k < 60; ++k) {
    const core::ObsEpoch& e = simulation_->rover.epochs[static_cast<std::size_t>(k)];
    const ExternalMotion a = truth_motion(k, 0.01);
    auto r1 = free_engine.process(e, base_at(e.time), &a);
    ASSERT_TRUE(r1.ok());
    fixed_free += r1->solution.status == core::SolutionStatus::Fixed ? 1 : 0;
    auto more = refusing.predict(e, base_at(e.time), &a);
    ASSERT_TRUE(more.ok());
    if (*more && refusing.update()) {
      FixSearch& search = refusing.propose_fixes();
      while (const FixCandidate* candidate = search.next()) {
        EXPECT_TRUE(candidate->position_ok);
        EXPECT_GE(candidate->ratio, options().ratio_threshold);  // only candidates that pass rtk's own tests
        ++asked;
        search.decide(false);
      }
      refusing.conclude_fixes();
    }
    fixed_refusing += refusing.take_epoch().solution.status == core::SolutionStatus::Fixed ? 1 : 0;
  }
  EXPECT_GT(fixed_free, 40);
  EXPECT_EQ(fixed_refusing, 0);
  EXPECT_GT(asked, 0);
}

TEST_F(RtkEngineTest, GatesRejectRowsWhosePredictionIsGood) {
  // Fix-and-hold keeps the state at the fix: code rows are predicted to millimetres.
  RtkOptions hold = options();
  hold.ar_mode = ArMode::FixAndHold;
  RtkEngine engine(hold, *ephemerides_, simulation_->base_p_E_m);
  run(engine, 20);
  const core::ObsEpoch& e = simulation_->rover.epochs[20];
  const ExternalMotion a = truth_motion(20, 0.01);
  const ThresholdGate code_gate(0.05, 1e9);  // code noise is decimetres: most code rows
  auto r = engine.process(e, base_at(e.time), &a, &code_gate);
  ASSERT_TRUE(r.ok());
  EXPECT_GT(r->rejected.size(), 5U);
  engine.revert_to_prior();
  // A normalised gate of 0 sigmas rejects everything: no DD phase is left.
  RtkEngine engine2(options(), *ephemerides_, simulation_->base_p_E_m);
  run(engine2, 20);
  const ExternalMotion b = truth_motion(20, 0.01);
  const ThresholdGate zero_sigmas(1e9, 0.0);
  auto r2 = engine2.process(e, base_at(e.time), &b, &zero_sigmas);
  ASSERT_TRUE(r2.ok());
  EXPECT_EQ(r2->num_dd_measurements, 0);
}

TEST_F(RtkEngineTest, AnAidedEpochIsSolvedWithoutASinglePointSolution) {
  RtkEngine engine(options(), *ephemerides_, simulation_->base_p_E_m);
  run(engine, 20);
  // Three satellites of one constellation: no single-point solution, but DD phase against the prior.
  core::ObsEpoch e = simulation_->rover.epochs[20];
  std::erase_if(e.sats, [](const core::SatelliteObs& s) { return s.sat.system != core::Constellation::Gps; });
  e.sats.resize(3);
  RtkEngine unaided(options(), *ephemerides_, simulation_->base_p_E_m);
  run(unaided, 20);
  EXPECT_FALSE(unaided.process(e, base_at(e.time)).ok());
  const ExternalMotion a = truth_motion(20, 0.01);
  auto r = engine.process(e, base_at(e.time), &a);
  ASSERT_TRUE(r.ok()) << r.error().to_string();
  EXPECT_TRUE(r->aided);
  EXPECT_GT(r->num_dd_measurements, 0);
  EXPECT_LT((r->solution.p_E_m - simulation_->truth[20].p_E_m).norm(), 0.5);
}

TEST_F(RtkEngineTest, NoFixFromFewerThanFourSatellites) {
  // Fixed and held, then aided epochs with GPS satellites tracked on two frequencies only: three of them leave the
  // position open along a line that only the prior holds, so no fix is tried however good the prior (their four DD
  // ambiguities pass min_fix_ambiguities); all of them fix again.
  RtkOptions hold = options();
  hold.ar_mode = ArMode::FixAndHold;
  RtkEngine engine(hold, *ephemerides_, simulation_->base_p_E_m);
  run(engine, 20);
  const auto two_frequency_gps = [](const core::SatelliteObs& s) {
    const auto with_phase = std::count_if(s.signals.begin(), s.signals.end(), [](const core::SignalObs& signal) {
      return core::has_value(signal.carrier_phase_cyc);
    });
    return s.sat.system == core::Constellation::Gps && with_phase >= 2;
  };
  int fixed_three = 0, too_few_three = 0, fixed_all = 0, too_few_all = 0;
  for (int k = 20; k < 40; ++k) {
    core::ObsEpoch e = simulation_->rover.epochs[static_cast<std::size_t>(k)];
    std::erase_if(e.sats, [&](const core::SatelliteObs& s) { return !two_frequency_gps(s); });
    ASSERT_GE(e.sats.size(), 5U);
    // The highest three: well above the AR elevation mask.
    const Eigen::Vector3d& p_E = simulation_->truth[static_cast<std::size_t>(k)].p_E_m;
    const core::Geodetic at = core::ecef_to_geodetic(p_E);
    const auto elevation = [&](const core::SatelliteObs& s) {
      const auto state = ephemerides_->state(s.sat, e.time);
      return state ? core::azimuth_elevation(p_E, at, state->p_E_m).elevation_rad : -1.0;
    };
    std::sort(e.sats.begin(), e.sats.end(),
              [&](const core::SatelliteObs& l, const core::SatelliteObs& r) { return elevation(l) > elevation(r); });
    if (k < 30) e.sats.resize(3);
    const ExternalMotion a = truth_motion(k, 0.001);
    auto r = engine.process(e, base_at(e.time), &a);
    ASSERT_TRUE(r.ok()) << r.error().to_string();
    const bool fixed = r->solution.status == core::SolutionStatus::Fixed;
    (k < 30 ? fixed_three : fixed_all) += fixed ? 1 : 0;
    (k < 30 ? too_few_three : too_few_all) += r->too_few_to_fix ? 1 : 0;
  }
  EXPECT_EQ(fixed_three, 0);
  EXPECT_EQ(too_few_three, 10);
  EXPECT_EQ(too_few_all, 0);
  EXPECT_GT(fixed_all, 5);
}

TEST_F(RtkEngineTest, AHeadingErrorStateAddsItsShareOfTheIncrementsCoherently) {
  RtkOptions o = options();
  o.aiding_heading_state = true;
  RtkEngine engine(o, *ephemerides_, simulation_->base_p_E_m);
  run(engine, 10);
  const Eigen::Vector3d p0 = engine.position_E_m();
  const Eigen::Matrix3d P0 = engine.position_covariance_E_m2();
  EXPECT_FALSE(engine.heading_error().has_value());  // no aided epoch yet
  const double variance = 0.1 * 0.1;                 // rad^2
  const double noise = 1e-6;                         // rad^2 per epoch
  // Two aided epochs, time updates only: a constant heading error psi moves the position by (J_1 + J_2) psi, so its
  // share of the covariance is (J_1 + J_2) var (J_1 + J_2)^T (plus the second epoch's share of the first's noise),
  // not J_1 var J_1^T + J_2 var J_2^T as white noise per increment would give.
  Eigen::Vector3d dp_sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d Q_sum = Eigen::Matrix3d::Zero();
  std::vector<Eigen::Vector3d> J;
  for (int k = 10; k < 12; ++k) {
    const core::ObsEpoch& e = simulation_->rover.epochs[static_cast<std::size_t>(k)];
    ExternalMotion a = truth_motion(k, 0.01);
    a.dp_d_heading_E_m = Eigen::Vector3d(1.0, -2.0, 0.5) * (k - 8);  // any Jacobian, different per epoch
    a.heading_variance_rad2 = variance;
    a.heading_noise_rad2 = noise;
    a.restart_heading = k == 10;
    auto more = engine.predict(e, base_at(e.time), &a);
    ASSERT_TRUE(more.ok() && *more);
    const RtkEpoch r = engine.take_epoch();
    dp_sum += a.delta_p_E_m;
    Q_sum += a.Q_E_m2;
    J.push_back(a.dp_d_heading_E_m);
    EXPECT_LT((r.prior_p_E_m - (p0 + dp_sum)).norm(), 1e-9);  // psi starts at zero
  }
  const Eigen::Vector3d J_sum = J[0] + J[1];
  const Eigen::Matrix3d expected = P0 + Q_sum + J_sum * variance * J_sum.transpose() + J[1] * noise * J[1].transpose();
  EXPECT_LT((engine.position_covariance_E_m2() - expected).norm(), 1e-9 * expected.norm());
  ASSERT_TRUE(engine.heading_error().has_value());
  EXPECT_DOUBLE_EQ(engine.heading_error()->psi_rad, 0.0);
  EXPECT_NEAR(engine.heading_error()->variance_rad2, variance + 2.0 * noise, 1e-15);
  // An epoch without aiding ends the estimate; the next aided epoch restarts it though it does not ask to.
  const core::ObsEpoch& e12 = simulation_->rover.epochs[12];
  ASSERT_TRUE(engine.process(e12, base_at(e12.time)).ok());
  EXPECT_FALSE(engine.heading_error().has_value());
  const core::ObsEpoch& e13 = simulation_->rover.epochs[13];
  ExternalMotion a = truth_motion(13, 0.01);
  a.dp_d_heading_E_m = Eigen::Vector3d(0.3, 0.2, 0.0);
  a.heading_variance_rad2 = 0.04;
  a.heading_noise_rad2 = noise;
  auto more = engine.predict(e13, base_at(e13.time), &a);
  ASSERT_TRUE(more.ok() && *more);
  (void)engine.take_epoch();
  ASSERT_TRUE(engine.heading_error().has_value());
  EXPECT_NEAR(engine.heading_error()->variance_rad2, 0.04 + noise, 1e-15);
}

TEST_F(RtkEngineTest, TheUpdateLearnsAHeadingErrorFromHowGnssCorrectsTheIncrements) {
  // The increments are the truth's rotated by 3 degrees about the vertical: the filter's heading error state
  // converges to -3 degrees (the rotation that undoes it) once the rover has moved.
  RtkOptions o = options();
  o.aiding_heading_state = true;
  RtkEngine engine(o, *ephemerides_, simulation_->base_p_E_m);
  run(engine, 5);
  const double psi_true = 3.0 * core::kDegToRad;
  const Eigen::Vector3d up_E =
      core::rotation_enu_from_ecef(core::ecef_to_geodetic(simulation_->base_p_E_m)).row(2).transpose();
  const Eigen::Matrix3d R_error = Eigen::AngleAxisd(psi_true, up_E).toRotationMatrix();
  const int n = static_cast<int>(simulation_->rover.epochs.size());
  for (int k = 5; k < n; ++k) {
    const core::ObsEpoch& e = simulation_->rover.epochs[static_cast<std::size_t>(k)];
    ExternalMotion a = truth_motion(k, 0.002);
    a.delta_p_E_m = R_error * a.delta_p_E_m;
    a.dp_d_heading_E_m = up_E.cross(a.delta_p_E_m);
    a.heading_variance_rad2 = std::pow(10.0 * core::kDegToRad, 2);
    a.restart_heading = k == 5;
    ASSERT_TRUE(engine.process(e, base_at(e.time), &a).ok());
  }
  ASSERT_TRUE(engine.heading_error().has_value());
  const double sigma = std::sqrt(engine.heading_error()->variance_rad2);
  EXPECT_NEAR(engine.heading_error()->psi_rad, -psi_true, std::max(3.0 * sigma, 0.2 * psi_true));
  EXPECT_LT(sigma, 0.5 * psi_true);
  std::printf("heading error: %.3f deg (truth %.3f), sigma %.3f deg\n",
              engine.heading_error()->psi_rad / core::kDegToRad, -psi_true / core::kDegToRad, sigma / core::kDegToRad);
}

}  // namespace
}  // namespace canyon::rtk
