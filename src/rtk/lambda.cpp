// MLAMBDA integer least squares (Chang, Yang, Zhou 2005), written from the paper's description.
//
// Notation (0-based indices in the code, 1-based in the maths comments of lambda.hpp):
//   Q = L^T D L, L unit lower triangular, D = diag(d). Row k of L is l_k^T with support 0..k and l_k(k) = 1, so
//   Q = sum_k d_k l_k l_k^T. The factorisation peels off k = n-1 first: d_k = Q_kk, l_k = Q(k, 0:k) / d_k,
//   Q(0:k-1, 0:k-1) -= d_k l_k l_k^T.
//   Integer Gauss transformation G_ik = I - mu e_i e_k^T (i > k, mu = round(L_ik)): L <- L G_ik subtracts mu times
//   column i from column k (L stays unit lower triangular, L_ik becomes L_ik - mu); Z <- Z G_ik likewise;
//   Z^{-1} <- G_ik^{-1} Z^{-1} adds mu times row k to row i; z_hat = Z^T a_hat: z_hat_k -= mu z_hat_i.
//   Swap of k, k+1 (P the transposition): with mu = L_{k+1,k}, Delta = d_k + mu^2 d_{k+1},
//     d_k' = d_k d_{k+1} / Delta, d_{k+1}' = Delta, L'_{k+1,k} = d_{k+1} mu / Delta,
//     L'(k, 0:k-1) = L(k+1, 0:k-1) - mu L(k, 0:k-1),
//     L'(k+1, 0:k-1) = (d_k L(k, 0:k-1) + d_{k+1} mu L(k+1, 0:k-1)) / Delta,
//     and columns k, k+1 of L swap in rows > k+1 (derived by rewriting d_k l_k l_k^T + d_{k+1} l_{k+1} l_{k+1}^T
//     in the swapped coordinates as a sum of two rank-one terms with the required unit entries).

#include "canyon/rtk/lambda.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <ranges>
#include <string>

#include <Eigen/Cholesky>

