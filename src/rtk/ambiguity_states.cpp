// Bookkeeping of the keyed states (see ambiguity_states.hpp).

#include "canyon/rtk/ambiguity_states.hpp"

#include <algorithm>

namespace canyon::rtk {

std::vector<StateKey> AmbiguityStates::stale(const core::GpsTime& t, double max_outage_s,
                                             double iono_max_outage_s) const {
  std::vector<StateKey> keys;
  for (const auto& [key, info] : info_) {
    if (t - info.last_seen > (key.ionosphere() ? iono_max_outage_s : max_outage_s)) keys.push_back(key);
  }
  return keys;
}

std::vector<FilterState::NewState> AmbiguityStates::admit(std::vector<SingleDiff>& sds, const FilterState& state,
                                                          const core::GpsTime& t, const SlipScan& slips,
                                                          const RtkOptions& options, bool iono_estimated) {
  // New states are collected and appended at once (in the order found, as one by one).
  std::vector<FilterState::NewState> new_states;
  const auto has_state = [&](const StateKey& key) {
    return state.has(key) || std::any_of(new_states.begin(), new_states.end(),
                                         [&](const FilterState::NewState& s) { return s.key == key; });
  };
  for (SingleDiff& sd : sds) {
    if (!core::has_value(sd.phase_m)) continue;
    const StateKey key{sd.sat, sd.frequency};
    if (!has_state(key)) {
      if (!core::has_value(sd.code_m)) continue;
      const double sigma = options.initial_ambiguity_sigma_cyc;
      new_states.push_back(FilterState::NewState{key, (sd.phase_m - sd.code_m) / sd.wavelength_m, sigma * sigma});
      info_[key] = Info{};
    }
    Info& a = info_[key];
    a.last_seen = t;
    ++a.lock_epochs;
    const bool half_cycle = (sd.lli & core::kLliHalfCycle) != 0 || slips.half_cycle(sd.sat, sd.frequency);
    const bool glonass_ok = sd.sat.system != core::Constellation::Glonass || options.glonass_ar;
    sd.fixable = !half_cycle && glonass_ok && a.lock_epochs > options.min_lock_epochs &&
                 sd.elevation_rad >= options.ar_elevation_mask_rad;
  }
  if (options.code_multipath_sigma_m > 0.0) {
    const double variance = options.code_multipath_sigma_m * options.code_multipath_sigma_m;
    for (const SingleDiff& sd : sds) {
      if (!core::has_value(sd.code_m)) continue;
      const StateKey key = StateKey::code_bias(sd.sat, sd.frequency);
      if (!has_state(key)) new_states.push_back(FilterState::NewState{key, 0.0, variance});
      info_[key].last_seen = t;
    }
  }
  if (iono_estimated) {
    for (const SingleDiff& sd : sds) info_[StateKey{sd.sat, StateKey::kIonosphere}].last_seen = t;
  }
  return new_states;
}

void assign_state_indices(std::vector<SingleDiff>& sds, const FilterState& state) {
  for (SingleDiff& sd : sds) {
    sd.ambiguity = core::has_value(sd.phase_m) ? state.index({sd.sat, sd.frequency}) : -1;
    sd.iono = state.index({sd.sat, StateKey::kIonosphere});
    sd.code_bias = state.index(StateKey::code_bias(sd.sat, sd.frequency));
  }
}

}  // namespace canyon::rtk
