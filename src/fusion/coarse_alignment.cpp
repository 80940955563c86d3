// The coarse alignment's schedule (see coarse_alignment.hpp; the fit itself: alignment.cpp, coarse_align()).

#include "canyon/fusion/coarse_alignment.hpp"

#include "canyon/core/constants.hpp"

namespace canyon::fusion {

std::string CoarseAlignmentOptions::validate() const {
  if (!(window_s > 0.0) || !(min_spread_m > 0.0) || !(max_yaw_sigma_deg > 0.0)) {
    return "coarse_window_s, coarse_min_spread_m and coarse_max_yaw_sigma_deg must be > 0";
  }
  return {};
}

std::optional<CoarseAlignment> try_coarse_alignment(const std::vector<WindowPoint>& history, const core::GpsTime& t,
                                                    int segment, const std::optional<VioAlignment>& current,
                                                    const Eigen::Vector3d& t_IA_m,
                                                    const CoarseAlignmentOptions& options, const AlignmentOptions& fit,
                                                    int& points) {
  std::vector<AlignmentPoint> coarse_points;
  for (const WindowPoint& w : history) {
    if (t - w.time > options.window_s || w.segment != segment) continue;
    if (current && w.status != core::SolutionStatus::Fixed) continue;
    if (!current && w.aided) continue;
    coarse_points.push_back(AlignmentPoint{w.T_OI, w.p_E_m});
  }
  points = static_cast<int>(coarse_points.size());
  auto coarse = coarse_align(coarse_points, t_IA_m, fit);
  const double max_sigma_rad = options.max_yaw_sigma_deg * core::kDegToRad;
  if (coarse && coarse->spread_m >= options.min_spread_m && coarse->yaw_sigma_rad <= max_sigma_rad &&
      (!current || coarse->yaw_sigma_rad < current->yaw_sigma_rad)) {
    return *coarse;
  }
  return std::nullopt;
}

}  // namespace canyon::fusion
