// The RTK filter state (rtk/filter_state.hpp): block layout, keyed states added and removed with their values and
// correlations, each propagation against the dense F P F^T + Q it stands for, the correction and the conditioning
// against their textbook forms, snapshot and revert.

#include "canyon/rtk/filter_state.hpp"

#include <cstdint>
#include <random>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <gtest/gtest.h>

namespace canyon::rtk {
namespace {

constexpr double kTolerance = 1e-12;

core::SatelliteId gps(int prn) {
  return core::SatelliteId{core::Constellation::Gps, static_cast<std::uint8_t>(prn)};
}

/// A random symmetric positive definite matrix.
Eigen::MatrixXd random_spd(Eigen::Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd A(n, n);
  for (Eigen::Index i = 0; i < A.size(); ++i) A.data()[i] = normal(rng);
  return A * A.transpose() + Eigen::MatrixXd::Identity(n, n);
}

/// A state with the given layout and three ambiguities and one ionosphere state, x and P random.
FilterState filled_state(StateLayout layout, unsigned seed) {
  FilterState s(layout);
  s.add({{{gps(3), 0}, 1.0, 1.0}, {{gps(7), 0}, 2.0, 1.0}, {{gps(7), 1}, 3.0, 1.0}, {{gps(7), -1}, 0.0, 1.0}});
  const Eigen::MatrixXd P = random_spd(s.size(), seed);
  Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(s.size(), 1.0, static_cast<double>(s.size()));
  s.restore_values(x, P);
  return s;
}

TEST(FilterState, LayoutPlacesEachBlock) {
  EXPECT_EQ(FilterState(StateLayout{}).num_unkeyed(), 3);
  EXPECT_EQ(FilterState(StateLayout{}).heading_index(), -1);
  EXPECT_EQ(FilterState(StateLayout{}).kinematics_index(), -1);
  EXPECT_EQ(FilterState({true, false}).num_unkeyed(), 9);
  EXPECT_EQ(FilterState({true, false}).kinematics_index(), 3);
  EXPECT_EQ(FilterState({false, true}).heading_index(), 3);
  EXPECT_EQ(FilterState({true, true}).heading_index(), 9);
  EXPECT_EQ(FilterState({true, true}).num_unkeyed(), 10);
  EXPECT_EQ(FilterState({true, true}).size(), 10);
}

TEST(FilterState, KeyedStatesAreAddedInOrderAndRemovedWithTheirRowsAndColumns) {
  FilterState s({false, true});
  s.add({{{gps(5), 0}, 1.5, 4.0}, {{gps(5), StateKey::kIonosphere}, 0.0, 0.01}});
  s.add({{{gps(9), 1}, -2.0, 9.0}});
  ASSERT_EQ(s.size(), 4 + 3);
  EXPECT_EQ(s.index({gps(5), 0}), 4);
  EXPECT_EQ(s.index({gps(5), -1}), 5);
  EXPECT_EQ(s.index({gps(9), 1}), 6);
  EXPECT_EQ(s.index({gps(9), 0}), -1);
  EXPECT_TRUE(s.key_at(5).ionosphere());
  EXPECT_DOUBLE_EQ(s.x()[6], -2.0);
  EXPECT_DOUBLE_EQ(s.P()(4, 4), 4.0);
  EXPECT_DOUBLE_EQ(s.P()(4, 6), 0.0);  // new states are uncorrelated
  // Give everything correlations, then remove the middle key: the rest keep theirs.
  const Eigen::MatrixXd P = random_spd(s.size(), 1);
  s.restore_values(s.x(), P);
  s.remove({gps(5), StateKey::kIonosphere});
  ASSERT_EQ(s.size(), 6);
  EXPECT_EQ(s.index({gps(9), 1}), 5);
  EXPECT_DOUBLE_EQ(s.P()(5, 5), P(6, 6));
  EXPECT_DOUBLE_EQ(s.P()(4, 5), P(4, 6));
  EXPECT_DOUBLE_EQ(s.P()(0, 5), P(0, 6));
  EXPECT_DOUBLE_EQ(s.P()(5, 3), P(6, 3));
  s.remove({gps(30), 0});  // absent: nothing happens
  EXPECT_EQ(s.size(), 6);
  s.clear_keyed();
  EXPECT_EQ(s.size(), 4);
  EXPECT_TRUE(s.keys().empty());
}

TEST(FilterState, KinematicPropagationIsTheDenseProductWithTheKeyedCorrelationsCarried) {
  FilterState s = filled_state({true, false}, 2);
  const Eigen::VectorXd x0 = s.x();
  const Eigen::MatrixXd P0 = s.P();
  Eigen::Matrix<double, 9, 9> F_k = Eigen::Matrix<double, 9, 9>::Identity();
  const double dt = 0.2;
  for (int i = 0; i < 3; ++i) {
    F_k(i, 3 + i) = dt;
    F_k(i, 6 + i) = 0.5 * dt * dt;
    F_k(3 + i, 6 + i) = dt;
  }
  s.propagate_kinematics(F_k);
  const Eigen::Matrix3d R_EN = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3d Q_N = Eigen::Vector3d(0.5, 0.5, 0.1).asDiagonal();
  s.add_acceleration_noise(R_EN, Q_N);
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(s.size(), s.size());
  F.topLeftCorner<9, 9>() = F_k;
  Eigen::MatrixXd expected = F * P0 * F.transpose();
  expected.block<3, 3>(6, 6) += R_EN * Q_N * R_EN.transpose();
  EXPECT_LT((s.x() - F * x0).norm(), kTolerance * x0.norm());
  EXPECT_LT((s.P() - expected).norm(), kTolerance * expected.norm());
}

TEST(FilterState, ResetKinematicsDecorrelatesThePositionAndAnIncrementKeepsItsCorrelations) {
  FilterState s = filled_state({false, false}, 3);
  const Eigen::MatrixXd P0 = s.P();
  const Eigen::Vector3d dp(0.4, -0.1, 0.05);
  const Eigen::Matrix3d Q = Eigen::Vector3d(1e-4, 2e-4, 3e-4).asDiagonal();
  const Eigen::Vector3d p0 = s.position_E_m();
  s.add_position_increment(dp, Q);
  EXPECT_LT((s.position_E_m() - (p0 + dp)).norm(), kTolerance);
  EXPECT_LT((s.position_covariance_E_m2() - (P0.topLeftCorner<3, 3>() + Q)).norm(), kTolerance);
  EXPECT_EQ(s.P().topRightCorner(3, s.size() - 3), P0.topRightCorner(3, s.size() - 3));  // x' = x + d: kept
  s.reset_kinematics(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d::Zero(), 900.0, 100.0);
  EXPECT_EQ(s.position_E_m(), (Eigen::Vector3d(1, 2, 3)));
  EXPECT_EQ(s.position_covariance_E_m2(), Eigen::Matrix3d::Identity() * 900.0);
  EXPECT_TRUE(s.P().topRightCorner(3, s.size() - 3).isZero());
  EXPECT_TRUE(s.P().bottomLeftCorner(s.size() - 3, 3).isZero());
  EXPECT_EQ(s.P().bottomRightCorner(s.size() - 3, s.size() - 3), P0.bottomRightCorner(s.size() - 3, s.size() - 3));
}

TEST(FilterState, HeadingCouplingIsFPFtWithFTheIdentityPlusJTimesPsi) {
  FilterState s = filled_state({false, true}, 4);
  s.restart_aiding_state(s.heading_index(), 0.01);
  const Eigen::Index h = s.heading_index();
  EXPECT_DOUBLE_EQ(s.x()[h], 0.0);
  EXPECT_TRUE(s.P().row(h).head(h).isZero());
  s.set_aiding_value(s.heading_index(), 0.02);  // a value, so that the mean moves too
  const Eigen::VectorXd x0 = s.x();
  const Eigen::MatrixXd P0 = s.P();
  const Eigen::Vector3d J(1.0, -0.5, 0.2);
  const double noise = 1e-6;
  s.couple_aiding_state(s.heading_index(), J, noise);
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(s.size(), s.size());
  F.block(0, h, 3, 1) = J;
  Eigen::MatrixXd expected = F * P0 * F.transpose();
  expected(h, h) += noise;
  EXPECT_LT((s.x() - F * x0).norm(), kTolerance);
  EXPECT_LT((s.P() - expected).norm(), kTolerance * expected.norm());
}

TEST(FilterState, InterpolationStepIsFPFtPlusGQGtWithTheErrorCarriedIntoThePosition) {
  FilterState s = filled_state({true, true, true, true}, 5);
  const int e = s.interpolation_index();
  ASSERT_EQ(e, 11);  // after position, kinematics, heading and scale
  EXPECT_EQ(s.num_unkeyed(), 14);
  s.restart_aiding_state(e, 4e-4, 3);
  EXPECT_TRUE(s.x().segment<3>(e).isZero());
  EXPECT_TRUE(s.P().middleRows<3>(e).leftCols(e).isZero());
  const Eigen::Matrix3d P_ee = s.P().block<3, 3>(e, e);
  EXPECT_TRUE(P_ee.isApprox(Eigen::Matrix3d::Identity() * 4e-4));
  // Give it a value and correlations (as a measurement update would), then one step inside an interval and one
  // across.
  s.restore_values(s.x() + Eigen::VectorXd::Constant(s.size(), 0.01), random_spd(s.size(), 6));
  for (const auto& [carry, noise] : {std::pair{0.6, 0.0}, std::pair{0.0, 9e-4}}) {
    const Eigen::VectorXd x0 = s.x();
    const Eigen::MatrixXd P0 = s.P();
    s.propagate_interpolation(carry, noise);
    Eigen::MatrixXd F = Eigen::MatrixXd::Identity(s.size(), s.size());
    F.block<3, 3>(0, e) = Eigen::Matrix3d::Identity() * (carry - 1.0);
    F.block<3, 3>(e, e) = Eigen::Matrix3d::Identity() * carry;
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(s.size(), 3);
    G.topRows<3>().setIdentity();
    G.middleRows<3>(e).setIdentity();
    const Eigen::MatrixXd expected = F * P0 * F.transpose() + G * G.transpose() * noise;
    EXPECT_LT((s.x() - F * x0).norm(), kTolerance);
    EXPECT_LT((s.P() - expected).norm(), kTolerance * expected.norm());
  }
  // Across an interval (carry 0) the position keeps only the chain: the old error is taken out, the new one added.
  EXPECT_TRUE(s.x().segment<3>(e).isZero());
}

TEST(FilterState, CorrectionAndConditioningMatchTheirDenseForms) {
  FilterState s = filled_state({false, false}, 5);
  const Eigen::Index n = s.size();
  const Eigen::VectorXd x0 = s.x();
  const Eigen::MatrixXd P0 = s.P();
  // A Kalman gain's correction: U V^T = K S K^T, symmetric.
  const Eigen::MatrixXd H = Eigen::MatrixXd::Random(2, n);
  const Eigen::MatrixXd S = H * P0 * H.transpose() + Eigen::MatrixXd::Identity(2, 2);
  const Eigen::MatrixXd K = P0 * H.transpose() * S.inverse();
  const Eigen::VectorXd dx = K * Eigen::Vector2d(0.3, -0.2);
  const Eigen::MatrixXd U = K * S;
  s.correct(dx, U, K);
  const Eigen::MatrixXd expected = P0 - K * H * P0;
  EXPECT_LT((s.x() - (x0 + dx)).norm(), kTolerance);
  EXPECT_LT((s.P() - expected).norm(), 1e-10 * expected.norm());
  EXPECT_EQ(s.P(), s.P().transpose());  // exactly symmetric
  // Conditioning: x -= A b, P -= A B.
  const Eigen::VectorXd x1 = s.x();
  const Eigen::MatrixXd P1 = s.P();
  const Eigen::MatrixXd A = P1.leftCols(2);
  const Eigen::Vector2d b(0.1, 0.2);
  const Eigen::MatrixXd B = A.transpose() * 0.5;
  s.condition(A, b, B);
  EXPECT_LT((s.x() - (x1 - A * b)).norm(), kTolerance);
  const Eigen::MatrixXd conditioned = P1 - A * B;
  EXPECT_LT((s.P() - 0.5 * (conditioned + conditioned.transpose())).norm(), kTolerance);
}

TEST(FilterState, RevertGoesBackToTheSnapshotAndSetPositionDecorrelates) {
  FilterState s = filled_state({false, false}, 6);
  const FilterState::Snapshot snapshot = s.snapshot();
  s.add_position_increment(Eigen::Vector3d(1, 1, 1), Eigen::Matrix3d::Identity());
  s.propagate_keyed({0.5, 0.25});
  s.revert(snapshot);
  EXPECT_EQ(s.x(), snapshot.x);
  EXPECT_EQ(s.P(), snapshot.P);
  s.set_position(Eigen::Vector3d(7, 8, 9), Eigen::Matrix3d::Identity() * 4.0);
  EXPECT_EQ(s.position_E_m(), (Eigen::Vector3d(7, 8, 9)));
  EXPECT_TRUE(s.P().topRightCorner(3, s.size() - 3).isZero());
}

TEST(FilterState, KeyedRandomWalkAddsEachKindsNoise) {
  FilterState s = filled_state({false, false}, 7);
  const Eigen::MatrixXd P0 = s.P();
  s.propagate_keyed({0.5, 0.25});
  for (int i = 3; i < s.size(); ++i) {
    EXPECT_DOUBLE_EQ(s.P()(i, i) - P0(i, i), s.key_at(i).ionosphere() ? 0.25 : 0.5) << i;
  }
  EXPECT_EQ(s.P().topLeftCorner(3, 3), P0.topLeftCorner(3, 3));
}

// A code multipath state is a first-order Gauss-Markov process: F = I but phi on its diagonal, P' = F P F^T + q on
// its variance; the random walks of the ambiguities and the ionosphere leave it alone.
TEST(FilterState, CodeBiasStatesAreGaussMarkovAndOutsideTheRandomWalks) {
  FilterState s({false, false});
  s.add({{{gps(3), 0}, 1.0, 1.0}, {StateKey::code_bias(gps(3), 0), 0.4, 1.0}, {{gps(3), -1}, 0.0, 1.0}});
  EXPECT_TRUE(s.key_at(4).code_bias());
  EXPECT_FALSE(s.key_at(4).ionosphere());
  EXPECT_FALSE(s.key_at(3).code_bias());
  EXPECT_FALSE(s.key_at(5).code_bias());
  EXPECT_NE(StateKey::code_bias(gps(3), 0), StateKey::code_bias(gps(3), 1));
  s.restore_values(Eigen::VectorXd::LinSpaced(s.size(), 1.0, 6.0), random_spd(s.size(), 11));
  const Eigen::VectorXd x0 = s.x();
  const Eigen::MatrixXd P0 = s.P();
  const double phi = 0.9, q = 0.05;
  s.propagate_keyed({0.0, 0.0, phi, q});
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(s.size(), s.size());
  F(4, 4) = phi;
  Eigen::MatrixXd expected = F * P0 * F.transpose();
  expected(4, 4) += q;
  EXPECT_TRUE(s.P().isApprox(expected, kTolerance));
  EXPECT_TRUE(s.x().isApprox(F * x0, kTolerance));
  const Eigen::MatrixXd P1 = s.P();
  s.propagate_keyed({0.5, 0.25});
  EXPECT_DOUBLE_EQ(s.P()(4, 4), P1(4, 4));
  EXPECT_DOUBLE_EQ(s.P()(3, 3) - P1(3, 3), 0.5);
  EXPECT_DOUBLE_EQ(s.P()(5, 5) - P1(5, 5), 0.25);
}

}  // namespace
}  // namespace canyon::rtk
