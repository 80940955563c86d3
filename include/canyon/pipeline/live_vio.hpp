#pragma once
// Live VIO for the fusion pipeline: VIO poses and the device's time-sync pairs that arrive while the rover runs
// (DDS topics canyon::msg::VioPose and TimeSyncSample, or any other stream), into the fusion engine's VIO track.
//
// Threads. The producers (one thread per kind, e.g. each DDS reader's listener) only queue: push_pose() and
// push_pair() never block; a full queue drops the pose or pair and counts it (the policy: VIO may be
// decimated, every drop is counted and published). The time bridge stage calls await(t) for each epoch, on its own
// thread: it takes what arrived, maps each pose to GPST with the causal time bridge (fusion::CausalTimeBridge: once
// the pairs it needs are in) and appends it to the track (FusionEngine::add_vio), until the track covers t
// (VioTrack::covers: the pose at t can no longer change). Then bridge(t) gives the same pose as `canyon process` with
// fusion.timesync_mode: causal on the same poses and pairs, which makes the live rover reproducible.
//
// Waiting. An epoch waits at most wait_s for its VIO; then it goes on without (counted as late: the prediction falls
// back to the RTK motion model for it). While the stream is silent after such a timeout, later epochs do not wait
// (a VIO that stopped costs one wait, not one per epoch) until a pose arrives again.

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>

#include "canyon/core/time.hpp"
#include "canyon/fusion/fusion_engine.hpp"
#include "canyon/fusion/time_bridge.hpp"
#include "canyon/io/vio_file.hpp"

namespace canyon::pipeline {

struct LiveVioOptions {
  double wait_s = 0.2;                  ///< longest an epoch waits for the VIO to cover it (s)
  std::size_t queue_poses = 4096;       ///< poses queued between the producer and the time bridge; beyond, dropped
  std::size_t queue_pairs = 1024;       ///< time-sync pairs likewise
  bool vio_on_gps_time = false;         ///< poses stamped with GPST ns (no pairs needed)
  fusion::TimeBridgeOptions time_sync;  ///< the causal bridge's fit (causal_hold_s, causal_window_pairs, limits)

  [[nodiscard]] std::string validate() const;
};

struct LiveVioCounts {
  std::uint64_t poses = 0;         ///< received (queued or dropped)
  std::uint64_t pairs = 0;         ///< received
  std::uint64_t dropped = 0;       ///< poses and pairs dropped because their queue was full
  std::uint64_t unmapped = 0;      ///< poses the causal time bridge could not map (no pair yet, fit refused, or
                                   ///< none came while a queue's worth of later poses waited)
  std::uint64_t out_of_order = 0;  ///< poses and pairs not after the previous one (ignored)
  std::uint64_t late_epochs = 0;   ///< epochs that went on without waiting longer for their VIO
  std::uint64_t appended = 0;      ///< poses appended to the track
};

class LiveVio {
 public:
  using WarnFn = std::function<void(const std::string&)>;
  LiveVio(fusion::FusionEngine& engine, LiveVioOptions options, WarnFn warn);
  ~LiveVio();
  LiveVio(const LiveVio&) = delete;
  LiveVio& operator=(const LiveVio&) = delete;

  /// Producer side (one thread each, never blocks).
  void push_pose(io::VioRecord pose);
  void push_pair(const io::TimeSyncPair& pair);

  /// The time bridge stage, before FusionEngine::bridge(t): see the top of this file.
  void await(const core::GpsTime& t);

  /// Thread-safe snapshot.
  [[nodiscard]] LiveVioCounts counts() const;

 private:
  struct Queues;
  /// Moves what is queued into pending_ and the bridge; true if a pose arrived.
  bool drain();
  /// Maps and appends the pending poses whose pairs are in.
  void map_ready();
  void warn_once(std::uint64_t count, const std::string& text);

  fusion::FusionEngine& engine_;
  LiveVioOptions options_;
  WarnFn warn_;
  std::unique_ptr<Queues> queues_;
  fusion::CausalTimeBridge bridge_;
  std::deque<io::VioRecord> pending_;  // received, waiting for their time-sync pairs
  bool stalled_ = false;
  int ignored_steps_reported_ = 0;  // the bridge's steps of the time sync alone, said so far
  std::atomic<std::uint64_t> poses_{0}, pairs_{0}, dropped_{0}, unmapped_{0}, out_of_order_{0}, late_{0}, appended_{0};
};

}  // namespace canyon::pipeline
