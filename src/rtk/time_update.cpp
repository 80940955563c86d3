// The RTK filter's time update (see time_update.hpp).

#include "canyon/rtk/time_update.hpp"

#include <cmath>

#include "canyon/core/geodesy.hpp"

namespace canyon::rtk {

void own_motion_update(FilterState& state, const RtkOptions& options, double dt_s, bool reinitialise,
                       const gnss::SppSolution& spp) {
  if (!options.dynamics || reinitialise || dt_s > 30.0) {
    // Position (and velocity, acceleration) from the single-point solution, uncorrelated with the ambiguities.
    const double var0 = options.initial_position_sigma_m * options.initial_position_sigma_m;
    state.reset_kinematics(spp.p_E_m, spp.v_E_mps.value_or(Eigen::Vector3d::Zero()), var0, 100.0);
    return;
  }
  Eigen::Matrix<double, 9, 9> F_k = Eigen::Matrix<double, 9, 9>::Identity();
  for (int i = 0; i < 3; ++i) {
    F_k(i, 3 + i) = dt_s;
    F_k(i, 6 + i) = 0.5 * dt_s * dt_s;
    F_k(3 + i, 6 + i) = dt_s;
  }
  state.propagate_kinematics(F_k);
  const core::Geodetic g = core::ecef_to_geodetic(state.position_E_m());
  const Eigen::Matrix3d R_EN = core::rotation_enu_from_ecef(g).transpose();
  Eigen::Matrix3d Q_N = Eigen::Matrix3d::Zero();
  Q_N(0, 0) = Q_N(1, 1) = options.accel_sigma_h_mps2 * options.accel_sigma_h_mps2 * dt_s;
  Q_N(2, 2) = options.accel_sigma_v_mps2 * options.accel_sigma_v_mps2 * dt_s;
  state.add_acceleration_noise(R_EN, Q_N);
}

namespace {

/// One aiding error state (absent: index < 0): restarted when asked or not live, then coupled into the position.
void aiding_state_update(FilterState& state, int index, bool restart, double variance, const Eigen::Vector3d& J,
                         double noise, bool& live) {
  if (index < 0) return;
  if (restart || !live) {
    state.restart_aiding_state(index, variance);
    live = true;
  }
  state.couple_aiding_state(index, J, noise);
}

}  // namespace

void external_motion_update(FilterState& state, const ExternalMotion& motion, AidingLive& live) {
  state.add_position_increment(motion.delta_p_E_m, motion.Q_E_m2);
  aiding_state_update(state, state.heading_index(), motion.restart_heading, motion.heading_variance_rad2,
                      motion.dp_d_heading_E_m, motion.heading_noise_rad2, live.heading);
  aiding_state_update(state, state.scale_index(), motion.restart_scale, motion.scale_variance, motion.delta_p_E_m,
                      motion.scale_noise, live.scale);
  if (const int e = state.interpolation_index(); e >= 0) {
    if (!live.interpolation) {
      state.restart_aiding_state(e, motion.interpolation_variance_m2, 3);
      live.interpolation = true;
    }
    state.propagate_interpolation(motion.interpolation_carry, motion.interpolation_noise_m2);
  }
}

void keyed_random_walk(FilterState& state, const RtkOptions& options, double dt_s) {
  FilterState::KeyedProcess process;
  process.q_ambiguity = options.ambiguity_noise_cyc * options.ambiguity_noise_cyc * dt_s;
  process.q_ionosphere = options.iono_noise_m * options.iono_noise_m * dt_s;
  if (options.code_multipath_sigma_m > 0.0) {
    process.phi_code = std::exp(-dt_s / options.code_multipath_correlation_s);
    const double s2 = options.code_multipath_sigma_m * options.code_multipath_sigma_m;
    process.q_code = s2 * (1.0 - process.phi_code * process.phi_code);
  }
  state.propagate_keyed(process);
}

}  // namespace canyon::rtk
