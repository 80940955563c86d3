// SO(3)/SE(3) maths: Exp/Log round trips, adjoint, and every analytic Jacobian against central differences (each
// comparison can fail: a wrong sign or a transposed block is off by far more than the tolerance).

#include "canyon/core/se3.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace canyon::core {
namespace {

constexpr double kStep = 1e-6;
constexpr double kMaxJacobianError = 1e-6;

Vector6d random_xi(std::mt19937_64& rng, double scale_rho, double scale_theta) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vector6d xi;
  for (int i = 0; i < 3; ++i) xi[i] = scale_rho * n(rng);
  for (int i = 3; i < 6; ++i) xi[i] = scale_theta * n(rng);
  return xi;
}

/// Tangent difference of two poses, Log(A^-1 B).
Vector6d minus(const Pose& B, const Pose& A) {
  return se3_log(A.inverse() * B);
}

TEST(Se3Test, ExpLogRoundTripsIncludingSmallAndLargeAngles) {
  std::mt19937_64 rng(1);
  for (const double theta_scale : {1e-9, 1e-5, 1e-3, 0.3, 1.5}) {
    for (int k = 0; k < 20; ++k) {
      const Vector6d xi = random_xi(rng, 3.0, theta_scale);
      if (xi.tail<3>().norm() >= 3.1) continue;
      EXPECT_LT((se3_log(se3_exp(xi)) - xi).norm(), 1e-10 * std::max(1.0, xi.norm())) << xi.transpose();
    }
  }
}

TEST(Se3Test, AdjointMovesAPerturbationAcrossThePose) {
  std::mt19937_64 rng(2);
  const Pose T = se3_exp(random_xi(rng, 5.0, 1.0));
  const Vector6d small = random_xi(rng, 1e-3, 1e-3);
  const Pose lhs = se3_exp(se3_adjoint(T) * small);
  const Pose rhs = T * se3_exp(small) * T.inverse();
  EXPECT_LT((lhs.p - rhs.p).norm(), 1e-12);
  EXPECT_LT(lhs.q.angularDistance(rhs.q), 1e-12);
}

TEST(Se3Test, So3JacobiansMatchNumericDifferences) {
  std::mt19937_64 rng(3);
  for (const double scale : {1e-6, 0.2, 1.2}) {
    const Eigen::Vector3d phi = random_xi(rng, 0.0, scale).tail<3>();
    // Exp(phi + d) = Exp(phi) Exp(J_r(phi) d).
    Eigen::Matrix3d numeric;
    for (int i = 0; i < 3; ++i) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d[i] = kStep;
      const Eigen::Vector3d plus = so3_log(so3_exp(phi).conjugate() * so3_exp(phi + d));
      const Eigen::Vector3d minus_d = so3_log(so3_exp(phi).conjugate() * so3_exp(phi - d));
      numeric.col(i) = (plus - minus_d) / (2.0 * kStep);
    }
    EXPECT_LT((numeric - so3_right_jacobian(phi)).norm(), kMaxJacobianError) << "phi " << phi.transpose();
    EXPECT_LT((so3_right_jacobian_inverse(phi) * so3_right_jacobian(phi) - Eigen::Matrix3d::Identity()).norm(), 1e-9);
    EXPECT_LT((so3_left_jacobian_inverse(phi) * so3_left_jacobian(phi) - Eigen::Matrix3d::Identity()).norm(), 1e-9);
  }
}

TEST(Se3Test, Se3RightJacobianMatchesNumericDifferences) {
  std::mt19937_64 rng(4);
  for (const double scale : {1e-6, 0.3, 1.3}) {
    const Vector6d xi = random_xi(rng, 2.0, scale);
    Matrix6d numeric;
    for (int i = 0; i < 6; ++i) {
      Vector6d d = Vector6d::Zero();
      d[i] = kStep;
      numeric.col(i) = (minus(se3_exp(xi + d), se3_exp(xi)) - minus(se3_exp(xi - d), se3_exp(xi))) / (2.0 * kStep);
    }
    EXPECT_LT((numeric - se3_right_jacobian(xi)).norm(), kMaxJacobianError) << "xi " << xi.transpose();
    EXPECT_LT((se3_right_jacobian_inverse(xi) * se3_right_jacobian(xi) - Matrix6d::Identity()).norm(), 1e-9);
  }
}

TEST(Se3Test, InterpolationJacobiansMatchNumericDifferences) {
  std::mt19937_64 rng(5);
  for (const double a : {0.0, 0.3, 0.77, 1.0, 1.2}) {
    const Pose T0 = se3_exp(random_xi(rng, 10.0, 1.0));
    const Pose T1 = T0 * se3_exp(random_xi(rng, 0.5, 0.4));
    Matrix6d J0, J1;
    const Pose T = se3_interpolate(T0, T1, a, &J0, &J1);
    Matrix6d numeric0, numeric1;
    for (int i = 0; i < 6; ++i) {
      Vector6d d = Vector6d::Zero();
      d[i] = kStep;
      numeric0.col(i) =
          (minus(se3_interpolate(T0 * se3_exp(d), T1, a), T) - minus(se3_interpolate(T0 * se3_exp(-d), T1, a), T)) /
          (2.0 * kStep);
      numeric1.col(i) =
          (minus(se3_interpolate(T0, T1 * se3_exp(d), a), T) - minus(se3_interpolate(T0, T1 * se3_exp(-d), a), T)) /
          (2.0 * kStep);
    }
    EXPECT_LT((numeric0 - J0).norm(), kMaxJacobianError) << "a " << a;
    EXPECT_LT((numeric1 - J1).norm(), kMaxJacobianError) << "a " << a;
  }
  // The ends: T(0) = T0, T(1) = T1.
  const Pose T0 = se3_exp(random_xi(rng, 10.0, 1.0));
  const Pose T1 = T0 * se3_exp(random_xi(rng, 0.5, 0.4));
  EXPECT_LT((se3_interpolate(T0, T1, 1.0).p - T1.p).norm(), 1e-12);
  EXPECT_LT(se3_interpolate(T0, T1, 0.0).q.angularDistance(T0.q), 1e-12);
}

TEST(Se3Test, PointJacobianMatchesNumericDifferences) {
  std::mt19937_64 rng(6);
  const Pose T = se3_exp(random_xi(rng, 10.0, 1.0));
  const Eigen::Vector3d x(0.1, -0.3, 0.12);
  Eigen::Matrix<double, 3, 6> J;
  const Eigen::Vector3d p = transform_point(T, x, &J);
  Eigen::Matrix<double, 3, 6> numeric;
  for (int i = 0; i < 6; ++i) {
    Vector6d d = Vector6d::Zero();
    d[i] = kStep;
    numeric.col(i) = (transform_point(T * se3_exp(d), x) - transform_point(T * se3_exp(-d), x)) / (2.0 * kStep);
  }
  EXPECT_LT((numeric - J).norm(), kMaxJacobianError);
  EXPECT_LT((p - T * x).norm(), 1e-12);
}

}  // namespace
}  // namespace canyon::core
