// The DD measurement update (rtk/dd_update.hpp) on a synthetic epoch (synthetic_epoch.hpp): the rows against the
// highest satellite, the update that brings the prior to the truth, the post-fit rejection of a code outlier, the
// fixed innovation limits and an injected gate (a phase its prediction cannot test taking its code's verdict; every
// phase of a signal whose code is refused, for a gate that refuses signals with their code), and
// float validation when more outliers remain than may be rejected.

#include "canyon/rtk/dd_update.hpp"

#include <algorithm>

#include <gtest/gtest.h>

#include "synthetic_epoch.hpp"

namespace canyon::rtk {
namespace {

using testing::synthetic_epoch;

const Eigen::Vector3d kOffsetM(1.2, -0.8, 2.0);  // the truth from the prior

testing::SyntheticEpoch epoch(int count = 8) {
  // Ambiguities known to a tenth of a cycle, so that the phase pins the position.
  return synthetic_epoch(count, kOffsetM, 100.0, 0.01,
                         [](int /*i*/, int integer) { return static_cast<double>(integer); });
}

TEST(DdUpdate, RowsAreFormedAgainstTheHighestSatelliteOfTheGroup) {
  testing::SyntheticEpoch e = epoch();
  const std::vector<DdRow> rows = dd_rows(e.state, e.sds);
  ASSERT_EQ(rows.size(), 2U * (e.sds.size() - 1));  // phase then code
  for (std::size_t k = 0; k < rows.size(); ++k) {
    EXPECT_EQ(rows[k].phase, k < e.sds.size() - 1);
    EXPECT_EQ(rows[k].reference, 0);  // satellite 1 is the highest
    const SingleDiff& sd = e.sds[static_cast<std::size_t>(rows[k].sd)];
    EXPECT_EQ(rows[k].h_pos, -(sd.los_E - e.sds[0].los_E));
    // At the true integers the phase innovation is the geometry alone, as the code's.
    EXPECT_NEAR(rows[k].innovation_m, rows[k].h_pos.dot(kOffsetM), 1e-9);
  }
}

// A code multipath state enters its signal's code rows (+1, the reference's -1) and nothing else.
TEST(DdUpdate, CodeRowsCarryTheCodeMultipathStates) {
  testing::SyntheticEpoch e = epoch(4);
  std::vector<FilterState::NewState> added;
  for (const SingleDiff& sd : e.sds) added.push_back({StateKey::code_bias(sd.sat, sd.frequency), 0.0, 1.0});
  e.state.add(added);
  for (SingleDiff& sd : e.sds) sd.code_bias = e.state.index(StateKey::code_bias(sd.sat, sd.frequency));
  Eigen::VectorXd x = e.state.x();
  x[e.sds[2].code_bias] = 0.7;  // the filter's estimate of satellite 3's code error, which the code carries
  e.state.restore_values(x, e.state.P());
  e.sds[2].code_m += 0.7;
  for (const DdRow& row : dd_rows(e.state, e.sds)) {
    EXPECT_NEAR(row.innovation_m, row.h_pos.dot(kOffsetM), 1e-9);  // the code error predicted away
    int code_entries = 0;
    for (int k = 0; k < row.num_entries; ++k) {
      const auto [index, coefficient] = row.entries[static_cast<std::size_t>(k)];
      if (!e.state.key_at(index).code_bias()) continue;
      ++code_entries;
      EXPECT_DOUBLE_EQ(coefficient, index == e.sds[static_cast<std::size_t>(row.sd)].code_bias ? 1.0 : -1.0);
    }
    EXPECT_EQ(code_entries, row.phase ? 0 : 2);
  }
}

TEST(DdUpdate, TheUpdateBringsThePriorToTheTruth) {
  testing::SyntheticEpoch e = epoch();
  std::vector<core::SatelliteId> rejected;
  const DdUpdateResult r = dd_measurement_update(e.state, e.sds, RtkOptions{}, nullptr, rejected);
  EXPECT_EQ(r.phase_rows, 7);
  EXPECT_EQ(r.code_rows, 7);
  EXPECT_TRUE(r.consistent);
  EXPECT_TRUE(rejected.empty());
  EXPECT_LT((e.state.position_E_m() - kOffsetM).norm(), 0.01);
  EXPECT_LT(e.state.position_covariance_E_m2().trace(), 1.0);
}

TEST(DdUpdate, ACodeOutlierIsRejectedAfterTheFitAndTheUpdateRedone) {
  testing::SyntheticEpoch e = epoch();
  e.sds[4].code_m += 50.0;  // within the 100 m innovation limit: only the post-fit test sees it
  std::vector<core::SatelliteId> rejected;
  const DdUpdateResult r = dd_measurement_update(e.state, e.sds, RtkOptions{}, nullptr, rejected);
  ASSERT_EQ(rejected.size(), 1U);
  EXPECT_EQ(rejected[0], e.sds[4].sat);
  EXPECT_FALSE(core::has_value(e.sds[4].code_m));
  EXPECT_TRUE(r.consistent);
  EXPECT_EQ(r.code_rows, 6);
  EXPECT_LT((e.state.position_E_m() - kOffsetM).norm(), 0.01);
}

TEST(DdUpdate, MoreOutliersThanRejectionsLeaveTheFloatInconsistent) {
  testing::SyntheticEpoch e = epoch();
  RtkOptions options;
  options.max_post_fit_rejections = 1;
  e.sds[3].code_m += 40.0;
  e.sds[5].code_m -= 60.0;
  e.sds[6].code_m += 30.0;
  std::vector<core::SatelliteId> rejected;
  const DdUpdateResult r = dd_measurement_update(e.state, e.sds, options, nullptr, rejected);
  EXPECT_FALSE(r.consistent);
  EXPECT_GT(r.worst_post_fit_normalised, 1.0);
  EXPECT_EQ(rejected.size(), 1U);
}

TEST(DdUpdate, FixedLimitsAndAnInjectedGateDropRowsAndTheirAmbiguitiesAreNotFixed) {
  testing::SyntheticEpoch e = epoch();
  RtkOptions options;
  options.max_phase_innovation_m = 1.0;  // rows whose geometry alone moves them more than 1 m
  std::vector<DdRow> rows = dd_rows(e.state, e.sds);
  const auto beyond = static_cast<int>(std::count_if(
      rows.begin(), rows.end(), [](const DdRow& row) { return row.phase && std::abs(row.innovation_m) > 1.0; }));
  ASSERT_GT(beyond, 0);
  std::vector<core::SatelliteId> rejected;
  const DdUpdateResult r = dd_measurement_update(e.state, e.sds, options, nullptr, rejected);
  EXPECT_EQ(r.phase_rows, 7 - beyond);
  EXPECT_EQ(static_cast<int>(rejected.size()), beyond);
  for (const core::SatelliteId& sat : rejected) {
    const auto it = std::find_if(e.sds.begin(), e.sds.end(), [&](const SingleDiff& sd) { return sd.sat == sat; });
    EXPECT_FALSE(it->fixable);
  }
  // A gate refusing every row leaves no update; it was asked about each row.
  struct RefuseAll final : InnovationGate {
    [[nodiscard]] bool passes(const DdInnovation& /*row*/) const override {
      ++asked;
      return false;
    }
    mutable int asked = 0;
  } refuse_all;
  testing::SyntheticEpoch f = epoch();
  const Eigen::VectorXd x0 = f.state.x();
  rejected.clear();
  const DdUpdateResult none = dd_measurement_update(f.state, f.sds, RtkOptions{}, &refuse_all, rejected);
  EXPECT_EQ(none.phase_rows, 0);
  EXPECT_EQ(refuse_all.asked, 14);
  EXPECT_EQ(rejected.size(), 14U);
  EXPECT_EQ(f.state.x(), x0);
  EXPECT_TRUE(
      std::none_of(f.sds.begin(), f.sds.end(), [](const SingleDiff& sd) { return sd.fixable && sd.sat.prn > 1; }));
}

TEST(DdUpdate, APhaseItsPredictionCannotTestTakesTheVerdictOfItsCode) {
  // A reflected signal: code and phase both carry 30 m of extra path. The gate refuses the code; the phase of a new
  // ambiguity (sigma 30 cycles) tells the gate nothing and must not start that ambiguity from the reflection.
  struct RefuseFarCode final : InnovationGate {
    [[nodiscard]] bool passes(const DdInnovation& row) const override {
      return row.phase() || std::abs(row.innovation_m()) < 5.0;
    }
  } gate;
  const auto reflected_epoch = [](double ambiguity_var_cyc2, double phase_extra_m) {
    testing::SyntheticEpoch e = synthetic_epoch(8, Eigen::Vector3d::Zero(), 1e-4, 0.01,
                                                [](int /*i*/, int integer) { return static_cast<double>(integer); });
    Eigen::MatrixXd P = e.state.P();
    P(e.sds[4].ambiguity, e.sds[4].ambiguity) = ambiguity_var_cyc2;
    e.state.restore_values(e.state.x(), P);
    e.sds[4].code_m += 30.0;
    e.sds[4].phase_m += phase_extra_m;
    return e;
  };
  testing::SyntheticEpoch fresh = reflected_epoch(900.0, 30.0);
  std::vector<core::SatelliteId> rejected;
  const DdUpdateResult r = dd_measurement_update(fresh.state, fresh.sds, RtkOptions{}, &gate, rejected);
  EXPECT_EQ(r.phase_rows, 6);
  EXPECT_EQ(r.code_rows, 6);
  EXPECT_EQ(std::count(rejected.begin(), rejected.end(), fresh.sds[4].sat), 2);  // its code and its phase
  EXPECT_FALSE(fresh.sds[4].fixable);
  // Code multipath on a signal whose ambiguity is known to a tenth of a cycle: its phase is tested by its own
  // prediction and kept.
  testing::SyntheticEpoch known = reflected_epoch(0.01, 0.0);
  rejected.clear();
  const DdUpdateResult k = dd_measurement_update(known.state, known.sds, RtkOptions{}, &gate, rejected);
  EXPECT_EQ(std::count(rejected.begin(), rejected.end(), known.sds[4].sat), 1);  // its code only
  EXPECT_EQ(k.phase_rows, 7);
  EXPECT_TRUE(known.sds[4].fixable);
  // A gate that refuses a signal with its code (the fusion's NLOS gate): the testable phase goes as well.
  struct RefuseFarCodeAndItsSignal final : InnovationGate {
    [[nodiscard]] bool passes(const DdInnovation& row) const override {
      return row.phase() || std::abs(row.innovation_m()) < 5.0;
    }
    [[nodiscard]] bool refuses_signal_with_code() const override { return true; }
  } whole;
  testing::SyntheticEpoch nlos = reflected_epoch(0.01, 0.0);
  rejected.clear();
  const DdUpdateResult n = dd_measurement_update(nlos.state, nlos.sds, RtkOptions{}, &whole, rejected);
  EXPECT_EQ(std::count(rejected.begin(), rejected.end(), nlos.sds[4].sat), 2);  // its code and its phase
  EXPECT_EQ(n.phase_rows, 6);
  EXPECT_FALSE(nlos.sds[4].fixable);
}

}  // namespace
}  // namespace canyon::rtk
