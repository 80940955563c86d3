// The keyed states' bookkeeping (rtk/ambiguity_states.hpp): a new ambiguity starts at (phase - code) / lambda with
// the initial sigma, becomes fixable after min_lock_epochs above the AR mask, never with a half cycle or a GLONASS
// signal without glonass_ar; a state unseen for longer than the outage limit is stale; ionosphere states come with
// the given prior sigma.

#include "canyon/rtk/ambiguity_states.hpp"

#include <gtest/gtest.h>

#include "canyon/rtk/ionosphere_prior.hpp"

#include "synthetic_epoch.hpp"

namespace canyon::rtk {
namespace {

core::GpsTime at(double tow_s) {
  return core::GpsTime{2200, tow_s};
}

TEST(AmbiguityStates, NewAmbiguitiesStartFromTheCodeAndBecomeFixableAfterTheirLockEpochs) {
  testing::SyntheticEpoch e = testing::synthetic_epoch(4, Eigen::Vector3d::Zero(), 1.0, 1.0,
                                                       [](int, int integer) { return static_cast<double>(integer); });
  FilterState state({false, false});
  RtkOptions o;
  o.min_lock_epochs = 2;
  o.ar_elevation_mask_rad = 0.5;  // the last satellite (25 deg) is below
  e.sds[1].lli = core::kLliHalfCycle;
  AmbiguityStates book;
  const SlipScan no_slips;
  const auto added = book.admit(e.sds, state, at(100.0), no_slips, o, false);
  ASSERT_EQ(added.size(), 4U);
  EXPECT_NEAR(added[2].value, e.integers[2], 1e-9);  // (phase - code) / lambda at zero range
  EXPECT_DOUBLE_EQ(added[2].variance, o.initial_ambiguity_sigma_cyc * o.initial_ambiguity_sigma_cyc);
  state.add(added);
  for (int epoch = 1; epoch <= 3; ++epoch) {
    EXPECT_TRUE(book.admit(e.sds, state, at(100.0 + epoch), no_slips, o, false).empty());
    EXPECT_EQ(e.sds[0].fixable, epoch >= 2) << epoch;  // tracked for more than 2 epochs
  }
  EXPECT_FALSE(e.sds[1].fixable);  // half cycle
  EXPECT_FALSE(e.sds[3].fixable);  // below the AR mask
  assign_state_indices(e.sds, state);
  EXPECT_EQ(e.sds[2].ambiguity, state.index({e.sds[2].sat, 0}));
  EXPECT_EQ(e.sds[2].iono, -1);
  // GLONASS without glonass_ar is never fixable.
  e.sds[0].sat.system = core::Constellation::Glonass;
  (void)book.admit(e.sds, state, at(104.0), no_slips, o, false);
  EXPECT_FALSE(e.sds[0].fixable);
}

TEST(AmbiguityStates, StaleAfterAnOutageAndIonosphereStatesWithTheirPrior) {
  testing::SyntheticEpoch e = testing::synthetic_epoch(3, Eigen::Vector3d::Zero(), 1.0, 1.0,
                                                       [](int, int integer) { return static_cast<double>(integer); });
  FilterState state({false, false});
  AmbiguityStates book;
  const SlipScan no_slips;
  const auto added = book.admit(e.sds, state, at(10.0), no_slips, RtkOptions{}, true);
  ASSERT_EQ(added.size(), 3U);  // three ambiguities; the ionosphere states are the caller's
  state.add(added);
  const gnss::EphemerisStore no_ephemerides{core::NavigationData{}};
  add_ionosphere_states(state, e.sds, IonospherePrior{0.05, 0.0, 0.001}, no_ephemerides);
  ASSERT_EQ(state.keys().size(), 6U);
  const int iono = state.index({e.sds[0].sat, StateKey::kIonosphere});
  ASSERT_GE(iono, 0);
  EXPECT_DOUBLE_EQ(state.P()(iono, iono), 0.05 * 0.05);
  EXPECT_TRUE(book.stale(at(14.0), 5.0, 5.0).empty());
  EXPECT_EQ(book.stale(at(16.0), 5.0, 5.0).size(), 6U);  // the ionosphere states marked seen as well
  book.forget(added[0].key);
  EXPECT_EQ(book.stale(at(16.0), 5.0, 5.0).size(), 5U);
}

TEST(AmbiguityStates, CodeMultipathStatesComeWithEachSignalsCodeAndTheirSigma) {
  testing::SyntheticEpoch e = testing::synthetic_epoch(3, Eigen::Vector3d::Zero(), 1.0, 1.0,
                                                       [](int, int integer) { return static_cast<double>(integer); });
  e.sds[2].code_m = core::kNoValue;  // no code: no code state (and no new ambiguity)
  FilterState state({false, false});
  RtkOptions o;
  o.code_multipath_sigma_m = 0.7;
  AmbiguityStates book;
  const auto added = book.admit(e.sds, state, at(10.0), SlipScan{}, o, false);
  ASSERT_EQ(added.size(), 4U);  // two ambiguities, then two code states
  for (std::size_t k = 2; k < 4; ++k) {
    EXPECT_EQ(added[k].key, StateKey::code_bias(e.sds[k - 2].sat, e.sds[k - 2].frequency));
    EXPECT_DOUBLE_EQ(added[k].value, 0.0);
    EXPECT_DOUBLE_EQ(added[k].variance, 0.49);
  }
  state.add(added);
  assign_state_indices(e.sds, state);
  EXPECT_EQ(e.sds[1].code_bias, state.index(StateKey::code_bias(e.sds[1].sat, 0)));
  EXPECT_EQ(e.sds[2].code_bias, -1);
  EXPECT_EQ(book.stale(at(16.0), 5.0, 5.0).size(), 4U);  // stale with the others
}

}  // namespace
}  // namespace canyon::rtk
