#pragma once
// The scenario generator: a pedestrian rover in a generated city and a static base 20 km away, their GNSS
// observations, and the ground truth.
//
// Observation model, per receiver r, satellite s and signal with wavelength lambda (all in metres unless noted):
//   t_rx = t_tag - dt_r               true GPST of reception of an epoch tagged t_tag by a clock that is dt_r ahead
//   t_tx : c (t_rx - t_tx) = rho,     rho = | R_z(-omega_e (t_rx - t_tx)) p_s(t_tx) - p_r(t_rx) |  (light time with
//                                     Earth rotation during the flight)
//   P = rho + c (dt_r - dt_s) + T + I + c gd + m_P + e_P
//   L = (rho + c (dt_r - dt_s) + T - I + m_L) / lambda + N + e_L / lambda          (cycles)
//   D = -(d(rho + m_L)/dt + c (ddt_r - ddt_s)) / lambda + e_D                      (Hz)
// p_s, dt_s: the broadcast state of the navigation file as written (read back through io and gnss::EphemerisStore,
// clock with the relativistic term), plus the scenario's orbit and clock errors, which the file does not contain;
// gd: the broadcast group delay of the signal (EphemerisStore::group_delay_s); T, I: atmosphere.hpp; m_P, m_L:
// multipath or the NLOS excess path (signal_model.hpp), from the city geometry (city.hpp); N: the channel's integer
// ambiguity (tracking.hpp); e: white noise with the C/N0-dependent sigmas. The rover antenna follows the trajectory
// (route.hpp); the base is static under open sky (no city, no multipath).

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "canyon/core/ephemeris.hpp"
#include "canyon/core/result.hpp"
#include "canyon/io/rinex_obs.hpp"
#include "canyon/sim/city.hpp"
#include "canyon/sim/route.hpp"
#include "canyon/sim/scenario.hpp"
#include "canyon/sim/vio.hpp"

namespace canyon::sim {

/// Everything about one output signal at one epoch (kept when SimulationOptions::keep_signal_truth).
struct SignalTruth {
  core::SatelliteId sat;
  core::SignalCode code;
  double wavelength_m = 0.0;
  bool direct = true;              ///< line of sight; false: received only by reflection (NLOS)
  double nlos_excess_m = 0.0;      ///< NLOS: extra path length
  double code_multipath_m = 0.0;   ///< line of sight: code error from reflections
  double phase_multipath_m = 0.0;  ///< line of sight: carrier error from reflections
  double range_m = 0.0;            ///< rho, geometric with Earth rotation
  double satellite_clock_m = 0.0;  ///< c dt_s (true)
  double receiver_clock_m = 0.0;   ///< c dt_r
  double troposphere_m = 0.0;
  double ionosphere_m = 0.0;  ///< on this signal's frequency
  double group_delay_m = 0.0;
  std::int64_t ambiguity_cyc = 0;
  double code_noise_m = 0.0;   ///< e_P as drawn
  double phase_noise_m = 0.0;  ///< e_L as drawn (m)
  double code_sigma_m = 0.0;
  double phase_sigma_m = 0.0;
  double cn0_dbhz = 0.0;  ///< true C/N0 (the file's S has reporting noise added)
  bool loss_of_lock = false;
  double elevation_rad = 0.0;
  Eigen::Vector3d u_N = Eigen::Vector3d::UnitZ();  ///< antenna -> satellite, city ENU
};

struct EpochTruth {
  core::GpsTime tag;                                ///< receiver time tag
  double t_s = 0.0;                                 ///< true reception time, seconds since the start
  Eigen::Vector3d p_E_m = Eigen::Vector3d::Zero();  ///< antenna, ECEF
  Eigen::Vector3d p_N_m = Eigen::Vector3d::Zero();  ///< antenna, city ENU
  std::vector<SignalTruth> signals;
};

/// Satellites tracking phase in line of sight that an epoch needs to count under the line-of-sight ceiling.
inline constexpr int kLineOfSightCeilingSatellites = 5;

struct ReceiverRun {
  io::RinexObsHeader header;
  std::vector<core::ObsEpoch> epochs;
  std::vector<EpochTruth> truth;  ///< one per epoch when signal truth is kept
  double clock_offset_s = 0.0;    ///< initial receiver clock offset
  double clock_drift_sps = 0.0;   ///< initial receiver clock drift
  int signal_epochs = 0;          ///< signals output, summed over epochs
  int nlos_signal_epochs = 0;     ///< of which received only by reflection
  /// Epochs with at least kLineOfSightCeilingSatellites satellites tracking phase on the direct path: the ceiling of
  /// what any RTK can fix correctly (the rest has too few clean double differences).
  int line_of_sight_epochs = 0;
  int losses = 0;  ///< lock losses
  int slips = 0;   ///< slips while locked
};

/// Rover antenna truth at a rover epoch tag (GPST), with the body attitude R_EI (I: x forward, y left, z up).
struct TruthSample {
  core::GpsTime time;
  Eigen::Vector3d p_E_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_EI = Eigen::Quaterniond::Identity();
};

struct Simulation {
  Scenario scenario;
  core::NavigationData nav;  ///< as read back from the written navigation file
  City city;
  Trajectory trajectory;
  Eigen::Vector3d base_p_E_m = Eigen::Vector3d::Zero();
  ReceiverRun rover;
  ReceiverRun base;
  std::vector<TruthSample> truth;
  VioRun vio;  ///< empty when scenario.vio.enabled is false
};

struct SimulationOptions {
  bool keep_signal_truth = false;  ///< fill ReceiverRun::truth (memory: tests and small scenarios)
};

/// Generates the scenario. The navigation records are written to `nav_path` (RINEX 3) and read back before any
/// observation is computed, so that the observations use exactly what any reader of that file gets. Error if the
/// scenario is invalid, its navigation file cannot be read, or the route leaves the city or enters a building.
Result<Simulation> simulate(const Scenario& scenario, const std::string& nav_path,
                            const SimulationOptions& options = {});

/// Writes rover.obs, base.obs (RINEX 3.04), truth.csv, city.geojson and, with VIO enabled, vio.csv and timesync.csv
/// into `dir` (created if needed). RINEX headers carry a fixed program date derived from the scenario start, so the
/// files depend on the scenario only.
Status write_simulation(const Simulation& simulation, const std::string& dir);

/// Writes vio.csv and timesync.csv of a VIO run into `dir` (which must exist).
Status write_vio_files(const VioRun& vio, const std::string& dir);

}  // namespace canyon::sim
