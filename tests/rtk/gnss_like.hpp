#pragma once
// Test and benchmark problems for integer least squares.
//
// GNSS-like: single-epoch, single-frequency double differences (DD) between two receivers, reference satellite 0.
// Unknowns: baseline b (3, m) and n DD ambiguities a (cycles). Code: P = G b + e_P, phase: Phi = G b + lambda a +
// e_Phi, G(s, :) = (u_s - u_0)^T with u_s the unit line of sight. Undifferenced noise sigma^2 per receiver, so the
// DD covariance is 2 sigma^2 (I + 1 1^T). Q_a is the ambiguity block of the inverse normal matrix: three loose
// directions (the baseline, code-level, ~cycles^2) and n - 3 tight ones (phase-level, ~1e-4 cycles^2), with the
// strong correlation of real DD float ambiguities.

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

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

// ---------------------------------------------------------------------------------------------------------------
// What an RTK engine feeds MLAMBDA: the DD-ambiguity covariance of a static-baseline EKF after k epochs of
// dual-frequency DD code and phase.
//   State:       x = [b (3, m); N (n_sat x n_freq single-difference ambiguities, cycles)], prior x ~ (0, P_0),
//                P_0 = diag(sigma_b0^2 I_3, sigma_N0^2 I) (large: 100 m, 100 cycles), no process noise.
//   Epoch e:     per frequency f, against the reference satellite r (highest at e = 0, kept throughout),
//                  DD code   P_sr = g_s^T b + e_P,               g_s = -(u_s - u_r), u the unit line of sight,
//                  DD phase  Phi_sr = g_s^T b + lambda_f (N_sf - N_rf) + e_Phi   [m].
//                Undifferenced noise sigma(el) = sigma_zenith / sin(el) per receiver, so the DD covariance per
//                frequency and type is diag(2 sigma_s^2)_{s != r} + 2 sigma_r^2 1 1^T; code, phase and frequencies
//                are independent. sigma_zenith 0.3 m (code), 3 mm (phase).
//   Sky:         n_sat satellites, azimuth uniform, sin(elevation) uniform in [sin 15 deg, 1], each moving at a
//                random rate (|d az/dt| <= 0.01 deg/s, |d el/dt| <= 0.008 deg/s, about the apparent motion of MEO
//                satellites) with epochs 30 s apart: the geometry changes by a few degrees over 20 epochs.
//   Output:      Q_a = cov(a), a = DD ambiguities a_sf = N_sf - N_rf, n = (n_sat - 1) n_freq, ordered frequency
//                major. With no process noise the EKF covariance after k updates equals the inverse of the
//                accumulated information P_0^{-1} + sum_e H_e^T R_e^{-1} H_e; it is formed in the DD
//                parameterisation y = [b; N_rf; a] (an exact change of variables, N = M y) and Q_a is the inverse of
//                the Schur complement of the (b, N_r) block. That avoids D P_NN D^T, which would cancel the
//                100-cycle common-mode prior down to the mm-level DD precision and lose ~8 digits.
// ---------------------------------------------------------------------------------------------------------------

struct EkfAmbiguityOptions {
  int num_satellites = 16;              ///< satellites in view, >= 2; n = (num_satellites - 1) num_frequencies
  int num_epochs = 5;                   ///< k, EKF updates accumulated, >= 1
  double sigma_code_zenith_m = 0.3;     ///< undifferenced code noise at zenith [m]
  double sigma_phase_zenith_m = 0.003;  ///< undifferenced phase noise at zenith [m]
  double sigma_baseline_prior_m = 100.0;
  double sigma_ambiguity_prior_cyc = 100.0;
  double epoch_interval_s = 30.0;
};