namespace canyon::rtk {
namespace {

constexpr double kSymmetryTolerance = 1e-10;  // relative to max |Q_ij|
constexpr double kSwapTolerance = 1e-8;       // swap only when d_{k+1} shrinks by more than this fraction
constexpr std::int64_t kMaxReductionSteps = 1'000'000;

Status check_problem(const Eigen::VectorXd& a_float, const Eigen::MatrixXd& Q_a, const char* who) {
  const std::string prefix = std::string(who) + ": ";
  if (a_float.size() == 0) return Error(prefix + "no ambiguities (n == 0)");
  if (Q_a.rows() != Q_a.cols()) {
    return Error(prefix + "Q_a is " + std::to_string(Q_a.rows()) + " x " + std::to_string(Q_a.cols()) + ", not square");
  }
  if (Q_a.rows() != a_float.size()) {
    return Error(prefix + "Q_a is " + std::to_string(Q_a.rows()) + " x " + std::to_string(Q_a.cols()) +
                 " but a_float has " + std::to_string(a_float.size()) + " entries");
  }
  if (!a_float.allFinite()) return Error(prefix + "a_float has a non-finite entry");
  if (!Q_a.allFinite()) return Error(prefix + "Q_a has a non-finite entry");
  return Ok{};
}

Status check_symmetric(const Eigen::MatrixXd& Q, const char* who) {
  double scale = 0.0;      // max |Q_ij|
  double asymmetry = 0.0;  // max |Q_ij - Q_ji|
  for (Eigen::Index j = 0; j < Q.cols(); ++j) {
    for (Eigen::Index i = 0; i < Q.rows(); ++i) {
      scale = std::max(scale, std::abs(Q(i, j)));
      if (i > j) asymmetry = std::max(asymmetry, std::abs(Q(i, j) - Q(j, i)));
    }
  }
  if (asymmetry > kSymmetryTolerance * scale) {
    return Error(std::string(who) + ": Q_a is not symmetric");
  }
  return Ok{};
}

/// std::round (to nearest, halves away from zero), bit for bit, without the library call that std::round is on
/// x86-64 without SSE4.1 (it dominated the search and the reduction). Below 2^52 the integer part of |x| fits an
/// int64 and |x| minus it is exact; from 2^52 on every double is an integer.
double round_half_away(double x) {
  constexpr double kAllIntegers = 4503599627370496.0;  // 2^52
  const double a = std::abs(x);
  if (!(a < kAllIntegers)) return x;                       // integers, infinities and NaN round to themselves
  const auto whole = static_cast<std::int64_t>(a);         // floor(|x|)
  const double fraction = a - static_cast<double>(whole);  // exact
  return std::copysign(static_cast<double>(whole + (fraction >= 0.5 ? 1 : 0)), x);
}

/// Round to nearest for a multiplier of an integer Gauss transformation; 0 when |x| <= 1/2 (already size-reduced),
/// the common case.
double gauss_multiplier(double x) {
  return std::abs(x) <= 0.5 ? 0.0 : round_half_away(x);
}

/// One factor of Z = P O_1 O_2 ...: an integer Gauss transformation I - mu e_i e_k^T, or (mu == 0) the swap of
/// k and k + 1 (then i == k + 1).
struct ElementaryOperation {
  Eigen::Index i;
  Eigen::Index k;
  double mu;
};

/// a_j = Z^{-T} z_j = P O_1^{-T} O_2^{-T} ... z_j for every column j of z (n x m), exact in integer arithmetic;
/// O(number of operations), not O(n^2) per operation as accumulating Z^{-1} would be, and one pass over the log for
/// all candidates. (I - mu e_i e_k^T)^{-T} = I + mu e_k e_i^T.
Eigen::MatrixXd back_transform(const std::vector<ElementaryOperation>& log, const std::vector<Eigen::Index>& perm,
                               const Eigen::MatrixXd& z) {
  const Eigen::Index m = z.cols();
  Eigen::MatrixXd z_T = z.transpose();  // column i holds entry i of every candidate, contiguous
  double* const entries = z_T.data();
  for (std::size_t k = log.size(); k-- > 0;) {  // newest first (no ranges: clang-tidy 14 cannot parse them)
    const ElementaryOperation& op = log[k];
    double* z_k = entries + op.k * m;
    double* z_i = entries + op.i * m;
    if (op.mu == 0.0) {
      for (Eigen::Index j = 0; j < m; ++j) std::swap(z_k[j], z_i[j]);
    } else {
      for (Eigen::Index j = 0; j < m; ++j) z_k[j] += op.mu * z_i[j];
    }
  }
  Eigen::MatrixXd a(z.rows(), m);
  for (std::size_t i = 0; i < perm.size(); ++i) a.row(perm[i]) = z_T.col(static_cast<Eigen::Index>(i)).transpose();
  return a;
}

/// Working view of a decorrelation during factorisation and reduction: raw column-major n x n arrays, so that every
/// update below is a plain loop without Eigen temporaries. Z_inv is kept transposed (Z_inv_T = Z^{-T}) so that its
/// updates are column operations too, and the back-transform a = Z^{-T} z is a product with Z_inv_T.
struct ReductionView {
  Eigen::Index n;
  double* L;        // L(i, k) = L[i + k n], unit lower triangular
  double* d;        // d[k]
  double* Z;        // Z(i, k) = Z[i + k n], or nullptr when Z is not wanted
  double* Z_inv_T;  // Z^{-T}(i, k) = Z_inv_T[i + k n], or nullptr when the operations are logged instead
  double* z_hat;    // Z^T (a_float - shift), or nullptr
  std::vector<Eigen::Index>* perm = nullptr;        // initial permutation: Z(perm[i], i) = 1 before the reduction
  std::vector<ElementaryOperation>* log = nullptr;  // Z = P O_1 O_2 ..., in order, when Z_inv_T is nullptr
};

/// Q = P L^T D L P^T with symmetric pivoting (see the contract): fills L, d, perm, and Z = P, Z_inv_T = P when kept.
Status factorise_with_pivoting(const Eigen::MatrixXd& Q, Eigen::MatrixXd& W, const ReductionView& v) {
  const Eigen::Index n = v.n;
  W = 0.5 * (Q + Q.transpose());
  double* w = W.data();
  const double min_pivot = static_cast<double>(n) * std::numeric_limits<double>::epsilon() * W.diagonal().maxCoeff();
  std::fill(v.L, v.L + n * n, 0.0);
  // perm[i] = original index of the variable now at position i.
  std::vector<Eigen::Index> perm(static_cast<std::size_t>(n));
  std::iota(perm.begin(), perm.end(), Eigen::Index{0});
  for (Eigen::Index k = n - 1; k >= 0; --k) {
    Eigen::Index q = k;
    for (Eigen::Index i = 0; i < k; ++i) {
      if (w[i + i * n] < w[q + q * n]) q = i;
    }
    if (q != k) {
      // Symmetric swap of q and k in the leading (k+1) x (k+1) block; rows > k of L move with the variables.
      for (Eigen::Index i = 0; i <= k; ++i) std::swap(w[i + q * n], w[i + k * n]);
      for (Eigen::Index j = 0; j <= k; ++j) std::swap(w[q + j * n], w[k + j * n]);
      for (Eigen::Index r = k + 1; r < n; ++r) std::swap(v.L[r + q * n], v.L[r + k * n]);
      std::swap(perm[static_cast<std::size_t>(q)], perm[static_cast<std::size_t>(k)]);
    }
    const double d_k = w[k + k * n];
    if (!(d_k > min_pivot)) {
      return Error("mlambda: Q_a is not positive definite (pivot " + std::to_string(d_k) + ")");
    }
    v.d[k] = d_k;
    v.L[k + k * n] = 1.0;
    for (Eigen::Index j = 0; j < k; ++j) v.L[k + j * n] = w[k + j * n] / d_k;
    // W(0:k-1, 0:k-1) -= d_k l l^T with l = L(k, 0:k-1), i.e. W(i, j) -= W(i, k) L(k, j) (W stays symmetric, so
    // column k is row k and the update reads contiguous memory).
    const double* w_col_k = w + k * n;
    for (Eigen::Index j = 0; j < k; ++j) {
      const double l_j = v.L[k + j * n];
      double* w_col = w + j * n;
      for (Eigen::Index i = 0; i < k; ++i) w_col[i] -= w_col_k[i] * l_j;
    }
  }
  if (v.Z != nullptr) {
    std::fill(v.Z, v.Z + n * n, 0.0);
    for (Eigen::Index i = 0; i < n; ++i) v.Z[perm[static_cast<std::size_t>(i)] + i * n] = 1.0;
    if (v.Z_inv_T != nullptr) std::copy(v.Z, v.Z + n * n, v.Z_inv_T);  // a permutation: Z^{-T} = Z
  }
  if (v.perm != nullptr) *v.perm = std::move(perm);
  return Ok{};
}

/// Integer Gauss transformation G_ik (i > k) with multiplier mu != 0 applied to L, Z, Z_inv_T and z_hat.
void apply_gauss_transform(const ReductionView& v, Eigen::Index i, Eigen::Index k, double mu) {
  const Eigen::Index n = v.n;
  double* L_k = v.L + k * n;
  const double* L_i = v.L + i * n;
  for (Eigen::Index r = i; r < n; ++r) L_k[r] -= mu * L_i[r];
  if (v.Z != nullptr) {
    double* Z_k = v.Z + k * n;
    const double* Z_i = v.Z + i * n;
    for (Eigen::Index r = 0; r < n; ++r) Z_k[r] -= mu * Z_i[r];
  }
  if (v.Z_inv_T != nullptr) {
    double* Zit_i = v.Z_inv_T + i * n;  // Z^{-1} <- G^{-1} Z^{-1}: row i += mu row k, i.e. column i of Z^{-T}
    const double* Zit_k = v.Z_inv_T + k * n;
    for (Eigen::Index r = 0; r < n; ++r) Zit_i[r] += mu * Zit_k[r];
  } else {
    v.log->push_back({i, k, mu});
  }
  if (v.z_hat != nullptr) v.z_hat[k] -= mu * v.z_hat[i];
}

/// G_ik with mu = round(L_ik), or nothing when L_ik is already reduced: the common case, one load and compare
/// (inline; the reduction makes millions of these tests on a file).
inline void gauss_transform(const ReductionView& v, Eigen::Index i, Eigen::Index k) {
  const double mu = gauss_multiplier(v.L[i + k * v.n]);
  if (mu != 0.0) apply_gauss_transform(v, i, k, mu);
}

/// Swap of neighbours k, k+1 given Delta = d_k + L_{k+1,k}^2 d_{k+1} (formulas at the top of this file).
void swap_neighbours(const ReductionView& v, Eigen::Index k, double delta) {
  const Eigen::Index n = v.n;
  const double mu = v.L[(k + 1) + k * n];
  const double d_k = v.d[k];
  const double d_k1 = v.d[k + 1];
  const double eta = d_k / delta;
  const double lambda = d_k1 * mu / delta;
  for (Eigen::Index j = 0; j < k; ++j) {
    double* rows_k = v.L + k + j * n;  // L(k, j), L(k + 1, j)
    const double l_k = rows_k[0];
    const double l_k1 = rows_k[1];
    rows_k[0] = l_k1 - mu * l_k;
    rows_k[1] = eta * l_k + lambda * l_k1;
  }
  v.L[(k + 1) + k * n] = lambda;
  std::swap_ranges(v.L + k * n + k + 2, v.L + k * n + n, v.L + (k + 1) * n + k + 2);
  v.d[k] = eta * d_k1;
  v.d[k + 1] = delta;
  if (v.Z != nullptr) std::swap_ranges(v.Z + k * n, v.Z + (k + 1) * n, v.Z + (k + 1) * n);
  if (v.Z_inv_T != nullptr) {
    std::swap_ranges(v.Z_inv_T + k * n, v.Z_inv_T + (k + 1) * n, v.Z_inv_T + (k + 1) * n);
  } else {
    v.log->push_back({k + 1, k, 0.0});
  }
  if (v.z_hat != nullptr) std::swap(v.z_hat[k], v.z_hat[k + 1]);
}

/// Reduction (decorrelation) of an already factorised problem: the swaps of MLAMBDA's reduction, with only the
/// sub-diagonal entry size-reduced before each swap test and, when `size_reduce_all`, one size-reduction pass at the
/// end (see the contract).
Status reduce(const ReductionView& v, bool size_reduce_all) {
  const Eigen::Index n = v.n;
  Eigen::Index k = n - 2;
  std::int64_t steps = 0;
  while (k >= 0) {
    if (++steps > kMaxReductionSteps) {
      return Error("mlambda: reduction did not terminate within " + std::to_string(kMaxReductionSteps) + " steps");
    }
    gauss_transform(v, k + 1, k);
    const double mu = v.L[(k + 1) + k * n];
    const double delta = v.d[k] + mu * mu * v.d[k + 1];
    if (delta < (1.0 - kSwapTolerance) * v.d[k + 1]) {
      // The swap moves column k below row k + 1 into column k + 1: size-reduce it first so that unreduced entries
      // cannot grow over repeated swaps (the instability of reducing the sub-diagonal only). Leaves L_{k+1,k}, d.
      for (Eigen::Index i = k + 2; i < n; ++i) gauss_transform(v, i, k);
      swap_neighbours(v, k, delta);
      // MLAMBDA restarts from k = n - 2; levels above k + 1 are untouched by this swap (their L_{j+1,j} and d
      // are those already reduced and tested), so those tests would fail again with no Gauss transformation:
      // resuming at k + 1 gives the same sequence of operations in O(1) instead of O(n) steps per swap.
      k = std::min(k + 1, n - 2);
    } else {
      --k;
    }
  }
  if (!size_reduce_all) return Ok{};
  // Size reduction: |L_ik| <= 1/2 for all i > k. Column k is reduced from the top (i = k + 1 first): G_ik changes
  // only rows >= i of column k, which are reduced afterwards; d and the columns > k are untouched.
  for (Eigen::Index col = n - 2; col >= 0; --col) {
    for (Eigen::Index i = col + 1; i < n; ++i) gauss_transform(v, i, col);
  }
  return Ok{};
}

/// Factorisation and reduction into dec. With log == nullptr, dec.Z_inv receives Z^{-T}; otherwise dec.Z_inv is
/// left empty and the operations are logged (with the initial permutation) for back_transform(). dec.Z is left empty
/// unless with_z. z_hat (with a_centred and perm) receives Z^T a_centred. Without `size_reduce_all` the final
/// size-reduction pass is skipped (for the search: it cannot change which nodes the search visits). With `start`
/// (Q_a then being start->Z^T Q start->Z, with Z and Z^{-T} kept and no log), Z and Z^{-T} accumulate from start's.
Status decorrelate_into(const Eigen::MatrixXd& Q_a, Decorrelation& dec, bool size_reduce_all, bool with_z,
                        Eigen::VectorXd* z_hat, const Eigen::VectorXd* a_centred, std::vector<Eigen::Index>* perm,
                        std::vector<ElementaryOperation>* log, const MlambdaWarmStart* start = nullptr) {
  assert(z_hat == nullptr || (a_centred != nullptr && perm != nullptr));
  const Eigen::Index n = Q_a.rows();
  dec.L.resize(n, n);
  dec.d.resize(n);
  if (with_z) dec.Z.resize(n, n);
  if (log == nullptr) dec.Z_inv.resize(n, n);
  ReductionView v{
      n,       dec.L.data(), dec.d.data(), with_z ? dec.Z.data() : nullptr, log == nullptr ? dec.Z_inv.data() : nullptr,
      nullptr, perm,         log};
  Eigen::MatrixXd W;
  if (auto s = factorise_with_pivoting(Q_a, W, v); !s) return s;
  if (start != nullptr) {
    // Z = Z_0 P and Z^{-T} = Z_0^{-T} P (P a permutation): column i is column perm[i] of Z_0, of Z_0^{-T}.
    assert(with_z && log == nullptr && perm != nullptr);
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Index from = (*perm)[static_cast<std::size_t>(i)];
      dec.Z.col(i) = start->Z.col(from);
      dec.Z_inv.col(i) = start->Z_inv_T.col(from);
    }
  }
  if (z_hat != nullptr) {
    // Z is the pivoting permutation P at this point, or Z_0 P with a_centred = Z_0^T a already (warm start):
    // Z^T a = (a_perm[0], a_perm[1], ...) of a_centred either way.
    z_hat->resize(n);
    for (Eigen::Index i = 0; i < n; ++i) (*z_hat)[i] = (*a_centred)[(*perm)[static_cast<std::size_t>(i)]];
    v.z_hat = z_hat->data();
  }
  return reduce(v, size_reduce_all);
}

double sign_toward(double y) {
  return y <= 0.0 ? -1.0 : 1.0;
}

/// The m best leaves of the search: z vectors in the columns of z, squared norms alongside (unsorted).
struct BestLeaves {
  Eigen::MatrixXd z;
  Eigen::VectorXd squared_norms;
  int count = 0;
};

/// Schnorr-Euchner depth-first search with shrinking ellipsoid in the decorrelated space. All storage is allocated
/// before the loop; the loop itself works on raw arrays.
Result<BestLeaves> search(const Decorrelation& dec, const Eigen::VectorXd& z_hat, int m, std::int64_t max_nodes,
                          std::int64_t& nodes_used) {
  const Eigen::Index n = dec.L.rows();
  const Eigen::MatrixXd L_T = dec.L.transpose();  // column k + 1 = row k + 1 of L, contiguous
  const double* Lt = L_T.data();
  const double* d = dec.d.data();
  const double* zh = z_hat.data();
  // S_T column k holds S(k, 0:k) = sum_{j>k} L(j, 0:k) (z_j - zbar_j): S_T[i + k n] = S(k, i).
  Eigen::MatrixXd S_T = Eigen::MatrixXd::Zero(n, n);
  double* S = S_T.data();
  Eigen::VectorXd storage(4 * n + 1);
  double* partial = storage.data();  // partial[k] = sum_{j>k} (z_j - zbar_j)^2 / d_j
  double* z_bar = partial + n + 1;
  double* z = z_bar + n;
  double* step = z + n;
  BestLeaves best;
  best.z.resize(n, m);
  best.squared_norms.resize(m);
  double* best_norms = best.squared_norms.data();
  int worst = 0;  // index of the largest norm among the m kept, once m are kept
  double radius = std::numeric_limits<double>::infinity();

  Eigen::Index k = n - 1;
  partial[k] = 0.0;
  z_bar[k] = zh[k];
  z[k] = round_half_away(z_bar[k]);
  double y = z_bar[k] - z[k];
  step[k] = sign_toward(y);
  nodes_used = 0;
  while (true) {
    if (++nodes_used > max_nodes) {
      return Error("mlambda: search exceeded the cap of " + std::to_string(max_nodes) +
                   " nodes (options.max_search_nodes)");
    }
    const double dist = partial[k] + y * y / d[k];
    if (dist < radius) {
      if (k != 0) {
        const double c = z[k] - z_bar[k];
        --k;
        partial[k] = dist;
        double* S_k = S + k * n;
        const double* S_k1 = S + (k + 1) * n;
        const double* L_row = Lt + (k + 1) * n;  // L(k + 1, 0:k)
        for (Eigen::Index i = 0; i <= k; ++i) S_k[i] = S_k1[i] + c * L_row[i];
        z_bar[k] = zh[k] + S_k[k];
        z[k] = round_half_away(z_bar[k]);
        y = z_bar[k] - z[k];
        step[k] = sign_toward(y);
        continue;
      }
      // Leaf: keep the m best, shrink the ellipsoid to the m-th best once m are known.
      const int slot = best.count < m ? best.count++ : worst;
      std::copy(z, z + n, best.z.col(slot).data());
      best_norms[slot] = dist;
      if (best.count == m) {
        worst = static_cast<int>(std::max_element(best_norms, best_norms + m) - best_norms);
        radius = best_norms[worst];
      }
    } else {
      if (k == n - 1) break;
      ++k;
    }
    // Next value of z_k in zig-zag order around z_bar_k.
    z[k] += step[k];
    y = z_bar[k] - z[k];
    step[k] = -step[k] - sign_toward(step[k]);
  }
  return best;
}

Eigen::VectorXd select(const Eigen::VectorXd& v, const std::vector<int>& idx) {
  Eigen::VectorXd out(static_cast<Eigen::Index>(idx.size()));
  for (std::size_t r = 0; r < idx.size(); ++r) out(static_cast<Eigen::Index>(r)) = v(idx[r]);
  return out;
}

Eigen::MatrixXd select(const Eigen::MatrixXd& M, const std::vector<int>& rows, const std::vector<int>& cols) {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(cols.size()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    for (std::size_t c = 0; c < cols.size(); ++c) {
      out(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = M(rows[r], cols[c]);
    }
  }
  return out;
}

/// Checks indices are in [0, n) and distinct; returns the complement, ascending.
Result<std::vector<int>> complement_of(const std::vector<int>& indices, Eigen::Index n, const char* who) {
  std::vector<bool> taken(static_cast<std::size_t>(n), false);
  for (int i : indices) {
    if (i < 0 || i >= n) {
      return Error(std::string(who) + ": index " + std::to_string(i) + " outside [0, " + std::to_string(n) + ")");
    }
    if (taken[static_cast<std::size_t>(i)]) return Error(std::string(who) + ": duplicate index " + std::to_string(i));
    taken[static_cast<std::size_t>(i)] = true;
  }
  std::vector<int> rest;
  for (int i = 0; i < n; ++i) {
    if (!taken[static_cast<std::size_t>(i)]) rest.push_back(i);
  }
  return rest;
}

bool warm_start_fits(const MlambdaWarmStart& warm, Eigen::Index n) {
  return warm.Z.rows() == n && warm.Z.cols() == n && warm.Z_inv_T.rows() == n && warm.Z_inv_T.cols() == n;
}

/// Entries this large suggest the carried basis has drifted: the next search starts cold (the products below stay
/// exact in double far beyond, this only keeps them small).
constexpr double kMaxWarmStartEntry = 1048576.0;  // 2^20

/// The body of mlambda(). `warm`, when not nullptr, is empty (cold start) or fits the problem; the decorrelation
/// reached is stored in it.
Result<IntegerSearchResult> solve_integer_least_squares(const Eigen::VectorXd& a_float, const Eigen::MatrixXd& Q_a,
                                                        const MlambdaOptions& options, MlambdaWarmStart* warm) {
  if (auto s = options.validate(); !s) return Error("mlambda: " + s.error().message);
  if (auto s = check_problem(a_float, Q_a, "mlambda"); !s) return s.error();
  if (auto s = check_symmetric(Q_a, "mlambda"); !s) return s.error();
  const bool from_warm = warm != nullptr && warm->Z.size() > 0;

  // Without a warm start, dec.Z_inv stays empty (the candidates are back-transformed through the operation log) and
  // dec.Z unless kept; with one, Z and Z^{-T} accumulate (from the carried ones, if any), no log is kept, and L is
  // size-reduced in full, which keeps the carried basis small.
  Decorrelation dec;
  const Eigen::VectorXd shift = a_float.unaryExpr(&round_half_away);
  Eigen::VectorXd a_centred = a_float - shift;
  Eigen::VectorXd z_hat;
  std::vector<Eigen::Index> perm;
  std::vector<ElementaryOperation> log;
  Status decorrelated = Ok{};
  if (warm != nullptr) {
    if (from_warm) {
      a_centred = warm->Z.transpose() * a_centred;  // a' = Z_0^T (a_float - shift)
      // Z_0^T Q_a Z_0, symmetric: the lower triangle of Z_0^T (Q_a Z_0) (three quarters of the two full products),
      // mirrored.
      const Eigen::MatrixXd Q_Z = Q_a * warm->Z;
      Eigen::MatrixXd Q_start(Q_a.rows(), Q_a.cols());
      Q_start.triangularView<Eigen::Lower>() = warm->Z.transpose() * Q_Z;
      Q_start.triangularView<Eigen::StrictlyUpper>() = Q_start.transpose();
      decorrelated = decorrelate_into(Q_start, dec, true, true, &z_hat, &a_centred, &perm, nullptr, warm);
    } else {
      decorrelated = decorrelate_into(Q_a, dec, true, true, &z_hat, &a_centred, &perm, nullptr);
    }
  } else {
    log.reserve(1024);
    decorrelated = decorrelate_into(Q_a, dec, options.with_z, options.with_z, &z_hat, &a_centred, &perm, &log);
  }
  if (!decorrelated) return decorrelated.error();

  IntegerSearchResult out;
  auto found = search(dec, z_hat, options.num_candidates, options.max_search_nodes, out.search_nodes);
  if (!found) return found.error();
  const int m = found->count;
  std::vector<int> order(static_cast<std::size_t>(m));
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](int l, int r) { return found->squared_norms(l) < found->squared_norms(r); });
  Eigen::MatrixXd z_sorted(a_float.size(), m);
  out.squared_norms.resize(m);
  for (int j = 0; j < m; ++j) {
    const int from = order[static_cast<std::size_t>(j)];
    z_sorted.col(j) = found->z.col(from);
    out.squared_norms(j) = found->squared_norms(from);
  }
  // a = Z^{-T} z, exact: integers.
  out.candidates = warm != nullptr ? Eigen::MatrixXd(dec.Z_inv * z_sorted) : back_transform(log, perm, z_sorted);
  out.candidates.colwise() += shift;
  if (warm != nullptr) {
    const bool small =
        dec.Z.cwiseAbs().maxCoeff() <= kMaxWarmStartEntry && dec.Z_inv.cwiseAbs().maxCoeff() <= kMaxWarmStartEntry;
    if (small) {
      warm->Z = options.with_z ? dec.Z : std::move(dec.Z);
      warm->Z_inv_T = std::move(dec.Z_inv);
    } else {
      *warm = {};
    }
  }
  if (options.with_z) out.Z = std::move(dec.Z);
  out.conditional_variances = std::move(dec.d);
  return out;
}

}  // namespace

