#pragma once
// A simulation scenario: every parameter of `canyon simulate`, with its unit and default. The shipped scenario files
// (config/scenarios/*.yaml) set these keys; config/scenario_config.hpp reads and writes them (YAML key = field name
// unless noted). Defaults describe the paper's set-up: a pedestrian with a head-worn antenna walking city streets
// for 10 minutes, GNSS at 5 Hz, GPS + GLONASS + Galileo dual frequency, a base station 20 km away under open sky.
//
// Frames: the city is modelled in the local ENU frame N at `origin` (ground level = the origin's ellipsoidal
// height, flat); the street grid frame G has its x axis along the avenues (azimuth `grid_azimuth_deg`) and its y
// axis 90 deg to the left. Times are GPST.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/geodesy.hpp"
#include "canyon/core/satellite.hpp"
#include "canyon/core/time.hpp"

namespace canyon::sim {

/// Streets and buildings (2.5-D: polygon footprints with flat roofs) generated around the route.
struct CityOptions {
  bool buildings = true;          ///< false: an open area (the street grid only guides the walk)
  double grid_azimuth_deg = 0.0;  ///< azimuth of the avenues (grid x axis), clockwise from north (deg)
  double street_width_m = 20.0;   ///< facade to facade (m)
  double block_length_m = 100.0;  ///< block size along the avenues (m)
  double block_width_m = 70.0;    ///< block size across the avenues (m)
  double lot_width_min_m = 15.0;  ///< narrowest building frontage (m)
  double lot_width_max_m = 40.0;  ///< widest building frontage (m)
  double height_mean_m = 55.0;    ///< mean building height before clipping to [min, max] (m)
  double height_sigma_m = 15.0;   ///< standard deviation of building heights (m)
  double height_min_m = 10.0;     ///< lowest building (m)
  double height_max_m = 81.0;     ///< tallest building (m)
  double gap_probability = 0.05;  ///< probability that a lot is empty (plaza, parking, side alley)
  double margin_m = 300.0;        ///< buildings extend at least this far beyond the route (m)
  /// Side of an open square centred on the origin, where a generated walk starts (a user starts a session in the
  /// open): no building overlaps it (m); 0: none.
  double start_square_m = 0.0;
  std::vector<int> blocks;  ///< optional [nx, ny]: city of nx by ny blocks centred on the origin
};

/// Street trees (light-blocked scenario): crowns as vertical cylinders along the kerbs.
struct TreeOptions {
  double spacing_m = 0.0;             ///< distance between trees along a kerb; 0: no trees (m)
  double presence_probability = 0.8;  ///< probability that a tree stands at each spot
  double crown_radius_m = 3.0;        ///< (m)
  double crown_bottom_m = 3.0;        ///< height of the lowest leaves (m)
  double crown_top_m = 12.0;          ///< tree height (m)
  double attenuation_db_per_m = 1.2;  ///< signal attenuation per metre of crown crossed (dB/m)
  double facade_offset_m = 5.0;       ///< distance of the tree line from the facades (m)
};

/// The pedestrian and the head-worn antenna.
struct RouteOptions {
  double speed_mps = 1.4;          ///< walking speed (m/s)
  double antenna_height_m = 1.7;   ///< antenna above the ground (m)
  double sidewalk_offset_m = 3.0;  ///< walking line distance from the facades (m)
  double turn_probability = 0.4;   ///< probability of turning at an intersection (generated walk)
  double turn_radius_m = 1.5;      ///< radius of the path at corners (m)
  double head_bob_m = 0.02;        ///< vertical head motion amplitude (m), at the step frequency
  double step_frequency_hz = 1.8;  ///< (Hz)
  /// Optional explicit route: waypoints (east, north) in metres from the origin, walked back and forth.
  std::vector<Eigen::Vector2d> waypoints_N_m;
};

/// The base station: static, open sky, `distance_m` from the city origin.
struct BaseOptions {
  double distance_m = 20000.0;  ///< horizontal distance from the origin (m)
  double azimuth_deg = 70.0;    ///< direction from the origin (deg)
  double height_m = 60.0;       ///< antenna ellipsoidal height (m)
  double rate_hz = 1.0;         ///< observation rate (Hz)
};

/// Receiver tracking and measurement noise (rover and base each have one).
struct ReceiverOptions {
  double cn0_zenith_dbhz = 47.0;              ///< line-of-sight C/N0 at 90 deg elevation, first band (dB-Hz)
  double cn0_horizon_dbhz = 32.0;             ///< line-of-sight C/N0 at 0 deg elevation, first band (dB-Hz)
  double band2_cn0_offset_db = -3.0;          ///< C/N0 of the second band relative to the first (dB)
  double cn0_noise_db = 0.5;                  ///< noise of the reported C/N0 (dB)
  double cn0_reference_dbhz = 45.0;           ///< C/N0 at which the sigmas below hold (dB-Hz)
  double code_sigma_m = 0.3;                  ///< pseudorange noise at the reference C/N0 (m), x 10^((ref - C/N0) / 20)
  double phase_sigma_m = 0.002;               ///< carrier-phase noise at the reference C/N0 (m), same scaling
  double doppler_sigma_hz = 0.05;             ///< Doppler noise at the reference C/N0 (Hz), same scaling
  double track_threshold_dbhz = 24.0;         ///< a signal weaker than this loses lock (dB-Hz)
  double acquire_threshold_dbhz = 28.0;       ///< a lost signal must be at least this strong to be reacquired (dB-Hz)
  double reacquisition_s = 1.0;               ///< time a lost signal must be receivable before it is output again (s)
  double slip_rate_hz = 0.02;                 ///< rate of lock losses (cycle slips) at the tracking threshold (1/s),
                                              ///< falling tenfold per 10 dB above it
  double path_change_slip_probability = 0.5;  ///< lock lost when the received path changes (LOS <-> reflection)
  double correlator_spacing_chips = 0.2;      ///< early-late spacing of the code loop (chips)
  double clock_offset_max_s = 2e-4;           ///< initial clock offset drawn uniformly in +-this (s)
  double clock_drift_max_sps = 5e-8;          ///< initial clock drift drawn uniformly in +-this (s/s)
  double clock_drift_noise = 2e-11;           ///< clock drift random walk (s/s per sqrt(s))
  double elevation_cutoff_deg = 0.0;          ///< no signal is tracked below this elevation (deg)
};

/// The base's geodetic receiver and antenna: stronger signals, lower noise, narrow correlator, 5 deg cutoff.
[[nodiscard]] ReceiverOptions geodetic_receiver();

/// Reflections at the rover (multipath and NLOS). The base is an open-sky geodetic installation without multipath.
struct ReflectionOptions {
  bool multipath = true;  ///< line-of-sight signals also get reflections off walls and the ground
  /// A signal whose direct path a building blocks is received by a wall reflection (NLOS) when one exists; false: not
  /// at all, as by an ideal antenna and receiver that reject every reflection (the bound of perfect NLOS exclusion).
  bool nlos = true;
  double wall_loss_db = 10.0;       ///< power of a wall reflection below the direct signal (dB)
  double nlos_extra_loss_db = 2.0;  ///< extra loss of a reflection received without the direct signal (dB)
  /// Spread (1 sigma) of an NLOS signal's loss about wall_loss_db + nlos_extra_loss_db (dB), drawn once per satellite
  /// and wall (surfaces differ: glass, concrete, angles), at least 0 dB: with a spread of several dB the C/N0 of NLOS
  /// signals overlaps that of line-of-sight ones, as in real streets, and no C/N0 threshold separates them. 0: every
  /// NLOS signal is exactly that loss down (a C/N0 screen is then perfect, as nowhere real).
  double nlos_loss_spread_db = 0.0;
  double ground_loss_db = 35.0;       ///< power of the ground reflection below the direct signal (dB)
  double max_wall_distance_m = 40.0;  ///< walls further from the antenna are not considered (m)
};

/// Differential ionosphere and troposphere between rover and base.
struct AtmosphereOptions {
  double vtec_tecu = 15.0;                             ///< mean vertical TEC (TECU)
  Eigen::Vector2d gradient_tecu_per_100km{0.4, -0.3};  ///< VTEC gradient (east, north) (TECU per 100 km)
  double wave_amplitude_tecu = 0.15;  ///< travelling ionospheric disturbances: amplitude of each (TECU)
  int wave_count = 3;                 ///< number of travelling waves
  double wave_length_km = 300.0;      ///< their mean horizontal wavelength (km)
  double wave_period_s = 2400.0;      ///< their mean period (s)
  double shell_height_km = 350.0;     ///< thin-shell height (km)
  double zwd_residual_m = 0.03;       ///< zenith wet delay not in the Saastamoinen model, rover (m)
  double zwd_difference_m = 0.005;    ///< base minus rover residual zenith wet delay (m)
  double zwd_variation_m = 0.003;     ///< slow variation of each receiver's residual (m)
};

/// Broadcast orbit and clock errors (the truth differs from the navigation file by these).
struct OrbitErrorOptions {
  double radial_m = 0.3;  ///< (m, 1 sigma)
  double along_m = 1.0;   ///< (m, 1 sigma)
  double cross_m = 0.6;   ///< (m, 1 sigma)
  double clock_m = 0.5;   ///< satellite clock error times c (m, 1 sigma)
};

/// Satellites and signals.
struct ConstellationOptions : core::ConstellationFlags {
  /// RINEX navigation file with the orbits to use (relative to the scenario file); empty: built-in constellation.
  std::string nav_file;
  int gps_satellites = 31;      ///< 24..32: the 24 nominal slots plus spares (built-in)
  int glonass_satellites = 24;  ///< 1..24 (built-in)
  int galileo_satellites = 24;  ///< 1..24 (built-in)
  int beidou_satellites = 24;   ///< 1..24 MEO (built-in)
  /// Tracked signals per system (RINEX 3 band+attribute), first the L1-band one.
  std::vector<core::SignalCode> gps_signals = {{'1', 'C'}, {'2', 'L'}};
  std::vector<core::SignalCode> glonass_signals = {{'1', 'C'}, {'2', 'C'}};
  std::vector<core::SignalCode> galileo_signals = {{'1', 'C'}, {'7', 'Q'}};
  std::vector<core::SignalCode> beidou_signals = {{'2', 'I'}, {'7', 'I'}};

