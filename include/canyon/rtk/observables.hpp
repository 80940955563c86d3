#pragma once
// One receiver's observations reduced to what carrier-phase differencing needs: per satellite at most one signal
// per frequency rank (L1/E1/B1I/G1 = 0, L2/E5b/B2I/G2 = 1, L5/E5a/B3I = 2; core::frequency_rank), chosen by tracking
// code priority, with its wavelength.
//
// Phase alignment: RINEX 3.01+ writers align the carrier phases of all tracking codes on one frequency to that
// frequency's reference code and record the shift they applied in "SYS / PHASE SHIFT" (e.g. a Trimble base writes
// G L2X -0.25000, a Septentrio rover states that no further shift is needed). Phases of different codes on one
// frequency are therefore comparable between receivers, and no correction is applied here. QZSS L1Z (L1-SAIF) is a
// different signal and is only used when no other L1 signal exists.

#include <cstdint>
#include <vector>

#include "canyon/core/observation.hpp"
#include "canyon/core/satellite.hpp"
#include "canyon/core/time.hpp"

namespace canyon::gnss {
class EphemerisStore;
}

namespace canyon::rtk {

inline constexpr int kMaxFrequencies = 3;

/// One signal of one satellite at one receiver, on one frequency rank. Missing observables are NaN.
struct SignalObservable {
  core::SatelliteId sat;
  int frequency = 0;  ///< rank within the system (core::frequency_rank)
  core::SignalCode code;
  double wavelength_m = 0.0;
  double pseudorange_m = core::kNoValue;
  double carrier_phase_cyc = core::kNoValue;
  double doppler_hz = core::kNoValue;
  double snr_dbhz = core::kNoValue;
  std::uint8_t lli = 0;  ///< core::kLli* bits
};

/// A receiver's epoch as observables, sorted by (satellite, frequency), at most one per pair.
struct ReceiverObservables {
  core::GpsTime time;  ///< receiver time tag (GPST)
  std::vector<SignalObservable> signals;

  /// The observable of `sat` on `frequency`, or nullptr.
  [[nodiscard]] const SignalObservable* find(core::SatelliteId sat, int frequency) const;
};

struct ObservableOptions : core::ConstellationFlags {  // use_gps ... use_qzss: constellations used
  int num_frequencies = 2;                             ///< 1..3: how many frequency ranks to keep
  std::vector<core::SatelliteId> excluded;             ///< never used
};

/// Selects the observables of an epoch. GLONASS FDMA wavelengths use the channel from the ephemerides (a GLONASS
/// satellite whose channel is unknown is skipped). Signals without a usable wavelength are skipped.
[[nodiscard]] ReceiverObservables select_observables(const core::ObsEpoch& epoch, const gnss::EphemerisStore& eph,
                                                     const ObservableOptions& options);

}  // namespace canyon::rtk
