// canyon-rtcm-probe: a measuring consumer (and, for the security tests, an injector) of the RtcmFrame topic.
//
//   subscribe: N participants, one reader each, count every frame: received, sequence gaps, out-of-order frames,
//              duplicates, frames that are not one RTCM 3 frame (CRC-24Q), and the latency from the base's send time
//              to arrival (wall clock: the same machine, or NTP-synchronised hosts). Stops after --duration, or
//              --idle seconds without a frame once frames came. Prints one JSON object (schema: README, Deployment).
//              --json-lines FILE writes a dashboard snapshot every second: correction age (time since the newest
//              frame was sent), frame gaps, and the link emulator's counters when --link-stats names its file.
//   inject:    publishes --count forged but valid RTCM 3 frames (station 4095) at 10 Hz: the security tests show
//              that a participant without valid credentials or permissions reaches no subscriber.
// Exit codes: 0 done, 1 runtime failure (DDS entities not created), 2 bad command line, 3 inject: the writer was
// refused (access control), 4 subscribe: no frame arrived (the summary is printed all the same).

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "canyon/core/time.hpp"
#include "canyon/dds/dds.hpp"
#include "canyon/dds/rtcm_frame.hpp"
#include "canyon/io/rtcm3.hpp"

#include "main_guard.hpp"

namespace {

constexpr int kExitRuntime = 1;
constexpr int kExitUsage = 2;
constexpr int kExitRefused = 3;
constexpr int kExitNothing = 4;

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int /*signal*/) {
  g_stop.store(true);
}

std::int64_t unix_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

struct ReaderStats {
  std::uint64_t received = 0;
  std::uint64_t gaps = 0;          ///< frames missing between consecutive sequence numbers
  std::uint64_t out_of_order = 0;  ///< a sequence number lower than one already seen
  std::uint64_t duplicates = 0;
  std::uint64_t bad = 0;       ///< not one RTCM 3 frame (from_msg refused it)
  std::uint64_t foreign = 0;   ///< frames of another station than --station (injected)
  std::uint64_t restarts = 0;  ///< the base started again (sequence number 0 after higher ones)
  std::int64_t first_seq = -1;
  std::int64_t last_seq = -1;
  std::int64_t newest_send_unix_ns = 0;
  std::set<std::uint64_t> seen;
  std::vector<double> latency_ms;
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto k = static_cast<std::size_t>(std::lround(p / 100.0 * static_cast<double>(v.size() - 1)));
  return v[std::min(k, v.size() - 1)];
}

std::string latency_json(const std::vector<double>& v) {
  std::ostringstream out;
  out.precision(4);
  out << std::fixed << "{\"p50_ms\":" << percentile(v, 50) << ",\"p95_ms\":" << percentile(v, 95)
      << ",\"p99_ms\":" << percentile(v, 99)
      << ",\"max_ms\":" << (v.empty() ? 0.0 : *std::max_element(v.begin(), v.end())) << ",\"count\":" << v.size()
      << "}";
  return out.str();
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  return text;
}

/// A number field of a flat JSON object written by canyon-linkemu ("lost":12), or 0.
double json_number(const std::string& text, const std::string& key) {
  const auto at = text.find("\"" + key + "\":");
  if (at == std::string::npos) return 0.0;
  return std::strtod(text.c_str() + at + key.size() + 3, nullptr);
}

