// The Kalman update kernels (rtk/kalman.hpp) against the textbook joint update: a block of code rows in compressed
// form, then a block of phase rows at the covariance it leaves, equal K = P H^T (H P H^T + R)^-1 with R block
// diagonal; a covariance that is not positive definite is refused; the symmetric subtraction keeps P symmetric.

#include "canyon/rtk/kalman.hpp"

#include <random>

#include <Eigen/LU>
#include <gtest/gtest.h>

namespace canyon::rtk {
namespace {

Eigen::MatrixXd random_spd(Eigen::Index n, std::mt19937& rng) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd A(n, n);
  for (Eigen::Index i = 0; i < A.size(); ++i) A.data()[i] = normal(rng);
  return A * A.transpose() + 0.5 * Eigen::MatrixXd::Identity(n, n);
}

/// Dense H of sparse rows.
Eigen::MatrixXd dense(const std::vector<const DdRow*>& rows, Eigen::Index n) {
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(rows.size()), n);
  for (std::size_t a = 0; a < rows.size(); ++a) {
    const auto r = static_cast<Eigen::Index>(a);
    H.row(r).head<3>() = rows[a]->h_pos.transpose();
    for (int k = 0; k < rows[a]->num_entries; ++k) {
      H(r, rows[a]->entries[static_cast<std::size_t>(k)].first) += rows[a]->entries[static_cast<std::size_t>(k)].second;
    }
  }
  return H;
}

/// DD-like rows: position part from random lines of sight, two keyed entries (s and the reference) for phase rows,
/// none (code rows) or ionosphere-like entries.
std::vector<DdRow> make_rows(int count, bool phase, Eigen::Index n, std::mt19937& rng) {
  std::normal_distribution<double> normal;
  std::uniform_int_distribution<int> keyed(3, static_cast<int>(n) - 1);
  std::vector<DdRow> rows(static_cast<std::size_t>(count));
  for (DdRow& row : rows) {
    row.phase = phase;
    row.h_pos = Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    row.innovation_m = normal(rng);
    if (phase) {
      row.add(keyed(rng), 0.19);
      row.add(3, -0.19);  // a shared reference
    }
  }
  return rows;
}

Eigen::MatrixXd block_R(int m, double variance, double shared) {
  Eigen::MatrixXd R = Eigen::MatrixXd::Constant(m, m, shared);
  R.diagonal().setConstant(variance);
  return R;
}

TEST(Kalman, CodeThenPhaseEqualsTheJointUpdate) {
  std::mt19937 rng(11);
  for (const Eigen::Index n : {8, 15, 30}) {
    const Eigen::MatrixXd P = random_spd(n, rng);
    const std::vector<DdRow> code = make_rows(6, false, n, rng);
    const std::vector<DdRow> phase = make_rows(5, true, n, rng);
    std::vector<const DdRow*> code_rows, phase_rows;
    for (const DdRow& r : code) code_rows.push_back(&r);
    for (const DdRow& r : phase) phase_rows.push_back(&r);
    const Eigen::MatrixXd R_code = block_R(6, 2.0, 0.5);
    const Eigen::MatrixXd R_phase = block_R(5, 1e-4, 4e-5);
    Eigen::VectorXd v_code(6), v_phase(5);
    for (int a = 0; a < 6; ++a) v_code[a] = code[static_cast<std::size_t>(a)].innovation_m;
    for (int a = 0; a < 5; ++a) v_phase[a] = phase[static_cast<std::size_t>(a)].innovation_m;
    auto step1 = compressed_update(P, code_rows, v_code, R_code);
    ASSERT_TRUE(step1.has_value());
    Eigen::VectorXd v2(5);
    for (int a = 0; a < 5; ++a)
      v2[a] = phase[static_cast<std::size_t>(a)].innovation_m - phase[static_cast<std::size_t>(a)].dot(step1->dx);
    auto step2 = dense_update(P, *step1, phase_rows, v2, R_phase);
    ASSERT_TRUE(step2.has_value());
    const Eigen::VectorXd dx = step1->dx + step2->dx;
    const Eigen::MatrixXd P_after = P - step1->U * step1->V.transpose() - step2->U * step2->V.transpose();
    // Textbook.
    Eigen::MatrixXd H(11, n);
    H << dense(code_rows, n), dense(phase_rows, n);
    Eigen::MatrixXd R = Eigen::MatrixXd::Zero(11, 11);
    R.topLeftCorner(6, 6) = R_code.selfadjointView<Eigen::Lower>();
    R.bottomRightCorner(5, 5) = R_phase.selfadjointView<Eigen::Lower>();
    Eigen::VectorXd v(11);
    v << v_code, v_phase;
    const Eigen::MatrixXd K = P * H.transpose() * (H * P * H.transpose() + R).inverse();
    const Eigen::MatrixXd expected = P - K * H * P;
    EXPECT_LT((dx - K * v).norm(), 1e-9 * (1.0 + dx.norm())) << n;
    EXPECT_LT((P_after - expected).norm(), 1e-9 * expected.norm()) << n;
  }
}

TEST(Kalman, ANonPositiveDefiniteInnovationCovarianceIsRefused) {
  std::mt19937 rng(3);
  const Eigen::MatrixXd P = random_spd(6, rng);
  std::vector<DdRow> rows = make_rows(2, false, 6, rng);
  rows[1] = rows[0];  // two identical rows and no noise: H P H^T + R is singular
  std::vector<const DdRow*> block{&rows[0], &rows[1]};
  const Eigen::MatrixXd R = Eigen::MatrixXd::Zero(2, 2);
  EXPECT_FALSE(compressed_update(P, block, Eigen::Vector2d(1, 1), R).has_value());
  EXPECT_FALSE(dense_update(P, no_step(6), block, Eigen::Vector2d(1, 1), R).has_value());
  const Eigen::MatrixXd negative = Eigen::MatrixXd::Identity(2, 2) * -1e6;
  EXPECT_FALSE(compressed_update(P, block, Eigen::Vector2d(1, 1), negative).has_value());
}

TEST(Kalman, SymmetricSubtractionSymmetrisesAndSubtracts) {
  std::mt19937 rng(5);
  Eigen::MatrixXd P = random_spd(9, rng);
  P(2, 5) += 1e-3;  // slightly asymmetric on entry
  const Eigen::MatrixXd sym = 0.5 * (P + P.transpose());
  const Eigen::MatrixXd U = Eigen::MatrixXd::Random(9, 6);
  const Eigen::MatrixXd V = U * 0.1;  // U V^T symmetric
  subtract_symmetric_product(P, U, V);
  EXPECT_EQ(P, P.transpose());
  EXPECT_LT((P - (sym - U * V.transpose())).norm(), 1e-12);
}

}  // namespace
}  // namespace canyon::rtk
