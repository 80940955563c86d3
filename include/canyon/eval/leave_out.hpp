#pragma once
// Checking fixes without ground truth: leave satellites out. A correct fix does not depend on which satellites give
// it: solved again with the most-observed satellites left out, an epoch fixed in both lands within a few centimetres
// of the full solution's fix. A fix that moves by decimetres or metres is wrong in one of the two (a wrong integer
// set biases the position by a combination of whole wavelengths), so the share of agreeing epochs bounds the share of
// wrong fixes from below where no truth exists.

#include <string>
#include <vector>

#include "canyon/core/satellite.hpp"
#include "canyon/core/solution.hpp"

namespace canyon::eval {

/// One left-out run against the full solution, on the epochs both fixed (matched by time within 5 ms).
struct LeaveOutAgreement {
  int left_out = 0;                           ///< number of satellites left out
  std::vector<core::SatelliteId> satellites;  ///< which, most observed first
  int fixed_full = 0;                         ///< fixed epochs of the full solution
  int fixed_left_out = 0;                     ///< fixed epochs of the left-out solution
  int fixed_both = 0;                         ///< epochs fixed in both
  int agree = 0;                              ///< of those, 3-D distance <= tolerance
  double tolerance_m = 0.05;
  double median_distance_m = 0.0;  ///< over the epochs fixed in both (0 when none)
  double worst_distance_m = 0.0;

  /// agree / fixed_both (1 when no epoch is fixed in both: nothing disagrees).
  [[nodiscard]] double agreement() const { return fixed_both > 0 ? static_cast<double>(agree) / fixed_both : 1.0; }
};

/// Compares the fixed epochs of `left_out` with those of `full`.
[[nodiscard]] LeaveOutAgreement leave_out_agreement(const std::vector<core::Solution>& full,
                                                    const std::vector<core::Solution>& left_out,
                                                    double tolerance_m = 0.05);

/// Text table: one row per left-out run (satellites, fixed epochs, fixed in both, agreeing within the tolerance,
/// median and worst distance), then a verdict line per run against `min_agreement`.
[[nodiscard]] std::string format_leave_out(const std::vector<LeaveOutAgreement>& runs, double min_agreement = 0.95);

}  // namespace canyon::eval
