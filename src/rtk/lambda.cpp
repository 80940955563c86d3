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
#include <limits>
#include <numeric>
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
  const double scale = Q.cwiseAbs().maxCoeff();
  if ((Q - Q.transpose()).cwiseAbs().maxCoeff() > kSymmetryTolerance * scale) {
    return Error(std::string(who) + ": Q_a is not symmetric");
  }
  return Ok{};
}

/// Q = P^T ... : factorises the symmetrised Q with symmetric pivoting, filling L, d, and Z = P, Z_inv = P^T.
Status factorise_with_pivoting(const Eigen::MatrixXd& Q, Decorrelation& out) {
  const Eigen::Index n = Q.rows();
  Eigen::MatrixXd W = 0.5 * (Q + Q.transpose());
  const double min_pivot = static_cast<double>(n) * std::numeric_limits<double>::epsilon() * W.diagonal().maxCoeff();
  std::vector<Eigen::Index> perm(static_cast<std::size_t>(n));
  std::iota(perm.begin(), perm.end(), Eigen::Index{0});
  out.L = Eigen::MatrixXd::Identity(n, n);
  out.d = Eigen::VectorXd::Zero(n);
  for (Eigen::Index k = n - 1; k >= 0; --k) {
    Eigen::Index q = 0;
    W.diagonal().head(k + 1).minCoeff(&q);
    if (q != k) {
      W.row(q).swap(W.row(k));
      W.col(q).swap(W.col(k));
      for (Eigen::Index r = k + 1; r < n; ++r) std::swap(out.L(r, q), out.L(r, k));
      std::swap(perm[static_cast<std::size_t>(q)], perm[static_cast<std::size_t>(k)]);
    }
    const double d_k = W(k, k);
    if (!(d_k > min_pivot)) {
      return Error("mlambda: Q_a is not positive definite (pivot " + std::to_string(d_k) + ")");
    }
    out.d(k) = d_k;
    out.L.row(k).head(k) = W.row(k).head(k) / d_k;
    W.topLeftCorner(k, k) -= d_k * out.L.row(k).head(k).transpose() * out.L.row(k).head(k);
  }
  out.Z = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i) out.Z(perm[static_cast<std::size_t>(i)], i) = 1.0;
  out.Z_inv = out.Z.transpose();
  return Ok{};
}

/// Integer Gauss transformation G_ik (i > k) applied to L, Z, Z_inv and (optionally) z_hat.
void gauss_transform(Decorrelation& dec, Eigen::Index i, Eigen::Index k, Eigen::VectorXd* z_hat) {
  const double mu = std::round(dec.L(i, k));
  if (mu == 0.0) return;
  const Eigen::Index n = dec.L.rows();
  dec.L.col(k).tail(n - i) -= mu * dec.L.col(i).tail(n - i);
  dec.Z.col(k) -= mu * dec.Z.col(i);
  dec.Z_inv.row(i) += mu * dec.Z_inv.row(k);
  if (z_hat != nullptr) (*z_hat)(k) -= mu * (*z_hat)(i);
}

/// Swap of neighbours k, k+1 given Delta = d_k + L_{k+1,k}^2 d_{k+1}.
void swap_neighbours(Decorrelation& dec, Eigen::Index k, double delta, Eigen::VectorXd* z_hat) {
  const Eigen::Index n = dec.L.rows();
  const double mu = dec.L(k + 1, k);
  const double d_k = dec.d(k);
  const double d_k1 = dec.d(k + 1);
  const Eigen::RowVectorXd row_k = dec.L.row(k).head(k);
  const Eigen::RowVectorXd row_k1 = dec.L.row(k + 1).head(k);
  dec.L.row(k).head(k) = row_k1 - mu * row_k;
  dec.L.row(k + 1).head(k) = (d_k * row_k + d_k1 * mu * row_k1) / delta;
  dec.L(k + 1, k) = d_k1 * mu / delta;
  for (Eigen::Index r = k + 2; r < n; ++r) std::swap(dec.L(r, k), dec.L(r, k + 1));
  dec.d(k) = d_k * d_k1 / delta;
  dec.d(k + 1) = delta;
  dec.Z.col(k).swap(dec.Z.col(k + 1));
  dec.Z_inv.row(k).swap(dec.Z_inv.row(k + 1));
  if (z_hat != nullptr) std::swap((*z_hat)(k), (*z_hat)(k + 1));
}

/// MLAMBDA reduction (decorrelation) of an already factorised problem.
Status reduce(Decorrelation& dec, Eigen::VectorXd* z_hat) {
  const Eigen::Index n = dec.L.rows();
  Eigen::Index k = n - 2;
  Eigen::Index last_swap = n - 2;  // columns > last_swap are still size-reduced (lazy transformations)
  std::int64_t steps = 0;
  while (k >= 0) {
    if (++steps > kMaxReductionSteps) {
      return Error("mlambda: reduction did not terminate within " + std::to_string(kMaxReductionSteps) + " steps");
    }
    if (k <= last_swap) {
      for (Eigen::Index i = k + 1; i < n; ++i) gauss_transform(dec, i, k, z_hat);
    }
    const double mu = dec.L(k + 1, k);
    const double delta = dec.d(k) + mu * mu * dec.d(k + 1);
    if (delta < (1.0 - kSwapTolerance) * dec.d(k + 1)) {
      swap_neighbours(dec, k, delta, z_hat);
      last_swap = k;
      k = n - 2;
    } else {
      --k;
    }
  }
  return Ok{};
}