  ConstellationOptions() { use_beidou = use_qzss = false; }
  [[nodiscard]] const std::vector<core::SignalCode>& signals(core::Constellation system) const;
};

/// The head-worn device's visual-inertial odometry and clock (see vio.hpp).
struct VioOptions {
  bool enabled = true;                      ///< write vio.csv and timesync.csv
  Eigen::Vector3d t_IA_m{0.0, 0.0, 0.12};   ///< antenna position in the IMU frame (lever arm) (m)
  double odometry_yaw_deg = 30.0;           ///< yaw of the odometry frame O from east, counter-clockwise (deg)
  double rate_hz = 10.0;                    ///< VIO pose rate, device clock (Hz)
  double position_drift_fraction = 0.0005;  ///< 1-sigma 3-D translation random walk after 1 km, per distance
  double yaw_drift_deg_per_km = 0.5;        ///< 1-sigma heading random walk after 1 km walked (deg)
  double tilt_drift_deg_per_km = 0.02;      ///< 1-sigma roll and pitch random walk after 1 km walked (deg)
  double device_clock_offset_s = 1234.5;    ///< device clock reading at the scenario start (s)
  double device_clock_drift_ppm = 20.0;     ///< device clock rate error (1e-6)
  double timesync_jitter_s = 0.0005;        ///< noise of the built-in GPS time-sync pairs, 1 sigma (s)
  /// Scale error of the VIO's translation: every increment is (1 + scale_error) times the true one (real VIO:
  /// 0.2-1 %). Not in the reported covariance, as a real VIO does not know its scale error.
  double scale_error = 0.0;
  /// The reported covariance is the drift model's divided by this factor squared: >1 is over-confident (real VIO
  /// reports sigmas 2-3 times too small); 1: the covariance describes the drift exactly.
  double covariance_optimism = 1.0;
};

struct Scenario {
  std::string name = "custom";
  std::uint64_t seed = 1;  ///< random seed (the command line's --seed overrides it)
  core::GpsTime start = core::calendar_to_gps({2023, 6, 14, 16, 0, 0.0});  ///< first epoch (GPST)
  double duration_s = 600.0;                                               ///< (s)
  double rover_rate_hz = 5.0;                                              ///< rover observation rate (Hz)
  core::Geodetic origin{47.6062 * 0.017453292519943295, -122.3321 * 0.017453292519943295, 20.0};  ///< city origin
  ConstellationOptions constellation;
  CityOptions city;
  TreeOptions trees;
  RouteOptions route;
  BaseOptions base;
  ReceiverOptions rover_receiver;
  ReceiverOptions base_receiver = geodetic_receiver();
  ReflectionOptions reflections;
  AtmosphereOptions atmosphere;
  OrbitErrorOptions orbit_errors;
  VioOptions vio;
  std::string source_file;  ///< file the scenario came from (for error messages), may be empty

  /// Empty if every parameter is in range, else the first broken rule naming the key ("city.street_width_m must be
  /// > 0").
  [[nodiscard]] std::string validate() const;
  /// Number of rover epochs.
  [[nodiscard]] int rover_epochs() const;
};

}  // namespace canyon::sim