Status MlambdaOptions::validate() const {
  if (num_candidates < 1) return Error("Violated constraint: num_candidates >= 1");
  if (max_search_nodes < 1) return Error("Violated constraint: max_search_nodes >= 1");
  return Ok{};
}

Result<Decorrelation> decorrelate(const Eigen::MatrixXd& Q_a) {
  if (Q_a.rows() == 0) return Error("decorrelate: empty Q_a");
  if (Q_a.rows() != Q_a.cols()) return Error("decorrelate: Q_a is not square");
  if (!Q_a.allFinite()) return Error("decorrelate: Q_a has a non-finite entry");
  if (auto s = check_symmetric(Q_a, "decorrelate"); !s) return s.error();
  Decorrelation dec;
  if (auto s = decorrelate_into(Q_a, dec, true, true, nullptr, nullptr, nullptr, nullptr); !s) return s.error();
  dec.Z_inv.transposeInPlace();
  return dec;
}

Result<IntegerSearchResult> mlambda(const Eigen::VectorXd& a_float, const Eigen::MatrixXd& Q_a,
                                    const MlambdaOptions& options, MlambdaWarmStart* warm) {
  if (warm != nullptr && !warm_start_fits(*warm, a_float.size())) *warm = {};
  auto out = solve_integer_least_squares(a_float, Q_a, options, warm);
  if (!out && warm != nullptr) *warm = {};
  return out;
}

