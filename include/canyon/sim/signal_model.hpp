#pragma once
// How a receiver sees one signal: C/N0, measurement noise, and the errors reflections cause in its code and carrier
// tracking loops.
//
// C/N0 of the direct signal (antenna gain pattern):
//   C/N0(el) = cn0_zenith - (cn0_zenith - cn0_horizon) (1 - sin el)^2   (+ band2_cn0_offset_db on the second band)
// Noise (thermal, scales with 1 / sqrt(C/N0)): sigma = sigma_ref 10^((cn0_reference - C/N0) / 20) for code, phase
// (in metres) and Doppler.
//
// Multipath (line-of-sight signal plus reflections i with relative amplitude a_i, excess delay d_i and phase
// phi_i = 2 pi d_i / lambda + pi): the composite carrier is 1 + sum a_i exp(j phi_i); the phase loop tracks its
// argument (phase error, metres = lambda / (2 pi) arg), the C/N0 changes by 20 log10 |composite|, and the coherent
// early-late code loop with spacing D chips is off by
//   sum a_i e(d_i) cos(phi_i) / (1 + sum a_i cos(phi_i))
// with the delay envelope e(d) = d up to D/2 chips, D/2 chips up to 1 - D/2 chips, falling linearly to 0 at
// 1 + D/2 chips (the classic narrow-correlator envelope). A signal received only by reflection (NLOS) is delayed by
// the whole excess path on the code and on the carrier, plus half a cycle for the reflection.

#include <vector>

#include "canyon/core/satellite.hpp"
#include "canyon/sim/scenario.hpp"

namespace canyon::sim {

/// Line-of-sight C/N0 (dB-Hz) at elevation `el` on the signal of rank `band_index` (0: first, 1: second...).
[[nodiscard]] double line_of_sight_cn0_dbhz(const ReceiverOptions& rx, double elevation_rad, int band_index);

/// Noise sigma at C/N0 `cn0` of a quantity whose sigma is `sigma_ref` at the reference C/N0.
[[nodiscard]] double scaled_sigma(const ReceiverOptions& rx, double sigma_ref, double cn0_dbhz);

/// Code chip length (m) of a signal (GPS C/A 293 m, P(Y) 29.3 m, GLONASS C/A 587 m...).
[[nodiscard]] double chip_length_m(core::Constellation system, core::SignalCode code);

/// Code-loop delay envelope e(d) (m) for excess delay `delay_m`.
[[nodiscard]] double dll_envelope_m(double delay_m, double chip_m, double spacing_chips);

struct Reflection {
  double amplitude = 0.0;  ///< relative to the direct signal
  double excess_m = 0.0;   ///< extra path length (m)
};

struct MultipathError {
  double code_m = 0.0;
  double phase_m = 0.0;
  double cn0_change_db = 0.0;
};

/// Errors of a line-of-sight signal with reflections.
[[nodiscard]] MultipathError line_of_sight_multipath(const std::vector<Reflection>& reflections, double wavelength_m,
                                                     double chip_m, double spacing_chips);

}  // namespace canyon::sim
