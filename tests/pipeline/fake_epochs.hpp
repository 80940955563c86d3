#pragma once
// Stage messages for tests that need an epoch at a given stage without an estimator: no ephemerides, no geometry.

#include <utility>

#include "canyon/gnss/ephemeris.hpp"
#include "canyon/pipeline/stage_messages.hpp"

namespace canyon::pipeline::testing {

/// An epoch bridged with a geometry that holds nothing.
inline BridgedEpoch bridged_without_geometry(IngestedEpoch epoch) {
  static const gnss::EphemerisStore kNoEphemerides{core::NavigationData{}};
  rtk::EpochGeometry geometry{gnss::EpochSatelliteStates(kNoEphemerides, epoch.rover.time),
                              Error{"no geometry"},
                              {},
                              false,
                              {},
                              {},
                              std::nullopt};
  return BridgedEpoch{std::move(epoch), fusion::FusionGeometry{std::move(geometry), std::nullopt, 0}, std::nullopt};
}

/// An epoch through every stage with the given output.
inline SolvedEpoch solved_epoch(IngestedEpoch epoch, Result<EpochOutput> output) {
  SolvedEpoch solved{
      UpdatedEpoch{PredictedEpoch{AlignedEpoch{bridged_without_geometry(std::move(epoch))}, true}, true}};
  solved.output = std::move(output);
  return solved;
}

}  // namespace canyon::pipeline::testing
