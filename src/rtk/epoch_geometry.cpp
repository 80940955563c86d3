// The filter-independent part of an RTK epoch (epoch_geometry.hpp).

#include "canyon/rtk/epoch_geometry.hpp"

#include <algorithm>
#include <cmath>

#include "canyon/core/constants.hpp"
#include "canyon/gnss/atmosphere.hpp"

namespace canyon::rtk {

ZeroDiff zero_difference(gnss::EpochSatelliteStates& states, const core::SatelliteId sat, double pseudorange_m,
                         const ReceiverGeometry& receiver, bool troposphere) {
  ZeroDiff z;
  const auto state = states.at_reception(sat, pseudorange_m, false);
  if (!state) return z;
  const double range_m = gnss::geometric_range_m(state->p_E_m, receiver.p_E_m, &z.los_E);
  z.elevation_rad = core::elevation_rad(receiver.p_E_m, receiver.g, receiver.R_NE, state->p_E_m);
  z.model_m = range_m - core::kSpeedOfLightMps * state->clock_bias_s +
              (troposphere ? gnss::saastamoinen_delay_m(receiver.g, z.elevation_rad) : 0.0);
  z.valid = true;
  return z;
}

double any_pseudorange(const ReceiverObservables& obs, const core::SatelliteId sat) {
  for (int f = 0; f < kMaxFrequencies; ++f) {
    if (const SignalObservable* s = obs.find(sat, f); s != nullptr && core::has_value(s->pseudorange_m)) {
      return s->pseudorange_m;
    }
  }
  return core::kNoValue;
}

ZeroDiff EpochGeometry::base_model(const core::SatelliteId sat) const {
  const auto it = std::lower_bound(base_models.begin(), base_models.end(), sat,
                                   [](const auto& entry, const core::SatelliteId& s) { return entry.first < s; });
  return it != base_models.end() && it->first == sat ? it->second : ZeroDiff{};
}

bool SlipScan::half_cycle(const core::SatelliteId sat, const int frequency) const {
  return std::binary_search(half_cycle_unresolved.begin(), half_cycle_unresolved.end(),
                            CycleSlipDetector::Key{sat, frequency});
}

EpochGeometryBuilder::EpochGeometryBuilder(Options options, const gnss::EphemerisStore& ephemerides,
                                           const Eigen::Vector3d& p_E_base_m)
    : options_(std::move(options)),
      eph_(&ephemerides),
      base_(p_E_base_m),
      rover_slips_(options_.slips),
      base_slips_(options_.slips) {}

SlipScan EpochGeometryBuilder::scan_slips(const EpochGeometry& geometry) {
  SlipScan scan;
  scan.events = rover_slips_.update(geometry.rover_obs);
  if (!last_base_time_ || std::abs(geometry.base_obs.time - *last_base_time_) > 1e-6) {
    const std::vector<SlipEvent> base_events = base_slips_.update(geometry.base_obs);
    scan.events.insert(scan.events.end(), base_events.begin(), base_events.end());
    last_base_time_ = geometry.base_obs.time;
  }
  for (const SignalObservable& s : geometry.rover_obs.signals) {
    if (rover_slips_.half_cycle_unresolved(s.sat, s.frequency) ||
        base_slips_.half_cycle_unresolved(s.sat, s.frequency)) {
      scan.half_cycle_unresolved.emplace_back(s.sat, s.frequency);
    }
  }
  std::sort(scan.half_cycle_unresolved.begin(), scan.half_cycle_unresolved.end());
  scan.half_cycle_unresolved.erase(std::unique(scan.half_cycle_unresolved.begin(), scan.half_cycle_unresolved.end()),
                                   scan.half_cycle_unresolved.end());
  return scan;
}

const EpochGeometryBuilder::BaseSide& EpochGeometryBuilder::base_side(const core::ObsEpoch& base) {
  if (base_cache_ && base_cache_->time == base.time && base_cache_->num_satellites == base.sats.size() &&
      base_cache_->ephemeris_stamp == eph_->selection_stamp()) {
    return *base_cache_;
  }
  BaseSide& side = base_cache_.emplace();
  side.time = base.time;
  side.num_satellites = base.sats.size();
  side.ephemeris_stamp = eph_->selection_stamp();
  side.obs = select_observables(base, *eph_, options_.observables);
  gnss::EpochSatelliteStates states(*eph_, side.obs.time);
  for (std::size_t i = 0; i < side.obs.signals.size(); ++i) {
    const core::SatelliteId sat = side.obs.signals[i].sat;
    if (i > 0 && side.obs.signals[i - 1].sat == sat) continue;  // signals are grouped by satellite
    const double pseudorange_m = any_pseudorange(side.obs, sat);
    if (!core::has_value(pseudorange_m)) continue;
    side.models.emplace_back(sat,
                             zero_difference(states, sat, pseudorange_m, base_, options_.troposphere_saastamoinen));
  }
  return side;
}

EpochGeometry EpochGeometryBuilder::build(const core::ObsEpoch& rover, const core::ObsEpoch* base, bool aided) {
  gnss::EpochSatelliteStates rover_states(*eph_, rover.time);
  auto spp = gnss::solve_spp(rover, *eph_, options_.spp, last_spp_p_E_m_, &rover_states);
  if (spp) last_spp_p_E_m_ = spp->p_E_m;
  EpochGeometry out{std::move(rover_states),
                    std::move(spp),
                    select_observables(rover, *eph_, options_.observables),
                    base != nullptr,
                    {},
                    {},
                    std::nullopt};
  if (base == nullptr) return out;
  const BaseSide& side = base_side(*base);
  out.base_obs = side.obs;
  out.base_models = side.models;
  // The prediction's own conditions for going on to the single differences (RtkEngine::predict()).
  if (!base_out_of_time(rover.time - base->time, options_.max_base_age_s) && (out.spp || aided)) {
    out.slips = scan_slips(out);
  }
  return out;
}

}  // namespace canyon::rtk
