#pragma once
// Integer ambiguity resolution: MLAMBDA integer least squares, ratio test, partial ambiguity resolution helpers and
// the fixed-solution update of the float state.
//
// ---------------------------------------------------------------------------------------------------------------
// CONTRACT (mlambda)
//   Reference: X.-W. Chang, X. Yang, T. Zhou (2005), "MLAMBDA: a modified LAMBDA method for integer least-squares
//              estimation", J. Geodesy 79:552-565; P.J.G. Teunissen (1995), "The least-squares ambiguity
//              decorrelation adjustment", J. Geodesy 70:65-82; P. de Jonge, C. Tiberius (1996), "The LAMBDA method
//              for integer ambiguity estimation: implementation aspects", LGR series 12, TU Delft.
//   Problem:   a_check = argmin_{a in Z^n} (a_float - a)^T Q_a^{-1} (a_float - a), plus the m best such vectors.
//   Inputs:    a_float  n-vector of float ambiguities [cycles], finite, n >= 1.
//              Q_a      n x n covariance of a_float [cycles^2], symmetric (relative tolerance 1e-10, then
//                       symmetrised) and positive definite (every pivot d_k > n eps max_i Q_ii).
//              options  num_candidates m >= 1 (default 2), cap on search nodes (default 1e6), with_z (default
//                       false: Z is not accumulated).
//   Outputs:   candidates     n x m, column j = the (j+1)-th best integer vector in the a-space, exact integers
//                             stored as double; squared_norms m-vector, ascending, (a_float - a_j)^T Q_a^{-1} (...).
//              Z              n x n unimodular (integer, |det Z| = 1), z = Z^T a, Q_z = Z^T Q_a Z (decorrelated);
//                             only with options.with_z, else empty.
//   Storage:   Eigen default, column major; indices 0-based; a's order is the caller's order throughout.
//   Maths:     1. Q_z = L^T D L with L unit lower triangular, D = diag(d) (computed from the last row up, with the
//                 symmetric pivoting of MLAMBDA: pivot k takes the smallest remaining diagonal element, so the
//                 conditional variances d_k tend to decrease towards k = n).
//              2. Reduction (LLL-like): integer Gauss transformations L <- L G_ik, G_ik = I - round(L_ik) e_i e_k^T
//                 (i > k), make |L_ik| <= 1/2; neighbours k, k+1 are swapped when
//                 d_k + L_{k+1,k}^2 d_{k+1} < d_{k+1} (the swap makes d_{k+1} smaller), restarting from k = n - 1.
//                 The swap test only involves L_{k+1,k}, so only that entry is size-reduced before each test; the
//                 rest of column k is size-reduced just before a swap at k (it moves into column k + 1 and would
//                 otherwise grow). decorrelate() then size-reduces all of L in one pass; mlambda() does not, as
//                 those transformations cannot change the nodes the search visits (each is an integer shift of the
//                 levels below). The swaps and d are those of MLAMBDA's reduction; the Gauss transformations
//                 skipped are those that cannot change a swap decision or the search (Xie, Chang, Al Borno 2011,
//                 "Partial LLL reduction", Proc. IEEE GLOBECOM; arXiv:1204.1398). Z, when kept, accumulates all
//                 transformations; decorrelate() accumulates Z^{-1} alongside, mlambda() logs the elementary operations
//                 instead and back-transforms only the m candidates, a = Z^{-T} z (exact integer arithmetic either
//                 way).
//              3. Search (Schnorr-Euchner enumeration, depth first, shrinking ellipsoid): with e = L^{-T}(z - z_hat),
//                 ||.||^2 = sum_k (z_k - zbar_k)^2 / d_k, zbar_k = z_hat_k + sum_{j>k} L_jk (z_j - zbar_j)
//                 (the conditional mean of z_k given z_{k+1..n}),
//                 levels from k = n down to 1, values of z_k in zig-zag order around zbar_k; the radius is
//                 infinite until m leaves are found, then the m-th best squared norm.
//              a_float is first shifted by round(a_float) (an integer shift commutes with the unimodular Z) so
//              large ambiguities (1e7 cycles) do not lose the fractional part.
//              Warm start (optional in/out argument): a unimodular Z_0 from an earlier search of a similar problem
//              (the same ambiguities an epoch later) is applied first, a' = Z_0^T a_float, Q' = Z_0^T Q_a Z_0, and
//              steps 1-3 run on (a', Q'), which is nearly reduced already: a few swaps instead of hundreds. The
//              problem is the same in any unimodular basis, so the candidates a = Z_0^{-T} a' and their norms are
//              those of a cold start; Z and d are those of the basis reached (the same reduction conditions hold).
//              On return the argument holds Z_0 Z_1 and its inverse, for the next search.
//   Errors:    n == 0, size mismatch, non-finite input, Q_a not symmetric or not positive definite,
//              m < 1, search exceeding options.max_search_nodes, reduction not terminating (cap 1e6 steps).
// ---------------------------------------------------------------------------------------------------------------

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/result.hpp"

