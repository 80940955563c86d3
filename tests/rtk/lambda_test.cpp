// Tests of MLAMBDA and the ambiguity-resolution helpers.
//
// Reference solutions come from an exhaustive enumeration written independently of the library's search:
//   - bound: chi2 = the larger squared norm of two distinct integer vectors (the ones mlambda returned, their norms
//     recomputed here in long double) bounds the second-best norm from above, so every integer vector with norm
//     <= chi2 contains the two best;
//   - basis: the primal lattice. With Q_a^{-1} = R^T R, ||R (a - a_float)||^2 is the norm; the columns of R are
//     LLL-reduced here (textbook LLL, delta = 0.99, long double), B = R U with U unimodular, and B = Q' R' (QR).
//     mlambda instead factorises and reduces the dual, Q_a itself, as L^T D L;
//   - enumeration: Fincke-Pohst, depth first over w = U^{-1} a from the last coordinate, every integer in the
//     interval allowed by the remaining budget chi2 - (partial norm), in ascending order, fixed radius (no
//     shrinking, no zig-zag). Every integer vector with norm <= chi2 is visited exactly once.

#include "canyon/rtk/lambda.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include "rtk/gnss_like.hpp"

namespace canyon::rtk {
namespace {

using MatrixXld = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
using VectorXld = Eigen::Matrix<long double, Eigen::Dynamic, 1>;

// Squared norms agree to 1e-9 relative, except that no double-precision factorisation of the given Q_a can do
// better than ~cond(Q_a) eps: the bound is max(1e-9, 10 cond eps) (2.2e-7 at cond 1e8; observed ~1e-8 there).
constexpr double kMaxRelNormError = 1e-9;
constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kMaxRelFactorError = 1e-12;

double condition_number(const Eigen::MatrixXd& Q) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Q);
  return eig.eigenvalues().maxCoeff() / eig.eigenvalues().minCoeff();
}

double norm_tolerance(const Eigen::MatrixXd& Q_a) {
  return std::max(kMaxRelNormError, 10.0 * condition_number(Q_a) * kEps);
}

/// (u - u_hat)^T Q^{-1} (u - u_hat) in long double.
class QuadraticForm {
 public:
  QuadraticForm(const Eigen::VectorXd& u_hat, const Eigen::MatrixXd& Q)
      : u_hat_(u_hat.cast<long double>()), ldlt_(Q.cast<long double>()) {}
  long double operator()(const Eigen::VectorXd& u) const {
    const VectorXld e = u.cast<long double>() - u_hat_;
    return e.dot(ldlt_.solve(e));
  }

 private:
  VectorXld u_hat_;
  Eigen::LDLT<MatrixXld> ldlt_;
};

struct EnumerationBest {
  Eigen::VectorXd best, second;  // in the a-space
  double best_norm = std::numeric_limits<double>::infinity();
  double second_norm = std::numeric_limits<double>::infinity();
  std::int64_t nodes = 0;  // enumeration nodes visited
};

constexpr std::int64_t kMaxEnumerationNodes = 20'000'000;

/// Textbook LLL (delta = 0.99) on the columns of B, in place; U accumulates the unimodular column operations
/// (B_out = B_in U). Gram-Schmidt is recomputed from scratch after each change (n <= 12 here: cheap and simple).
void lll_reduce_columns(MatrixXld& B, MatrixXld& U) {
  constexpr long double kDelta = 0.99L;
  const Eigen::Index n = B.cols();
  U = MatrixXld::Identity(n, n);
  MatrixXld mu(n, n);
  VectorXld b_star_sq(n);
  const auto gram_schmidt = [&] {
    MatrixXld b_star = B;
    for (Eigen::Index i = 0; i < n; ++i) {
      for (Eigen::Index j = 0; j < i; ++j) {
        mu(i, j) = B.col(i).dot(b_star.col(j)) / b_star_sq(j);
        b_star.col(i) -= mu(i, j) * b_star.col(j);
      }
      b_star_sq(i) = b_star.col(i).squaredNorm();
    }
  };
  gram_schmidt();
  Eigen::Index k = 1;
  for (int step = 0; k < n && step < 100'000; ++step) {
    for (Eigen::Index j = k - 1; j >= 0; --j) {
      const long double q = std::round(mu(k, j));
      if (q == 0.0L) continue;
      B.col(k) -= q * B.col(j);
      U.col(k) -= q * U.col(j);
      gram_schmidt();
    }
    if (b_star_sq(k) >= (kDelta - mu(k, k - 1) * mu(k, k - 1)) * b_star_sq(k - 1)) {
      ++k;
    } else {
      B.col(k).swap(B.col(k - 1));
      U.col(k).swap(U.col(k - 1));
      gram_schmidt();
      k = std::max<Eigen::Index>(k - 1, 1);
    }
  }
}

