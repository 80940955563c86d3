#pragma once
// Beyond the paper: a coarse alignment while no window passes the paper's gates. Why: a walk that starts in a canyon
// has no 6 s of centimetre solutions with enough excitation for the paper's alignment (FER < 0.97, RMSE < 0.1 m) for
// minutes, and without an alignment the VIO cannot help at all. O is gravity-aligned, so the last window_s of any RTK
// solutions (metre-level) fix the yaw and the translation of T_EO (alignment.hpp: coarse_align); the yaw's
// uncertainty (the fit's RMSE over the solutions' horizontal spread) is carried into the prediction (as a heading
// state, heading_state.hpp, or as noise on each increment, vio_prediction.hpp). Before any alignment it uses every
// unaided RTK solution of the segment, afterwards fixed ones; a coarse fit replaces a coarse alignment only with a
// smaller yaw sigma, and never a fine one.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/solution.hpp"
#include "canyon/core/time.hpp"
#include "canyon/fusion/alignment.hpp"
#include "canyon/fusion/heading_state.hpp"

namespace canyon::fusion {

struct CoarseAlignmentOptions {
  bool enabled = true;
  double window_s = 60.0;           ///< its window (s)
  double min_spread_m = 1.0;        ///< RMS horizontal spread it needs (m; its yaw sigma bound decides)
  double max_yaw_sigma_deg = 30.0;  ///< largest yaw uncertainty it accepts (deg)

  [[nodiscard]] std::string validate() const;
};

/// A recent solution with its VIO pose (the alignment windows' points).
struct WindowPoint {
  core::GpsTime time;
  core::Pose T_OI;
  Eigen::Vector3d p_E_m;
  core::SolutionStatus status = core::SolutionStatus::None;
  double sigma_m = 0.0;  ///< 3D position sigma
  int segment = 0;
  bool aided = false;
};

/// A coarse alignment at `t` of VIO segment `segment` from `history`, if one qualifies and improves on `current`;
/// `points` is set to the number of solutions it used.
[[nodiscard]] std::optional<CoarseAlignment> try_coarse_alignment(const std::vector<WindowPoint>& history,
                                                                  const core::GpsTime& t, int segment,
                                                                  const std::optional<VioAlignment>& current,
                                                                  const Eigen::Vector3d& t_IA_m,
                                                                  const CoarseAlignmentOptions& options,
                                                                  const AlignmentOptions& fit, int& points);

}  // namespace canyon::fusion
