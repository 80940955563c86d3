#pragma once
// Rigid-body maths, written once for all of canyon: SO(3) and SE(3) exponential and logarithm, adjoint, Jacobians,
// geodesic interpolation with its Jacobians.
//
// Conventions (DESIGN.md, as manif):
//  - Hamilton quaternions, q = (w, x, y, z), rotating vectors as R(q) v; T = (R, p) maps x to R x + p, and
//    T_AB maps B-coordinates into A (p_A = T_AB * p_B).
//  - Tangent vectors xi = [rho; theta] (translation first, then rotation vector), right perturbation:
//      T (+) xi = T Exp(xi),   Exp(xi) = (Exp(theta), J_l(theta) rho).
//  - Jacobians of f(T) are right Jacobians: f(T Exp(xi)) = f(T) Exp(J xi) + O(|xi|^2) on groups, or
//    f(T) + J xi + O(|xi|^2) on vectors; they are named J_<out>_<in>.
//  - SO(3): J_l(phi) = I + (1 - cos t) / t^2 [phi]x + (t - sin t) / t^3 [phi]x^2 (t = |phi|), J_r(phi) = J_l(-phi);
//    Exp(phi + d) = Exp(phi) Exp(J_r(phi) d), Log(Exp(phi) Exp(d)) = phi + J_r(phi)^-1 d.
//  - SE(3): Ad(T) = [[R, [p]x R], [0, R]] (Exp(Ad(T) xi) = T Exp(xi) T^-1);
//    J_l(xi) = [[J_l(theta), Q(rho, theta)], [0, J_l(theta)]] with Barfoot's Q (State Estimation for Robotics,
//    eq. 7.86), J_r(xi) = J_l(-xi); Exp(xi + d) = Exp(xi) Exp(J_r(xi) d), Log(T Exp(d)) = Log(T) + J_r(Log T)^-1 d.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace canyon::core {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// [v]x: skew(v) w = v x w.
[[nodiscard]] Eigen::Matrix3d skew(const Eigen::Vector3d& v);

/// SO(3) exponential of a rotation vector, and logarithm (angle in [0, pi]).
[[nodiscard]] Eigen::Quaterniond so3_exp(const Eigen::Vector3d& phi);
[[nodiscard]] Eigen::Vector3d so3_log(const Eigen::Quaterniond& q);
/// SO(3) left and right Jacobians and their inverses.
[[nodiscard]] Eigen::Matrix3d so3_left_jacobian(const Eigen::Vector3d& phi);
[[nodiscard]] Eigen::Matrix3d so3_right_jacobian(const Eigen::Vector3d& phi);
[[nodiscard]] Eigen::Matrix3d so3_left_jacobian_inverse(const Eigen::Vector3d& phi);
[[nodiscard]] Eigen::Matrix3d so3_right_jacobian_inverse(const Eigen::Vector3d& phi);

/// A rigid transform T = (R(q), p) in SE(3).
struct Pose {
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();

  [[nodiscard]] Pose operator*(const Pose& b) const { return {q * b.q, p + q * b.p}; }
  /// T x = R x + p.
  [[nodiscard]] Eigen::Vector3d operator*(const Eigen::Vector3d& x) const { return q * x + p; }
  [[nodiscard]] Pose inverse() const { return {q.conjugate(), -(q.conjugate() * p)}; }
  [[nodiscard]] Eigen::Matrix3d rotation() const { return q.toRotationMatrix(); }
};

/// SE(3) exponential and logarithm for xi = [rho; theta].
[[nodiscard]] Pose se3_exp(const Vector6d& xi);
[[nodiscard]] Vector6d se3_log(const Pose& T);
/// Adjoint of T for the [translation; rotation] ordering: Exp(Ad(T) xi) = T Exp(xi) T^-1.
[[nodiscard]] Matrix6d se3_adjoint(const Pose& T);
/// SE(3) left and right Jacobians (ordering [rho; theta]) and the inverse of the right one.
[[nodiscard]] Matrix6d se3_left_jacobian(const Vector6d& xi);
[[nodiscard]] Matrix6d se3_right_jacobian(const Vector6d& xi);
[[nodiscard]] Matrix6d se3_right_jacobian_inverse(const Vector6d& xi);

/// Geodesic interpolation T(a) = T_0 Exp(a Log(T_0^-1 T_1)), a in [0, 1] (a outside extrapolates), with its right
/// Jacobians: with d = Log(T_0^-1 T_1) and D = T_0^-1 T_1,
///   J_T_T1 = a J_r(a d) J_r(d)^-1,   J_T_T0 = Ad(Exp(-a d)) - J_T_T1 Ad(D^-1).
[[nodiscard]] Pose se3_interpolate(const Pose& T_0, const Pose& T_1, double a, Matrix6d* J_T_T0 = nullptr,
                                   Matrix6d* J_T_T1 = nullptr);

/// A point x of the body frame in the reference frame, T x, with its right Jacobian [R, -R [x]x].
[[nodiscard]] Eigen::Vector3d transform_point(const Pose& T, const Eigen::Vector3d& x,
                                              Eigen::Matrix<double, 3, 6>* J_p_T = nullptr);

}  // namespace canyon::core
