#pragma once
// Single differences (rover - base) of one epoch, the inputs of the DD measurement update and the ambiguity
// resolution, formed at the filter's prior position.
//
// Per (satellite, frequency rank) tracked by both receivers above the elevation mask, in metres:
//   phase_m = lambda (Phi_rover - Phi_base) - (model_rover - model_base)
//   code_m  = (P_rover - P_base)             - (model_rover - model_base)
// with each receiver's zero-difference model (epoch_geometry.hpp: geometric range with the Sagnac term, minus the
// satellite clock, plus the Saastamoinen troposphere) at its own transmission time. Zero-difference variance per
// receiver, at that receiver's elevation el and C/N0:
//   sigma_phase^2 = a^2 + b^2 / sin^2(el)                      (elevation model, the default, as RTKLIB's)
//   sigma_phase^2 = a^2 + b^2 10^((snr_reference - C/N0) / 10)  (snr_weighting, SIGMA-epsilon: the C/N0 already
//                                                                holds the elevation through the antenna gain, and
//                                                                reflected signals arrive weaker)
//   sigma_code = code_phase_ratio * sigma_phase,
// the SD variance the sum of the two receivers'. test_variance_m2 keeps the elevation model alone, for the post-fit
// tests (dd_update.hpp), so that weighting down a weak signal does not hide it from them.
//
// Time-correlated code multipath (code_multipath_sigma_m > 0): a wall beside the street gives a signal a code error
// that lasts as long as the geometry does, which white code noise would count again at every epoch (the float
// ambiguities it pulls are then biased with a small sigma). Each signal's SD code then has an error state m_sd
// (metres, in the code rows only), a first-order Gauss-Markov process with sigma s and correlation time tau:
//   m' = phi m + w,  phi = exp(-dt / tau),  var(w) = s^2 (1 - phi^2),  m starting at 0 with variance s^2;
// so code informs the position and ambiguities once per correlation time, not once per epoch.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/observation.hpp"
#include "canyon/core/satellite.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/rtk/epoch_geometry.hpp"
#include "canyon/rtk/rtk_options.hpp"

namespace canyon::rtk {

/// One single-differenced (rover - base) observable ready for double differencing.
struct SingleDiff {
  core::SatelliteId sat;
  int frequency = 0;
  int group = 0;  ///< constellation * kMaxFrequencies + frequency: the DD group
  double wavelength_m = 0.0;
  double phase_m = core::kNoValue;  ///< lambda (Phi_r - Phi_b) - (model_r - model_b)
  double code_m = core::kNoValue;   ///< (P_r - P_b) - (model_r - model_b)
  double phase_variance_m2 = 0.0;
  double code_variance_m2 = 0.0;
  double test_variance_m2 = 0.0;  ///< phase variance of the elevation model alone, for the post-fit tests
  Eigen::Vector3d los_E = Eigen::Vector3d::Zero();  ///< rover line of sight (unit, ECEF)
  double elevation_rad = 0.0;
  std::uint8_t lli = 0;     ///< rover | base loss-of-lock bits
  int ambiguity = -1;       ///< state index of N_sd, -1 if none (or its phase is not used this epoch)
  int iono = -1;            ///< state index of the satellite's SD ionosphere, -1 if not estimated
  int code_bias = -1;       ///< state index of the signal's SD code multipath error, -1 if not modelled
  double iono_scale = 1.0;  ///< (f_1 / f)^2: the delay on this frequency per metre of first-frequency delay
  bool fixable = false;     ///< its ambiguity may be fixed this epoch
};

/// Zero-difference carrier-phase variance (m^2) of a signal at `elevation_rad` with C/N0 `snr_dbhz` (NaN: unknown)
/// (the model above).
[[nodiscard]] double zero_diff_phase_variance(const RtkOptions& options, double elevation_rad, double snr_dbhz);

/// Wavelength of a satellite's first frequency (rank 0), the reference of the ionosphere state.
[[nodiscard]] double first_wavelength_m(const gnss::EphemerisStore& eph, core::SatelliteId sat);

/// The epoch's single differences at the rover position `p_E_rover_m` (the filter's prior), ordered by satellite and
/// frequency; the rover's satellite states are added to the geometry's (shared with its single-point solution).
/// `iono_estimated`: fill iono_scale for the ionosphere states.
[[nodiscard]] std::vector<SingleDiff> form_single_differences(EpochGeometry& geometry,
                                                              const Eigen::Vector3d& p_E_rover_m,
                                                              const RtkOptions& options,
                                                              const gnss::EphemerisStore& eph, bool iono_estimated);

}  // namespace canyon::rtk
