#pragma once
// One linearised double-differenced (DD) measurement row, sparse: the position part h_pos and at most four more
// entries (the two satellites' ambiguities and ionosphere states), with its innovation.
//   h x = h_pos . p + sum_k coefficient_k x[state_k]

#include <array>
#include <utility>

#include <Eigen/Core>

namespace canyon::rtk {

struct DdRow {
  Eigen::Vector3d h_pos = Eigen::Vector3d::Zero();
  std::array<std::pair<int, double>, 4> entries{};  ///< (state index, coefficient)
  int num_entries = 0;
  double innovation_m = 0.0;
  int sd = -1;         ///< index into the epoch's single differences of satellite s
  int reference = -1;  ///< index of the reference satellite's single difference
  bool phase = true;   ///< a carrier-phase row (else pseudorange)

  /// Adds `coefficient` to the entry of `index` (a new entry if there is none).
  void add(int index, double coefficient) {
    for (int k = 0; k < num_entries; ++k) {
      if (entries[static_cast<std::size_t>(k)].first == index) {
        entries[static_cast<std::size_t>(k)].second += coefficient;
        return;
      }
    }
    entries[static_cast<std::size_t>(num_entries++)] = {index, coefficient};
  }
  /// h . c for a state-sized column c (e.g. a column of P H^T).
  [[nodiscard]] double dot(const Eigen::Ref<const Eigen::VectorXd>& c) const {
    double sum = h_pos.dot(c.head<3>());
    for (int k = 0; k < num_entries; ++k) {
      sum += entries[static_cast<std::size_t>(k)].second * c[entries[static_cast<std::size_t>(k)].first];
    }
    return sum;
  }
  /// P h for a symmetric P: one column of P H^T, from columns of P.
  void covariance_times(const Eigen::MatrixXd& P, Eigen::Ref<Eigen::VectorXd> P_h) const {
    P_h = h_pos[0] * P.col(0) + h_pos[1] * P.col(1) + h_pos[2] * P.col(2);
    for (int k = 0; k < num_entries; ++k) {
      P_h += entries[static_cast<std::size_t>(k)].second * P.col(entries[static_cast<std::size_t>(k)].first);
    }
  }
};

}  // namespace canyon::rtk
