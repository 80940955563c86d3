#pragma once
// Beyond the paper: an integrity check of the output against the single points. Why: the fusion can carry a wrong
// position along for minutes (an alignment to solutions far off, NLOS floats that pulled it away) with nothing in its
// own tests to see it. The horizontal offset of each aided epoch's single-point solution from the output, in local
// east and north, is kept over window_s; when the median offset (per axis) of at least min_points of them exceeds
// max_offset_m, the position moves horizontally by that median (the single points' spread about it as its variance;
// the vertical and the alignment stay), every ambiguity starts again and so does the heading error (at least 10 deg).
// Single points in street canyons are tens of metres off for tens of seconds at a time (a 30 s median up to 43 m on
// urban-severe), hence a median over a window and a bound above that. And no restart while at least
// min_agreeing_share of the single points lie within max_offset_m of the output: on downtown they split into a group
// near a good output and a group about 200 m off for 30 s at a time, their median fell in the latter, and without
// this the check moved the output there (docs/results/urban-claim.md). And the median must be one over the window: each
// half of it must hold at least half of min_points single points (on downtown seed 17 the single points came back after
// a blockage 80 m off for 10 s; a window of those alone moved a good output 52 m away for the rest of the walk).

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/time.hpp"

namespace canyon::fusion {

struct IntegrityCheckOptions {
  bool enabled = true;
  double window_s = 30.0;           ///< the window of aided epochs (s)
  int min_points = 50;              ///< single points the window needs before it judges
  double max_offset_m = 60.0;       ///< median horizontal offset of the single points beyond which it restarts (m)
  double min_agreeing_share = 0.2;  ///< no restart while this share of them is within max_offset_m of the output

  [[nodiscard]] std::string validate() const;
};

/// A restart from the single points.
struct IntegrityRestart {
  Eigen::Vector3d p_E_m;   ///< the output moved horizontally by the median offset
  Eigen::Matrix3d P_E_m2;  ///< the single points' spread horizontally, the output's vertical variance
  double offset_m = 0.0;   ///< the median offset's length
};

class IntegrityCheck {
 public:
  explicit IntegrityCheck(const IntegrityCheckOptions& options) : options_(options) {}
  /// An aided epoch's output `p_out_E_m` (covariance `P_out_E_m2`) and its single point, if any: the restart, when the
  /// window says so (then the window starts again).
  [[nodiscard]] std::optional<IntegrityRestart> check(const core::GpsTime& t, const Eigen::Vector3d& p_out_E_m,
                                                      const Eigen::Matrix3d& P_out_E_m2,
                                                      const std::optional<Eigen::Vector3d>& spp_p_E_m);
  /// An epoch that was not aided (or had no output): the window starts again.
  void clear() { offsets_.clear(); }

 private:
  struct Offset {
    core::GpsTime time;
    Eigen::Vector2d d_EN_m;  // single point minus output, local east and north (m)
  };
  [[nodiscard]] double median_offset_m(int axis);
  /// Whether each half of the window before `t` holds at least half of min_points single points.
  [[nodiscard]] bool spans_window(const core::GpsTime& t) const;

  IntegrityCheckOptions options_;
  std::deque<Offset> offsets_;
  std::vector<double> scratch_m_;  // the medians' working copy (kept: no allocation per epoch)
};

}  // namespace canyon::fusion
