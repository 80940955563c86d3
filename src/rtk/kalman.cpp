// The Kalman measurement update kernels (see kalman.hpp).

#include "canyon/rtk/kalman.hpp"

#include <algorithm>

#include <Eigen/Cholesky>

namespace canyon::rtk {
namespace {

/// The states a block of DD rows touches, ascending, and the rows' Jacobian on them (H = H_J on J, zero elsewhere).
struct CompressedJacobian {
  std::vector<int> states;  // J
  Eigen::MatrixXd H_J;      // rows x |J|
};

CompressedJacobian compress(const std::vector<const DdRow*>& rows) {
  CompressedJacobian c;
  c.states = {0, 1, 2};
  for (const DdRow* row : rows) {
    for (int k = 0; k < row->num_entries; ++k) c.states.push_back(row->entries[static_cast<std::size_t>(k)].first);
  }
  std::sort(c.states.begin(), c.states.end());
  c.states.erase(std::unique(c.states.begin(), c.states.end()), c.states.end());
  c.H_J = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(c.states.size()));
  for (std::size_t a = 0; a < rows.size(); ++a) {
    const auto r = static_cast<Eigen::Index>(a);
    c.H_J.row(r).head<3>() = rows[a]->h_pos.transpose();
    for (int k = 0; k < rows[a]->num_entries; ++k) {
      const auto& [state, coefficient] = rows[a]->entries[static_cast<std::size_t>(k)];
      const auto column = std::lower_bound(c.states.begin(), c.states.end(), state) - c.states.begin();
      c.H_J(r, column) += coefficient;
    }
  }
  return c;
}

}  // namespace

KalmanStep no_step(Eigen::Index n) {
  return KalmanStep{Eigen::VectorXd::Zero(n), Eigen::MatrixXd(n, 0), Eigen::MatrixXd(n, 0)};
}

// v is taken by value and solved in place: Eigen's solveInPlace() takes its argument as a const reference and writes
// through it, which clang-tidy reads as a copy used only as a const reference.
std::optional<KalmanStep> compressed_update(const Eigen::MatrixXd& P, const std::vector<const DdRow*>& rows,
                                            Eigen::VectorXd v,  // NOLINT(performance-unnecessary-value-param)
                                            const Eigen::MatrixXd& R) {
  const CompressedJacobian c = compress(rows);
  const auto m = static_cast<Eigen::Index>(rows.size());
  const auto q = static_cast<Eigen::Index>(c.states.size());
  KalmanStep step;
  step.V.resize(P.rows(), q);  // A
  for (Eigen::Index j = 0; j < q; ++j) step.V.col(j) = P.col(c.states[static_cast<std::size_t>(j)]);
  Eigen::MatrixXd P_JJ(q, q);
  for (Eigen::Index i = 0; i < q; ++i) P_JJ.row(i) = step.V.row(c.states[static_cast<std::size_t>(i)]);
  const Eigen::MatrixXd H_P_JJ = c.H_J.lazyProduct(P_JJ);
  Eigen::MatrixXd S(m, m);
  for (Eigen::Index b = 0; b < m; ++b) {
    for (Eigen::Index a = b; a < m; ++a) S(a, b) = H_P_JJ.row(a).dot(c.H_J.row(b)) + R(a, b);
  }
  const Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(S);  // in place, from the lower triangle
  if (llt.info() != Eigen::Success) return std::nullopt;
  Eigen::MatrixXd G = c.H_J;
  llt.matrixL().solveInPlace(G);
  llt.matrixL().solveInPlace(v);
  step.dx = step.V * (G.transpose() * v);
  step.U = step.V.lazyProduct(G.transpose().lazyProduct(G));
  return step;
}

std::optional<KalmanStep> dense_update(const Eigen::MatrixXd& P, const KalmanStep& prior,
                                       const std::vector<const DdRow*>& rows,
                                       Eigen::VectorXd v,  // NOLINT(performance-unnecessary-value-param): as above
                                       const Eigen::MatrixXd& R) {
  const auto m = static_cast<Eigen::Index>(rows.size());
  KalmanStep step;
  step.U.resize(P.rows(), m);
  for (Eigen::Index a = 0; a < m; ++a) {
    const DdRow& row = *rows[static_cast<std::size_t>(a)];
    row.covariance_times(P, step.U.col(a));
    for (Eigen::Index j = 0; j < prior.V.cols(); ++j) step.U.col(a) -= row.dot(prior.V.col(j)) * prior.U.col(j);
  }
  Eigen::MatrixXd S(m, m);
  for (Eigen::Index b = 0; b < m; ++b) {
    for (Eigen::Index a = b; a < m; ++a) S(a, b) = rows[static_cast<std::size_t>(a)]->dot(step.U.col(b)) + R(a, b);
  }
  const Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(S);  // in place, from the lower triangle
  if (llt.info() != Eigen::Success) return std::nullopt;
  llt.matrixU().solveInPlace<Eigen::OnTheRight>(step.U);  // U L^-T
  llt.matrixL().solveInPlace(v);
  step.dx = step.U * v;
  step.V = step.U;
  return step;
}

void subtract_symmetric_product(Eigen::MatrixXd& P, const Eigen::MatrixXd& U, const Eigen::MatrixXd& V) {
  const Eigen::Index n = P.rows();
  const Eigen::Index r = U.cols();
  for (Eigen::Index j = 0; j < n; ++j) {
    double* p_j = P.col(j).data();
    for (Eigen::Index i = j + 1; i < n; ++i) p_j[i] = 0.5 * (p_j[i] + P(j, i));
    Eigen::Index c = 0;
    for (; c + 4 <= r; c += 4) {  // four columns of U per pass over column j of P
      const double* u_0 = U.col(c).data();
      const double* u_1 = U.col(c + 1).data();
      const double* u_2 = U.col(c + 2).data();
      const double* u_3 = U.col(c + 3).data();
      const double v_0 = V(j, c), v_1 = V(j, c + 1), v_2 = V(j, c + 2), v_3 = V(j, c + 3);
      for (Eigen::Index i = j; i < n; ++i) p_j[i] -= (v_0 * u_0[i] + v_1 * u_1[i]) + (v_2 * u_2[i] + v_3 * u_3[i]);
    }
    for (; c < r; ++c) {
      const double v_jc = V(j, c);
      const double* u_c = U.col(c).data();
      for (Eigen::Index i = j; i < n; ++i) p_j[i] -= v_jc * u_c[i];
    }
    for (Eigen::Index i = j + 1; i < n; ++i) P(j, i) = p_j[i];
  }
}

}  // namespace canyon::rtk
