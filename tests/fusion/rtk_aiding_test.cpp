// The RTK engine's aiding hook (rtk::RtkAiding), on a short simulated open-sky scenario: the prior is the state plus
// the increment with the covariance added, revert_to_prior() restores it, accept_fix vetoes fixes, the gates reject
// rows, and an aided epoch is solved without a single-point solution.

#include <filesystem>

#include <gtest/gtest.h>
#include <unistd.h>

#include "canyon/app/scenario_config.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/rtk/engine.hpp"
#include "canyon/sim/simulator.hpp"

namespace canyon::rtk {
namespace {

namespace fs = std::filesystem;

class RtkAidingTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto scenario = app::load_scenario((fs::path(CANYON_SOURCE_DIR) / "config/scenarios/open-sky.yaml").string());
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
  static RtkAiding truth_aiding(int k, double sigma_m) {
    RtkAiding a;
    a.delta_p_E_m = simulation_->truth[static_cast<std::size_t>(k)].p_E_m -
                    simulation_->truth[static_cast<std::size_t>(k - 1)].p_E_m;
    a.Q_E_m2 = Eigen::Matrix3d::Identity() * sigma_m * sigma_m;
    return a;
  }

  static sim::Simulation* simulation_;
  static gnss::EphemerisStore* ephemerides_;
};

sim::Simulation* RtkAidingTest::simulation_ = nullptr;
gnss::EphemerisStore* RtkAidingTest::ephemerides_ = nullptr;

TEST_F(RtkAidingTest, PriorIsTheStatePlusTheIncrementAndRevertRestoresIt) {
  RtkEngine engine(options(), *ephemerides_, simulation_->base_p_E_m);
  run(engine, 10);
  const Eigen::Vector3d p_before = engine.position_E_m();
  const Eigen::Matrix3d P_before = engine.position_covariance_E_m2();
  const RtkAiding aiding = truth_aiding(10, 0.01);
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

TEST_F(RtkAidingTest, AcceptFixVetoesEveryFix) {
  RtkEngine free_engine(options(), *ephemerides_, simulation_->base_p_E_m);
  RtkEngine vetoed(options(), *ephemerides_, simulation_->base_p_E_m);
  run(free_engine, 5);
  run(vetoed, 5);
  int fixed_free = 0, fixed_vetoed = 0, asked = 0;
  for (int k = 5; k < 60; ++k) {
    const core::ObsEpoch& e = simulation_->rover.epochs[static_cast<std::size_t>(k)];
    RtkAiding a = truth_aiding(k, 0.01);
    auto r1 = free_engine.process(e, base_at(e.time), &a);
    a.accept_fix = [&asked](const Eigen::Vector3d&, const Eigen::Matrix3d&) {
      ++asked;
      return false;
    };
    auto r2 = vetoed.process(e, base_at(e.time), &a);
    ASSERT_TRUE(r1.ok() && r2.ok());
    fixed_free += r1->solution.status == core::SolutionStatus::Fixed ? 1 : 0;
    fixed_vetoed += r2->solution.status == core::SolutionStatus::Fixed ? 1 : 0;
  }
  EXPECT_GT(fixed_free, 40);
  EXPECT_EQ(fixed_vetoed, 0);
  EXPECT_GT(asked, 0);
}

TEST_F(RtkAidingTest, GatesRejectRowsWhosePredictionIsGood) {
  // Fix-and-hold keeps the state at the fix: code rows are predicted to millimetres.
  RtkOptions hold = options();
  hold.ar_mode = ArMode::FixAndHold;
  RtkEngine engine(hold, *ephemerides_, simulation_->base_p_E_m);
  run(engine, 20);
  const core::ObsEpoch& e = simulation_->rover.epochs[20];
  RtkAiding a = truth_aiding(20, 0.01);
  a.max_code_innovation_m = 0.05;  // code noise is decimetres: most code rows
  auto r = engine.process(e, base_at(e.time), &a);
  ASSERT_TRUE(r.ok());
  EXPECT_GT(r->rejected.size(), 5U);
  engine.revert_to_prior();
  // A normalised gate of 0 sigmas rejects everything: no DD phase is left.
  RtkEngine engine2(options(), *ephemerides_, simulation_->base_p_E_m);
  run(engine2, 20);
  RtkAiding b = truth_aiding(20, 0.01);
  b.max_normalised_innovation = 0.0;
  auto r2 = engine2.process(e, base_at(e.time), &b);
  ASSERT_TRUE(r2.ok());
  EXPECT_EQ(r2->num_dd_measurements, 0);
}

TEST_F(RtkAidingTest, AnAidedEpochIsSolvedWithoutASinglePointSolution) {
  RtkEngine engine(options(), *ephemerides_, simulation_->base_p_E_m);
  run(engine, 20);
  // Three satellites of one constellation: no single-point solution, but DD phase against the prior.
  core::ObsEpoch e = simulation_->rover.epochs[20];
  std::erase_if(e.sats, [](const core::SatelliteObs& s) { return s.sat.system != core::Constellation::Gps; });
  e.sats.resize(3);
  RtkEngine unaided(options(), *ephemerides_, simulation_->base_p_E_m);
  run(unaided, 20);
  EXPECT_FALSE(unaided.process(e, base_at(e.time)).ok());
  const RtkAiding a = truth_aiding(20, 0.01);
  auto r = engine.process(e, base_at(e.time), &a);
  ASSERT_TRUE(r.ok()) << r.error().to_string();
  EXPECT_TRUE(r->aided);
  EXPECT_GT(r->num_dd_measurements, 0);
  EXPECT_LT((r->solution.p_E_m - simulation_->truth[20].p_E_m).norm(), 0.5);
}

}  // namespace
}  // namespace canyon::rtk
