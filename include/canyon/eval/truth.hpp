#pragma once
// Ground truth for solution evaluation: a constant ECEF point (static rover) or a time series of antenna positions
// interpolated linearly at solution times.
//
// Readers:
//  - Spirent SimGEN PVA CSV (instinct-spirent-rtk-sim `Rover-dynamic_PVA_Spirent.csv`): columns `GpsCycle`,
//    `GpsWeek` (GPS week = 1024 * GpsCycle + GpsWeek), `GpsToW [s]`, `Pos ECEF X/Y/Z [m]`, found by header name.
//  - canyon's truth CSV (DESIGN.md): `gps_week,gps_tow_s,x,y,z[,qx,qy,qz,qw]` with a header row.
//  - RTKLIB-style `week tow x y z ...` or any .pos file io::read_pos_file reads (e.g.
//  truth_rover_dynamic_ecef_10Hz.pos).
// Bad input returns an Error naming the file and line.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/result.hpp"
#include "canyon/core/time.hpp"

namespace canyon::eval {

struct TruthSample {
  core::GpsTime time;                               ///< GPST
  Eigen::Vector3d p_E_m = Eigen::Vector3d::Zero();  ///< antenna position, ECEF
};

struct TruthOptions {
  /// Largest distance in time outside the truth span at which the end segment is still extrapolated linearly (s).
  double max_extrapolation_s = 0.2;
  /// Two neighbouring samples further apart than this are a gap: no truth between them (s).
  double max_gap_s = 2.0;
};

class Truth {
 public:
  /// A static rover: the same point at every time.
  static Truth constant(const Eigen::Vector3d& p_E_m);
  /// A trajectory. Error if `samples` is empty or not strictly increasing in time (names the sample index).
  static Result<Truth> from_samples(std::vector<TruthSample> samples, TruthOptions options = {});

  /// Truth position at `time`; nullopt outside the span (beyond max_extrapolation_s) or inside a gap.
  [[nodiscard]] std::optional<Eigen::Vector3d> position_at(const core::GpsTime& time) const;
  [[nodiscard]] bool is_constant() const { return samples_.size() == 1 && constant_; }
  [[nodiscard]] const std::vector<TruthSample>& samples() const { return samples_; }

 private:
  Truth(std::vector<TruthSample> samples, TruthOptions options, bool constant)
      : samples_(std::move(samples)), options_(options), constant_(constant) {}

  std::vector<TruthSample> samples_;
  TruthOptions options_;
  bool constant_ = false;
};

/// Spirent SimGEN PVA CSV (see above).
Result<Truth> read_spirent_pva_csv(const std::string& path, TruthOptions options = {});
/// canyon's truth CSV `gps_week,gps_tow_s,x,y,z[,...]`.
Result<Truth> read_truth_csv(const std::string& path, TruthOptions options = {});
/// Positions of every record of a .pos file (RTKLIB or canyon; ECEF or geodetic).
Result<Truth> read_truth_pos(const std::string& path, TruthOptions options = {});

/// A truth given as text, as on a command line:
///  - "ecef:X,Y,Z"          constant ECEF point (m)
///  - "llh:LAT,LON,H"       constant point, latitude and longitude in degrees, ellipsoidal height in metres
///  - a file path: *.csv    Spirent PVA or canyon truth CSV (told apart by the header row)
///  - any other file path   a .pos-style file (`week tow x y z` or a full .pos)
Result<Truth> parse_truth_spec(const std::string& spec, TruthOptions options = {});

}  // namespace canyon::eval