namespace canyon::rtk {

/// Options of mlambda().
struct MlambdaOptions {
  int num_candidates = 2;                     ///< m, number of best integer vectors returned, >= 1
  std::int64_t max_search_nodes = 1'000'000;  ///< cap on search steps (one step = one level move), > 0
  bool with_z = false;  ///< also return Z (accumulating it costs about 15 % of a call; decorrelate() always has it)

  /// Ok, or the violated constraint, e.g. "Violated constraint: num_candidates >= 1".
  [[nodiscard]] Status validate() const;
};

/// Output of mlambda().
struct IntegerSearchResult {
  Eigen::MatrixXd candidates;             ///< n x m, column j = j-th best integer vector in the a-space (integers)
  Eigen::VectorXd squared_norms;          ///< m, ascending: (a_float - a_j)^T Q_a^{-1} (a_float - a_j)
  Eigen::MatrixXd Z;                      ///< n x n unimodular decorrelation, z = Z^T a (options.with_z)
  Eigen::VectorXd conditional_variances;  ///< d of Q_z = L^T diag(d) L after the reduction [cycles^2]
  std::int64_t search_nodes = 0;          ///< search steps used (for diagnostics and benchmarks)
};

/// The decorrelated problem: Z^T Q_a Z = L^T diag(d) L.
struct Decorrelation {
  Eigen::MatrixXd Z;      ///< n x n unimodular (integer entries stored as double)
  Eigen::MatrixXd Z_inv;  ///< n x n, exact integer inverse of Z
  Eigen::MatrixXd L;      ///< n x n unit lower triangular
  Eigen::VectorXd d;      ///< n conditional variances, d_k = var(z_k | z_{k+1..n})
};

/// Steps 1-2 of the contract: validated L^T D L factorisation with symmetric pivoting and reduction of Q_a.
[[nodiscard]] Result<Decorrelation> decorrelate(const Eigen::MatrixXd& Q_a);

/// A decorrelation carried from one search to the next (see "Warm start" in the contract). Empty, or of another
/// size than the problem: a cold start.
struct MlambdaWarmStart {
  Eigen::MatrixXd Z;        ///< n x n unimodular (integer entries stored as double)
  Eigen::MatrixXd Z_inv_T;  ///< Z^{-T}, exact integers
};

/// Integer least squares by MLAMBDA; see the contract block at the top of this header. With `warm` (may be nullptr),
/// the search starts from warm->Z when it has the problem's size, and *warm receives the decorrelation reached
/// (emptied when the search fails or its entries grow beyond 2^20, so that the next search starts cold).
[[nodiscard]] Result<IntegerSearchResult> mlambda(const Eigen::VectorXd& a_float, const Eigen::MatrixXd& Q_a,
                                                  const MlambdaOptions& options = {}, MlambdaWarmStart* warm = nullptr);

/// Outcome of the ratio test.
struct RatioTestOutcome {
  double ratio = 0.0;   ///< squared_norms(1) / squared_norms(0); +inf when the best norm is 0 and the second is not
  bool passed = false;  ///< ratio >= threshold
};

/// Default ratio-test threshold (the value used by Chang et al. 2005 and common RTK practice).
inline constexpr double kDefaultRatioThreshold = 3.0;

/// Ratio test second-best / best squared norm. Needs >= 2 candidates (asserted; returns not passed otherwise).
[[nodiscard]] RatioTestOutcome ratio_test(const IntegerSearchResult& result, double threshold = kDefaultRatioThreshold);

/// Success rate of integer bootstrapping on the decorrelated ambiguities, a sharp lower bound of the success rate of
/// integer least squares (Teunissen 1999, "An optimality property of the integer least-squares estimator",
/// J. Geodesy 73:587-593):  P_s = prod_k (2 Phi(1 / (2 sqrt(d_k))) - 1) = prod_k erf(1 / (2 sqrt(2 d_k))).
/// It depends only on the model (the float covariance), not on the data: the probability that the fix is right if
/// the float solution is unbiased. 1 for an empty d; 0 if some d_k is not positive.
[[nodiscard]] double bootstrap_success_rate(const Eigen::VectorXd& conditional_variances);

/// Contribution of each ambiguity to the integer least-squares residual of a fixed vector a_fix:
///   c_i = r(a) - r_{-i}(a),  r(a) = e^T Q_a^{-1} e,  e = a_float - a_fix,
/// where r_{-i} is the same quadratic form with ambiguity i removed (row/column i dropped from Q_a).
/// Closed form (Schur complement of Q_a^{-1}): c_i = w_i^2 / W_ii, W = Q_a^{-1}, w = W e. c_i >= 0 is the
/// square of the w-test statistic of a bias in ambiguity i; pruning the largest c_i lowers the residual most.
/// Errors: size mismatch, non-finite input, Q_a not symmetric positive definite.
[[nodiscard]] Result<Eigen::VectorXd> ils_residual_contributions(const Eigen::VectorXd& a_float,
                                                                 const Eigen::MatrixXd& Q_a,
                                                                 const Eigen::VectorXd& a_fix);

/// Indices of the `count` largest contributions, largest first (ties: lower index first).
[[nodiscard]] std::vector<int> largest_contributions(const Eigen::VectorXd& contributions, int count);

/// mlambda on the sub-problem with the ambiguities `removed` dropped.
struct PartialSolution {
  std::vector<int> kept_indices;  ///< indices into the original a_float, ascending; row r of candidates is kept[r]
  IntegerSearchResult search;     ///< result of mlambda on (a_float[kept], Q_a[kept, kept])
};

/// Removes `removed` (each in [0, n), no duplicates) from (a_float, Q_a) and solves again.
/// Errors: bad indices, nothing left, and every error of mlambda().
[[nodiscard]] Result<PartialSolution> solve_without(const Eigen::VectorXd& a_float, const Eigen::MatrixXd& Q_a,
                                                    const std::vector<int>& removed,
                                                    const MlambdaOptions& options = {});

/// The non-ambiguity block b of the state conditioned on the fixed ambiguities.
struct FixedSolution {
  std::vector<int> state_indices;  ///< indices of x that form b, ascending; entry r of x_fixed is x[state_indices[r]]
  Eigen::VectorXd x_fixed;         ///< x_b - Q_ba Q_a^{-1} (a_float - a_fix)
  Eigen::MatrixXd P_fixed;         ///< P_bb - Q_ba Q_a^{-1} Q_ab (exactly symmetric)
};

/// Fixed-solution update. x (N) with covariance P (N x N); ambiguity_indices (n distinct, in [0, N)) pick a_float
/// = x[ambiguity_indices] with Q_a = P[amb, amb], ordered like a_fix. Uses the Cholesky factor Q_a = C C^T:
/// G = C^{-1} Q_ab, x_fixed = x_b - G^T C^{-1} (a_float - a_fix), P_fixed = P_bb - G^T G (no inverse formed).
/// Errors: size mismatch, bad indices, non-finite input, Q_a not positive definite.
[[nodiscard]] Result<FixedSolution> fixed_solution(const Eigen::VectorXd& x, const Eigen::MatrixXd& P,
                                                   const std::vector<int>& ambiguity_indices,
                                                   const Eigen::VectorXd& a_fix);

}  // namespace canyon::rtk