/// Every integer a with (a - a_hat)^T Q^{-1} (a - a_hat) <= chi2, enumerated (see the top of this file); the two
/// smallest norms. Stops after kMaxEnumerationNodes (the caller asserts on nodes).
EnumerationBest enumerate_two_best(const Eigen::VectorXd& a_hat, const Eigen::MatrixXd& Q, double chi2) {
  const Eigen::Index n = a_hat.size();
  const MatrixXld W = Q.cast<long double>().ldlt().solve(MatrixXld::Identity(n, n));
  const Eigen::LLT<MatrixXld> llt(0.5L * (W + W.transpose()));
  MatrixXld B = llt.matrixU();  // W = R^T R, R upper triangular; norm = ||R (a - a_hat)||^2
  const VectorXld R_a_hat = B * a_hat.cast<long double>();
  MatrixXld U;
  lll_reduce_columns(B, U);
  const Eigen::HouseholderQR<MatrixXld> qr(B);
  const MatrixXld R_red = qr.matrixQR().triangularView<Eigen::Upper>();
  const VectorXld y = qr.householderQ().transpose() * R_a_hat;  // norm = ||R_red w - y||^2, a = U w
  const long double bound = static_cast<long double>(chi2) * (1.0L + 1e-9L) + 1e-300L;

  EnumerationBest out;
  VectorXld w = VectorXld::Zero(n);
  const auto visit = [&](const auto& self, Eigen::Index level, long double partial) -> void {
    if (++out.nodes > kMaxEnumerationNodes) return;
    long double centre_times_r = y(level);
    for (Eigen::Index j = level + 1; j < n; ++j) centre_times_r -= R_red(level, j) * w(j);
    const long double r = R_red(level, level);
    const long double centre = centre_times_r / r;
    const long double half_width = std::sqrt(std::max(bound - partial, 0.0L)) / std::abs(r);
    const auto first = static_cast<long long>(std::ceil(centre - half_width));
    const auto last = static_cast<long long>(std::floor(centre + half_width));
    for (long long candidate = first; candidate <= last; ++candidate) {
      const auto v = static_cast<long double>(candidate);
      const long double residual = r * v - centre_times_r;
      const long double norm = partial + residual * residual;
      if (norm > bound) continue;
      w(level) = v;
      if (level > 0) {
        self(self, level - 1, norm);
        continue;
      }
      const auto norm_d = static_cast<double>(norm);
      if (norm_d < out.second_norm) {
        const Eigen::VectorXd a = (U * w).cast<double>();
        if (norm_d < out.best_norm) {
          out.second = out.best;
          out.second_norm = out.best_norm;
          out.best = a;
          out.best_norm = norm_d;
        } else {
          out.second = a;
          out.second_norm = norm_d;
        }
      }
    }
  };
  visit(visit, n - 1, 0.0L);
  return out;
}

bool is_integer(const Eigen::MatrixXd& M) {
  return (M.array() == M.array().round()).all();
}

/// Random unimodular T (and its exact inverse) from integer column operations and swaps.
void random_unimodular(int n, int operations, std::mt19937_64& rng, Eigen::MatrixXd& T, Eigen::MatrixXd& T_inv) {
  std::uniform_int_distribution<int> index(0, n - 1);
  std::uniform_int_distribution<int> multiplier(-2, 2);
  T = Eigen::MatrixXd::Identity(n, n);
  T_inv = T;
  for (int s = 0; s < operations; ++s) {
    const int i = index(rng);
    const int j = index(rng);
    if (i == j) {
      continue;
    }
    const double c = multiplier(rng);
    T.col(j) += c * T.col(i);          // T <- T (I + c e_i e_j^T)
    T_inv.row(i) -= c * T_inv.row(j);  // inverse: (I - c e_i e_j^T) T^{-1}
    if (s % 3 == 0) {
      T.col(i).swap(T.col(j));
      T_inv.row(i).swap(T_inv.row(j));
    }
  }
}

Eigen::MatrixXd random_spd(int n, double diagonal_loading, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd B(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) B(i, j) = normal(rng);
  }
  return B.transpose() * B / n + diagonal_loading * Eigen::MatrixXd::Identity(n, n);
}

Eigen::VectorXd random_float(int n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> value(-100.0, 100.0);
  Eigen::VectorXd a(n);
  for (int i = 0; i < n; ++i) a(i) = value(rng);
  return a;
}

/// Q_a = T^{-T} Q_u T^{-1} with a random unimodular T, more column operations until cond(Q_a) >= target_cond.
/// Returns cond(Q_a) (may overshoot the target).
double correlated_problem(int n, double target_cond, const Eigen::MatrixXd& Q_u, std::mt19937_64& rng,
                          Eigen::MatrixXd& T, Eigen::MatrixXd& Q_a) {
  Eigen::MatrixXd T_inv;
  double cond = 0.0;
  for (int operations = n; operations < 400 && cond < target_cond; operations += 2) {
    random_unimodular(n, operations, rng, T, T_inv);
    Q_a = T_inv.transpose() * Q_u * T_inv;
    Q_a = 0.5 * (Q_a + Q_a.transpose());
    cond = condition_number(Q_a);
  }
  return cond;
}

double check_decorrelation(const Eigen::MatrixXd& Q_a);

/// Checks mlambda's two best against the independent enumeration.
void expect_matches_enumeration(const Eigen::VectorXd& a_float, const Eigen::MatrixXd& Q_a) {
  auto result = mlambda(a_float, Q_a);
  ASSERT_TRUE(result.ok()) << result.error().message;
  const double rel_tol = norm_tolerance(Q_a);
  ASSERT_EQ(result->candidates.cols(), 2);
  ASSERT_TRUE(is_integer(result->candidates));
  ASSERT_NE(result->candidates.col(0), result->candidates.col(1));
  const QuadraticForm norm(a_float, Q_a);
  const Eigen::VectorXd a0 = result->candidates.col(0);
  const Eigen::VectorXd a1 = result->candidates.col(1);
  const auto independent0 = static_cast<double>(norm(a0));
  const auto independent1 = static_cast<double>(norm(a1));
  EXPECT_NEAR(result->squared_norms(0), independent0, rel_tol * independent0);
  EXPECT_NEAR(result->squared_norms(1), independent1, rel_tol * independent1);

  const EnumerationBest ref = enumerate_two_best(a_float, Q_a, std::max(independent0, independent1));
  ASSERT_LE(ref.nodes, kMaxEnumerationNodes) << "test problem too large for the enumeration";
  EXPECT_EQ(a0, ref.best) << "n = " << a_float.size();
  EXPECT_EQ(a1, ref.second) << "n = " << a_float.size();
  check_decorrelation(Q_a);
  EXPECT_NEAR(result->squared_norms(0), ref.best_norm, rel_tol * ref.best_norm);
  EXPECT_NEAR(result->squared_norms(1), ref.second_norm, rel_tol * ref.second_norm);
}

