#pragma once
// Time bridge: maps the VIO device clock to GPST through the device's built-in GPS, which reports GPST at known
// device-clock instants (timesync.csv pairs).
//
// Model (one line, offset and drift):
//   t_gps(t_ns) - t_ref = a + b (t_ns - n_ref) 1e-9 s,
// with (n_ref, t_ref) the first pair (device ns, GPST) and b = 1 / (1 + drift) for a device clock running fast by
// `drift` (s/s). Fit (robust, pairs with outliers and jitter):
//   1. b0 = median of the slopes between pair i and pair i + n/2 (an outlier spoils one slope, not the median);
//      a0 = median of (y_i - b0 x_i), x_i = (t_ns,i - n_ref) 1e-9, y_i = t_gps,i - t_ref;
//   2. repeat: residuals r_i = y_i - a - b x_i, sigma = 1.4826 median|r_i|, inliers |r_i| <= max(k sigma, r_min),
//      least squares on the inliers, until the inlier set no longer changes (at most 20 times).
// Reported: a, b (as the drift in ppm), the inliers' residual RMS and largest residual, and the rejected pairs.
// One pair determines the offset only: b = 1 (drift taken as zero), with a warning. VIO already on GPST (t_ns =
// GPST nanoseconds since 1980-01-06 00:00:00) needs no pairs: TimeBridge::gps_clock().

#include <cstdint>
#include <string>
#include <vector>

#include "canyon/core/result.hpp"
#include "canyon/core/time.hpp"
#include "canyon/io/vio_file.hpp"

namespace canyon::fusion {

struct TimeBridgeOptions {
  double outlier_sigmas = 4.0;            ///< k: a pair whose residual exceeds k robust sigmas is an outlier
  double min_outlier_threshold_s = 2e-3;  ///< r_min: residuals up to this are never outliers (s)
  double max_residual_rms_s = 0.02;       ///< a fit whose inliers' residual RMS is larger is refused (s)
  double max_drift_ppm = 1000.0;          ///< a fitted drift beyond this is refused (ppm)

  /// Empty if valid, else the violated rule.
  [[nodiscard]] std::string validate() const;
};

/// Device clock -> GPST.
class TimeBridge {
 public:
  /// The identity for VIO stamped with GPST nanoseconds since the GPS epoch.
  static TimeBridge gps_clock();
  TimeBridge(std::int64_t reference_ns, core::GpsTime reference_time, double a_s, double b)
      : reference_ns_(reference_ns), reference_time_(reference_time), a_s_(a_s), b_(b) {}

  [[nodiscard]] core::GpsTime to_gps(std::int64_t t_ns) const;
  [[nodiscard]] double offset_s() const { return a_s_; }
  /// Device clock rate error: the device runs fast by this (1e-6).
  [[nodiscard]] double drift_ppm() const { return (1.0 / b_ - 1.0) * 1e6; }
  [[nodiscard]] bool is_gps_clock() const { return gps_clock_; }

 private:
  TimeBridge() = default;
  std::int64_t reference_ns_ = 0;
  core::GpsTime reference_time_;
  double a_s_ = 0.0;
  double b_ = 1.0;
  bool gps_clock_ = false;
};

struct TimeBridgeFit {
  TimeBridge bridge = TimeBridge::gps_clock();
  int pairs = 0;
  std::vector<int> outlier_lines;  ///< lines of the rejected pairs in the time-sync file
  double residual_rms_s = 0.0;     ///< of the inliers
  double max_residual_s = 0.0;     ///< largest inlier residual (absolute)
  std::vector<std::string> warnings;
};

/// Fits the bridge to time-sync pairs (any order). Error if there is none, if all device times are equal, if the
/// inliers' residual RMS or the drift is beyond the options' limits, or if fewer than half the pairs are inliers.
Result<TimeBridgeFit> fit_time_bridge(const std::vector<io::TimeSyncPair>& pairs,
                                      const TimeBridgeOptions& options = {});

}  // namespace canyon::fusion
