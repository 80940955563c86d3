// The RTK filter's state and covariance (see filter_state.hpp).

#include "canyon/rtk/filter_state.hpp"

#include <algorithm>
#include <cassert>

#include "canyon/rtk/kalman.hpp"

namespace canyon::rtk {

FilterState::FilterState(StateLayout layout) : layout_(layout) {
  x_ = Eigen::VectorXd::Zero(num_unkeyed());
  P_ = Eigen::MatrixXd::Zero(num_unkeyed(), num_unkeyed());
}

int FilterState::index(const StateKey& key) const {
  const auto it = std::find(keys_.begin(), keys_.end(), key);
  return it == keys_.end() ? -1 : num_unkeyed() + static_cast<int>(it - keys_.begin());
}

const StateKey& FilterState::key_at(int index) const {
  assert(index >= num_unkeyed() && index < x_.size());
  return keys_[static_cast<std::size_t>(index - num_unkeyed())];
}

void FilterState::add(const std::vector<NewState>& states) {
  if (states.empty()) return;
  const Eigen::Index n = x_.size();
  const auto added = static_cast<Eigen::Index>(states.size());
  // One new x and P (a copy of the old block, zeros, the new variances) rather than one resize per state.
  Eigen::VectorXd x(n + added);
  x.head(n) = x_;
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(n + added, n + added);
  P.topLeftCorner(n, n) = P_;
  for (Eigen::Index i = 0; i < added; ++i) {
    const NewState& state = states[static_cast<std::size_t>(i)];
    x[n + i] = state.value;
    P(n + i, n + i) = state.variance;
    keys_.push_back(state.key);
  }
  x_.swap(x);
  P_.swap(P);
}

void FilterState::add_combination(const StateKey& key, const std::vector<Term>& terms, double residual_variance,
                                  double offset) {
  const Eigen::Index n = x_.size();
  Eigen::VectorXd w = Eigen::VectorXd::Zero(n);
  for (const Term& t : terms) {
    assert(t.index >= 0 && t.index < n);
    w[t.index] += t.weight;
  }
  const Eigen::VectorXd Pw = P_ * w;
  x_.conservativeResize(n + 1);
  x_[n] = offset + w.dot(x_.head(n));
  P_.conservativeResize(n + 1, n + 1);
  P_.topRightCorner(n, 1) = Pw;
  P_.bottomLeftCorner(1, n) = Pw.transpose();
  P_(n, n) = w.dot(Pw) + residual_variance;
  keys_.push_back(key);
}

void FilterState::remove(const StateKey& key) {
  const int index = this->index(key);
  if (index < 0) return;
  // x and P without the state: one copy into new storage (four blocks of P), no shifting in place.
  const auto n = x_.size();
  const auto tail = n - index - 1;
  Eigen::VectorXd x(n - 1);
  x << x_.head(index), x_.tail(tail);
  Eigen::MatrixXd P(n - 1, n - 1);
  P.topLeftCorner(index, index) = P_.topLeftCorner(index, index);
  P.topRightCorner(index, tail) = P_.topRightCorner(index, tail);
  P.bottomLeftCorner(tail, index) = P_.bottomLeftCorner(tail, index);
  P.bottomRightCorner(tail, tail) = P_.bottomRightCorner(tail, tail);
  x_.swap(x);
  P_.swap(P);
  keys_.erase(keys_.begin() + (index - num_unkeyed()));
}

void FilterState::clear_keyed() {
  const int k = num_unkeyed();
  x_.conservativeResize(k);
  P_.conservativeResize(k, k);
  keys_.clear();
}

void FilterState::reset_kinematics(const Eigen::Vector3d& p_E_m, const Eigen::Vector3d& v_E_mps, double var_position_m2,
                                   double var_kinematics) {
  const int k = num_unkeyed();
  P_.topRows(k).setZero();
  P_.leftCols(k).setZero();
  x_.head<3>() = p_E_m;
  P_.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * var_position_m2;
  if (layout_.kinematics) {
    x_.segment<3>(3) = v_E_mps;
    x_.segment<3>(6).setZero();
    P_.block<3, 3>(3, 3) = Eigen::Matrix3d::Identity() * var_kinematics;
    P_.block<3, 3>(6, 6) = Eigen::Matrix3d::Identity() * var_kinematics;
  }
}

void FilterState::propagate_kinematics(const Eigen::Matrix<double, 9, 9>& F_k) {
  assert(layout_.kinematics);
  // F is the identity but for its kinematic block F_k, so P_kk' = F_k P_kk F_k^T, P_ka' = F_k P_ka and the rest is
  // unchanged: O(81 N) instead of the O(N^3) of the whole product.
  constexpr int kKinematic = 9;
  const Eigen::Index m = x_.size() - kKinematic;
  x_.head<kKinematic>() = F_k * x_.head<kKinematic>();
  P_.topLeftCorner<kKinematic, kKinematic>() = F_k * P_.topLeftCorner<kKinematic, kKinematic>() * F_k.transpose();
  if (m > 0) {
    P_.topRightCorner(kKinematic, m) = F_k * P_.topRightCorner(kKinematic, m);
    P_.bottomLeftCorner(m, kKinematic) = P_.topRightCorner(kKinematic, m).transpose();
  }
}

void FilterState::add_acceleration_noise(const Eigen::Matrix3d& R_EN, const Eigen::Matrix3d& Q_N) {
  assert(layout_.kinematics);
  P_.block<3, 3>(6, 6) += R_EN * Q_N * R_EN.transpose();
}

void FilterState::add_position_increment(const Eigen::Vector3d& dp_E_m, const Eigen::Matrix3d& Q_E_m2) {
  x_.head<3>() += dp_E_m;
  P_.topLeftCorner<3, 3>() += 0.5 * (Q_E_m2 + Q_E_m2.transpose());
}

void FilterState::propagate_keyed(const KeyedProcess& process) {
  const int k = num_unkeyed();
  for (Eigen::Index i = k; i < x_.size(); ++i) {
    const StateKey& key = keys_[static_cast<std::size_t>(i - k)];
    if (!key.code_bias()) {
      P_(i, i) += key.ionosphere() ? process.q_ionosphere : process.q_ambiguity;
      continue;
    }
    if (process.phi_code != 1.0) {
      x_[i] *= process.phi_code;
      P_.row(i) *= process.phi_code;
      P_.col(i) *= process.phi_code;
    }
    P_(i, i) += process.q_code;
  }
}

void FilterState::restart_aiding_state(int index, double variance, int size) {
  assert(index >= 0 && index + size <= num_unkeyed());
  x_.segment(index, size).setZero();
  P_.middleRows(index, size).setZero();
  P_.middleCols(index, size).setZero();
  P_.block(index, index, size, size).diagonal().setConstant(variance);
}

void FilterState::couple_aiding_state(int index, const Eigen::Vector3d& J, double noise) {
  assert(index >= 0 && index < num_unkeyed());
  // F = I + J e_i^T: F P gives the position rows J times row i, then (F P) F^T the position columns column i J^T.
  x_.head<3>() += J * x_[index];
  P_.topRows<3>() += J * P_.row(index);
  P_.leftCols<3>() += P_.col(index) * J.transpose();
  P_(index, index) += noise;
}

void FilterState::propagate_interpolation(double carry, double noise_m2) {
  const int e = interpolation_index();
  assert(e >= 0);
  // F = I but for the rows of p (p + (carry - 1) e) and of e (carry e): F P on the rows, then (F P) F^T on the
  // columns, each reading the e block before it is scaled.
  const double k = carry - 1.0;
  x_.head<3>() += k * x_.segment<3>(e);
  x_.segment<3>(e) *= carry;
  P_.topRows<3>() += k * P_.middleRows<3>(e);
  P_.middleRows<3>(e) *= carry;
  P_.leftCols<3>() += k * P_.middleCols<3>(e);
  P_.middleCols<3>(e) *= carry;
  // G G^T noise: the same w enters p and e.
  const Eigen::Matrix3d Q = Eigen::Matrix3d::Identity() * noise_m2;
  P_.topLeftCorner<3, 3>() += Q;
  P_.block<3, 3>(0, e) += Q;
  P_.block<3, 3>(e, 0) += Q;
  P_.block<3, 3>(e, e) += Q;
}

void FilterState::set_position(const Eigen::Vector3d& p_E_m, const Eigen::Matrix3d& P_E_m2) {
  x_.head<3>() = p_E_m;
  P_.topRows<3>().setZero();
  P_.leftCols<3>().setZero();
  P_.topLeftCorner<3, 3>() = 0.5 * (P_E_m2 + P_E_m2.transpose());
}

void FilterState::correct(const Eigen::VectorXd& dx, const Eigen::MatrixXd& U, const Eigen::MatrixXd& V) {
  x_ += dx;
  subtract_symmetric_product(P_, U, V);
}

void FilterState::condition(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::MatrixXd& B) {
  x_ -= A * b;
  P_ -= A * B;
  P_ = 0.5 * (P_ + P_.transpose()).eval();
}

void FilterState::revert(const Snapshot& s) {
  assert(s.keys == keys_);
  x_ = s.x;
  P_ = s.P;
}

}  // namespace canyon::rtk