double bootstrap_success_rate(const Eigen::VectorXd& conditional_variances) {
  double p = 1.0;
  for (const double d : conditional_variances) {
    if (!(d > 0.0)) return 0.0;
    p *= std::erf(1.0 / (2.0 * std::sqrt(2.0 * d)));
  }
  return p;
}

RatioTestOutcome ratio_test(const IntegerSearchResult& result, double threshold) {
  assert(result.squared_norms.size() >= 2);
  if (result.squared_norms.size() < 2) return {std::numeric_limits<double>::quiet_NaN(), false};
  const double best = result.squared_norms(0);
  const double second = result.squared_norms(1);
  RatioTestOutcome out;
  out.ratio = best > 0.0 ? second / best : (second > 0.0 ? std::numeric_limits<double>::infinity() : 1.0);
  out.passed = out.ratio >= threshold;
  return out;
}

Result<Eigen::VectorXd> ils_residual_contributions(const Eigen::VectorXd& a_float, const Eigen::MatrixXd& Q_a,
                                                   const Eigen::VectorXd& a_fix) {
  if (auto s = check_problem(a_float, Q_a, "ils_residual_contributions"); !s) return s.error();
  if (a_fix.size() != a_float.size()) return Error("ils_residual_contributions: a_fix and a_float differ in size");
  if (!a_fix.allFinite()) return Error("ils_residual_contributions: a_fix has a non-finite entry");
  if (auto s = check_symmetric(Q_a, "ils_residual_contributions"); !s) return s.error();
  const Eigen::LLT<Eigen::MatrixXd> llt(0.5 * (Q_a + Q_a.transpose()));
  if (llt.info() != Eigen::Success) return Error("ils_residual_contributions: Q_a is not positive definite");
  const Eigen::Index n = a_float.size();
  const Eigen::VectorXd w = llt.solve(a_float - a_fix);  // w = Q_a^{-1} e
  // W_ii = ||C^{-1} e_i||^2 with Q_a = C C^T.
  const Eigen::MatrixXd C_inv = llt.matrixL().solve(Eigen::MatrixXd::Identity(n, n));
  const Eigen::VectorXd W_diag = C_inv.colwise().squaredNorm().transpose();
  return (w.array().square() / W_diag.array()).matrix().eval();
}

