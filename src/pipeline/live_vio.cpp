// Live VIO into the fusion engine's track (see live_vio.hpp).

#include "canyon/pipeline/live_vio.hpp"

#include <chrono>

#include <readerwriterqueue/readerwritercircularbuffer.h>

namespace canyon::pipeline {
namespace {

constexpr std::int64_t kPollUs = 1000;  // while poses wait for their pairs, look at the pairs this often
constexpr std::uint64_t kWarnings = 3;  // of each kind, then counted only

}  // namespace

std::string LiveVioOptions::validate() const {
  if (!(wait_s >= 0.0)) return "vio_wait_s must be >= 0";
  if (queue_poses < 1 || queue_pairs < 1) return "the VIO queues need room for at least one sample";
  return time_sync.validate();
}

struct LiveVio::Queues {
  Queues(std::size_t poses, std::size_t pairs) : pose(poses), pair(pairs) {}
  moodycamel::BlockingReaderWriterCircularBuffer<io::VioRecord> pose;
  moodycamel::BlockingReaderWriterCircularBuffer<io::TimeSyncPair> pair;
};

LiveVio::LiveVio(fusion::FusionEngine& engine, LiveVioOptions options, WarnFn warn)
    : engine_(engine),
      options_(options),
      warn_(std::move(warn)),
      queues_(std::make_unique<Queues>(options.queue_poses, options.queue_pairs)),
      bridge_(options.vio_on_gps_time ? fusion::CausalTimeBridge::gps_clock()
                                      : fusion::CausalTimeBridge(options.time_sync)) {}

LiveVio::~LiveVio() = default;

void LiveVio::push_pose(io::VioRecord pose) {
  poses_.fetch_add(1);
  if (!queues_->pose.try_enqueue(std::move(pose))) dropped_.fetch_add(1);
}

void LiveVio::push_pair(const io::TimeSyncPair& pair) {
  pairs_.fetch_add(1);
  if (!queues_->pair.try_enqueue(pair)) dropped_.fetch_add(1);
}

void LiveVio::warn_once(std::uint64_t count, const std::string& text) {
  if (count <= kWarnings && warn_) warn_(text + (count == kWarnings ? " (further ones counted only)" : ""));
}

bool LiveVio::drain() {
  io::TimeSyncPair pair;
  while (queues_->pair.try_dequeue(pair)) {
    if (Status s = bridge_.add(pair); !s)
      warn_once(out_of_order_.fetch_add(1) + 1, "VIO time sync: " + s.error().message);
  }
  bool any = false;
  io::VioRecord pose;
  while (queues_->pose.try_dequeue(pose)) {
    pending_.push_back(std::move(pose));
    any = true;
  }
  // Poses whose time-sync pairs never come (a silent time-sync stream) are not kept without bound: beyond a queue's
  // worth, the oldest are given up and counted as not mapped.
  while (pending_.size() > options_.queue_poses) {
    warn_once(unmapped_.fetch_add(1) + 1, "VIO pose at device time " + std::to_string(pending_.front().t_ns) +
                                              " ns given up: no time-sync pair for it arrived");
    pending_.pop_front();
  }
  return any;
}

void LiveVio::map_ready() {
  while (!pending_.empty() && bridge_.ready(pending_.front().t_ns)) {
    const io::VioRecord& pose = pending_.front();
    auto t = bridge_.to_gps(pose.t_ns);
    if (bridge_.ignored_steps() > ignored_steps_reported_) {
      ignored_steps_reported_ = bridge_.ignored_steps();
      if (warn_) warn_(bridge_.ignored_step_note());
    }
    if (!t) {
      warn_once(unmapped_.fetch_add(1) + 1, "VIO pose at device time " + std::to_string(pose.t_ns) +
                                                " ns not mapped to GPST: " + t.error().message);
    } else {
      std::string note;
      if (engine_.add_vio(pose, *t, &note, bridge_.steps_seen())) {
        appended_.fetch_add(1);
      } else {
        warn_once(out_of_order_.fetch_add(1) + 1, "VIO pose at device time " + std::to_string(pose.t_ns) +
                                                      " ns is not after the previous one: ignored");
      }
      if (!note.empty() && warn_) warn_(note);
    }
    pending_.pop_front();
  }
}

void LiveVio::await(const core::GpsTime& t) {
  using Clock = std::chrono::steady_clock;
  if (drain()) stalled_ = false;
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(stalled_ ? 0.0 : options_.wait_s));
  for (;;) {
    map_ready();
    if (engine_.vio_covers(t)) return;
    const auto now = Clock::now();
    if (now >= deadline) {
      late_.fetch_add(1);
      stalled_ = true;
      return;
    }
    // Sleep until a pose arrives (or a little while, for pairs), at most until the deadline.
    const auto left_us = std::chrono::duration_cast<std::chrono::microseconds>(deadline - now).count();
    io::VioRecord pose;
    if (queues_->pose.wait_dequeue_timed(pose, std::min<std::int64_t>(left_us, kPollUs))) {
      pending_.push_back(std::move(pose));
      stalled_ = false;
    }
    drain();
  }
}

LiveVioCounts LiveVio::counts() const {
  LiveVioCounts c;
  c.poses = poses_.load();
  c.pairs = pairs_.load();
  c.dropped = dropped_.load();
  c.unmapped = unmapped_.load();
  c.out_of_order = out_of_order_.load();
  c.late_epochs = late_.load();
  c.appended = appended_.load();
  return c;
}

}  // namespace canyon::pipeline