inline Eigen::MatrixXd ekf_ambiguity_covariance(const EkfAmbiguityOptions& options, std::mt19937_64& rng) {
  constexpr double kPi = 3.14159265358979323846;
  constexpr double kDegToRad = kPi / 180.0;
  constexpr double kWavelengthM[] = {299792458.0 / 1575.42e6, 299792458.0 / 1227.60e6};  // GPS L1, L2
  constexpr int kNumFrequencies = 2;
  const int n_sat = options.num_satellites;
  const int n_dd = n_sat - 1;
  const int n = n_dd * kNumFrequencies;
  std::uniform_real_distribution<double> azimuth_rad(0.0, 2.0 * kPi);
  std::uniform_real_distribution<double> sin_elevation(std::sin(15.0 * kDegToRad), 1.0);
  std::uniform_real_distribution<double> azimuth_rate_rad_s(-0.01 * kDegToRad, 0.01 * kDegToRad);
  std::uniform_real_distribution<double> elevation_rate_rad_s(-0.008 * kDegToRad, 0.008 * kDegToRad);
  Eigen::VectorXd az0(n_sat), el0(n_sat), az_rate(n_sat), el_rate(n_sat);
  for (int s = 0; s < n_sat; ++s) {
    az0(s) = azimuth_rad(rng);
    el0(s) = std::asin(sin_elevation(rng));
    az_rate(s) = azimuth_rate_rad_s(rng);
    el_rate(s) = elevation_rate_rad_s(rng);
  }
  Eigen::Index ref = 0;
  el0.maxCoeff(&ref);
  std::vector<int> others;  // satellites s != ref, in the order of the DD ambiguities
  for (int s = 0; s < n_sat; ++s) {
    if (s != ref) others.push_back(s);
  }

  // y = [b (3); N_ref per frequency (2); a (n)]: information matrix Lambda_y.
  const int n_y = 3 + kNumFrequencies + n;
  Eigen::MatrixXd info = Eigen::MatrixXd::Zero(n_y, n_y);
  info.topLeftCorner(3, 3).diagonal().setConstant(1.0 /
                                                  (options.sigma_baseline_prior_m * options.sigma_baseline_prior_m));
  // Prior on N = M y: N_rf = y_{3+f}, N_sf = y_{3+f} + a_sf, so sum over N of N^2 / sigma^2 becomes M^T M / sigma^2.
  const double w_prior = 1.0 / (options.sigma_ambiguity_prior_cyc * options.sigma_ambiguity_prior_cyc);
  for (int f = 0; f < kNumFrequencies; ++f) {
    const int r = 3 + f;
    info(r, r) += w_prior * n_sat;
    for (int j = 0; j < n_dd; ++j) {
      const int a = 3 + kNumFrequencies + f * n_dd + j;
      info(a, a) += w_prior;
      info(r, a) += w_prior;
      info(a, r) += w_prior;
    }
  }
  for (int epoch = 0; epoch < options.num_epochs; ++epoch) {
    const double t_s = epoch * options.epoch_interval_s;
    Eigen::MatrixXd u(n_sat, 3);
    Eigen::VectorXd sin_el(n_sat);
    for (int s = 0; s < n_sat; ++s) {
      const double el = std::clamp(el0(s) + el_rate(s) * t_s, 10.0 * kDegToRad, 90.0 * kDegToRad);
      const double az = az0(s) + az_rate(s) * t_s;
      sin_el(s) = std::sin(el);
      u.row(s) << std::cos(el) * std::sin(az), std::cos(el) * std::cos(az), sin_el(s);
    }
    Eigen::MatrixXd G(n_dd, 3);
    for (int j = 0; j < n_dd; ++j) G.row(j) = -(u.row(others[j]) - u.row(ref));
    for (const bool phase : {false, true}) {
      const double sigma_zenith_m = phase ? options.sigma_phase_zenith_m : options.sigma_code_zenith_m;
      Eigen::MatrixXd R = Eigen::MatrixXd::Constant(n_dd, n_dd, 2.0 * std::pow(sigma_zenith_m / sin_el(ref), 2));
      for (int j = 0; j < n_dd; ++j) R(j, j) += 2.0 * std::pow(sigma_zenith_m / sin_el(others[j]), 2);
      const Eigen::MatrixXd W = R.llt().solve(Eigen::MatrixXd::Identity(n_dd, n_dd));
      for (int f = 0; f < kNumFrequencies; ++f) {
        // H = [G, 0, lambda_f I on this frequency's block] (phase) or [G, 0, 0] (code).
        const int a0 = 3 + kNumFrequencies + f * n_dd;
        info.topLeftCorner(3, 3) += G.transpose() * W * G;
        if (!phase) continue;
        const double lambda = kWavelengthM[f];
        info.block(0, a0, 3, n_dd) += lambda * G.transpose() * W;
        info.block(a0, 0, n_dd, 3) += lambda * W * G;
        info.block(a0, a0, n_dd, n_dd) += lambda * lambda * W;
      }
    }
  }
  // Q_a = (Lambda_aa - Lambda_ar Lambda_rr^{-1} Lambda_ra)^{-1}, r = (b, N_ref).
  const int n_r = 3 + kNumFrequencies;
  const Eigen::LLT<Eigen::MatrixXd> llt_rr(info.topLeftCorner(n_r, n_r));
  const Eigen::MatrixXd schur =
      info.bottomRightCorner(n, n) - info.bottomLeftCorner(n, n_r) * llt_rr.solve(info.topRightCorner(n_r, n));
  const Eigen::MatrixXd Q_a =
      Eigen::MatrixXd(0.5 * (schur + schur.transpose())).llt().solve(Eigen::MatrixXd::Identity(n, n));
  return 0.5 * (Q_a + Q_a.transpose());
}

/// EKF-like covariance (above) with n = 2 (num_satellites - 1) and a_float = a_true + a draw from Q_a.
inline IlsProblem ekf_ambiguity_problem(const EkfAmbiguityOptions& options, std::mt19937_64& rng) {
  IlsProblem p;
  p.Q_a = ekf_ambiguity_covariance(options, rng);
  p.a_float = sample_float(p.Q_a, rng);
  return p;
}

/// The problem of ekf_ambiguity_problem() epoch after epoch: the same satellites (their geometry drawn from `seed`),
/// options.num_epochs epochs of data in the first problem and one more in each next (for warm starts of the search).
inline std::vector<IlsProblem> ekf_ambiguity_sequence(EkfAmbiguityOptions options, std::uint64_t seed, int count) {
  std::vector<IlsProblem> out;
  std::mt19937_64 noise(seed + 1);
  for (int k = 0; k < count; ++k, ++options.num_epochs) {
    std::mt19937_64 geometry(seed);
    IlsProblem p;
    p.Q_a = ekf_ambiguity_covariance(options, geometry);
    p.a_float = sample_float(p.Q_a, noise);
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace canyon::rtk::testing
