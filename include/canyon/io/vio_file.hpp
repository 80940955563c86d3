#pragma once
// Readers of the VIO pose file and the device's GPS time-sync file (DESIGN.md file contracts).
//
// vio.csv: a header row whose first eight names are `t_ns,px,py,pz,qx,qy,qz,qw`, followed by 21 names (upper triangle
// of the covariance) and optionally 36 more (cross-covariance); then one row per pose:
//   t_ns            device clock (ns), integer
//   px py pz        p_O_I, the IMU position in the odometry frame O (m)
//   qx qy qz qw     R_OI as a Hamilton quaternion (normalised on reading)
//   21 values       upper triangle, row-major, of the 6x6 covariance of xi_OI = [delta p; delta theta] (m, rad),
//                   right perturbation T_OI,est = T_OI Exp(xi)
//   36 values       (optional) cov(xi_OI of the previous row, xi_OI of this row), row-major; absent: zero
// timesync.csv: a header row `t_ns,gps_week,gps_tow_s`, then pairs: the device clock (ns) when the device's GPS gave
// that GPST (week, seconds of week).
//
// Handling of bad input (every message names the file and the line):
//   error (nothing returned): a missing or wrong header row; a row whose number of fields differs from the header's;
//     a field that is not a number; a value that is not finite; a quaternion whose norm is not within [0.5, 1.5]; a
//     GPS week < 0 or a time of week outside [0, 604800); a file with no usable row.
//   warning, row dropped: a pose whose time is not after the previous kept pose's (non-monotonic time); a pose whose
//     covariance is not positive definite (smallest eigenvalue <= 0); the next row's cross-covariance, which refers
//     to a dropped row, is then ignored (taken as absent).
//   warning, row dropped: the last row with too few fields (a file cut short); on any other row it is an error.
//   not judged here: jumps of the pose (a VIO reset of its odometry frame) and gaps in time: the fusion's VIO track
//     splits the trajectory into segments there (fusion/vio_track.hpp).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "canyon/core/result.hpp"
#include "canyon/core/se3.hpp"
#include "canyon/core/time.hpp"

namespace canyon::io {

struct VioRecord {
  std::int64_t t_ns = 0;  ///< device clock (or GPST, see the fusion's vio_clock option)
  core::Pose T_OI;
  core::Matrix6d covariance = core::Matrix6d::Zero();  ///< of xi_OI
  /// cov(xi_OI of the previous kept record, xi_OI of this one); nullopt when the file has none for this row.
  std::optional<core::Matrix6d> cross_previous;
  int line = 0;  ///< line in the file
};

struct VioFile {
  std::vector<VioRecord> records;
  bool has_cross_covariance = false;  ///< the file has the 36 cross-covariance columns
  int dropped_non_monotonic = 0;
  int dropped_not_positive_definite = 0;
  std::vector<std::string> warnings;  ///< "file:line: what" (the first few of each kind, then a count)
};

struct TimeSyncPair {
  std::int64_t t_ns = 0;  ///< device clock
  core::GpsTime time;     ///< GPST the device's GPS gave at t_ns
  int line = 0;
};

struct TimeSyncFile {
  std::vector<TimeSyncPair> pairs;
  std::vector<std::string> warnings;
};

Result<VioFile> read_vio_csv(const std::string& path);
/// vio.csv's header row, with the 36 cross-covariance columns.
[[nodiscard]] std::string vio_csv_header();
/// A vio.csv row of `record`, every value with 17 significant digits (read back exactly); an absent
/// cross-covariance is written as zeros, which the reader takes the same way.
[[nodiscard]] std::string vio_csv_row(const VioRecord& record);
Result<TimeSyncFile> read_timesync_csv(const std::string& path);
/// timesync.csv's header row ("t_ns,gps_week,gps_tow_s").
[[nodiscard]] std::string timesync_csv_header();
/// A timesync.csv row of `pair`, the time of week with 17 significant digits (read back exactly).
[[nodiscard]] std::string timesync_csv_row(const TimeSyncPair& pair);

}  // namespace canyon::io
