#pragma once
// The simulator's runs as the estimators take them, for tests and benches that fuse a simulation in memory: its VIO
// poses as VIO track samples, and the base epoch to use with a rover epoch.

#include <cstddef>
#include <vector>

#include "canyon/core/time.hpp"
#include "canyon/fusion/vio_track.hpp"
#include "canyon/sim/simulator.hpp"
#include "canyon/sim/vio.hpp"

namespace canyon::test {

/// The simulator's VIO poses as track samples, timed from `start` (on GPST: no time-sync file).
inline std::vector<fusion::VioTrackSample> track_samples(const std::vector<sim::VioSample>& poses,
                                                         const core::GpsTime& start) {
  std::vector<fusion::VioTrackSample> samples;
  samples.reserve(poses.size());
  for (const sim::VioSample& v : poses) {
    fusion::VioTrackSample t;
    t.t_s = v.time - start;
    t.T_OI = v.T_OI;
    t.P = v.covariance;
    t.C_previous = v.cross_previous;
    samples.push_back(t);
  }
  return samples;
}

/// The index of the base epoch to use with a rover epoch at `t`: the last within 0.05 s after it, moving on from
/// `base` (the epochs come in time order).
inline std::size_t base_epoch_for(const sim::Simulation& sim, std::size_t base, const core::GpsTime& t) {
  while (base + 1 < sim.base.epochs.size() && sim.base.epochs[base + 1].time - t <= 0.05) ++base;
  return base;
}

}  // namespace canyon::test