TEST(MlambdaTest, OneDimension) {
  auto result = mlambda(Eigen::VectorXd::Constant(1, 2.3), Eigen::MatrixXd::Constant(1, 1, 0.1));
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result->candidates(0, 0), 2.0);
  EXPECT_EQ(result->candidates(0, 1), 3.0);
  EXPECT_NEAR(result->squared_norms(0), 0.09 / 0.1, 1e-12);
  EXPECT_NEAR(result->squared_norms(1), 0.49 / 0.1, 1e-12);
}

TEST(MlambdaTest, MatchesEnumerationOnWellConditionedProblems) {
  std::mt19937_64 rng(7);
  for (int n = 2; n <= 12; ++n) {
    for (int trial = 0; trial < 10; ++trial) {
      const Eigen::MatrixXd Q_a = 0.05 * random_spd(n, 0.5, rng);
      const Eigen::VectorXd a_float = random_float(n, rng);
      SCOPED_TRACE(::testing::Message() << "n = " << n << " trial " << trial << " cond " << condition_number(Q_a));
      expect_matches_enumeration(a_float, Q_a);
    }
  }
}

/// Q_a = 0.5 R diag(lambda) R^T with a random rotation R and lambda log-spaced from 1 to 1/cond.
Eigen::MatrixXd rotated_spectrum(int n, double cond, std::mt19937_64& rng) {
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(random_spd(n, 0.0, rng));
  const Eigen::MatrixXd R = qr.householderQ();
  Eigen::VectorXd lambda = Eigen::VectorXd::LinSpaced(n, 0.0, 1.0);
  lambda = (-std::log(cond) * lambda.array()).exp();
  const Eigen::MatrixXd Q_a = 0.5 * R * lambda.asDiagonal() * R.transpose();
  return 0.5 * (Q_a + Q_a.transpose());
}

TEST(MlambdaTest, MatchesEnumerationOnIllConditionedProblems) {
  // Intrinsically ill-conditioned (no unimodular transformation makes these well conditioned): condition numbers
  // 1e3 .. 1e8 in random directions.
  std::mt19937_64 rng(11);
  for (int n = 2; n <= 12; ++n) {
    for (int exponent = 3; exponent <= 8; ++exponent) {
      const double cond = std::pow(10.0, exponent);
      for (int trial = 0; trial < 2; ++trial) {
        const Eigen::MatrixXd Q_a = rotated_spectrum(n, cond, rng);
        const Eigen::VectorXd a_float = random_float(n, rng);
        SCOPED_TRACE(::testing::Message() << "n = " << n << " cond " << condition_number(Q_a));
        EXPECT_GT(condition_number(Q_a), 0.5 * cond);
        expect_matches_enumeration(a_float, Q_a);
      }
    }
  }
}

TEST(MlambdaTest, MatchesEnumerationOnHighlyCorrelatedProblems) {
  // Q_a = T^{-T} Q_u T^{-1}: correlated like DD ambiguities (a unimodular T decorrelates them), condition numbers
  // 1e3 .. 1e8.
  std::mt19937_64 rng(13);
  double largest_cond = 0.0;
  int problems = 0;
  for (int n = 2; n <= 12; ++n) {
    for (int trial = 0; trial < 12; ++trial) {
      const Eigen::MatrixXd Q_u = 0.02 * random_spd(n, 0.3, rng);
      const double target_cond = std::pow(10.0, 3.0 + 5.0 * trial / 11.0);
      Eigen::MatrixXd T, Q_a;
      const double cond = correlated_problem(n, target_cond, Q_u, rng, T, Q_a);
      if (cond < 1e3 || cond > 1e9) continue;  // generator overshoot or undershoot; counted below
      ++problems;
      largest_cond = std::max(largest_cond, cond);
      const Eigen::VectorXd a_float = random_float(n, rng);
      SCOPED_TRACE(::testing::Message() << "n = " << n << " trial " << trial << " cond " << cond);
      expect_matches_enumeration(a_float, Q_a);
    }
  }
  EXPECT_GE(problems, 100);
  EXPECT_GT(largest_cond, 1e7);
}

TEST(MlambdaTest, MatchesEnumerationOnEkfAmbiguityProblems) {
  // What an RTK engine feeds MLAMBDA (tests/rtk/gnss_like.hpp): dual-frequency DD ambiguities after k epochs.
  std::mt19937_64 rng(59);
  for (int satellites = 2; satellites <= 7; ++satellites) {
    for (int epochs : {1, 5, 20}) {
      for (int trial = 0; trial < 3; ++trial) {
        testing::EkfAmbiguityOptions options;
        options.num_satellites = satellites;
        options.num_epochs = epochs;
        const auto p = testing::ekf_ambiguity_problem(options, rng);
        SCOPED_TRACE(::testing::Message() << "n = " << p.a_float.size() << " epochs " << epochs);
        expect_matches_enumeration(p.a_float, p.Q_a);
      }
    }
  }
}

TEST(MlambdaTest, WithZReturnsTheDecorrelationAndTheSameCandidates) {
  // Z is only accumulated on request, and then L is size-reduced in full as decorrelate() does (without Z the search
  // runs on the partially reduced L, which visits the same nodes): the candidates are the same, the norms the same
  // up to rounding, and the Z returned is decorrelate()'s.
  std::mt19937_64 rng(67);
  for (int satellites : {4, 9, 16}) {
    testing::EkfAmbiguityOptions options;
    options.num_satellites = satellites;
    const auto p = testing::ekf_ambiguity_problem(options, rng);
    MlambdaOptions with_z;
    with_z.with_z = true;
    const auto plain = mlambda(p.a_float, p.Q_a);
    const auto full = mlambda(p.a_float, p.Q_a, with_z);
    const auto dec = decorrelate(p.Q_a);
    ASSERT_TRUE(plain.ok() && full.ok() && dec.ok());
    EXPECT_EQ(plain->Z.size(), 0);
    EXPECT_EQ(plain->candidates, full->candidates);
    for (Eigen::Index j = 0; j < plain->squared_norms.size(); ++j) {
      EXPECT_NEAR(plain->squared_norms[j], full->squared_norms[j], 1e-12 * full->squared_norms[j]);
    }
    EXPECT_EQ(full->Z, dec->Z);
  }
}

