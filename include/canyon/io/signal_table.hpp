#pragma once
// State kept per (satellite, signal) by the stream codecs (lock times, phase arcs): a table indexed by satellite
// with a short list of signals each, so that a lookup is an index and a scan of a few entries, without allocation
// once a signal has been seen.

#include <array>
#include <utility>
#include <vector>

#include "canyon/core/satellite.hpp"

namespace canyon::io {

template <typename T>
class SignalTable {
 public:
  /// The state of a signal, created (value-initialised) on first use.
  T& at(const core::SatelliteId& sat, core::SignalCode code) {
    auto& list = table_[static_cast<std::size_t>(sat.index())];
    for (auto& [c, value] : list) {
      if (c == code) return value;
    }
    list.emplace_back(code, T{});
    return list.back().second;
  }
  /// The state of a signal, or nullptr if never used.
  T* find(const core::SatelliteId& sat, core::SignalCode code) {
    auto& list = table_[static_cast<std::size_t>(sat.index())];
    for (auto& [c, value] : list) {
      if (c == code) return &value;
    }
    return nullptr;
  }

 private:
  std::array<std::vector<std::pair<core::SignalCode, T>>, core::kMaxSatellites> table_;
};

}  // namespace canyon::io
