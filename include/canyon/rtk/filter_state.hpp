#pragma once
// The RTK filter's state x and covariance P, and their one owner: every read and write of x and P goes through here.
//
// Blocks, in this order (indices from the block accessors, never computed by the caller):
//   position      p_E_u (3, ECEF, m)
//   kinematics    v_E_u, a_E_u (6, m/s and m/s^2; with dynamics)
//   heading       psi (1, rad; the error of an external aiding's heading, with a heading state)
//   scale         s (1, relative; the error of an external aiding's scale, with a scale state)
//   interpolation e (3, ECEF, m; the error of an external aiding's position interpolated between its samples, with an
//                 interpolation state: time_update.hpp)
//   keyed states  one per StateKey, in the order added: an ambiguity N_sd of (satellite, frequency rank) in cycles,
//                 a satellite's single-differenced ionosphere I_sd in L1-band metres (frequency kIonosphere), or a
//                 signal's single-differenced code multipath error in metres (StateKey::code_bias).
// Keyed states come and go every epoch (a satellite rises, a slip resets it); the measurement update and the ambiguity
// resolution address them by index(key), which stays valid until the next add() or remove().

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/satellite.hpp"

namespace canyon::rtk {

/// The key of a keyed state: (satellite, frequency rank) for an ambiguity, (satellite, kIonosphere) for the
/// satellite's ionosphere. Ordered by satellite, then frequency.
struct StateKey {
  static constexpr int kIonosphere = -1;
  static constexpr int kCodeBiasRank0 = -2;  ///< the code bias of frequency rank f has frequency kCodeBiasRank0 - f
  core::SatelliteId sat;
  int frequency = 0;

  /// The key of the code multipath error of (satellite, frequency rank).
  [[nodiscard]] static StateKey code_bias(core::SatelliteId sat, int rank) { return {sat, kCodeBiasRank0 - rank}; }
  [[nodiscard]] bool ionosphere() const { return frequency == kIonosphere; }
  [[nodiscard]] bool code_bias() const { return frequency <= kCodeBiasRank0; }
  friend bool operator==(const StateKey& a, const StateKey& b) = default;
  // NOLINTNEXTLINE(modernize-use-nullptr): clang-tidy 14 misreads a defaulted operator<=>
  friend auto operator<=>(const StateKey& a, const StateKey& b) = default;
};

/// The layout of the unkeyed blocks.
struct StateLayout {
  bool kinematics = false;     ///< velocity and acceleration (the constant-acceleration model)
  bool heading = false;        ///< the external aiding's heading error
  bool scale = false;          ///< the external aiding's scale error
  bool interpolation = false;  ///< the external aiding's interpolation error (3 states)
};

class FilterState {
 public:
  static constexpr int kPosition = 0;  ///< index of the position block

  explicit FilterState(StateLayout layout = {});

  // ---- layout ----
  [[nodiscard]] const StateLayout& layout() const { return layout_; }
  /// Size of x (and of P's sides).
  [[nodiscard]] Eigen::Index size() const { return x_.size(); }
  /// Index of the velocity block (3), then the acceleration block (3); -1 without kinematics.
  [[nodiscard]] int kinematics_index() const { return layout_.kinematics ? 3 : -1; }
  /// Index of the heading error; -1 without a heading state.
  [[nodiscard]] int heading_index() const { return layout_.heading ? (layout_.kinematics ? 9 : 3) : -1; }
  /// Index of the scale error; -1 without a scale state.
  [[nodiscard]] int scale_index() const {
    return layout_.scale ? 3 + (layout_.kinematics ? 6 : 0) + (layout_.heading ? 1 : 0) : -1;
  }
  /// Index of the interpolation error block (3); -1 without an interpolation state.
  [[nodiscard]] int interpolation_index() const { return layout_.interpolation ? num_unkeyed() - 3 : -1; }
  /// Number of unkeyed states (position, kinematics, heading, scale, interpolation): the index of the first keyed
  /// state.
  [[nodiscard]] int num_unkeyed() const {
    return 3 + (layout_.kinematics ? 6 : 0) + (layout_.heading ? 1 : 0) + (layout_.scale ? 1 : 0) +
           (layout_.interpolation ? 3 : 0);
  }

  // ---- keyed states ----
  /// Index of a keyed state in x, -1 if absent.
  [[nodiscard]] int index(const StateKey& key) const;
  [[nodiscard]] bool has(const StateKey& key) const { return index(key) >= 0; }
  /// The key of the keyed state at `index` (>= num_unkeyed()).
  [[nodiscard]] const StateKey& key_at(int index) const;
  [[nodiscard]] const std::vector<StateKey>& keys() const { return keys_; }
  /// A keyed state to append: its initial value and variance, uncorrelated with every other state.
  struct NewState {
    StateKey key;
    double value = 0.0;
    double variance = 0.0;
  };
  /// Appends the states in order (one resize of x and P for all of them).
  void add(const std::vector<NewState>& states);
  /// One term of a linear combination of held states: weight times the state at index.
  struct Term {
    int index = 0;
    double weight = 0.0;
  };
  /// Appends a keyed state that is a linear combination of held states plus a constant and an independent residual:
  /// x_new = offset + sum w_i x_i + r, var(r) = residual_variance; its covariances with every state follow (P_new,* =
  /// sum w_i P_i,*), so what the held states learn later moves it as well.
  void add_combination(const StateKey& key, const std::vector<Term>& terms, double residual_variance,
                       double offset = 0.0);
  /// Removes a keyed state (no-op if absent).
  void remove(const StateKey& key);
  /// Removes every keyed state.
  void clear_keyed();