TEST(MlambdaTest, WarmStartGivesTheCandidatesOfAColdStartAndCarriesAnExactUnimodularBasis) {
  // An EKF's ambiguities epoch after epoch, each searched cold and warm (the decorrelation carried from the last
  // search): the same candidates, the same norms up to rounding, and the carried Z unimodular with Z^{-T} exact.
  for (int satellites : {5, 10, 16}) {
    testing::EkfAmbiguityOptions options;
    options.num_satellites = satellites;
    options.num_epochs = 2;
    MlambdaWarmStart warm;
    int epoch = 0;
    for (testing::IlsProblem& p : testing::ekf_ambiguity_sequence(options, 83 + satellites, 20)) {
      p.a_float.array() += 1.0e7;  // large ambiguities keep their fractional part
      const auto cold = mlambda(p.a_float, p.Q_a);
      const auto carried = mlambda(p.a_float, p.Q_a, MlambdaOptions{}, &warm);
      ASSERT_TRUE(cold.ok() && carried.ok()) << "satellites " << satellites << " epoch " << epoch;
      EXPECT_EQ(cold->candidates, carried->candidates) << "satellites " << satellites << " epoch " << epoch;
      for (Eigen::Index j = 0; j < cold->squared_norms.size(); ++j) {
        EXPECT_NEAR(cold->squared_norms[j], carried->squared_norms[j], 1e-9 * cold->squared_norms[j]);
      }
      const Eigen::Index n = p.a_float.size();
      ASSERT_EQ(warm.Z.rows(), n);
      ASSERT_EQ(warm.Z_inv_T.rows(), n);
      EXPECT_EQ(warm.Z, warm.Z.array().round().matrix());
      EXPECT_EQ(Eigen::MatrixXd(warm.Z.transpose() * warm.Z_inv_T), Eigen::MatrixXd::Identity(n, n));
      ++epoch;
    }
  }
}

TEST(MlambdaTest, WarmStartOfAnotherSizeStartsColdAndAFailedSearchForgetsIt) {
  std::mt19937_64 rng(89);
  const auto p = testing::gnss_like_problem(8, rng);
  MlambdaWarmStart warm;
  warm.Z = Eigen::MatrixXd::Identity(5, 5);
  warm.Z_inv_T = Eigen::MatrixXd::Identity(5, 5);
  const auto result = mlambda(p.a_float, p.Q_a, MlambdaOptions{}, &warm);
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result->candidates, mlambda(p.a_float, p.Q_a)->candidates);
  EXPECT_EQ(warm.Z.rows(), 8);
  MlambdaOptions capped;
  capped.max_search_nodes = 1;
  EXPECT_FALSE(mlambda(p.a_float, p.Q_a, capped, &warm).ok());
  EXPECT_EQ(warm.Z.size(), 0);
  EXPECT_EQ(warm.Z_inv_T.size(), 0);
}

TEST(MlambdaTest, DeJongeTiberiusExample) {
  // Three-dimensional example of de Jonge & Tiberius (1996, LGR-12) and Teunissen's LAMBDA papers, numbers as
  // recalled from the literature: a_float = (5.45, 3.10, 2.97), Q_a below; the published ILS solution is (5, 3, 4).
  // The brute-force check makes the expected answer independent of that recollection.
  Eigen::Vector3d a_float(5.45, 3.10, 2.97);
  Eigen::Matrix3d Q_a;
  Q_a << 6.290, 5.978, 0.544,  //
      5.978, 6.292, 2.340,     //
      0.544, 2.340, 6.288;
  auto result = mlambda(a_float, Q_a);
  ASSERT_TRUE(result.ok()) << result.error().message;
  EXPECT_EQ(Eigen::Vector3d(result->candidates.col(0)), Eigen::Vector3d(5, 3, 4));
  expect_matches_enumeration(a_float, Q_a);
}

TEST(MlambdaTest, LargeAmbiguitiesKeepTheirFractionalPart) {
  std::mt19937_64 rng(17);
  const auto p = testing::gnss_like_problem(10, rng);
  const double offset_cyc = 3.0e7;  // a realistic absolute ambiguity magnitude
  auto small = mlambda(p.a_float, p.Q_a);
  auto large = mlambda(p.a_float.array() + offset_cyc, p.Q_a);
  ASSERT_TRUE(small.ok() && large.ok());
  EXPECT_EQ(large->candidates, (small->candidates.array() + offset_cyc).matrix());
  EXPECT_NEAR(large->squared_norms(0), small->squared_norms(0), 1e-6 * small->squared_norms(0));
}

TEST(MlambdaTest, ReturnsTheRequestedNumberOfCandidatesInOrder) {
  std::mt19937_64 rng(19);
  const auto p = testing::gnss_like_problem(6, rng);
  MlambdaOptions options;
  options.num_candidates = 5;
  auto result = mlambda(p.a_float, p.Q_a, options);
  ASSERT_TRUE(result.ok());
  ASSERT_EQ(result->candidates.cols(), 5);
  const QuadraticForm norm(p.a_float, p.Q_a);
  for (int j = 0; j < 5; ++j) {
    const auto independent = static_cast<double>(norm(result->candidates.col(j)));
    EXPECT_NEAR(result->squared_norms(j), independent, 1e-8 * independent);
    if (j > 0) {
      EXPECT_GE(result->squared_norms(j), result->squared_norms(j - 1));
    }
  }
}

