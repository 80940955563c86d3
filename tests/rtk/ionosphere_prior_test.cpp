// A new ionosphere state's prior (rtk/ionosphere_prior.hpp): independent with s0, or from the others' mapped vertical
// delay plus a residual, as a linear combination of the held states (so it stays correlated with them).

#include "canyon/rtk/ionosphere_prior.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "synthetic_epoch.hpp"

namespace canyon::rtk {
namespace {

constexpr double kDeg = 0.017453292519943295;

TEST(IonospherePrior, ObliquityIsOneAtTheZenithAndAboutThreeAtTheHorizon) {
  EXPECT_NEAR(ionosphere_obliquity(90.0 * kDeg), 1.0, 1e-12);
  // 1 / sqrt(1 - (6371 / 6821)^2) at a 450 km shell.
  EXPECT_NEAR(ionosphere_obliquity(0.0), 1.0 / std::sqrt(1.0 - std::pow(6371.0 / 6821.0, 2)), 1e-12);
  EXPECT_GT(ionosphere_obliquity(20.0 * kDeg), ionosphere_obliquity(40.0 * kDeg));
}

TEST(IonospherePrior, AtTheStartTheFirstStateIsIndependentAndTheOthersAreTiedToIt) {
  testing::SyntheticEpoch e = testing::synthetic_epoch(3, Eigen::Vector3d::Zero(), 1.0, 1.0,
                                                       [](int, int integer) { return static_cast<double>(integer); });
  const gnss::EphemerisStore eph{core::NavigationData{}};
  FilterState& state = e.state;
  add_ionosphere_states(state, e.sds, IonospherePrior{0.06, 0.01, 0.001}, eph);
  const int i0 = state.index({e.sds[0].sat, StateKey::kIonosphere});
  const int i1 = state.index({e.sds[1].sat, StateKey::kIonosphere});
  const int i2 = state.index({e.sds[2].sat, StateKey::kIonosphere});
  ASSERT_TRUE(i0 >= 0 && i1 >= 0 && i2 >= 0);
  EXPECT_DOUBLE_EQ(state.P()(i0, i0), 0.06 * 0.06);
  const double k0 = ionosphere_obliquity(e.sds[0].elevation_rad);
  const double k1 = ionosphere_obliquity(e.sds[1].elevation_rad);
  // I_1 = (k1 / k0) I_0 + e_1: covariance (k1 / k0) s0^2, variance (k1 / k0)^2 s0^2 + (k1 r)^2.
  EXPECT_NEAR(state.P()(i1, i0), k1 / k0 * 0.06 * 0.06, 1e-15);
  EXPECT_NEAR(state.P()(i1, i1), std::pow(k1 / k0 * 0.06, 2) + std::pow(k1 * 0.01, 2), 1e-15);
  // The correlation makes a DD of the two far better known than either state.
  const double dd_var = state.P()(i1, i1) + state.P()(i0, i0) - 2.0 * state.P()(i1, i0);
  EXPECT_LT(std::sqrt(dd_var), 0.03);
  EXPECT_GT(state.P()(i2, i1), 0.0);
  // The positions and ambiguities stay uncorrelated with them.
  EXPECT_EQ(state.P()(0, i2), 0.0);
}

TEST(IonospherePrior, ANewSatelliteStartsFromTheVerticalDelayTheOthersMeasured) {
  testing::SyntheticEpoch e = testing::synthetic_epoch(5, Eigen::Vector3d::Zero(), 1.0, 1.0,
                                                       [](int, int integer) { return static_cast<double>(integer); });
  const gnss::EphemerisStore eph{core::NavigationData{}};
  FilterState& state = e.state;
  // Four satellites whose SD delays are known to 2 mm: 3 cm vertical through each one's obliquity.
  constexpr double kVerticalM = 0.03;
  std::vector<FilterState::NewState> held;
  for (int i = 0; i < 4; ++i) {
    const double k = ionosphere_obliquity(e.sds[i].elevation_rad);
    held.push_back({{e.sds[i].sat, StateKey::kIonosphere}, k * kVerticalM, 0.002 * 0.002});
  }
  state.add(held);
  add_ionosphere_states(state, e.sds, IonospherePrior{0.06, 0.01, 0.001}, eph);
  const int fresh = state.index({e.sds[4].sat, StateKey::kIonosphere});
  ASSERT_GE(fresh, 0);
  const double k_new = ionosphere_obliquity(e.sds[4].elevation_rad);
  EXPECT_NEAR(state.x()[fresh], k_new * kVerticalM, 1e-12);
  const double sigma = std::sqrt(state.P()(fresh, fresh));
  EXPECT_GT(sigma, k_new * 0.01);          // at least its own residual
  EXPECT_LT(sigma, k_new * 0.01 + 0.002);  // and little of the others' uncertainty
  // Without a residual sigma the states stay independent, as before.
  FilterState plain = testing::synthetic_epoch(2, Eigen::Vector3d::Zero(), 1.0, 1.0, [](int, int n) {
                        return static_cast<double>(n);
                      }).state;
  std::vector<SingleDiff> two(e.sds.begin(), e.sds.begin() + 2);
  add_ionosphere_states(plain, two, IonospherePrior{0.06, 0.0, 0.001}, eph);
  const int a = plain.index({two[0].sat, StateKey::kIonosphere});
  const int b = plain.index({two[1].sat, StateKey::kIonosphere});
  EXPECT_EQ(plain.P()(a, b), 0.0);
  EXPECT_DOUBLE_EQ(plain.P()(b, b), 0.06 * 0.06);
}

}  // namespace
}  // namespace canyon::rtk
