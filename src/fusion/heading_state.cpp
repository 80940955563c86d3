// The alignment's heading error as a filter state (see heading_state.hpp).

#include "canyon/fusion/heading_state.hpp"

#include <cmath>

#include <Eigen/Geometry>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"

namespace canyon::fusion {

std::string HeadingStateOptions::validate() const {
  if (!(random_walk_deg_per_sqrt_km >= 0.0) || !(fine_sigma_deg > 0.0)) {
    return "heading_random_walk_deg_per_sqrt_km must be >= 0 and fine_heading_sigma_deg > 0";
  }
  return {};
}

void couple_heading(rtk::ExternalMotion& motion, const Eigen::Vector3d& dp_E_m, const Eigen::Vector3d& up_E,
                    VioAlignment& alignment, const HeadingStateOptions& options) {
  const double walk_rad = options.random_walk_deg_per_sqrt_km * core::kDegToRad;
  motion.dp_d_heading_E_m = up_E.cross(dp_E_m);
  motion.heading_noise_rad2 = walk_rad * walk_rad * dp_E_m.norm() / 1000.0;
  motion.heading_variance_rad2 = alignment.yaw_sigma_rad * alignment.yaw_sigma_rad;
  motion.restart_heading = !alignment.heading_started;
  alignment.heading_started = true;
}

std::optional<double> fold_heading_error(rtk::RtkEngine& engine, VioAlignment& alignment) {
  const std::optional<rtk::RtkEngine::HeadingError> heading = engine.take_heading_error();
  if (!heading) return std::nullopt;
  const Eigen::Vector3d p_E_m = engine.position_E_m();
  const Eigen::Vector3d up_E = core::rotation_enu_from_ecef(core::ecef_to_geodetic(p_E_m)).row(2).transpose();
  const Eigen::Quaterniond q_psi(Eigen::AngleAxisd(heading->psi_rad, up_E));
  core::Pose& T_EO = alignment.T_EO;
  T_EO = core::Pose{(q_psi * T_EO.q).normalized(), q_psi * (T_EO.p - p_E_m) + p_E_m};
  alignment.yaw_sigma_rad = std::sqrt(heading->variance_rad2);
  return heading->psi_rad;
}

}  // namespace canyon::fusion
