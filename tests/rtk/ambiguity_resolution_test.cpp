// Ambiguity resolution (rtk/ambiguity_resolution.hpp) on synthetic floats (synthetic_epoch.hpp): the full set is
// proposed first with the true integers and its fixed position; a satellite biased by half a cycle is pruned; a
// caller's refusals send the search on through partial fixing and end without a fix; fewer than 4 satellites are not
// searched; a fix that contradicts the last one is not proposed; fix-and-hold conditions the state on the integers;
// an imprecise partial fix is held with its own sigma without becoming the last fix.

#include "canyon/rtk/ambiguity_resolution.hpp"

#include <gtest/gtest.h>

#include "synthetic_epoch.hpp"

namespace canyon::rtk {
namespace {

using testing::synthetic_epoch;

/// Floats a few hundredths of a cycle from the true integers, precise (sigma 0.02 cycles), satellite `biased` (if
/// any) half a cycle off.
testing::SyntheticEpoch floats(int count, int biased = -1) {
  return synthetic_epoch(count, Eigen::Vector3d::Zero(), 1e-4, 4e-4,
                         [biased](int i, int integer) { return integer + (i == biased ? 0.5 : 0.01 * ((i % 3) - 1)); });
}

/// Runs the search, deciding with `decide`; the number of candidates proposed.
template <typename Decide>
int run(FixSearch& search, Decide decide) {
  int proposed = 0;
  while (const FixCandidate* candidate = search.next()) {
    ++proposed;
    search.decide(decide(*candidate));
  }
  return proposed;
}

TEST(AmbiguityResolution, TheFullSetComesFirstWithTheTrueIntegersAndItsFixedPosition) {
  testing::SyntheticEpoch e = floats(8);
  AmbiguityResolver resolver{RtkOptions{}};
  FixSearch search = resolver.search(e.state, e.sds);
  const FixCandidate* first = search.next();
  ASSERT_NE(first, nullptr);
  EXPECT_FALSE(first->combinations);
  EXPECT_TRUE(first->pruned.empty());
  ASSERT_EQ(first->a_fix.size(), 7);
  for (Eigen::Index k = 0; k < 7; ++k) {
    EXPECT_EQ(first->a_fix[k], e.integers[static_cast<std::size_t>(k + 1)] - e.integers[0]) << k;
  }
  EXPECT_GE(first->ratio, 3.0);
  EXPECT_GE(first->success_rate, 0.99);
  ASSERT_TRUE(first->position_ok);
  EXPECT_LT(first->p_E_m.norm(), 0.01);  // the floats' errors, conditioned away
  EXPECT_LE(first->P_E_m2.trace(), e.state.position_covariance_E_m2().trace());
  search.decide(true);
  EXPECT_EQ(search.next(), nullptr);
  ASSERT_TRUE(search.fix().has_value());
  EXPECT_TRUE(search.why_not().empty());
  ASSERT_TRUE(search.ratio().has_value());
}

TEST(AmbiguityResolution, ASatelliteHalfACycleOffIsPrunedByItsIntegerLeastSquaresResidual) {
  testing::SyntheticEpoch e = floats(9, 5);
  AmbiguityResolver resolver{RtkOptions{}};
  FixSearch search = resolver.search(e.state, e.sds);
  std::optional<FixCandidate> accepted;
  run(search, [&](const FixCandidate& c) {
    if (c.combinations || accepted) return false;  // this test is about the DD sets
    accepted = c;
    return true;
  });
  ASSERT_TRUE(accepted.has_value());
  ASSERT_EQ(accepted->pruned.size(), 1U);
  EXPECT_EQ(accepted->pruned[0], e.sds[5].sat);
  EXPECT_EQ(accepted->a_fix.size(), 7);  // 8 satellites left
  ASSERT_TRUE(search.fix().has_value());
  EXPECT_EQ(search.fix()->pruned, accepted->pruned);
}

TEST(AmbiguityResolution, RefusalsSendTheSearchThroughPartialFixingToNoFix) {
  testing::SyntheticEpoch e = floats(8);
  AmbiguityResolver resolver{RtkOptions{}};
  FixSearch search = resolver.search(e.state, e.sds);
  std::vector<std::size_t> sizes;
  const int proposed = run(search, [&](const FixCandidate& c) {
    sizes.push_back(c.dd.size());
    return false;
  });
  EXPECT_GT(proposed, 2);
  EXPECT_EQ(sizes.front(), 7U);  // the full set first
  EXPECT_FALSE(search.fix().has_value());
  EXPECT_NE(search.why_not().find("refused"), std::string::npos) << search.why_not();
  // Without partial fixing only the full set is proposed.
  RtkOptions no_partial;
  no_partial.partial_ar = false;
  AmbiguityResolver resolver2{no_partial};
  FixSearch search2 = resolver2.search(e.state, e.sds);
  EXPECT_EQ(run(search2, [](const FixCandidate&) { return false; }), 1);
}

TEST(AmbiguityResolution, FewerThanFourSatellitesAreNotSearched) {
  testing::SyntheticEpoch e = floats(3);
  RtkOptions options;
  options.min_fix_ambiguities = 2;
  AmbiguityResolver resolver{options};
  FixSearch search = resolver.search(e.state, e.sds);
  EXPECT_EQ(search.next(), nullptr);
  EXPECT_TRUE(search.too_few_satellites());
  EXPECT_FALSE(search.ratio().has_value());
}

TEST(AmbiguityResolution, AFixThatContradictsTheLastOneIsNotProposedAndHoldConditionsTheState) {
  testing::SyntheticEpoch e = floats(8);
  RtkOptions hold;
  hold.ar_mode = ArMode::FixAndHold;
  AmbiguityResolver resolver{hold};
  {
    FixSearch search = resolver.search(e.state, e.sds);
    run(search, [](const FixCandidate&) { return true; });
    ASSERT_TRUE(search.fix().has_value());
    resolver.commit(*search.fix(), e.state);
  }
  EXPECT_EQ(resolver.last_fix().size(), 7U);
  const int index = e.state.index({e.sds[2].sat, 0});
  EXPECT_NEAR(e.state.x()[index] - e.state.x()[e.state.index({e.sds[0].sat, 0})], e.integers[2] - e.integers[0], 1e-3);
  EXPECT_LT(e.state.P()(index, index), 4e-4);  // held
  // The same satellites a cycle apart: every DD of satellite 3 contradicts the held integers.
  testing::SyntheticEpoch shifted = floats(8);
  Eigen::VectorXd x = shifted.state.x();
  x[shifted.state.index({shifted.sds[2].sat, 0})] += 1.0;
  shifted.state.restore_values(x, shifted.state.P());
  FixSearch search = resolver.search(shifted.state, shifted.sds);
  while (const FixCandidate* c = search.next()) {
    if (!c->combinations) {
      EXPECT_LE(c->a_fix.size(), 6) << "only sets without satellite 3 agree with the last fix";
    }
    search.decide(false);
  }
  resolver.forget({shifted.sds[2].sat, 0});
  EXPECT_EQ(resolver.last_fix().size(), 6U);
}

TEST(AmbiguityResolution, HoldConditionsTheStateWithItsSigmaAndLeavesTheLastFixAlone) {
  testing::SyntheticEpoch e = floats(8);
  RtkOptions options;
  options.ar_mode = ArMode::FixAndHold;
  AmbiguityResolver resolver{options};
  FixSearch search = resolver.search(e.state, e.sds);
  run(search, [](const FixCandidate&) { return true; });
  ASSERT_TRUE(search.fix().has_value());
  const int s = e.state.index({e.sds[2].sat, 0});
  const int r = e.state.index({e.sds[0].sat, 0});
  const auto dd_variance = [&] {
    const Eigen::MatrixXd& P = e.state.P();
    return P(s, s) + P(r, r) - 2.0 * P(s, r);
  };
  const double before = dd_variance();
  resolver.hold(*search.fix(), e.state, 0.2);
  EXPECT_TRUE(resolver.last_fix().empty()) << "a hold is not a fix";
  // Conditioned with sigma 0.2 cycles: the DD variance falls to about var 0.04 / (var + 0.04) of what it was.
  EXPECT_LT(dd_variance(), before);
  EXPECT_GT(dd_variance(), 0.5 * before * 0.04 / (before + 0.04));
  EXPECT_NEAR(e.state.x()[s] - e.state.x()[r], e.integers[2] - e.integers[0], 0.05);
  // Outside fix-and-hold a hold does nothing.
  testing::SyntheticEpoch again = floats(8);
  AmbiguityResolver continuous{RtkOptions{}};
  FixSearch search2 = continuous.search(again.state, again.sds);
  run(search2, [](const FixCandidate&) { return true; });
  ASSERT_TRUE(search2.fix().has_value());
  const Eigen::MatrixXd P = again.state.P();
  continuous.hold(*search2.fix(), again.state, 0.2);
  EXPECT_EQ(again.state.P(), P);
}

}  // namespace
}  // namespace canyon::rtk
