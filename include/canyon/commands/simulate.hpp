#pragma once
// `canyon simulate`: generate a scenario and write its files into a folder.
//
// Files (DIR):
//   nav.rnx       RINEX 3.04 navigation: the broadcast records every observation was computed from
//   rover.obs     RINEX 3.04 observations of the pedestrian rover (head-worn antenna, GNSS rate of the scenario)
//   base.obs      RINEX 3.04 observations of the base; APPROX POSITION XYZ is its true antenna position
//   truth.csv     gps_week,gps_tow_s,x,y,z,qx,qy,qz,qw: rover antenna (ECEF, m) and R_EI at every rover epoch
//   city.geojson  buildings (footprint, height), trees, route, base and origin (WGS84 lon/lat)
//   vio.csv       the device's VIO poses T_OI (device clock, odometry frame) with covariances and consecutive-pose
//                 cross-covariances (DESIGN.md contract; see canyon/sim/vio.hpp)
//   timesync.csv  t_ns,gps_week,gps_tow_s: device clock at each GPST second from the built-in GPS
//   scenario.yaml the effective scenario (every key; `canyon simulate --scenario DIR/scenario.yaml` regenerates the
//                 same files) and a `truth:` section with the true parameters: base position, receiver clocks, the
//                 city realised, lever arm t_IA, odometry frame T_EO, device clock, final VIO error
// The same scenario and seed give the same files, byte for byte.

#include <cstdint>
#include <string>
#include <vector>

#include "canyon/core/result.hpp"
#include "canyon/sim/scenario.hpp"
#include "canyon/sim/vio.hpp"

namespace canyon::commands {

struct SimulateSummary {
  int rover_epochs = 0;
  int base_epochs = 0;
  int rover_signal_epochs = 0;  ///< signals in the rover file, summed over epochs
  double nlos_fraction = 0.0;   ///< of rover signals received only by reflection
  /// Rover epochs with >= 5 satellites tracking phase in line of sight (the line-of-sight ceiling of a correct fix).
  int line_of_sight_epochs = 0;
  int rover_losses = 0;  ///< rover lock losses (followed by a reacquisition with LLI, if the signal returns)
  int rover_slips = 0;   ///< rover cycle slips while locked (LLI set)
  int buildings = 0;
  double route_length_m = 0.0;
  double wall_s = 0.0;
};

/// Generates `scenario` and writes its files into `out_dir` (created if needed). Error naming the file (and line)
/// on invalid input or when a file cannot be written.
Result<SimulateSummary> run_simulate(const sim::Scenario& scenario, const std::string& out_dir);

/// A 6-DoF ground truth: canyon's truth.csv with the attitude columns (gps_week,gps_tow_s,x,y,z,qx,qy,qz,qw, R_EI
/// with I x forward, y left, z up), or a Spirent SimGEN PVA CSV (GpsCycle, GpsWeek, GpsToW [s], Pos ECEF X/Y/Z [m],
/// Roll/Pitch/Yaw [deg] of the body x forward, y right, z down against local north-east-down, turned into canyon's
/// x forward, y left, z up). Error naming the file and line.
Result<std::vector<sim::SixDofSample>> read_six_dof_truth(const std::string& path);

struct VioFromTruthSummary {
  int poses = 0;
  int timesync_pairs = 0;
  double duration_s = 0.0;
  double final_position_error_m = 0.0;  ///< of the VIO at its last pose
  double wall_s = 0.0;
};

/// `canyon simulate --vio-from-truth TRUTH`: the VIO (vio.csv) and time sync (timesync.csv) of a device carried along
/// the truth, with the drift, covariances and clock of `vio` (a scenario's vio section), and vio_truth.yaml (T_EO,
/// t_IA, device clock, final VIO error) into `out_dir`.
Result<VioFromTruthSummary> run_vio_from_truth(const std::string& truth_path, const sim::VioOptions& vio,
                                               std::uint64_t seed, const std::string& out_dir);

}  // namespace canyon::commands