/// Structural checks of a decorrelation; returns cond(Z^T Q_a Z).
double check_decorrelation(const Eigen::MatrixXd& Q_a) {
  const Eigen::Index n = Q_a.rows();
  auto dec = decorrelate(Q_a);
  EXPECT_TRUE(dec.ok()) << dec.error().message;
  if (!dec.ok()) return std::numeric_limits<double>::infinity();
  EXPECT_TRUE(is_integer(dec->Z));
  EXPECT_TRUE(is_integer(dec->Z_inv));
  // Z Z_inv = I exactly (integer products and sums below 2^53 are exact in double), so det Z det Z_inv = 1 with both
  // determinants integers: |det Z| = 1. The LU determinant is a cross-check of that argument.
  EXPECT_EQ(dec->Z * dec->Z_inv, Eigen::MatrixXd::Identity(n, n));
  EXPECT_EQ(dec->Z_inv * dec->Z, Eigen::MatrixXd::Identity(n, n));
  EXPECT_NEAR(std::abs(dec->Z.fullPivLu().determinant()), 1.0, 1e-6);
  // "Triangular factors exact": Z^T Q_a Z is formed in long double from the exact integer Z and compared entrywise
  // with L^T D L in two ways.
  //   (a) Relative to the scale the transformed covariance is formed from, (|Z|^T |Q_a| |Z|)_ij: the factors are
  //       backward stable, <= 1e-12 (observed <= 3e-14) on every problem class.
  //   (b) Relative to the entry's own scale sqrt(Q_z,ii Q_z,jj): <= 1e-12 as long as cond(Q_a) eps is below that
  //       (observed <= 8e-13 on the EKF-like problems at cond 1e5, ~1e-16 on well-conditioned ones); for
  //       ill-conditioned Q_a no double-precision algorithm given Q_a in double can do better than ~cond eps, since
  //       Z^T Q_a Z cancels by a factor ~cond (observed 1e-9 at cond 1e8), so the bound is max(1e-12, cond eps).
  const MatrixXld Z_ld = dec->Z.cast<long double>();
  const MatrixXld Q_a_ld = Q_a.cast<long double>();
  const MatrixXld Q_z_ld = Z_ld.transpose() * Q_a_ld * Z_ld;
  const MatrixXld L_ld = dec->L.cast<long double>();
  const MatrixXld LtDL = L_ld.transpose() * dec->d.cast<long double>().asDiagonal() * L_ld;
  const MatrixXld formed_scale = Z_ld.cwiseAbs().transpose() * Q_a_ld.cwiseAbs() * Z_ld.cwiseAbs();
  const VectorXld sd = Q_z_ld.diagonal().cwiseSqrt();
  const MatrixXld abs_err = (Q_z_ld - LtDL).cwiseAbs();
  const auto err_vs_formed = static_cast<double>((abs_err.array() / formed_scale.array()).maxCoeff());
  const auto err_vs_entry = static_cast<double>((abs_err.array() / (sd * sd.transpose()).array()).maxCoeff());
  EXPECT_LE(err_vs_formed, kMaxRelFactorError) << "L^T D L vs Z^T Q_a Z relative to |Z|^T |Q_a| |Z|, n = " << n;
  EXPECT_LE(err_vs_entry, std::max(kMaxRelFactorError, condition_number(Q_a) * kEps))
      << "L^T D L vs Z^T Q_a Z relative to sqrt(Q_z,ii Q_z,jj), n = " << n;
  const Eigen::MatrixXd Q_z = Q_z_ld.cast<double>();
  EXPECT_TRUE(dec->L.isLowerTriangular(0.0));
  EXPECT_EQ(dec->L.diagonal(), Eigen::VectorXd::Ones(n));
  // Size-reduced and ordered: the LLL-like conditions the reduction stops on.
  for (Eigen::Index k = 0; k + 1 < n; ++k) {
    for (Eigen::Index i = k + 1; i < n; ++i) EXPECT_LE(std::abs(dec->L(i, k)), 0.5 + 1e-12);
    const double delta = dec->d(k) + dec->L(k + 1, k) * dec->L(k + 1, k) * dec->d(k + 1);
    EXPECT_GE(delta, (1.0 - 1e-8) * dec->d(k + 1) * (1.0 - 1e-12));
  }
  return condition_number(Q_z);
}

TEST(DecorrelateTest, GnssLikeAmbiguitiesAreDecorrelatedByAUnimodularZ) {
  std::mt19937_64 rng(23);
  for (int n : {5, 8, 15, 30}) {
    for (int trial = 0; trial < 5; ++trial) {
      const Eigen::MatrixXd Q_a = testing::gnss_like_covariance(n, rng);
      const double cond_a = condition_number(Q_a);
      const double cond_z = check_decorrelation(Q_a);
      EXPECT_LT(cond_z, cond_a / 10.0) << "n = " << n << " cond_a " << cond_a;
    }
  }
}

TEST(DecorrelateTest, EkfAmbiguitiesAreDecorrelatedByAUnimodularZ) {
  std::mt19937_64 rng(61);
  for (int satellites : {6, 11, 16}) {
    for (int epochs : {1, 5, 20}) {
      testing::EkfAmbiguityOptions options;
      options.num_satellites = satellites;
      options.num_epochs = epochs;
      const Eigen::MatrixXd Q_a = testing::ekf_ambiguity_covariance(options, rng);
      const double cond_a = condition_number(Q_a);
      EXPECT_LT(check_decorrelation(Q_a), cond_a / 10.0) << "n = " << Q_a.rows() << " epochs " << epochs;
    }
  }
}

TEST(DecorrelateTest, HighlyCorrelatedProblemsAreNotMadeWorse) {
  std::mt19937_64 rng(53);
  for (int n = 2; n <= 10; ++n) {
    for (int trial = 0; trial < 5; ++trial) {
      Eigen::MatrixXd T, Q_a;
      const double cond_a = correlated_problem(n, std::pow(10.0, 3.0 + trial), random_spd(n, 0.3, rng), rng, T, Q_a);
      EXPECT_GE(cond_a, 1e3);
      EXPECT_LE(check_decorrelation(Q_a), cond_a) << "n = " << n << " cond_a " << cond_a;
    }
  }
}

