#pragma once
// What a rover's byte stream (the receiver's, or the base's corrections) lost so far: carried by each epoch from
// ingest (pipeline/epoch_pipeline.hpp), published in canyon::msg::StageTiming, shown by canyon monitor.

#include <cstdint>

namespace canyon::pipeline {

struct LinkCounts {
  std::uint64_t dropped_bytes = 0;  ///< bytes that arrived faster than they were read, beyond the link's queue
  std::uint64_t link_failures = 0;  ///< failed connection attempts (refused, timed out, stalled, lost)
  std::uint64_t bad_frames = 0;     ///< RTCM 3 frames and UBX packets that failed their check or were cut
  std::uint64_t undecodable = 0;    ///< intact frames and packets whose content was invalid
};

}  // namespace canyon::pipeline
