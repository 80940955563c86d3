// The fill-in before the VIO is aligned (see heading_free_fill_in.hpp).

#include "canyon/fusion/heading_free_fill_in.hpp"

#include "canyon/core/geodesy.hpp"

namespace canyon::fusion {

std::optional<core::GpsTime> HeadingFreeFillIn::anchor_time(int segment) const {
  if (!options_.enabled || !track_ || track_->segment != segment) return std::nullopt;
  return track_->time;
}

core::Solution HeadingFreeFillIn::fill(const core::GpsTime& t, const VioIncrement& increment) {
  Track& track = *track_;
  track.dp_O_m += increment.dp_O_m;
  track.var_up_m2 += increment.cov_O_m2(2, 2);
  track.time = t;
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(core::ecef_to_geodetic(track.p_E_m));
  const double var_horizontal_m2 = track.dp_O_m.head<2>().squaredNorm() / 2.0;  // a circle of radius h
  core::Solution s;
  s.time = t;
  s.status = core::SolutionStatus::VioFillIn;
  s.p_E_m = track.p_E_m + R_NE.row(2).transpose() * track.dp_O_m.z();
  s.P_E_m2 = track.P_E_m2 + R_NE.transpose() *
                                Eigen::Vector3d(var_horizontal_m2, var_horizontal_m2, track.var_up_m2).asDiagonal() *
                                R_NE;
  return s;
}

void HeadingFreeFillIn::anchor(const core::Solution& solution, const core::GpsTime& t, int segment) {
  track_ = Track{solution.p_E_m, solution.P_E_m2, Eigen::Vector3d::Zero(), 0.0, t, segment};
}

}  // namespace canyon::fusion
