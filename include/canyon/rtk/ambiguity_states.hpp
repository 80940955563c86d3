#pragma once
// Bookkeeping of the filter's keyed states (filter_state.hpp) from epoch to epoch: an ambiguity is added when both
// receivers track its (satellite, frequency) with phase and code, reset on a cycle slip at either receiver (the
// caller removes it), removed after an outage longer than max_outage_s, and may be fixed once it has been tracked for
// more than min_lock_epochs, above the AR elevation mask, without an unresolved half cycle (and, for GLONASS, with
// glonass_ar). A satellite's ionosphere state (when estimated) is added by the caller (ionosphere_prior.hpp) and
// removed after the same outage.

#include <map>
#include <vector>

#include "canyon/core/time.hpp"
#include "canyon/rtk/epoch_geometry.hpp"
#include "canyon/rtk/filter_state.hpp"
#include "canyon/rtk/rtk_options.hpp"
#include "canyon/rtk/single_difference.hpp"

namespace canyon::rtk {

class AmbiguityStates {
 public:
  /// Keys of the states not seen for longer than `max_outage_s` (ionosphere states: `iono_max_outage_s`) before `t`,
  /// in key order.
  [[nodiscard]] std::vector<StateKey> stale(const core::GpsTime& t, double max_outage_s,
                                            double iono_max_outage_s) const;
  /// A state left the filter.
  void forget(const StateKey& key) { info_.erase(key); }
  void clear() { info_.clear(); }
  /// The states to add for the epoch's single differences that `state` does not hold yet (ambiguities in SD order,
  /// then code multipath states), with the epoch counted for every ambiguity and SingleDiff::fixable set; with
  /// `iono_estimated` the satellites' ionosphere states are marked seen (the caller adds the missing ones:
  /// ionosphere_prior.hpp).
  [[nodiscard]] std::vector<FilterState::NewState> admit(std::vector<SingleDiff>& sds, const FilterState& state,
                                                         const core::GpsTime& t, const SlipScan& slips,
                                                         const RtkOptions& options, bool iono_estimated);

 private:
  struct Info {
    int lock_epochs = 0;
    core::GpsTime last_seen;
  };
  std::map<StateKey, Info> info_;
};

/// SingleDiff::ambiguity and ::iono from the state's indices (an SD without phase has no ambiguity).
void assign_state_indices(std::vector<SingleDiff>& sds, const FilterState& state);

}  // namespace canyon::rtk
