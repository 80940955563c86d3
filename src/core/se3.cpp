// SO(3) and SE(3) maths (conventions in se3.hpp).

#include "canyon/core/se3.hpp"

#include <cmath>

namespace canyon::core {
namespace {

// Below this angle the closed forms lose digits and their Taylor series are used (rad).
constexpr double kSmallAngleRad = 1e-4;

}  // namespace

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

Eigen::Quaterniond so3_exp(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  if (theta < kSmallAngleRad) {
    // sin(t/2)/t = 1/2 - t^2/48, cos(t/2) = 1 - t^2/8.
    const double s = 0.5 - theta * theta / 48.0;
    return Eigen::Quaterniond(1.0 - theta * theta / 8.0, s * phi.x(), s * phi.y(), s * phi.z()).normalized();
  }
  const double half = 0.5 * theta;
  const double s = std::sin(half) / theta;
  return {std::cos(half), s * phi.x(), s * phi.y(), s * phi.z()};
}

Eigen::Vector3d so3_log(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // the same rotation, angle in [0, pi]
  const double n = q.vec().norm();
  if (n < 0.5 * kSmallAngleRad) {
    // angle = 2 atan2(n, w) ~ 2 n / w (1 - n^2 / (3 w^2)).
    return (2.0 / q.w()) * (1.0 - n * n / (3.0 * q.w() * q.w())) * q.vec();
  }
  return (2.0 * std::atan2(n, q.w()) / n) * q.vec();
}

Eigen::Matrix3d so3_left_jacobian(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d k = skew(phi);
  const double t2 = theta * theta;
  double a = 0.0;  // (1 - cos t) / t^2
  double b = 0.0;  // (t - sin t) / t^3
  if (theta < kSmallAngleRad) {
    a = 0.5 - t2 / 24.0;
    b = 1.0 / 6.0 - t2 / 120.0;
  } else {
    a = (1.0 - std::cos(theta)) / t2;
    b = (theta - std::sin(theta)) / (t2 * theta);
  }
  return Eigen::Matrix3d::Identity() + a * k + b * k * k;
}

Eigen::Matrix3d so3_right_jacobian(const Eigen::Vector3d& phi) {
  return so3_left_jacobian(-phi);
}

Eigen::Matrix3d so3_left_jacobian_inverse(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d k = skew(phi);
  double c = 0.0;  // 1/t^2 - (1 + cos t) / (2 t sin t)
  if (theta < kSmallAngleRad) {
    c = 1.0 / 12.0 + theta * theta / 720.0;
  } else {
    c = 1.0 / (theta * theta) - (1.0 + std::cos(theta)) / (2.0 * theta * std::sin(theta));
  }
  return Eigen::Matrix3d::Identity() - 0.5 * k + c * k * k;
}

Eigen::Matrix3d so3_right_jacobian_inverse(const Eigen::Vector3d& phi) {
  return so3_left_jacobian_inverse(-phi);
}

Pose se3_exp(const Vector6d& xi) {
  const Eigen::Vector3d phi = xi.tail<3>();
  return {so3_exp(phi), so3_left_jacobian(phi) * xi.head<3>()};
}

Vector6d se3_log(const Pose& T) {
  const Eigen::Vector3d phi = so3_log(T.q);
  Vector6d xi;
  xi << so3_left_jacobian_inverse(phi) * T.p, phi;
  return xi;
}

Matrix6d se3_adjoint(const Pose& T) {
  const Eigen::Matrix3d R = T.q.toRotationMatrix();
  Matrix6d ad = Matrix6d::Zero();
  ad.topLeftCorner<3, 3>() = R;
  ad.topRightCorner<3, 3>() = skew(T.p) * R;
  ad.bottomRightCorner<3, 3>() = R;
  return ad;
}

Matrix6d se3_left_jacobian(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d phi = xi.tail<3>();
  const double theta = phi.norm();
  const double t2 = theta * theta;
  double c1 = 0.0;  // (t - sin t) / t^3
  double c2 = 0.0;  // (t^2 + 2 cos t - 2) / (2 t^4)
  double c3 = 0.0;  // (2 t - 3 sin t + t cos t) / (2 t^5)
  if (theta < kSmallAngleRad) {
    c1 = 1.0 / 6.0 - t2 / 120.0;
    c2 = 1.0 / 24.0 - t2 / 720.0;
    c3 = 1.0 / 120.0 - t2 / 2520.0;
  } else {
    const double s = std::sin(theta);
    const double c = std::cos(theta);
    c1 = (theta - s) / (t2 * theta);
    c2 = (t2 + 2.0 * c - 2.0) / (2.0 * t2 * t2);
    c3 = (2.0 * theta - 3.0 * s + theta * c) / (2.0 * t2 * t2 * theta);
  }
  const Eigen::Matrix3d P = skew(phi);
  const Eigen::Matrix3d V = skew(rho);
  const Eigen::Matrix3d PV = P * V;
  const Eigen::Matrix3d VP = V * P;
  const Eigen::Matrix3d PVP = PV * P;
  const Eigen::Matrix3d Q =
      0.5 * V + c1 * (PV + VP + PVP) + c2 * (P * PV + VP * P - 3.0 * PVP) + c3 * (PVP * P + P * PVP);
  Matrix6d J = Matrix6d::Zero();
  const Eigen::Matrix3d J_so3 = so3_left_jacobian(phi);
  J.topLeftCorner<3, 3>() = J_so3;
  J.topRightCorner<3, 3>() = Q;
  J.bottomRightCorner<3, 3>() = J_so3;
  return J;
}

Matrix6d se3_right_jacobian(const Vector6d& xi) {
  return se3_left_jacobian(-xi);
}

Matrix6d se3_right_jacobian_inverse(const Vector6d& xi) {
  // [[A, B], [0, A]]^-1 = [[A^-1, -A^-1 B A^-1], [0, A^-1]].
  const Matrix6d J = se3_right_jacobian(xi);
  const Eigen::Matrix3d A_inv = so3_right_jacobian_inverse(xi.tail<3>());
  Matrix6d inv = Matrix6d::Zero();
  inv.topLeftCorner<3, 3>() = A_inv;
  inv.topRightCorner<3, 3>() = -A_inv * J.topRightCorner<3, 3>() * A_inv;
  inv.bottomRightCorner<3, 3>() = A_inv;
  return inv;
}

Pose se3_interpolate(const Pose& T_0, const Pose& T_1, double a, Matrix6d* J_T_T0, Matrix6d* J_T_T1) {
  const Pose D = T_0.inverse() * T_1;
  const Vector6d d = se3_log(D);
  const Vector6d ad = a * d;
  const Pose step = se3_exp(ad);
  if (J_T_T0 != nullptr || J_T_T1 != nullptr) {
    const Matrix6d J1 = a * se3_right_jacobian(ad) * se3_right_jacobian_inverse(d);
    if (J_T_T1 != nullptr) *J_T_T1 = J1;
    if (J_T_T0 != nullptr) *J_T_T0 = se3_adjoint(step.inverse()) - J1 * se3_adjoint(D.inverse());
  }
  Pose T = T_0 * step;
  T.q.normalize();
  return T;
}

Eigen::Vector3d transform_point(const Pose& T, const Eigen::Vector3d& x, Eigen::Matrix<double, 3, 6>* J_p_T) {
  const Eigen::Matrix3d R = T.q.toRotationMatrix();
  if (J_p_T != nullptr) {
    J_p_T->leftCols<3>() = R;
    J_p_T->rightCols<3>() = -R * skew(x);
  }
  return R * x + T.p;
}

}  // namespace canyon::core
