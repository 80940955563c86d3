// canyon vio (see vio_app.hpp).

#include "canyon/dds/vio_app.hpp"

#include <algorithm>
#include <chrono>
#include <thread>
#include <utility>

#include <spdlog/spdlog.h>

namespace canyon::dds {
namespace {

// pace 0: wait for the readers' acknowledgements after this many samples (at most the writer's history depth, 1024
// on vio_writer and 256 on ros2_stream_writer), so that no sample is overwritten before a reader has it.
constexpr int kAckEvery = 256;
// --ros2, after the readers matched: a best-effort reader (ROS 2's sensor-data QoS, as canyon rover reads Odometry)
// drops the samples of a writer it has not matched yet, and the writer learns of a reader before the reader of the
// writer; give the readers' side of discovery this long (measured: without it a rover missed a whole 601-pose burst).
constexpr auto kReaderDiscoverySettle = std::chrono::milliseconds(500);

io::VioFile read_vio(const std::string& path) {
  io::VioFile vio = value_or_throw(io::read_vio_csv(path), kExitRuntime);
  for (const std::string& w : vio.warnings) spdlog::warn("{}", w);
  return vio;
}

std::optional<io::TimeSyncFile> read_timesync(const std::string& path) {
  if (path.empty()) return std::nullopt;
  io::TimeSyncFile sync = value_or_throw(io::read_timesync_csv(path), kExitRuntime);
  for (const std::string& w : sync.warnings) spdlog::warn("{}", w);
  std::sort(sync.pairs.begin(), sync.pairs.end(), [](const auto& l, const auto& r) { return l.t_ns < r.t_ns; });
  return sync;
}

}  // namespace

VioApp::VioApp(VioOptions options)
    : options_(std::move(options)),
      vio_(read_vio(options_.vio)),
      sync_(read_timesync(options_.timesync)),
      leaps_(core::builtin_leap_seconds()) {
  if (options_.ros2 && sync_) {
    throw AppError(kExitUsage, Error{"--ros2 publishes Odometry stamped on ROS time (UTC), which needs poses stamped "
                                     "with GPST: leave out --timesync (" +
                                     options_.timesync + ")"});
  }
  const ProfileSet profiles = value_or_throw(load_profiles(options_.profiles), kExitUsage);
  participant_ = value_or_throw(DdsParticipant::create(options_.domain, profiles.participant_profile()), kExitRuntime);
  if (options_.ros2) {
    odometry_ = value_or_throw(
        OdometryWriter::create(*participant_, ros2_dds_topic(options_.ros2_topic), profile::kRos2StreamWriter),
        kExitRuntime);
    return;
  }
  poses_ = value_or_throw(VioPoseWriter::create(*participant_, options_.vio_topic, profile::kVioWriter), kExitRuntime);
  if (sync_) {
    pairs_ = value_or_throw(TimeSyncWriter::create(*participant_, options_.timesync_topic, profile::kVioWriter),
                            kExitRuntime);
  }
}

VioApp::~VioApp() = default;

bool VioApp::wait_for_readers() const {
  const int n = options_.wait_readers;
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(options_.wait_timeout_s);
  const auto enough = [&] { return matched() >= n; };
  while (!enough() && std::chrono::steady_clock::now() < until && !stop_.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (odometry_ && enough()) std::this_thread::sleep_for(kReaderDiscoverySettle);
  return enough();
}

int VioApp::matched() const {
  if (odometry_) return odometry_->matched();
  return pairs_ ? std::min(poses_->matched(), pairs_->matched()) : poses_->matched();
}

bool VioApp::acknowledged(double timeout_s) {
  if (odometry_) return odometry_->wait_for_acknowledgments(timeout_s);
  return poses_->wait_for_acknowledgments(timeout_s) && (!pairs_ || pairs_->wait_for_acknowledgments(timeout_s));
}

std::uint64_t VioApp::publish() {
  std::size_t next_pose = 0, next_pair = 0;
  std::uint64_t refused = 0, sent = 0;
  const std::int64_t first_ns = vio_.records.front().t_ns;
  const auto start = std::chrono::steady_clock::now();
  const std::size_t pairs = sync_ ? sync_->pairs.size() : 0;
  while ((next_pose < vio_.records.size() || next_pair < pairs) && !stop_.load()) {
    const bool pair_first = next_pair < pairs && (next_pose == vio_.records.size() ||
                                                  sync_->pairs[next_pair].t_ns <= vio_.records[next_pose].t_ns);
    const std::int64_t t_ns = pair_first ? sync_->pairs[next_pair].t_ns : vio_.records[next_pose].t_ns;
    if (options_.pace > 0.0) {
      const auto due = start + std::chrono::nanoseconds(static_cast<std::int64_t>(
                                   static_cast<double>(std::max<std::int64_t>(t_ns - first_ns, 0)) / options_.pace));
      std::this_thread::sleep_until(due);
    }
    if (pair_first) {
      auto m = to_msg(sync_->pairs[next_pair++]);
      if (!pairs_->write(m)) ++refused;
    } else if (odometry_) {
      auto m =
          to_ros2_odometry(vio_.records[next_pose++], options_.ros2_frame_id, options_.ros2_child_frame_id, leaps_);
      if (!odometry_->write(m)) ++refused;
    } else {
      auto m = to_msg(vio_.records[next_pose], next_pose);
      ++next_pose;
      if (!poses_->write(m)) ++refused;
    }
    if (options_.pace == 0.0 && ++sent % kAckEvery == 0) (void)acknowledged(5.0);
  }
  return refused;
}

void VioApp::linger() const {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(options_.linger_s);
  while (matched() > 0 && std::chrono::steady_clock::now() < until && !stop_.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

int VioApp::run() {
  if (options_.wait_readers > 0 && !wait_for_readers()) {
    spdlog::warn("fewer than {} readers matched after {} s; publishing anyway", options_.wait_readers,
                 options_.wait_timeout_s);
  }
  spdlog::info(
      "publishing {} VIO poses on {}{} on domain {}, pace {}", vio_.records.size(),
      odometry_ ? ros2_dds_topic(options_.ros2_topic) + " (nav_msgs/msg/Odometry)" : options_.vio_topic,
      sync_ ? " and " + std::to_string(sync_->pairs.size()) + " time-sync pairs on " + options_.timesync_topic : "",
      options_.domain, options_.pace);
  const std::uint64_t refused = publish();
  if (!acknowledged(5.0)) spdlog::warn("not every sample was acknowledged by every reader within 5 s");
  linger();
  if (refused > 0) {
    spdlog::error("{} samples refused by the DDS writers (history full)", refused);
    return kExitRuntime;
  }
  spdlog::info("done{}", stop_.load() ? " (stopped by signal)" : "");
  return kExitOk;
}

}  // namespace canyon::dds
