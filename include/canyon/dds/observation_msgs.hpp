#pragma once
// A receiver's observation epoch <-> canyon::msg::GnssObservationEpoch (idl/GnssObservation.idl), exactly (doubles
// as they are, NaN for a missing observable): the rover publishes its ingested epochs on canyon/observations
// (dds.publish_observations), so that a recorded session holds the rover's inputs and `canyon process --session`
// re-runs it. Sizes are checked on the way back (Fast DDS does not enforce IDL bounds).

#include <cstdint>
#include <string>

#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/dds/dds.hpp"

#include "GnssObservation.h"
#include "GnssObservationPubSubTypes.h"

namespace canyon::dds {

/// The epoch as a message; satellites and signals beyond the IDL bounds (128, 16) are left out.
[[nodiscard]] msg::GnssObservationEpoch to_msg(const core::ObsEpoch& epoch, std::uint64_t sequence_number,
                                               const std::string& receiver_id, std::int64_t ingest_monotonic_ns);
/// The epoch of a message; Error naming what is wrong: an unknown system letter or PRN, a signal that is no RINEX 3
/// code, an epoch flag or GPS time out of range, sizes beyond the bounds.
Result<core::ObsEpoch> from_msg(const msg::GnssObservationEpoch& m);

using ObservationWriter = DdsWriter<msg::GnssObservationEpoch, msg::GnssObservationEpochPubSubType>;

}  // namespace canyon::dds
