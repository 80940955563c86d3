// Satellite states of one receiver epoch (see satellite_states.hpp).

#include "canyon/gnss/satellite_states.hpp"

#include <algorithm>

namespace canyon::gnss {

EpochSatelliteStates::EpochSatelliteStates(const EphemerisStore& ephemerides, core::GpsTime t_rx)
    : ephemerides_(&ephemerides), t_rx_(t_rx) {}

std::optional<SatelliteState> EpochSatelliteStates::at_reception(core::SatelliteId sat, double pseudorange_m,
                                                                 bool with_velocity) {
  const auto it = std::find_if(entries_.begin(), entries_.end(),
                               [&](const Entry& e) { return e.sat == sat && e.pseudorange_m == pseudorange_m; });
  if (it != entries_.end() && (it->with_velocity || !with_velocity)) return it->state;
  Entry entry{sat, pseudorange_m, with_velocity,
              ephemerides_->state_at_reception(sat, t_rx_, pseudorange_m, nullptr, with_velocity)};
  if (it != entries_.end()) {
    *it = entry;
  } else {
    entries_.push_back(entry);
  }
  return entry.state;
}

}  // namespace canyon::gnss
