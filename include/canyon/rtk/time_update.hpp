#pragma once
// The RTK filter's time update (prediction), between two epochs dt_s apart.
//
// Own motion model (no external aiding): without dynamics (RTKLIB's "dynamics off") the position is re-initialised
// each epoch from the single-point solution with variance initial_position_sigma_m^2, uncorrelated with the other
// states; with dynamics a constant-acceleration model with white jerk:
//   x_k' = F_k x_k,  F_k = [I dt I dt^2/2 I; 0 I dt I; 0 0 I],  P' = F P F^T + Q,
//   Q on the acceleration: R_EN diag(sh^2, sh^2, sv^2) dt R_EN^T (sh, sv: accel_sigma_h_mps2, accel_sigma_v_mps2),
// re-initialised (velocity from the single point's Doppler) after a gap of more than 30 s.
// External motion (ExternalMotion, e.g. the fusion's VIO increment, fusion/vio_prediction.hpp): the increment and
// its covariance are the model, p += dp, P_pp += Q, the position's correlations with the ambiguities kept. With a
// heading state, psi (the error of the aiding frame's heading) rotates the increment about the local vertical:
// p += dp + J psi with J = dp_d_heading_E_m (= up x dp), P' = F P F^T with F = I + J e_psi^T, and psi walks by
// heading_noise_rad2; it restarts (value 0, variance heading_variance_rad2, uncorrelated) when the aiding asks and
// after any epoch that was not aided. With a scale state, s (the increment's relative scale error) adds dp s the same
// way (J = dp) and walks by scale_noise; it restarts likewise (variance scale_variance). With an interpolation state,
// e (the error of the aiding's position at this epoch, interpolated between its own samples) is carried instead of
// being added to Q at every epoch, where it would accumulate as a random walk: the aiding's increment runs between the
// interpolated positions, so p' = p + dp + e' - e with e' = interpolation_carry e + w, var(w) =
// interpolation_noise_m2 per axis; it restarts (value 0, variance interpolation_variance_m2) likewise.
// Either way the ambiguities and ionosphere states are random walks: ambiguity_noise_cyc^2 dt, iono_noise_m^2 dt.

#include <Eigen/Core>

#include "canyon/gnss/spp.hpp"
#include "canyon/rtk/filter_state.hpp"
#include "canyon/rtk/rtk_options.hpp"

namespace canyon::rtk {

/// One epoch's motion from an external sensor (see above).
struct ExternalMotion {
  Eigen::Vector3d delta_p_E_m = Eigen::Vector3d::Zero();  ///< position increment since the state's last epoch (m)
  Eigen::Matrix3d Q_E_m2 = Eigen::Matrix3d::Zero();       ///< its covariance, added to the position's (m^2)
  // With RtkOptions::aiding_heading_state only:
  Eigen::Vector3d dp_d_heading_E_m = Eigen::Vector3d::Zero();  ///< d(delta_p) / d(heading error): up x delta_p (m/rad)
  double heading_noise_rad2 = 0.0;     ///< random walk of the heading error over this increment (rad^2)
  double heading_variance_rad2 = 0.0;  ///< variance of the heading error when its state (re)starts (rad^2)
  bool restart_heading = false;        ///< the aiding frame changed (a new alignment): restart the heading state
  // With RtkOptions::aiding_scale_state only (the increment's scale error s: p += dp (1 + s), s a slow random walk):
  double scale_noise = 0.0;     ///< random walk of the scale error over this increment (relative^2)
  double scale_variance = 0.0;  ///< variance of the scale error when its state (re)starts (relative^2)
  bool restart_scale = false;   ///< the aiding itself changed (a new odometry segment): restart the scale state
  // With RtkOptions::aiding_interpolation_state only (above):
  double interpolation_carry = 0.0;        ///< e' = carry e + w (sigma' / sigma inside one interval, 0 across)
  double interpolation_noise_m2 = 0.0;     ///< var(w) per axis (m^2)
  double interpolation_variance_m2 = 0.0;  ///< var(e) at the state's epoch when the state (re)starts (m^2 per axis)
};

/// The own motion model over dt_s; `reinitialise` (no estimate yet) starts the position from `spp`.
void own_motion_update(FilterState& state, const RtkOptions& options, double dt_s, bool reinitialise,
                       const gnss::SppSolution& spp);

/// Whether the aiding error states hold an estimate (aided since their restart).
struct AidingLive {
  bool heading = false;
  bool scale = false;
  bool interpolation = false;
};

/// The external motion; `live` is read and set.
void external_motion_update(FilterState& state, const ExternalMotion& motion, AidingLive& live);

/// The random walks of the keyed states over dt_s, and the Gauss-Markov step of the code multipath states
/// (single_difference.hpp).
void keyed_random_walk(FilterState& state, const RtkOptions& options, double dt_s);

}  // namespace canyon::rtk
