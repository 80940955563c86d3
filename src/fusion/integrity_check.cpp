// The integrity check against the single points (see integrity_check.hpp).

#include "canyon/fusion/integrity_check.hpp"

#include "canyon/core/geodesy.hpp"
#include "canyon/core/statistics.hpp"

namespace canyon::fusion {

std::string IntegrityCheckOptions::validate() const {
  if (!(window_s > 0.0) || min_points < 1 || !(max_offset_m > 0.0) || !(min_agreeing_share > 0.0)) {
    return "integrity_window_s, integrity_max_offset_m and integrity_min_agreeing_share must be > 0 and "
           "integrity_min_points >= 1";
  }
  return {};
}

double IntegrityCheck::median_offset_m(int axis) {
  scratch_m_.clear();
  for (const Offset& o : offsets_) scratch_m_.push_back(o.d_EN_m[axis]);
  return core::median_in_place(scratch_m_);
}

bool IntegrityCheck::spans_window(const core::GpsTime& t) const {
  const core::GpsTime middle = t - 0.5 * options_.window_s;
  int older = 0;
  for (const Offset& o : offsets_) older += o.time - middle < 0.0 ? 1 : 0;
  const int newer = static_cast<int>(offsets_.size()) - older;
  const int needed = (options_.min_points + 1) / 2;
  return older >= needed && newer >= needed;
}

std::optional<IntegrityRestart> IntegrityCheck::check(const core::GpsTime& t, const Eigen::Vector3d& p_out_E_m,
                                                      const Eigen::Matrix3d& P_out_E_m2,
                                                      const std::optional<Eigen::Vector3d>& spp_p_E_m) {
  if (!options_.enabled || !spp_p_E_m) return std::nullopt;
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(core::ecef_to_geodetic(p_out_E_m));
  offsets_.push_back(Offset{t, (R_NE * (*spp_p_E_m - p_out_E_m)).head<2>()});
  while (t - offsets_.front().time > options_.window_s) offsets_.pop_front();
  if (static_cast<int>(offsets_.size()) < options_.min_points) return std::nullopt;
  // A window whose single points all came in its last seconds (after a blockage) is one stretch of NLOS, not a median
  // over window_s.
  if (!spans_window(t)) return std::nullopt;
  const Eigen::Vector2d median_m(median_offset_m(0), median_offset_m(1));
  if (median_m.norm() <= options_.max_offset_m) return std::nullopt;
  // An output that a share of the single points still agrees with has not left them: in a deep canyon the single
  // points split into a group near the output and a group hundreds of metres off (NLOS), and the median may fall in
  // the latter.
  int agreeing = 0;
  for (const Offset& o : offsets_) agreeing += o.d_EN_m.norm() <= options_.max_offset_m ? 1 : 0;
  if (agreeing >= options_.min_agreeing_share * static_cast<double>(offsets_.size())) return std::nullopt;
  // Horizontally the single points' median, with their spread about it as its variance; vertically the output's.
  Eigen::Vector2d spread2 = Eigen::Vector2d::Zero();
  for (const Offset& o : offsets_) spread2 += (o.d_EN_m - median_m).cwiseAbs2();
  spread2 /= static_cast<double>(offsets_.size());
  Eigen::Matrix3d P_N = R_NE * P_out_E_m2 * R_NE.transpose();
  P_N.topRows<2>().setZero();
  P_N.leftCols<2>().setZero();
  P_N(0, 0) = spread2[0];
  P_N(1, 1) = spread2[1];
  offsets_.clear();
  return IntegrityRestart{p_out_E_m + R_NE.transpose() * Eigen::Vector3d(median_m[0], median_m[1], 0.0),
                          R_NE.transpose() * P_N * R_NE, median_m.norm()};
}

}  // namespace canyon::fusion
