#pragma once
// Test and benchmark problems for integer least squares.
//
// GNSS-like: single-epoch, single-frequency double differences (DD) between two receivers, reference satellite 0.
// Unknowns: baseline b (3, m) and n DD ambiguities a (cycles). Code: P = G b + e_P, phase: Phi = G b + lambda a +
// e_Phi, G(s, :) = (u_s - u_0)^T with u_s the unit line of sight. Undifferenced noise sigma^2 per receiver, so the
// DD covariance is 2 sigma^2 (I + 1 1^T). Q_a is the ambiguity block of the inverse normal matrix: three loose
// directions (the baseline, code-level, ~cycles^2) and n - 3 tight ones (phase-level, ~1e-4 cycles^2), with the
// strong correlation of real DD float ambiguities.

#include <cmath>
#include <random>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>

namespace canyon::rtk::testing {

struct IlsProblem {
  Eigen::VectorXd a_float;
  Eigen::MatrixXd Q_a;
};

inline Eigen::MatrixXd gnss_like_covariance(int n, std::mt19937_64& rng, double sigma_code_m = 0.3,
                                            double sigma_phase_m = 0.003, double wavelength_m = 0.1903) {
  constexpr double kPi = 3.14159265358979323846;
  std::uniform_real_distribution<double> azimuth_rad(0.0, 2.0 * kPi);
  std::uniform_real_distribution<double> sin_elevation(std::sin(10.0 * kPi / 180.0), 1.0);
  Eigen::MatrixXd u(n + 1, 3);
  for (int s = 0; s <= n; ++s) {
    const double se = sin_elevation(rng);
    const double ce = std::sqrt(1.0 - se * se);
    const double az = azimuth_rad(rng);
    u.row(s) << ce * std::sin(az), ce * std::cos(az), se;
  }
  const Eigen::MatrixXd G = u.bottomRows(n).rowwise() - u.row(0);
  const Eigen::MatrixXd C_dd = 2.0 * (Eigen::MatrixXd::Identity(n, n) + Eigen::MatrixXd::Ones(n, n));
  const Eigen::MatrixXd W_dd = C_dd.inverse();
  const double w_code = 1.0 / (sigma_code_m * sigma_code_m);
  const double w_phase = 1.0 / (sigma_phase_m * sigma_phase_m);
  Eigen::MatrixXd N(n + 3, n + 3);
  N.topLeftCorner(3, 3) = (w_code + w_phase) * G.transpose() * W_dd * G;
  N.topRightCorner(3, n) = w_phase * wavelength_m * G.transpose() * W_dd;
  N.bottomLeftCorner(n, 3) = N.topRightCorner(3, n).transpose();
  N.bottomRightCorner(n, n) = w_phase * wavelength_m * wavelength_m * W_dd;
  const Eigen::MatrixXd Q = N.inverse();
  const Eigen::MatrixXd Q_a = Q.bottomRightCorner(n, n);
  return 0.5 * (Q_a + Q_a.transpose());
}

/// a_float = a_true + noise ~ N(0, Q_a), a_true integers in [-1000, 1000].
inline Eigen::VectorXd sample_float(const Eigen::MatrixXd& Q_a, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_int_distribution<int> integer(-1000, 1000);
  const Eigen::Index n = Q_a.rows();
  Eigen::VectorXd white(n), a_true(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    white(i) = normal(rng);
    a_true(i) = integer(rng);
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(Q_a);
  return a_true + llt.matrixL() * white;
}

inline IlsProblem gnss_like_problem(int n, std::mt19937_64& rng) {
  IlsProblem p;
  p.Q_a = gnss_like_covariance(n, rng);
  p.a_float = sample_float(p.Q_a, rng);
  return p;
}

}  // namespace canyon::rtk::testing
