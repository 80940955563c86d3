#pragma once
// Beyond the paper: the alignment's heading error as a filter state (rtk::RtkOptions::aiding_heading_state). Why: an
// alignment's heading is never exact (a coarse fit's is degrees off, a fine one's drifts with the VIO), and taken as
// exact, or as independent noise on each increment, it makes the fill-in drift sideways by the whole error times the
// distance walked. With the state, the increment is rotated by psi about the local vertical
// (dp_E += (up x dp_E) psi, rtk/time_update.hpp), so that the updates learn psi from how GNSS corrects the VIO
// motion. After every aided epoch psi is folded into T_EO (rotated about the vertical through the position) and the
// state restarts at zero with its variance kept; it starts at the coarse fit's yaw sigma or at fine_sigma_deg after a
// fine alignment, and walks by random_walk_deg_per_sqrt_km with the distance.

#include <optional>
#include <string>

#include <Eigen/Core>

#include "canyon/core/constants.hpp"
#include "canyon/core/se3.hpp"
#include "canyon/core/time.hpp"
#include "canyon/rtk/engine.hpp"

namespace canyon::fusion {

struct HeadingStateOptions {
  bool enabled = true;
  double random_walk_deg_per_sqrt_km = 1.0;  ///< VIO heading drift: the state's random walk (deg/sqrt(km))
  double fine_sigma_deg = 1.0;               ///< heading sigma after a fine alignment (deg)

  [[nodiscard]] std::string validate() const;
};

/// The heading error's sigma after an integrity restart (integrity_check.hpp): wide, but within what its
/// linearised state handles.
inline constexpr double kRestartHeadingSigmaRad = 10.0 * core::kDegToRad;

/// The VIO frame's registration to ECEF as the fusion uses it.
struct VioAlignment {
  core::Pose T_EO;
  int segment = 0;  ///< the VIO segment it holds for
  /// The heading's sigma: a coarse fit's; after a fine one 0 (taken as exact) or, with the heading state,
  /// fine_sigma_deg; with the heading state the filter's from the first aided epoch on.
  double yaw_sigma_rad = 0.0;
  bool fine = false;
  core::GpsTime time;
  bool heading_started = false;  ///< the filter's heading error has been restarted for it
};

/// The heading coupling of an epoch's motion whose increment is `dp_E_m` (up: the local vertical): the Jacobian, the
/// random walk over the distance, the restart of the state for a new alignment.
void couple_heading(rtk::ExternalMotion& motion, const Eigen::Vector3d& dp_E_m, const Eigen::Vector3d& up_E,
                    VioAlignment& alignment, const HeadingStateOptions& options);

/// Folds the filter's heading error into T_EO (turned about the vertical through the filter's position) and keeps its
/// sigma as the alignment's; the heading correction folded, nullopt if the filter had no estimate.
std::optional<double> fold_heading_error(rtk::RtkEngine& engine, VioAlignment& alignment);

}  // namespace canyon::fusion
