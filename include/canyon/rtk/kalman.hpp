#pragma once
// The Kalman measurement update at the sizes of RTK (tens of states, tens of rows), on sparse DD rows (dd_row.hpp).
// The factorisation and the triangular solves are Eigen's (an in-place LLT of the innovation covariance); the products
// are plain loops and matrix-vector products because Eigen's blocked matrix-matrix routines spend more on packing than
// on arithmetic at these sizes. Hand-written Cholesky and triangular solves measured 0-20 % faster per update
// (tests/bench/kalman_bench.cpp) but 0.6 % of a whole RTK run's instructions (callgrind, cssrlib-kinematic-doy265):
// not worth code of their own (docs/results/rtk.md).
//
// The effect of one block of rows on the state is a KalmanStep: x' = x + dx, P' = P - U V^T. Two blocks (code, then
// phase) are computed before either is applied, the second at the covariance the first leaves:
//   compressed_update (rows touching few states, the DD code): with A = P E_J (the columns of P of the states J the
//     rows touch) and S = H_J P_JJ H_J^T + R = L L^T:  G = L^-1 H_J,  dx = A G^T L^-1 v,  U = A G^T G,  V = A;
//   dense_update (rows touching most states, the DD phase), at P - U_prior V_prior^T: with X = P H^T and
//     S = H X + R = L L^T:  dx = (X L^-T) L^-1 v,  U = V = X L^-T.
// R is the rows' measurement covariance, read on and below its diagonal.

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "canyon/rtk/dd_row.hpp"

namespace canyon::rtk {

/// The effect of one block of measurements on the state: x' = x + dx, P' = P - U V^T.
struct KalmanStep {
  Eigen::VectorXd dx;
  Eigen::MatrixXd U;
  Eigen::MatrixXd V;
};

/// A step that changes nothing, for a state of size n.
[[nodiscard]] KalmanStep no_step(Eigen::Index n);

/// Update with rows that touch few states, in compressed form (see above). nullopt if S is not positive definite.
[[nodiscard]] std::optional<KalmanStep> compressed_update(const Eigen::MatrixXd& P,
                                                          const std::vector<const DdRow*>& rows, Eigen::VectorXd v,
                                                          const Eigen::MatrixXd& R);

/// Update with rows that touch most states, at the covariance P - prior.U prior.V^T of a preceding step not applied
/// yet (see above). nullopt if S is not positive definite.
[[nodiscard]] std::optional<KalmanStep> dense_update(const Eigen::MatrixXd& P, const KalmanStep& prior,
                                                     const std::vector<const DdRow*>& rows, Eigen::VectorXd v,
                                                     const Eigen::MatrixXd& R);

/// P <- sym(P) - U V^T for an n x n P with U V^T symmetric (U, V n x r), where sym(P) = (P + P^T) / 2 (P itself when
/// symmetric): computed on the lower triangle, one matrix-vector product per column, and mirrored, so that P is
/// exactly symmetric afterwards.
void subtract_symmetric_product(Eigen::MatrixXd& P, const Eigen::MatrixXd& U, const Eigen::MatrixXd& V);

}  // namespace canyon::rtk
