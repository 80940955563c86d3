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

/// canyon's own status of a partial fix (a wide-lane-only fix): a float conditioned on the fixed integers of its most
/// precise (wide-lane-like) DD combinations, too few to pin the position to centimetres. RTKLIB's Q has no such
/// value: .pos and NMEA write it as a float (Q 2, GGA 5); DDS solutions and CSV records carry this value.
inline constexpr std::uint8_t kPartialFixStatus = 8;

struct Solution {
  GpsTime time;  ///< GPST of the solution
  SolutionStatus status = SolutionStatus::None;
  Eigen::Vector3d p_E_m = Eigen::Vector3d::Zero();   ///< antenna position, ECEF
  Eigen::Matrix3d P_E_m2 = Eigen::Matrix3d::Zero();  ///< its covariance, ECEF
  std::optional<Eigen::Vector3d> v_E_mps;            ///< velocity, ECEF, if known
  int num_satellites = 0;
  double age_s = 0.0;  ///< age of differential corrections (0 for single point)
  double ratio = 0.0;  ///< ambiguity ratio test value (0 if none)
  /// With status Float: integer combinations fixed that condition it (a partial fix, kPartialFixStatus); else 0.
  int fixed_combinations = 0;
};

/// The status canyon reports beside RTKLIB's Q: kPartialFixStatus for a float conditioned on fixed combinations,
/// else the Q value.
[[nodiscard]] inline std::uint8_t exact_status(const Solution& s) {
  if (s.status == SolutionStatus::Float && s.fixed_combinations > 0) return kPartialFixStatus;
  return static_cast<std::uint8_t>(s.status);
}

}  // namespace canyon::core
