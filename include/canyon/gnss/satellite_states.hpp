#pragma once
// Satellite states of one receiver epoch, computed once and shared.
//
// The single-point solution and the RTK zero differences of a rover epoch ask for the same broadcast states (same
// satellite, receive time and pseudorange); each costs three ephemeris selections and an orbit evaluation. An
// EpochSatelliteStates computes a state on the first request and answers later ones from its table. It lives for
// one receiver epoch (the caller's local), so no state outlives the epoch and the estimation core stays free of
// caches with a lifetime of their own.

#include <optional>
#include <vector>

#include "canyon/core/satellite.hpp"
#include "canyon/core/time.hpp"
#include "canyon/gnss/ephemeris.hpp"

namespace canyon::gnss {

class EpochSatelliteStates {
 public:
  /// States of signals received at GPST `t_rx` (the epoch's time tag), from `ephemerides` (which must outlive this).
  EpochSatelliteStates(const EphemerisStore& ephemerides, core::GpsTime t_rx);

  /// EphemerisStore::state_at_reception(sat, t_rx, pseudorange_m, nullptr, with_velocity): computed on the first
  /// request for (sat, pseudorange_m) -- or when velocity is asked for and the stored state has none -- and then
  /// returned unchanged (a state with velocity also answers a request without: position and clock are the same).
  [[nodiscard]] std::optional<SatelliteState> at_reception(core::SatelliteId sat, double pseudorange_m,
                                                           bool with_velocity);

  [[nodiscard]] core::GpsTime receive_time() const { return t_rx_; }
  [[nodiscard]] const EphemerisStore& ephemerides() const { return *ephemerides_; }

 private:
  struct Entry {
    core::SatelliteId sat;
    double pseudorange_m = 0.0;
    bool with_velocity = false;
    std::optional<SatelliteState> state;  // nullopt: no usable ephemeris
  };
  const EphemerisStore* ephemerides_;
  core::GpsTime t_rx_;
  std::vector<Entry> entries_;  // a few dozen at most: a linear search beats any index
};

}  // namespace canyon::gnss