TEST(DecorrelateTest, CodeOnlyThreeSatelliteCaseDocumentsThatCondMayGrow) {
  // Three DD ambiguities from code only: Q_a ~ I + 1 1^T (cond 4). The reduction orders the conditional variances
  // but the condition number goes to 3 + 2 sqrt(2) = 5.83: LLL-type reduction does not promise a smaller
  // condition number, only a size-reduced, ordered L^T D L (and a search that is never slower in practice).
  const Eigen::MatrixXd Q_a = Eigen::MatrixXd::Identity(3, 3) + Eigen::MatrixXd::Ones(3, 3);
  EXPECT_NEAR(condition_number(Q_a), 4.0, 1e-12);
  EXPECT_LT(check_decorrelation(Q_a), 6.0);
}

TEST(MlambdaTest, RejectsBadInput) {
  const Eigen::Vector2d a(0.3, 0.4);
  Eigen::Matrix2d indefinite;
  indefinite << 1.0, 2.0, 2.0, 1.0;
  EXPECT_FALSE(mlambda(a, indefinite).ok());
  EXPECT_NE(mlambda(a, indefinite).error().message.find("positive definite"), std::string::npos);
  Eigen::Matrix2d singular;
  singular << 1.0, 1.0, 1.0, 1.0;
  EXPECT_FALSE(mlambda(a, singular).ok());
  Eigen::Matrix2d asymmetric;
  asymmetric << 1.0, 0.1, 0.2, 1.0;
  EXPECT_FALSE(mlambda(a, asymmetric).ok());
  EXPECT_FALSE(mlambda(Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Matrix2d::Identity()).ok());
  EXPECT_FALSE(mlambda(a, Eigen::MatrixXd::Identity(2, 3)).ok());
  EXPECT_FALSE(mlambda(Eigen::VectorXd(), Eigen::MatrixXd()).ok());
  EXPECT_FALSE(mlambda(Eigen::Vector2d(std::nan(""), 0.0), Eigen::Matrix2d::Identity()).ok());
  Eigen::Matrix2d with_inf = Eigen::Matrix2d::Identity();
  with_inf(1, 1) = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(mlambda(a, with_inf).ok());
  MlambdaOptions no_candidates;
  no_candidates.num_candidates = 0;
  EXPECT_FALSE(mlambda(a, Eigen::Matrix2d::Identity(), no_candidates).ok());
  EXPECT_FALSE(decorrelate(indefinite).ok());
}

TEST(MlambdaTest, SearchCapReturnsAnError) {
  std::mt19937_64 rng(29);
  const auto p = testing::gnss_like_problem(12, rng);
  MlambdaOptions options;
  options.max_search_nodes = 5;
  auto result = mlambda(p.a_float, p.Q_a, options);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().message.find("cap"), std::string::npos) << result.error().message;
  EXPECT_TRUE(mlambda(p.a_float, p.Q_a).ok());
}

TEST(MlambdaTest, GnssLikeDimension30IsFastAndOptimalAgainstObviousCandidates) {
  std::mt19937_64 rng(31);
  const auto start = std::chrono::steady_clock::now();
  constexpr int kProblems = 50;
  for (int trial = 0; trial < kProblems; ++trial) {
    const auto p = testing::gnss_like_problem(30, rng);
    auto result = mlambda(p.a_float, p.Q_a);
    ASSERT_TRUE(result.ok()) << result.error().message;
    const QuadraticForm norm(p.a_float, p.Q_a);
    const auto bootstrapped = static_cast<double>(norm(p.a_float.array().round().matrix()));
    EXPECT_LE(result->squared_norms(0), bootstrapped * (1.0 + 1e-9));
    EXPECT_NEAR(result->squared_norms(0), static_cast<double>(norm(result->candidates.col(0))),
                1e-8 * result->squared_norms(0));
  }
  const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(elapsed_s / kProblems, 0.05) << "mean time per n = 30 problem";
}

TEST(RatioTest, ThresholdAndEdgeCases) {
  IntegerSearchResult r;
  r.squared_norms = Eigen::Vector2d(1.0, 3.5);
  EXPECT_TRUE(ratio_test(r).passed);
  EXPECT_DOUBLE_EQ(ratio_test(r).ratio, 3.5);
  EXPECT_FALSE(ratio_test(r, 4.0).passed);
  r.squared_norms = Eigen::Vector2d(1.0, 2.9);
  EXPECT_FALSE(ratio_test(r).passed);
  r.squared_norms = Eigen::Vector2d(0.0, 2.0);
  EXPECT_TRUE(ratio_test(r).passed);
  EXPECT_TRUE(std::isinf(ratio_test(r).ratio));
  r.squared_norms = Eigen::Vector2d(1.0, 3.0);
  EXPECT_TRUE(ratio_test(r).passed);  // >= threshold passes
}

TEST(PartialArTest, ContributionsEqualTheDecreaseWhenRemovingEachAmbiguity) {
  std::mt19937_64 rng(37);
  for (int trial = 0; trial < 10; ++trial) {
    const int n = 4 + trial;
    const auto p = testing::gnss_like_problem(n, rng);
    const Eigen::VectorXd a_fix = p.a_float.array().round();
    auto c = ils_residual_contributions(p.a_float, p.Q_a, a_fix);
    ASSERT_TRUE(c.ok()) << c.error().message;
    const double full = static_cast<double>(QuadraticForm(p.a_float, p.Q_a)(a_fix));
    for (int i = 0; i < n; ++i) {
      std::vector<int> keep;
      for (int j = 0; j < n; ++j) {
        if (j != i) keep.push_back(j);
      }
      Eigen::VectorXd a_sub(n - 1), fix_sub(n - 1);
      Eigen::MatrixXd Q_sub(n - 1, n - 1);
      for (int r = 0; r < n - 1; ++r) {
        a_sub(r) = p.a_float(keep[r]);
        fix_sub(r) = a_fix(keep[r]);
        for (int s = 0; s < n - 1; ++s) Q_sub(r, s) = p.Q_a(keep[r], keep[s]);
      }
      const double reduced = static_cast<double>(QuadraticForm(a_sub, Q_sub)(fix_sub));
      EXPECT_GE((*c)(i), 0.0);
      EXPECT_NEAR((*c)(i), full - reduced, 1e-7 * full) << "i = " << i;
    }
  }
}

