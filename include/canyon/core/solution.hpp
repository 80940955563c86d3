#pragma once
// A position solution of any mode (single point, RTK float/fixed, VIO fill-in), as written to .pos files and
// published to consumers.

#include <cstdint>
#include <optional>

#include <Eigen/Core>

#include "canyon/core/time.hpp"

namespace canyon::core {

/// RTKLIB's Q values, so RTKLIB's tools read canyon's output.
enum class SolutionStatus : std::uint8_t { None = 0, Fixed = 1, Float = 2, Single = 5, VioFillIn = 7 };

struct Solution {
  GpsTime time;  ///< GPST of the solution
  SolutionStatus status = SolutionStatus::None;
  Eigen::Vector3d p_E_m = Eigen::Vector3d::Zero();   ///< antenna position, ECEF
  Eigen::Matrix3d P_E_m2 = Eigen::Matrix3d::Zero();  ///< its covariance, ECEF
  std::optional<Eigen::Vector3d> v_E_mps;            ///< velocity, ECEF, if known
  int num_satellites = 0;
  double age_s = 0.0;  ///< age of differential corrections (0 for single point)
  double ratio = 0.0;  ///< ambiguity ratio test value (0 if none)
};

}  // namespace canyon::core
