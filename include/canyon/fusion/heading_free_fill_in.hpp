#pragma once
// Beyond the paper: a fill-in before the VIO is aligned. Why: a session that starts in a canyon (or a VIO reset in
// one) has no alignment and often no GNSS solution; the paper's fill-in needs T_EO. The VIO's vertical motion needs no
// heading (O is gravity-aligned): an epoch without any GNSS solution gets the last solution of the VIO segment moved
// by it, and the horizontal motion of unknown direction stands as the uncertainty, sigma h / sqrt(2) per horizontal
// axis, h the horizontal distance travelled since (status VIO fill-in, Q 7).

#include <optional>

#include <Eigen/Core>

#include "canyon/core/solution.hpp"
#include "canyon/core/time.hpp"
#include "canyon/fusion/vio_prediction.hpp"

namespace canyon::fusion {

struct HeadingFreeFillInOptions {
  bool enabled = true;
};

class HeadingFreeFillIn {
 public:
  explicit HeadingFreeFillIn(const HeadingFreeFillInOptions& options) : options_(options) {}
  /// The anchor's time, if there is one in the VIO segment `segment` (and the fill-in is on).
  [[nodiscard]] std::optional<core::GpsTime> anchor_time(int segment) const;
  /// The fill-in at `t` from the antenna's VIO increment since the anchor's time (in O: dp_O_m, cov_O_m2).
  [[nodiscard]] core::Solution fill(const core::GpsTime& t, const VioIncrement& increment);
  /// An epoch's solution of VIO segment `segment` becomes the anchor.
  void anchor(const core::Solution& solution, const core::GpsTime& t, int segment);

 private:
  struct Track {
    Eigen::Vector3d p_E_m;
    Eigen::Matrix3d P_E_m2;
    Eigen::Vector3d dp_O_m = Eigen::Vector3d::Zero();  // antenna displacement since, in O (z up) (m)
    double var_up_m2 = 0.0;                            // variance of its vertical component (m^2)
    core::GpsTime time;                                // of the last pose added
    int segment = 0;
  };
  HeadingFreeFillInOptions options_;
  std::optional<Track> track_;
};

}  // namespace canyon::fusion