TEST(PartialArTest, BiasedAmbiguityHasTheLargestContribution) {
  std::mt19937_64 rng(41);
  std::uniform_int_distribution<int> pick(0, 11);
  int detected = 0;
  constexpr int kTrials = 20;
  for (int trial = 0; trial < kTrials; ++trial) {
    auto p = testing::gnss_like_problem(12, rng);
    // Bias-free float solution close to its integers, then a half-cycle slip on one ambiguity.
    const Eigen::VectorXd a_true = p.a_float.array().round();
    Eigen::VectorXd a_float = a_true + 0.01 * (p.a_float - a_true);
    const int biased = pick(rng);
    a_float(biased) += 0.5;
    auto c = ils_residual_contributions(a_float, p.Q_a, a_true);
    ASSERT_TRUE(c.ok());
    if (largest_contributions(*c, 1).front() == biased) ++detected;
  }
  EXPECT_EQ(detected, kTrials);
}

TEST(PartialArTest, LargestContributionsOrder) {
  EXPECT_EQ(largest_contributions(Eigen::Vector4d(0.1, 5.0, 2.0, 5.0), 3), (std::vector<int>{1, 3, 2}));
  EXPECT_EQ(largest_contributions(Eigen::Vector2d(0.1, 5.0), 5), (std::vector<int>{1, 0}));
}

TEST(PartialArTest, SolveWithoutMatchesTheExtractedSubproblem) {
  std::mt19937_64 rng(43);
  const auto p = testing::gnss_like_problem(9, rng);
  const std::vector<int> removed{7, 2};
  auto partial = solve_without(p.a_float, p.Q_a, removed);
  ASSERT_TRUE(partial.ok()) << partial.error().message;
  const std::vector<int> expected_kept{0, 1, 3, 4, 5, 6, 8};
  EXPECT_EQ(partial->kept_indices, expected_kept);
  Eigen::VectorXd a_sub(7);
  Eigen::MatrixXd Q_sub(7, 7);
  for (int r = 0; r < 7; ++r) {
    a_sub(r) = p.a_float(expected_kept[r]);
    for (int s = 0; s < 7; ++s) Q_sub(r, s) = p.Q_a(expected_kept[r], expected_kept[s]);
  }
  auto direct = mlambda(a_sub, Q_sub);
  ASSERT_TRUE(direct.ok());
  EXPECT_EQ(partial->search.candidates, direct->candidates);
  EXPECT_EQ(partial->search.squared_norms, direct->squared_norms);

  EXPECT_FALSE(solve_without(p.a_float, p.Q_a, {9}).ok());
  EXPECT_FALSE(solve_without(p.a_float, p.Q_a, {-1}).ok());
  EXPECT_FALSE(solve_without(p.a_float, p.Q_a, {3, 3}).ok());
  EXPECT_FALSE(solve_without(p.a_float, p.Q_a, {0, 1, 2, 3, 4, 5, 6, 7, 8}).ok());
}

TEST(FixedSolutionTest, MatchesConditionalGaussianFromThePrecisionMatrix) {
  std::mt19937_64 rng(47);
  for (int trial = 0; trial < 10; ++trial) {
    constexpr int kN = 11;
    const Eigen::MatrixXd P = random_spd(kN, 0.05, rng);
    const Eigen::VectorXd x = random_float(kN, rng);
    const std::vector<int> amb{7, 2, 5, 10};
    const Eigen::Vector4d a_fix(std::round(x(7)) + 1.0, std::round(x(2)), std::round(x(5)) - 2.0, std::round(x(10)));
    auto fixed = fixed_solution(x, P, amb, a_fix);
    ASSERT_TRUE(fixed.ok()) << fixed.error().message;
    const std::vector<int> b{0, 1, 3, 4, 6, 8, 9};
    ASSERT_EQ(fixed->state_indices, b);
    // Conditional Gaussian: Lambda = P^{-1}; cov(b | a) = Lambda_bb^{-1},
    // E(b | a = a_fix) = x_b - Lambda_bb^{-1} Lambda_ba (a_fix - x_a).
    const Eigen::MatrixXd Lambda = P.inverse();
    Eigen::MatrixXd Lambda_bb(7, 7), Lambda_ba(7, 4);
    Eigen::VectorXd x_b(7), x_a(4);
    for (int r = 0; r < 7; ++r) {
      x_b(r) = x(b[r]);
      for (int s = 0; s < 7; ++s) Lambda_bb(r, s) = Lambda(b[r], b[s]);
      for (int s = 0; s < 4; ++s) Lambda_ba(r, s) = Lambda(b[r], amb[s]);
    }
    for (int s = 0; s < 4; ++s) x_a(s) = x(amb[s]);
    const Eigen::MatrixXd cov_expected = Lambda_bb.inverse();
    const Eigen::VectorXd mean_expected = x_b - cov_expected * Lambda_ba * (a_fix - x_a);
    EXPECT_LT((fixed->x_fixed - mean_expected).cwiseAbs().maxCoeff(), 1e-9 * (1.0 + mean_expected.norm()));
    EXPECT_LT((fixed->P_fixed - cov_expected).cwiseAbs().maxCoeff(), 1e-10 * cov_expected.norm());
    EXPECT_EQ(fixed->P_fixed, fixed->P_fixed.transpose());
  }
}