std::vector<int> largest_contributions(const Eigen::VectorXd& contributions, int count) {
  std::vector<int> order(static_cast<std::size_t>(contributions.size()));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int l, int r) { return contributions(l) > contributions(r); });
  order.resize(std::min(order.size(), static_cast<std::size_t>(std::max(count, 0))));
  return order;
}

Result<PartialSolution> solve_without(const Eigen::VectorXd& a_float, const Eigen::MatrixXd& Q_a,
                                      const std::vector<int>& removed, const MlambdaOptions& options) {
  if (auto s = check_problem(a_float, Q_a, "solve_without"); !s) return s.error();
  auto kept = complement_of(removed, a_float.size(), "solve_without");
  if (!kept) return kept.error();
  if (kept->empty()) return Error("solve_without: every ambiguity removed");
  auto search_result = mlambda(select(a_float, *kept), select(Q_a, *kept, *kept), options);
  if (!search_result) return search_result.error();
  return PartialSolution{std::move(*kept), std::move(*search_result)};
}

Result<FixedSolution> fixed_solution(const Eigen::VectorXd& x, const Eigen::MatrixXd& P,
                                     const std::vector<int>& ambiguity_indices, const Eigen::VectorXd& a_fix) {
  if (P.rows() != P.cols() || P.rows() != x.size()) return Error("fixed_solution: P is not N x N with N = size of x");
  if (a_fix.size() != static_cast<Eigen::Index>(ambiguity_indices.size())) {
    return Error("fixed_solution: a_fix and ambiguity_indices differ in size");
  }
  if (ambiguity_indices.empty()) return Error("fixed_solution: no ambiguities");
  if (!x.allFinite() || !P.allFinite() || !a_fix.allFinite()) return Error("fixed_solution: non-finite input");
  auto b = complement_of(ambiguity_indices, x.size(), "fixed_solution");
  if (!b) return b.error();
  const Eigen::MatrixXd Q_a = select(P, ambiguity_indices, ambiguity_indices);
  if (auto s = check_symmetric(Q_a, "fixed_solution"); !s) return s.error();
  const Eigen::LLT<Eigen::MatrixXd> llt(0.5 * (Q_a + Q_a.transpose()));
  if (llt.info() != Eigen::Success) return Error("fixed_solution: Q_a is not positive definite");

  const Eigen::MatrixXd Q_ab = select(P, ambiguity_indices, *b);
  const Eigen::MatrixXd G = llt.matrixL().solve(Q_ab);  // C^{-1} Q_ab
  const Eigen::VectorXd r = llt.matrixL().solve(select(x, ambiguity_indices) - a_fix);
  FixedSolution out;
  out.x_fixed = select(x, *b) - G.transpose() * r;
  const Eigen::MatrixXd P_bb = select(P, *b, *b);
  out.P_fixed = 0.5 * (P_bb + P_bb.transpose()) - G.transpose() * G;
  out.state_indices = std::move(*b);
  return out;
}

}  // namespace canyon::rtk
