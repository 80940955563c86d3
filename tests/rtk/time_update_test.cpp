// The time update (rtk/time_update.hpp): the own model re-initialises the position from the single point without
// dynamics and propagates the constant-acceleration model with dynamics; an external motion adds its increment and
// restarts the heading error when asked and after an unaided epoch; the keyed random walks grow with dt.

#include "canyon/rtk/time_update.hpp"

#include <gtest/gtest.h>

namespace canyon::rtk {
namespace {

gnss::SppSolution spp_at(const Eigen::Vector3d& p, const Eigen::Vector3d& v) {
  gnss::SppSolution s;
  s.p_E_m = p;
  s.v_E_mps = v;
  return s;
}

const Eigen::Vector3d kPosition(-3962108.7, 3381309.6, 3668678.6);

TEST(TimeUpdate, WithoutDynamicsThePositionStartsFromTheSinglePointEachEpoch) {
  FilterState state({false, false});
  state.add({{{core::SatelliteId{}, 0}, 5.0, 1.0}});
  RtkOptions o;
  own_motion_update(state, o, 0.2, false, spp_at(kPosition, Eigen::Vector3d::Zero()));
  EXPECT_EQ(state.position_E_m(), kPosition);
  EXPECT_EQ(state.position_covariance_E_m2(), Eigen::Matrix3d::Identity() * 900.0);
  EXPECT_DOUBLE_EQ(state.x()[3], 5.0);  // the ambiguity is kept
}

TEST(TimeUpdate, WithDynamicsTheConstantAccelerationModelMovesThePosition) {
  FilterState state({true, false});
  RtkOptions o;
  o.dynamics = true;
  own_motion_update(state, o, 0.0, true, spp_at(kPosition, Eigen::Vector3d(1.0, 2.0, 0.0)));
  EXPECT_EQ(Eigen::Vector3d(state.x().segment<3>(3)), Eigen::Vector3d(1.0, 2.0, 0.0));
  const Eigen::Matrix3d P_a0 = state.P().block<3, 3>(6, 6);
  own_motion_update(state, o, 0.5, false, spp_at(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()));
  EXPECT_LT((state.position_E_m() - (kPosition + 0.5 * Eigen::Vector3d(1.0, 2.0, 0.0))).norm(), 1e-9);
  // The acceleration's variance grows by sh^2 dt horizontally and sv^2 dt vertically: trace 2 * 9 * 0.5 + 1 * 0.5.
  EXPECT_NEAR((state.P().block<3, 3>(6, 6) - P_a0).trace(), 9.5, 1e-9);
  // After a gap of more than 30 s the state starts again from the single point.
  own_motion_update(state, o, 31.0, false, spp_at(kPosition, Eigen::Vector3d::Zero()));
  EXPECT_EQ(state.position_E_m(), kPosition);
}

TEST(TimeUpdate, AnExternalMotionAddsItsIncrementAndRestartsTheHeadingWhenAskedOrNotLive) {
  FilterState state({false, true});
  state.reset_kinematics(kPosition, Eigen::Vector3d::Zero(), 1.0, 0.0);
  ExternalMotion m;
  m.delta_p_E_m = Eigen::Vector3d(0.5, 0.0, 0.0);
  m.Q_E_m2 = Eigen::Matrix3d::Identity() * 1e-4;
  m.heading_variance_rad2 = 0.01;
  m.heading_noise_rad2 = 1e-6;
  m.dp_d_heading_E_m = Eigen::Vector3d(0.0, 0.5, 0.0);
  AidingLive live;
  external_motion_update(state, m, live);
  EXPECT_TRUE(live.heading);
  EXPECT_FALSE(live.scale);  // no scale state in this layout
  const int h = state.heading_index();
  EXPECT_NEAR(state.P()(h, h), 0.01 + 1e-6, 1e-15);
  EXPECT_LT((state.position_E_m() - (kPosition + m.delta_p_E_m)).norm(), 1e-9);
  EXPECT_NEAR(state.P()(1, 1), 1.0 + 1e-4 + 0.25 * 0.01, 1e-12);  // J var J^T on the position
  external_motion_update(state, m, live);                         // live and not asked: the heading goes on
  EXPECT_NEAR(state.P()(h, h), 0.01 + 2e-6, 1e-15);
  m.restart_heading = true;
  m.heading_variance_rad2 = 0.04;
  external_motion_update(state, m, live);
  EXPECT_NEAR(state.P()(h, h), 0.04 + 1e-6, 1e-15);
}

TEST(TimeUpdate, AScaleStateScalesTheIncrementAndLearnsFromThePosition) {
  FilterState state({false, false, true});
  state.reset_kinematics(kPosition, Eigen::Vector3d::Zero(), 1e-6, 0.0);
  ExternalMotion m;
  m.delta_p_E_m = Eigen::Vector3d(1.0, 0.0, 0.0);
  m.scale_variance = 1e-4;
  m.scale_noise = 1e-8;
  AidingLive live;
  external_motion_update(state, m, live);
  EXPECT_TRUE(live.scale);
  const int s = state.scale_index();
  EXPECT_EQ(s, 3);
  EXPECT_NEAR(state.P()(s, s), 1e-4 + 1e-8, 1e-15);
  EXPECT_NEAR(state.P()(0, s), 1e-4, 1e-12);  // the position along the increment correlates with the scale
  EXPECT_NEAR(state.P()(0, 0), 1e-6 + 1e-4, 1e-12);
  state.set_aiding_value(s, 0.01);
  external_motion_update(state, m, live);  // p += dp (1 + s)
  EXPECT_NEAR(state.position_E_m().x() - kPosition.x(), 2.01, 1e-9);
  m.restart_scale = true;
  external_motion_update(state, m, live);
  EXPECT_NEAR(state.P()(s, s), 1e-4 + 1e-8, 1e-15);
  EXPECT_EQ(state.x()[s], 0.0);
}

TEST(TimeUpdate, KeyedRandomWalksGrowWithTheInterval) {
  FilterState state({false, false});
  state.add({{{core::SatelliteId{}, 0}, 0.0, 1.0}, {{core::SatelliteId{}, StateKey::kIonosphere}, 0.0, 1.0}});
  RtkOptions o;
  o.ambiguity_noise_cyc = 0.1;
  o.iono_noise_m = 0.01;
  keyed_random_walk(state, o, 4.0);
  EXPECT_DOUBLE_EQ(state.P()(3, 3), 1.0 + 0.01 * 4.0);
  EXPECT_DOUBLE_EQ(state.P()(4, 4), 1.0 + 1e-4 * 4.0);
}

}  // namespace
}  // namespace canyon::rtk