  // ---- values ----
  [[nodiscard]] const Eigen::VectorXd& x() const { return x_; }
  [[nodiscard]] const Eigen::MatrixXd& P() const { return P_; }
  [[nodiscard]] Eigen::Vector3d position_E_m() const { return x_.head<3>(); }
  [[nodiscard]] Eigen::Matrix3d position_covariance_E_m2() const { return P_.topLeftCorner<3, 3>(); }

  // ---- propagation (time update) ----
  /// Sets the position (and, with kinematics, velocity and acceleration), uncorrelated with every other state: the
  /// unkeyed block's rows and columns are cleared first. `var_position_m2` on the position's diagonal,
  /// `var_kinematics` on the velocity's and acceleration's.
  void reset_kinematics(const Eigen::Vector3d& p_E_m, const Eigen::Vector3d& v_E_mps, double var_position_m2,
                        double var_kinematics);
  /// x_k' = F_k x_k and P' = F P F^T for a transition F that is the identity but for its 9 x 9 kinematic block F_k
  /// (position, velocity, acceleration; needs kinematics).
  void propagate_kinematics(const Eigen::Matrix<double, 9, 9>& F_k);
  /// The acceleration's process noise: P_aa += R_EN Q_N R_EN^T for Q_N given in local ENU (R_EN: ENU -> ECEF).
  void add_acceleration_noise(const Eigen::Matrix3d& R_EN, const Eigen::Matrix3d& Q_N);
  /// An external motion as the model: p += dp, P_pp += sym(Q); the position's correlations with the other states
  /// are kept (dp does not depend on x).
  void add_position_increment(const Eigen::Vector3d& dp_E_m, const Eigen::Matrix3d& Q_E_m2);
  /// The keyed states' process over one interval, per kind: a first-order Gauss-Markov step x_i <- phi x_i (its row
  /// and column of P times phi), then q added to its variance; phi = 1 is a random walk.
  struct KeyedProcess {
    double q_ambiguity = 0.0;   ///< ambiguities: random walk
    double q_ionosphere = 0.0;  ///< ionosphere states: random walk
    double phi_code = 1.0;      ///< code multipath states
    double q_code = 0.0;
  };
  void propagate_keyed(const KeyedProcess& process);
  /// An aiding error state (heading_index() or scale_index(), or the `size` states of interpolation_index()) restarted:
  /// value 0, the variance on each, uncorrelated.
  void restart_aiding_state(int index, double variance, int size = 1);
  /// Its share of the position: p += J x_i, P = F P F^T with F = I + J e_i^T, then its variance grows by `noise`.
  /// The heading error psi: J = up x dp (rad); the scale error s: J = dp.
  void couple_aiding_state(int index, const Eigen::Vector3d& J, double noise);
  /// One step of the interpolation error e (needs the block): e' = carry e + w, var(w) = noise_m2 per axis, and the
  /// position takes the change, p' = p + e' - e (x' = F x + G w, P' = F P F^T + G G^T noise_m2, G = [I; I] on p, e).
  void propagate_interpolation(double carry, double noise_m2);
  /// Sets an aiding error state's value (its variance and correlations kept).
  void set_aiding_value(int index, double value) { x_[index] = value; }
  /// Sets the position, uncorrelated with every other state.
  void set_position(const Eigen::Vector3d& p_E_m, const Eigen::Matrix3d& P_E_m2);

  // ---- measurement update ----
  /// x += dx and P <- sym(P) - U V^T (U V^T symmetric, n x r each), P exactly symmetric afterwards.
  void correct(const Eigen::VectorXd& dx, const Eigen::MatrixXd& U, const Eigen::MatrixXd& V);
  /// x -= A b, P -= A B, then P symmetrised: conditioning the state on linear functions of it (fix and hold: A = P D^T,
  /// b = S^-1 (a_float - a_fix), B = S^-1 D P).
  void condition(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::MatrixXd& B);

  // ---- snapshot ----
  struct Snapshot {
    Eigen::VectorXd x;
    Eigen::MatrixXd P;
    std::vector<StateKey> keys;
  };
  [[nodiscard]] Snapshot snapshot() const { return {x_, P_, keys_}; }
  /// Back to a snapshot taken with the same keys (the caller keeps them unchanged in between).
  void revert(const Snapshot& s);
  /// Only x and P back to a snapshot of the same layout and keys (a retried update).
  void restore_values(const Eigen::VectorXd& x, const Eigen::MatrixXd& P) {
    x_ = x;
    P_ = P;
  }

 private:
  StateLayout layout_;
  Eigen::VectorXd x_;
  Eigen::MatrixXd P_;
  std::vector<StateKey> keys_;  // keyed state i is at index num_unkeyed() + i
};

}  // namespace canyon::rtk
