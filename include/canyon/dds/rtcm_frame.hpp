#pragma once
// RtcmFrame (idl/RtcmFrame.idl) <-> base::BaseFrame: the IDL adapter of the base station's corrections, and the DDS
// output of `canyon base` built on it.

#include <memory>

#include "canyon/base/base_station.hpp"
#include "canyon/core/result.hpp"
#include "canyon/dds/dds.hpp"

#include "RtcmFrame.h"
#include "RtcmFramePubSubTypes.h"

namespace canyon::dds {

/// The message of a frame; send times are stamped by the caller (publish_rtcm_frame).
[[nodiscard]] msg::RtcmFrame to_msg(const base::BaseFrame& frame);
/// The frame of a message. Error if the bytes are not one RTCM 3 frame (length, preamble, CRC-24Q) or exceed the
/// IDL bound (sequence bounds are not enforced by Fast DDS), naming the sequence number.
Result<base::BaseFrame> from_msg(const msg::RtcmFrame& message);

using RtcmWriter = DdsWriter<msg::RtcmFrame, msg::RtcmFramePubSubType>;
using RtcmReader = DdsReader<msg::RtcmFrame, msg::RtcmFramePubSubType>;

/// Stamps the send times and writes; false if DDS refused the sample.
bool publish_rtcm_frame(RtcmWriter& writer, const base::BaseFrame& frame);

}  // namespace canyon::dds
