#pragma once
// Single-point positioning (SPP) from pseudoranges: the paper's "GNSS-PR" trajectory and RTK's starting point.
//
// Model, per satellite s of constellation k, on the first usable frequency of s:
//   P_s = |p_E_sat,s(t_tx) - p_E_u| (+ Sagnac) + c (dt_k - dt_sat,s + tgd_s) + I_s + T_s + e_s
// Unknowns x = [p_E_u (3); c dt_k for each constellation present] (m). QZSS shares the GPS clock unless
// SppOptions::qzss_own_clock. Weighted least squares, Gauss-Newton from the previous solution (or the Earth's
// centre), iterated until the correction is below 1e-4 m. Weights 1 / sigma_s^2 with
//   sigma_s^2 = sigma_code^2 (1 + 1 / sin^2 el) + sigma_eph^2 + (0.5 I_s)^2 + (0.3 / (sin el + 0.1))^2
// (code noise growing at low elevation; half the Klobuchar delay and a Saastamoinen residual as model errors).
//
// Integrity (RAIM-FDE): after the solution, the normalised residual sum v' W v is tested against the chi-square
// quantile (p = 0.999, n - m degrees of freedom). If it fails and at least one redundant measurement remains,
// each satellite is excluded in turn and the exclusion that passes with the smallest residual sum is kept.
// Velocity: from Doppler where present, least squares on [v_E_u; c ddt] with the satellites of the position fix.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/gnss/satellite_states.hpp"

namespace canyon::gnss {

struct SppOptions : core::ConstellationFlags {              // use_gps ... use_qzss: constellations used
  double elevation_mask_rad = 15.0 * 0.017453292519943295;  ///< satellites below are not used
  bool qzss_own_clock = false;       ///< false: QZSS shares the GPS receiver clock (same system time)
  bool ionosphere_klobuchar = true;  ///< false: no ionosphere model
  bool troposphere_saastamoinen = true;
  double code_sigma_m = 0.3;  ///< zenith pseudorange noise, metres
  int max_iterations = 10;
  double convergence_m = 1e-4;
  bool raim_fde = true;                     ///< fault detection and exclusion of one satellite
  double max_gdop = 30.0;                   ///< solutions with a larger GDOP are rejected
  std::vector<core::SatelliteId> excluded;  ///< satellites never used

  /// Empty if valid, else the violated rule, e.g. "elevation_mask_rad must be in [0, pi/2)".
  [[nodiscard]] std::string validate() const;
};

struct Dop {
  double gdop = 0.0, pdop = 0.0, hdop = 0.0, vdop = 0.0;
};

struct SppSolution {
  core::GpsTime time;           ///< receiver time tag corrected by the GPS (or first) receiver clock
  core::GpsTime receiver_time;  ///< time tag of the observation epoch
  Eigen::Vector3d p_E_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d P_E_m2 = Eigen::Matrix3d::Zero();                  ///< position covariance (ECEF)
  std::optional<Eigen::Vector3d> v_E_mps;                            ///< from Doppler, when enough satellites have it
  std::vector<std::pair<core::Constellation, double>> clock_bias_m;  ///< c dt per clock
  Dop dop;
  int num_satellites = 0;  ///< used in the fix
  std::vector<core::SatelliteId> used;
  std::vector<core::SatelliteId> excluded_by_raim;
  int iterations = 0;
  double residual_rms_m = 0.0;
};

/// Solves one epoch. `initial_p_E_m`: a prior position (e.g. the last solution) to start from; the Earth's centre
/// if none. `states`: the epoch's satellite states to take and leave for later users of the same epoch (its receive
/// time must be epoch.time); computed here if null. Error (no file) with a reason on failure; the caller goes on
/// with the next epoch.
Result<SppSolution> solve_spp(const core::ObsEpoch& epoch, const EphemerisStore& ephemerides, const SppOptions& options,
                              const std::optional<Eigen::Vector3d>& initial_p_E_m = {},
                              EpochSatelliteStates* states = nullptr);

/// The signal of a satellite the single point uses: its first-frequency signal with a plausible pseudorange, the
/// best by core::code_priority (the table the RTK filter's observables use too); nullptr if none.
[[nodiscard]] const core::SignalObs* spp_signal(const core::SatelliteObs& sat_obs);

}  // namespace canyon::gnss