TEST(FixedSolutionTest, RejectsBadInput) {
  const Eigen::VectorXd x = Eigen::VectorXd::Zero(4);
  const Eigen::MatrixXd P = Eigen::MatrixXd::Identity(4, 4);
  EXPECT_FALSE(fixed_solution(x, P, {1, 1}, Eigen::Vector2d(0, 0)).ok());
  EXPECT_FALSE(fixed_solution(x, P, {1, 4}, Eigen::Vector2d(0, 0)).ok());
  EXPECT_FALSE(fixed_solution(x, P, {1}, Eigen::Vector2d(0, 0)).ok());
  EXPECT_FALSE(fixed_solution(x, Eigen::MatrixXd::Identity(3, 3), {1}, Eigen::VectorXd::Zero(1)).ok());
  Eigen::MatrixXd not_pd = P;
  not_pd(2, 2) = -1.0;
  EXPECT_FALSE(fixed_solution(x, not_pd, {2}, Eigen::VectorXd::Zero(1)).ok());
  Eigen::VectorXd x_nan = x;
  x_nan(0) = std::nan("");
  EXPECT_FALSE(fixed_solution(x_nan, P, {2}, Eigen::VectorXd::Zero(1)).ok());
  EXPECT_TRUE(fixed_solution(x, P, {0, 1, 2, 3}, Eigen::Vector4d::Zero()).ok());  // nothing but ambiguities
}

}  // namespace
}  // namespace canyon::rtk

namespace canyon::rtk {
namespace {

// Integer bootstrapping success rate, computed here from Phi (erfc) rather than erf: 2 Phi(1 / (2 sigma)) - 1.
double bootstrap_reference(const Eigen::VectorXd& variances) {
  double p = 1.0;
  for (const double d : variances) p *= 2.0 * (0.5 * std::erfc(-1.0 / (2.0 * std::sqrt(d)) / std::sqrt(2.0))) - 1.0;
  return p;
}

TEST(SuccessRateTest, DiagonalCovarianceGivesTheProductOfIndependentRoundings) {
  const Eigen::Vector3d variances(0.01, 0.04, 0.09);  // sigma 0.1, 0.2, 0.3 cycles
  const auto result = mlambda(Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Matrix3d(variances.asDiagonal()));
  ASSERT_TRUE(result) << result.error().message;
  EXPECT_NEAR(bootstrap_success_rate(result->conditional_variances), bootstrap_reference(variances), 1e-12);
  // sigma 0.3 cycles alone: 2 Phi(1.667) - 1 = 0.9044.
  EXPECT_NEAR(bootstrap_success_rate(Eigen::VectorXd::Constant(1, 0.09)), 0.90442, 1e-5);
}

TEST(SuccessRateTest, ConditionalVariancesMultiplyToTheDeterminant) {
  // Z is unimodular, so det(Q_z) = det(Q_a) = prod d_k: the reported conditional variances are those of Q_a.
  std::mt19937_64 rng(7);
  for (const int n : {4, 10, 24}) {
    const Eigen::MatrixXd Q_a = testing::gnss_like_covariance(n, rng);
    const auto result = mlambda(Eigen::VectorXd::Zero(n), Q_a);
    ASSERT_TRUE(result) << result.error().message;
    ASSERT_EQ(result->conditional_variances.size(), n);
    const double log_det = Q_a.llt().matrixLLT().diagonal().array().log().sum() * 2.0;
    EXPECT_NEAR(result->conditional_variances.array().log().sum(), log_det, 1e-8 * std::abs(log_det)) << n;
  }
}

TEST(SuccessRateTest, BoundsTheIntegerLeastSquaresSuccessRateFromBelow) {
  // Teunissen (1999): P(ILS correct) >= bootstrapped success rate. Monte Carlo on a GNSS-like covariance scaled so
  // that the bound is about 0.8: the observed ILS success fraction must not fall below it (3 binomial sigmas).
  std::mt19937_64 rng(11);
  const int n = 8;
  Eigen::MatrixXd Q_a = testing::gnss_like_covariance(n, rng);
  double rate = 0.0;
  for (int i = 0; i < 60 && !(rate > 0.75 && rate < 0.85); ++i) {
    const auto r = mlambda(Eigen::VectorXd::Zero(n), Q_a);
    ASSERT_TRUE(r);
    rate = bootstrap_success_rate(r->conditional_variances);
    Q_a *= rate > 0.85 ? 1.3 : 0.8;
  }
  const auto r = mlambda(Eigen::VectorXd::Zero(n), Q_a);
  ASSERT_TRUE(r);
  rate = bootstrap_success_rate(r->conditional_variances);
  ASSERT_GT(rate, 0.6);
  ASSERT_LT(rate, 0.95);
  const Eigen::LLT<Eigen::MatrixXd> llt(Q_a);
  std::normal_distribution<double> normal(0.0, 1.0);
  const int trials = 4000;
  int correct = 0;
  for (int t = 0; t < trials; ++t) {
    Eigen::VectorXd white(n);
    for (Eigen::Index i = 0; i < n; ++i) white(i) = normal(rng);
    const auto fix = mlambda(llt.matrixL() * white, Q_a);  // the true ambiguities are 0
    ASSERT_TRUE(fix);
    if (fix->candidates.col(0).isZero()) ++correct;
  }
  const double observed = static_cast<double>(correct) / trials;
  EXPECT_GE(observed, rate - 3.0 * std::sqrt(rate * (1.0 - rate) / trials)) << "bound " << rate;
}

TEST(SuccessRateTest, DegenerateInput) {
  EXPECT_EQ(bootstrap_success_rate(Eigen::VectorXd()), 1.0);
  EXPECT_EQ(bootstrap_success_rate(Eigen::Vector2d(0.01, 0.0)), 0.0);
  EXPECT_EQ(bootstrap_success_rate(Eigen::Vector2d(0.01, std::nan(""))), 0.0);
}

}  // namespace
}  // namespace canyon::rtk
