// canyon-vio: publishes a VIO run on DDS, as a VIO node would: the poses of vio.csv as canyon::msg::VioPose samples
// (topic canyon/vio) and the device's time-sync pairs of timesync.csv as TimeSyncSample samples (canyon/timesync),
// merged in device-time order, at real-time pace or faster (--pace; 0: as fast as the readers acknowledge).
// `canyon vio ...` runs this executable; canyon rover with input.vio dds subscribes. SIGINT/SIGTERM stop it.
// Exit codes: 0 success, 1 input or runtime failure, 2 bad command line.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "canyon/dds/dds.hpp"
#include "canyon/dds/rover_msgs.hpp"
#include "canyon/io/vio_file.hpp"

#include "main_guard.hpp"

namespace {

constexpr int kExitRuntime = 1;
constexpr int kExitUsage = 2;
constexpr int kAckEvery = 256;  // pace 0: wait for the readers' acknowledgements after this many samples

namespace pl = canyon::dds;
namespace io = canyon::io;

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int /*signal*/) {
  g_stop.store(true);
}

struct Args {
  std::string vio;
  std::string timesync;
  double pace = 1.0;
  int domain = 0;
  std::string profiles;
  std::string vio_topic = "canyon/vio";
  std::string timesync_topic = "canyon/timesync";
  int wait_readers = 0;
  double wait_timeout_s = 30.0;
  double linger_s = 2.0;
  bool quiet = false;
};

struct Writers {
  std::unique_ptr<pl::VioPoseWriter> poses;
  std::unique_ptr<pl::TimeSyncWriter> pairs;
};

/// Waits until both writers have `n` readers, at most timeout_s; false if they did not.
bool wait_for_readers(const Writers& w, int n, double timeout_s) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  const auto enough = [&] { return w.poses->matched() >= n && (!w.pairs || w.pairs->matched() >= n); };
  while (!enough() && std::chrono::steady_clock::now() < until && !g_stop.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return enough();
}

/// Publishes poses and pairs in device-time order; the number of samples the writers refused.
std::uint64_t publish(const Args& args, const io::VioFile& vio, const io::TimeSyncFile* sync, Writers& w) {
  std::size_t next_pose = 0, next_pair = 0;
  std::uint64_t refused = 0, sent = 0;
  const std::int64_t first_ns = vio.records.front().t_ns;
  const auto start = std::chrono::steady_clock::now();
  const std::size_t pairs = sync != nullptr ? sync->pairs.size() : 0;
  while ((next_pose < vio.records.size() || next_pair < pairs) && !g_stop.load()) {
    const bool pair_first = next_pair < pairs && (next_pose == vio.records.size() ||
                                                  sync->pairs[next_pair].t_ns <= vio.records[next_pose].t_ns);
    const std::int64_t t_ns = pair_first ? sync->pairs[next_pair].t_ns : vio.records[next_pose].t_ns;
    if (args.pace > 0.0) {
      const auto due = start + std::chrono::nanoseconds(static_cast<std::int64_t>(
                                   static_cast<double>(std::max<std::int64_t>(t_ns - first_ns, 0)) / args.pace));
      std::this_thread::sleep_until(due);
    }
    if (pair_first) {
      auto m = pl::to_msg(sync->pairs[next_pair++]);
      if (!w.pairs->write(m)) ++refused;
    } else {
      auto m = pl::to_msg(vio.records[next_pose], next_pose);
      ++next_pose;
      if (!w.poses->write(m)) ++refused;
    }
    if (args.pace == 0.0 && ++sent % kAckEvery == 0) {
      (void)w.poses->wait_for_acknowledgments(5.0);
      if (w.pairs) (void)w.pairs->wait_for_acknowledgments(5.0);
    }
  }
  return refused;
}