struct Candidate {
  double squared_norm;
  Eigen::VectorXd z;
};

double sign_toward(double y) {
  return y <= 0.0 ? -1.0 : 1.0;
}

/// Schnorr-Euchner depth-first search with shrinking ellipsoid in the decorrelated space.
Result<std::vector<Candidate>> search(const Decorrelation& dec, const Eigen::VectorXd& z_hat, int m,
                                      std::int64_t max_nodes, std::int64_t& nodes_used) {
  const Eigen::Index n = dec.L.rows();
  const Eigen::MatrixXd& L = dec.L;
  const Eigen::VectorXd& d = dec.d;
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(n, n);  // S(k, 0:k) = sum_{j>k} L(j, 0:k) (z_j - zbar_j)
  Eigen::VectorXd partial(n + 1);                   // partial(k) = sum_{j>k} (z_j - zbar_j)^2 / d_j
  Eigen::VectorXd z_bar(n), z(n), step(n);
  std::vector<Candidate> best;
  best.reserve(static_cast<std::size_t>(m));
  double radius = std::numeric_limits<double>::infinity();

  Eigen::Index k = n - 1;
  partial(k) = 0.0;
  z_bar(k) = z_hat(k);
  z(k) = std::round(z_bar(k));
  double y = z_bar(k) - z(k);
  step(k) = sign_toward(y);
  nodes_used = 0;
  while (true) {
    if (++nodes_used > max_nodes) {
      return Error("mlambda: search exceeded the cap of " + std::to_string(max_nodes) +
                   " nodes (options.max_search_nodes)");
    }
    const double dist = partial(k) + y * y / d(k);
    if (dist < radius) {
      if (k != 0) {
        --k;
        partial(k) = dist;
        S.row(k).head(k + 1) = S.row(k + 1).head(k + 1) + (z(k + 1) - z_bar(k + 1)) * L.row(k + 1).head(k + 1);
        z_bar(k) = z_hat(k) + S(k, k);
        z(k) = std::round(z_bar(k));
        y = z_bar(k) - z(k);
        step(k) = sign_toward(y);
        continue;
      }
      // Leaf: keep the m best, shrink the ellipsoid to the m-th best once m are known.
      if (static_cast<int>(best.size()) < m) {
        best.push_back({dist, z});
      } else {
        auto worst = std::max_element(best.begin(), best.end(), [](const Candidate& l, const Candidate& r) {
          return l.squared_norm < r.squared_norm;
        });
        *worst = {dist, z};
      }
      if (static_cast<int>(best.size()) == m) {
        radius = std::max_element(best.begin(), best.end(), [](const Candidate& l, const Candidate& r) {
                   return l.squared_norm < r.squared_norm;
                 })->squared_norm;
      }
    } else {
      if (k == n - 1) break;
      ++k;
    }
    // Next value of z_k in zig-zag order around z_bar_k.
    z(k) += step(k);
    y = z_bar(k) - z(k);
    step(k) = -step(k) - sign_toward(step(k));
  }
  std::sort(best.begin(), best.end(),
            [](const Candidate& l, const Candidate& r) { return l.squared_norm < r.squared_norm; });
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
  if (auto s = factorise_with_pivoting(Q_a, dec); !s) return s.error();
  if (auto s = reduce(dec, nullptr); !s) return s.error();
  return dec;
}

Result<IntegerSearchResult> mlambda(const Eigen::VectorXd& a_float, const Eigen::MatrixXd& Q_a,
                                    const MlambdaOptions& options) {
  if (auto s = options.validate(); !s) return Error("mlambda: " + s.error().message);
  if (auto s = check_problem(a_float, Q_a, "mlambda"); !s) return s.error();
  if (auto s = check_symmetric(Q_a, "mlambda"); !s) return s.error();

  Decorrelation dec;
  if (auto s = factorise_with_pivoting(Q_a, dec); !s) return s.error();
  const Eigen::VectorXd shift = a_float.array().round().matrix();
  Eigen::VectorXd z_hat = dec.Z.transpose() * (a_float - shift);
  if (auto s = reduce(dec, &z_hat); !s) return s.error();

  IntegerSearchResult out;
  auto found = search(dec, z_hat, options.num_candidates, options.max_search_nodes, out.search_nodes);
  if (!found) return found.error();
  const Eigen::Index n = a_float.size();
  const auto m = static_cast<Eigen::Index>(found->size());
  out.candidates.resize(n, m);
  out.squared_norms.resize(m);
  for (Eigen::Index j = 0; j < m; ++j) {
    const Candidate& c = (*found)[static_cast<std::size_t>(j)];
    out.candidates.col(j) = dec.Z_inv.transpose() * c.z + shift;  // exact: integer matrix times integer vector
    out.squared_norms(j) = c.squared_norm;
  }
  out.Z = std::move(dec.Z);
  return out;
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