int inject(canyon::dds::DdsParticipant& participant, const std::string& topic, int count, double wait_s) {
  auto writer = canyon::dds::RtcmWriter::create(participant, topic, canyon::dds::profile::kRtcmWriter);
  if (!writer) {
    std::cout << "{\"writer\":false,\"error\":\"" << writer.error().message << "\"}\n";
    return kExitRefused;
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_s);
  while ((*writer)->matched() == 0 && std::chrono::steady_clock::now() < deadline && !g_stop.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const int matched = (*writer)->matched();
  int written = 0;
  for (int i = 0; i < count && !g_stop.load(); ++i) {
    std::vector<std::uint8_t> payload(20, 0);
    payload[0] = static_cast<std::uint8_t>(1005 >> 4);  // a 1005 of station 4095
    payload[1] = static_cast<std::uint8_t>(((1005 & 0xF) << 4) | 0x0F);
    payload[2] = 0xFF;
    canyon::base::BaseFrame f;
    f.sequence = static_cast<std::uint64_t>(i);
    f.message_number = 1005;
    f.station_id = 4095;
    f.bytes = *canyon::io::rtcm3::frame_rtcm3(payload);
    f.receive_ns = canyon::core::pipeline_now_ns();
    if (canyon::dds::publish_rtcm_frame(**writer, f)) ++written;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  (*writer)->wait_for_acknowledgments(2.0);
  std::cout << "{\"writer\":true,\"matched\":" << matched << ",\"written\":" << written << "}\n";
  return 0;
}

struct Args {
  std::string mode = "subscribe";
  std::string profiles;
  std::string topic = "canyon/rtcm";
  std::string json_lines;
  std::string link_stats;
  std::string arrivals;
  int domain = 0;
  int readers = 1;
  int count = 20;
  int station = -1;
  double duration_s = 600.0;
  double idle_s = 5.0;
  double wait_s = 20.0;
};

/// Counts one frame of reader `k` (under the caller's lock); reader 0 also writes its arrival to `arrivals`.
void count_frame(ReaderStats& s, std::size_t k, const canyon::msg::RtcmFrame& m,
                 const canyon::Result<canyon::base::BaseFrame>& f, int station, std::int64_t now,
                 std::ostream* arrivals) {
  if (!f) {
    ++s.bad;
    return;
  }
  if (station >= 0 && f->station_id != station) {
    ++s.foreign;
    return;
  }
  ++s.received;
  const auto seq = static_cast<std::int64_t>(f->sequence);
  if (seq == 0 && s.last_seq > 0) {  // a new base run numbers its frames from 0 again
    ++s.restarts;
    s.seen.clear();
    s.last_seq = -1;
  }
  if (k == 0 && arrivals != nullptr) {
    *arrivals << canyon::core::pipeline_now_ns() << "," << seq << "," << m.send_unix_ns() << "," << now << "\n";
  }
  if (!s.seen.insert(f->sequence).second) {
    ++s.duplicates;
    return;
  }
  if (s.first_seq < 0) s.first_seq = seq;
  if (seq < s.last_seq) {
    ++s.out_of_order;
  } else {
    if (s.last_seq >= 0 && seq > s.last_seq + 1) s.gaps += static_cast<std::uint64_t>(seq - s.last_seq - 1);
    s.last_seq = seq;
  }
  s.newest_send_unix_ns = std::max(s.newest_send_unix_ns, m.send_unix_ns());
  s.latency_ms.push_back(static_cast<double>(now - m.send_unix_ns()) * 1e-6);
}

/// The dashboard snapshot of reader 0 (one JSON line).
std::string snapshot_line(const ReaderStats& s, std::int64_t start_ns, std::int64_t now,
                          const std::string& link_stats) {
  std::vector<double> recent(
      s.latency_ms.end() - std::min<std::ptrdiff_t>(200, static_cast<std::ptrdiff_t>(s.latency_ms.size())),
      s.latency_ms.end());
  std::ostringstream line;
  line.precision(6);
  line << "{\"t_s\":" << static_cast<double>(now - start_ns) * 1e-9;
  line << ",\"stages\":{\"dds_transport\":{\"p50_us\":" << percentile(recent, 50) * 1e3
       << ",\"p95_us\":" << percentile(recent, 95) * 1e3 << ",\"p99_us\":" << percentile(recent, 99) * 1e3
       << ",\"max_us\":" << (recent.empty() ? 0.0 : *std::max_element(recent.begin(), recent.end())) * 1e3
       << ",\"count\":" << s.latency_ms.size() << "}}";
  line << ",\"correction_age_s\":"
       << (s.newest_send_unix_ns > 0 ? static_cast<double>(unix_now_ns() - s.newest_send_unix_ns) * 1e-9 : -1.0);
  line << ",\"queues\":{},\"drops\":{\"rtcm_gap\":" << s.gaps << ",\"rtcm_bad\":" << s.bad;
  if (!link_stats.empty()) {
    const std::string link = read_file(link_stats);
    line << ",\"link_lost\":"
         << json_number(link, "lost") + json_number(link, "outage_drops") + json_number(link, "queue_drops")
         << ",\"link_packets\":" << json_number(link, "packets");
  }
  line << "}}\n";
  return line.str();
}

/// Prints the summary of every reader (one JSON object); kExitNothing if no frame arrived.
int summarise(const std::vector<ReaderStats>& stats, const Args& a) {
  std::vector<double> all;
  std::ostringstream out;
  out << "{\"readers\":[";
  std::uint64_t min_received = UINT64_MAX;
  std::uint64_t total_gaps = 0;
  std::uint64_t total_ooo = 0;
  std::uint64_t total_dup = 0;
  std::uint64_t total_bad = 0;
  std::uint64_t total_foreign = 0;
  for (std::size_t k = 0; k < stats.size(); ++k) {
    const ReaderStats& s = stats[k];
    out << (k > 0 ? "," : "") << "{\"received\":" << s.received << ",\"first_seq\":" << s.first_seq
        << ",\"last_seq\":" << s.last_seq << ",\"gaps\":" << s.gaps << ",\"out_of_order\":" << s.out_of_order
        << ",\"duplicates\":" << s.duplicates << ",\"bad\":" << s.bad << ",\"foreign\":" << s.foreign
        << ",\"restarts\":" << s.restarts << ",\"latency\":" << latency_json(s.latency_ms) << "}";
    all.insert(all.end(), s.latency_ms.begin(), s.latency_ms.end());
    min_received = std::min(min_received, s.received);
    total_gaps += s.gaps;
    total_ooo += s.out_of_order;
    total_dup += s.duplicates;
    total_bad += s.bad;
    total_foreign += s.foreign;
  }
  out << "],\"min_received\":" << min_received << ",\"gaps\":" << total_gaps << ",\"out_of_order\":" << total_ooo
      << ",\"duplicates\":" << total_dup << ",\"bad\":" << total_bad << ",\"foreign\":" << total_foreign
      << ",\"latency\":" << latency_json(all) << "}\n";
  std::cout << out.str();
  if (all.empty()) {
    std::cerr << "canyon-rtcm-probe: no frame received on '" << a.topic << "' (domain " << a.domain
              << "): no base matched (link down, wrong domain, profile or topic, or refused by DDS-Security)\n";
    return kExitNothing;
  }
  return 0;
}

/// Opens `path` for writing into `file` ("-": stdout); `out` null if `path` is empty; false if it cannot be written.
bool open_output(const std::string& path, std::ofstream& file, std::ostream*& out) {
  out = nullptr;
  if (path == "-") {
    out = &std::cout;
  } else if (!path.empty()) {
    file.open(path, std::ios::trunc);
    if (!file) return false;
    out = &file;
  }
  return true;
}

int subscribe(const Args& a, const canyon::dds::ProfileSet& profiles) {
  std::ofstream arrivals_file;
  std::ostream* arrivals_out = nullptr;
  if (!a.arrivals.empty()) {
    arrivals_file.open(a.arrivals, std::ios::trunc);
    if (!arrivals_file) {
      std::cerr << "canyon-rtcm-probe: cannot write " << a.arrivals << "\n";
      return kExitUsage;
    }
    arrivals_file << "recv_monotonic_ns,seq,send_unix_ns,recv_unix_ns\n";
    arrivals_out = &arrivals_file;
  }
  std::mutex mutex;
  std::vector<ReaderStats> stats(static_cast<std::size_t>(a.readers));
  std::atomic<std::int64_t> last_frame_ns{0};
  std::vector<std::unique_ptr<canyon::dds::DdsParticipant>> participants;
  std::vector<std::unique_ptr<canyon::dds::RtcmReader>> dds_readers;
  for (std::size_t k = 0; k < stats.size(); ++k) {
    auto p = canyon::dds::DdsParticipant::create(a.domain, profiles.participant_profile());
    if (!p) {
      std::cerr << "canyon-rtcm-probe: " << p.error().to_string() << "\n";
      return kExitRuntime;
    }
    auto r = canyon::dds::RtcmReader::create(**p, a.topic, canyon::dds::profile::kRtcmReader,
                                             [&, k](canyon::msg::RtcmFrame&& m) {
                                               const std::int64_t now = unix_now_ns();
                                               last_frame_ns.store(canyon::core::pipeline_now_ns());
                                               const auto f = canyon::dds::from_msg(m);
                                               const std::lock_guard lock(mutex);
                                               count_frame(stats[k], k, m, f, a.station, now, arrivals_out);
                                             });
    if (!r) {
      std::cerr << "canyon-rtcm-probe: " << r.error().to_string() << "\n";
      return kExitRuntime;
    }
    participants.push_back(std::move(*p));
    dds_readers.push_back(std::move(*r));
  }
  std::ofstream snapshot_file;
  std::ostream* snapshots = nullptr;
  if (!open_output(a.json_lines, snapshot_file, snapshots)) {
    std::cerr << "canyon-rtcm-probe: cannot write " << a.json_lines << "\n";
    return kExitUsage;
  }
  const std::int64_t start_ns = canyon::core::pipeline_now_ns();
  std::int64_t next_snapshot_ns = start_ns + 1'000'000'000;
  while (!g_stop.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const std::int64_t now = canyon::core::pipeline_now_ns();
    if (static_cast<double>(now - start_ns) * 1e-9 > a.duration_s) break;
    const std::int64_t last = last_frame_ns.load();
    if (last > 0 && static_cast<double>(now - last) * 1e-9 > a.idle_s) break;
    if (snapshots != nullptr && now >= next_snapshot_ns) {
      next_snapshot_ns += 1'000'000'000;
      const std::lock_guard lock(mutex);
      *snapshots << snapshot_line(stats[0], start_ns, now, a.link_stats) << std::flush;
    }
  }
  dds_readers.clear();
  participants.clear();
  return summarise(stats, a);
}

int run(int argc, char** argv) {
  CLI::App cli{"canyon-rtcm-probe: measure (or, for security tests, inject) RtcmFrame samples"};
  Args a;
  cli.add_option("--mode", a.mode, "subscribe or inject")->check(CLI::IsMember({"subscribe", "inject"}));
  cli.add_option("--profiles", a.profiles,
                 "Deployment profiles (transport and discovery) on top of the shipped config/dds/canyon_profiles.xml")
      ->check(CLI::ExistingFile);
  cli.add_option("--domain", a.domain, "DDS domain")->check(CLI::Range(0, 232));
  cli.add_option("--topic", a.topic, "topic of RtcmFrame samples");
  cli.add_option("--readers", a.readers, "subscribe: participants, one reader each")->check(CLI::Range(1, 256));
  cli.add_option("--station", a.station, "subscribe: the expected station id; frames of others count as foreign");
  cli.add_option("--duration", a.duration_s, "stop after this many seconds")->check(CLI::PositiveNumber);
  cli.add_option("--idle", a.idle_s, "subscribe: stop this many seconds after the last frame")
      ->check(CLI::PositiveNumber);
  cli.add_option("--wait", a.wait_s, "inject: wait this long for a matched reader")->check(CLI::NonNegativeNumber);
  cli.add_option("--count", a.count, "inject: frames to publish")->check(CLI::Range(1, 100000));
  cli.add_option("--json-lines", a.json_lines, "subscribe: dashboard snapshot every second to this file ('-' stdout)");
  cli.add_option("--arrivals", a.arrivals, "subscribe: CSV of every frame of reader 0 (monotonic arrival, seq, times)");
  cli.add_option("--link-stats", a.link_stats, "canyon-linkemu --stats file whose counters go into the snapshots");
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : kExitUsage;
  }
  const auto loaded = canyon::dds::load_profiles(a.profiles);
  if (!loaded) {
    std::cerr << "canyon-rtcm-probe: " << loaded.error().to_string() << "\n";
    return kExitUsage;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  if (a.mode == "inject") {
    auto p = canyon::dds::DdsParticipant::create(a.domain, loaded->participant_profile());
    if (!p) {
      std::cout << "{\"participant\":false,\"error\":\"" << p.error().message << "\"}\n";
      return kExitRefused;
    }
    return inject(**p, a.topic, a.count, a.wait_s);
  }
  return subscribe(a, *loaded);
}

}  // namespace

int main(int argc, char** argv) {
  return canyon::apps::guarded_main("canyon-rtcm-probe", kExitRuntime, run, argc, argv);
}