int run(int argc, char** argv) {
  CLI::App cli{"canyon-vio: publish VIO poses and time-sync pairs on DDS (a VIO node; canyon rover input.vio dds)"};
  Args a;
  cli.add_option("--vio", a.vio, "VIO poses (vio.csv, DESIGN.md contract)")->required()->check(CLI::ExistingFile);
  cli.add_option("--timesync", a.timesync, "Time-sync pairs (timesync.csv); omit for VIO stamped with GPST")
      ->check(CLI::ExistingFile);
  cli.add_option("--pace", a.pace, "Replay speed: 1 real time, 10 ten times faster, 0 as fast as readers acknowledge")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--domain", a.domain, "DDS domain id")->check(CLI::Range(0, 232));
  cli.add_option("--profiles", a.profiles,
                 "Deployment profiles (transport and discovery, deploy/dds/*.xml) on top of the shipped "
                 "config/dds/canyon_profiles.xml");
  cli.add_option("--vio-topic", a.vio_topic, "Topic of the VioPose samples");
  cli.add_option("--timesync-topic", a.timesync_topic, "Topic of the TimeSyncSample samples");
  cli.add_option("--wait-for-readers", a.wait_readers, "Start once this many readers of each topic are matched")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--wait-timeout", a.wait_timeout_s, "Give up waiting for readers after this many seconds");
  cli.add_option("--linger", a.linger_s,
                 "At the end, stay up to this many seconds while readers are matched (a reader still taking the "
                 "last samples from shared memory loses them when the writer goes)")
      ->check(CLI::NonNegativeNumber);
  cli.add_flag("-q,--quiet", a.quiet, "Warnings and errors only");
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : kExitUsage;
  }
  spdlog::set_pattern("[%Y-%m-%d %H:%M:%S.%e] [canyon-vio] [%^%l%$] %v");
  if (a.quiet) spdlog::set_level(spdlog::level::warn);

  auto vio = io::read_vio_csv(a.vio);
  if (!vio) {
    spdlog::error("{}", vio.error().to_string());
    return kExitRuntime;
  }
  for (const std::string& w : vio->warnings) spdlog::warn("{}", w);
  std::optional<io::TimeSyncFile> sync;
  if (!a.timesync.empty()) {
    auto s = io::read_timesync_csv(a.timesync);
    if (!s) {
      spdlog::error("{}", s.error().to_string());
      return kExitRuntime;
    }
    for (const std::string& w : s->warnings) spdlog::warn("{}", w);
    std::sort(s->pairs.begin(), s->pairs.end(), [](const auto& l, const auto& r) { return l.t_ns < r.t_ns; });
    sync = std::move(*s);
  }

  const auto profiles = pl::load_profiles(a.profiles);
  if (!profiles) {
    spdlog::error("{}", profiles.error().to_string());
    return kExitUsage;
  }
  auto participant = pl::DdsParticipant::create(a.domain, profiles->participant_profile());
  if (!participant) {
    spdlog::error("{}", participant.error().to_string());
    return kExitRuntime;
  }
  Writers w;
  auto poses = pl::VioPoseWriter::create(**participant, a.vio_topic, pl::profile::kVioWriter);
  if (!poses) {
    spdlog::error("{}", poses.error().to_string());
    return kExitRuntime;
  }
  w.poses = std::move(*poses);
  if (sync) {
    auto pairs = pl::TimeSyncWriter::create(**participant, a.timesync_topic, pl::profile::kVioWriter);
    if (!pairs) {
      spdlog::error("{}", pairs.error().to_string());
      return kExitRuntime;
    }
    w.pairs = std::move(*pairs);
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  if (a.wait_readers > 0 && !wait_for_readers(w, a.wait_readers, a.wait_timeout_s)) {
    spdlog::warn("fewer than {} readers matched after {} s; publishing anyway", a.wait_readers, a.wait_timeout_s);
  }
  spdlog::info("publishing {} VIO poses on {}{} on domain {}, pace {}", vio->records.size(), a.vio_topic,
               sync ? " and " + std::to_string(sync->pairs.size()) + " time-sync pairs on " + a.timesync_topic : "",
               a.domain, a.pace);
  const std::uint64_t refused = publish(a, *vio, sync ? &*sync : nullptr, w);
  const bool acked = w.poses->wait_for_acknowledgments(5.0) && (!w.pairs || w.pairs->wait_for_acknowledgments(5.0));
  if (!acked) spdlog::warn("not every sample was acknowledged by every reader within 5 s");
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(a.linger_s);
  while (w.poses->matched() > 0 && std::chrono::steady_clock::now() < until && !g_stop.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (refused > 0) {
    spdlog::error("{} samples refused by the DDS writers (history full)", refused);
    return kExitRuntime;
  }
  spdlog::info("done{}", g_stop.load() ? " (stopped by signal)" : "");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return canyon::apps::guarded_main("canyon-vio", kExitRuntime, run, argc, argv);
}
