// canyon-record, canyon-echo and canyon-monitor (one executable, canyon-monitor, with canyon-record and canyon-echo
// links to it; the name it runs under selects the tool): consumers of the rover's and the base's DDS topics.
// `canyon record|echo|monitor ...` runs them.
//   record TOPIC --out FILE: canyon/solution to .pos (RTKLIB format), .nmea (GGA) or .csv (every sample, status 0
//     too, with its sequence number and arrival time: the sequence accounting); canyon/rtcm to the raw
//     RTCM 3 stream (replayable: canyon base input.kind rtcm3, canyon process base: FILE.rtcm3); canyon/timing and
//     canyon/bridged to CSV; canyon/vio and canyon/timesync to vio.csv and timesync.csv (replayable: canyon vio;
//     every value with 17 significant digits, so the replay carries the same numbers).
//   echo TOPIC: one line per sample.
//   monitor: per-stage and end-to-end latency percentiles, correction age, queues, drops and the solution, refreshed
//     in the terminal or as JSON lines (--json; schema in pipeline/monitor_model.hpp).
// All of them stop on SIGINT/SIGTERM, after --count samples, after --duration seconds, or once the publishers they
// matched are all gone (--until-gone, on by default for record and monitor).
// Exit codes: 0 success, 1 runtime failure, 2 bad command line.

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>

#include "canyon/dds/dds.hpp"
#include "canyon/dds/rover_msgs.hpp"
#include "canyon/dds/rtcm_frame.hpp"
#include "canyon/io/nmea.hpp"
#include "canyon/io/pos_file.hpp"
#include "canyon/io/vio_file.hpp"
#include "canyon/pipeline/monitor_model.hpp"

#include "main_guard.hpp"
#ifdef CANYON_WITH_DASHBOARD
#include "canyon/dashboard/dashboard.hpp"
#endif

namespace {

constexpr int kExitRuntime = 1;
constexpr int kExitUsage = 2;
// "record", "echo" or "monitor": set once in main from the name the executable runs under, before anything reads it.
std::string g_tool;

namespace pl = canyon::dds;

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int /*signal*/) {
  g_stop.store(true);
}

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

/// The output of canyon record, written from the DDS listener thread (one reader: one thread at a time).
class Recorder {
 public:
  virtual ~Recorder() = default;
  virtual canyon::Status close() = 0;
};

int fail(const std::string& message, int code) {
  std::cerr << "canyon " << g_tool << ": error: " << message << "\n";
  return code;
}

int run(int argc, char** argv) {
  CLI::App cli{"canyon-" + g_tool};
  std::string topic;
  std::string out;
  int domain = 0;
  std::string profiles;
  std::int64_t count = 0;
  double duration_s = 0.0;
  bool json = false;
  double interval_s = 1.0;
  bool until_gone = g_tool != "echo";
  std::string solution_topic = "canyon/solution";
  std::string timing_topic = "canyon/timing";
#ifdef CANYON_WITH_DASHBOARD
  int http_port = -1;  // -1: no dashboard
  canyon::dashboard::ServerOptions dashboard_options;
#endif
  if (g_tool != "monitor") {
    cli.add_option("topic", topic,
                   "canyon/solution, canyon/timing, canyon/rtcm, canyon/bridged, canyon/alignment, canyon/prior, "
                   "canyon/float, canyon/vio or canyon/timesync")
        ->required();
  } else {
    cli.add_option("--solution-topic", solution_topic, "Solution topic");
    cli.add_option("--timing-topic", timing_topic, "Stage timing topic");
    cli.add_flag("--json", json, "One JSON object per line (schema: include/canyon/pipeline/monitor_model.hpp)");
    cli.add_option("--interval", interval_s, "Refresh period (s)")->check(CLI::Range(0.05, 3600.0));
#ifdef CANYON_WITH_DASHBOARD
    cli.add_option("--http", http_port, "Also serve the live dashboard (web page, /events, /metrics) on this port")
        ->check(CLI::Range(0, 65535));
    cli.add_option("--http-host", dashboard_options.host,
                   "Address the dashboard listens on (0.0.0.0: every interface)");
    cli.add_option("--web", dashboard_options.web_dir,
                   "Folder of the bundled dashboard page (default: build/web/dist)");
#endif
  }
  if (g_tool == "record") {
    cli.add_option("--out", out, "Output file: .pos, .nmea or .csv (solutions), .rtcm3 (canyon/rtcm), .csv")
        ->required();
  }
  cli.add_option("--domain", domain, "DDS domain id")->check(CLI::Range(0, 232));
  cli.add_option("--profiles", profiles,
                 "Deployment profiles (transport and discovery, deploy/dds/*.xml) on top of the shipped "
                 "config/dds/canyon_profiles.xml");
  cli.add_option("--count", count, "Stop after this many samples (0: no limit)")->check(CLI::NonNegativeNumber);
  cli.add_option("--duration", duration_s, "Stop after this many seconds (0: no limit)")->check(CLI::NonNegativeNumber);
  cli.add_option("--until-gone", until_gone, "Stop once every matched publisher has left (true/false)");
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : kExitUsage;
  }
  if (g_tool != "monitor") {
    bool known = false;
    for (const char* suffix :
         {"solution", "timing", "rtcm", "bridged", "prior", "float", "alignment", "vio", "timesync"}) {
      known = known || ends_with(topic, suffix);
    }
    if (!known) {
      return fail("unknown topic '" + topic +
                      "': canyon/solution, canyon/timing, canyon/rtcm, canyon/bridged, canyon/alignment, canyon/prior, "
                      "canyon/float, canyon/vio or canyon/timesync",
                  kExitUsage);
    }
  }
  if (auto s = pl::load_profiles(profiles); !s.ok()) return fail(s.error().to_string(), kExitUsage);
#ifdef CANYON_WITH_DASHBOARD
  std::unique_ptr<canyon::dashboard::DashboardServer> dashboard;
  if (http_port >= 0) {
    dashboard_options.port = http_port;
    if (dashboard_options.web_dir.empty())
      dashboard_options.web_dir = canyon::dashboard::find_web_dir(CANYON_WEB_DIST_DIR);
    if (const std::string e = dashboard_options.validate(); !e.empty()) return fail(e, kExitUsage);
    auto started = canyon::dashboard::DashboardServer::start(dashboard_options);
    if (!started) return fail(started.error().to_string(), kExitRuntime);
    dashboard = std::move(*started);
    std::cerr << "canyon monitor: dashboard on http://" << dashboard_options.host << ":" << dashboard->port() << "/"
              << (dashboard_options.web_dir.empty() ? " (page not built: /events and /metrics only)" : "") << std::endl;
  }
#endif
  auto participant = pl::DdsParticipant::create(domain, pl::load_profiles(profiles)->participant_profile());
  if (!participant) return fail(participant.error().to_string(), kExitRuntime);

  std::mutex mutex;  // the listeners of different readers may run on different threads
  std::atomic<std::int64_t> received{0};
  std::string error;
  const auto count_one = [&received] { received.fetch_add(1); };

  // Outputs of record.
  std::optional<canyon::io::PosWriter> pos;
  std::optional<canyon::io::NmeaWriter> nmea;
  std::ofstream raw;
  const bool solutions = ends_with(topic, "solution");
  if (g_tool == "record") {
    if (solutions && ends_with(out, ".pos")) {
      auto p = canyon::io::PosWriter::create(out, {canyon::io::PosCoordinates::Llh,
                                                   canyon::io::PosTimeFormat::WeekTow,
                                                   {"program   : canyon record " + topic}});
      if (!p) return fail(p.error().to_string(), kExitRuntime);
      pos = std::move(*p);
    } else if (solutions && ends_with(out, ".nmea")) {
      auto n = canyon::io::NmeaWriter::create(out);
      if (!n) return fail(n.error().to_string(), kExitRuntime);
      nmea = std::move(*n);
    } else {
      raw.open(out, std::ios::binary | std::ios::trunc);
      if (!raw) return fail("cannot create " + out, kExitRuntime);
      if (solutions) {
        raw << "seq,gps_week,gps_tow_s,status,x_m,y_m,z_m,lat_deg,lon_deg,height_m,n_sats,ratio,age_s,"
               "received_monotonic_ns\n";
      } else if (ends_with(topic, "vio")) {
        raw << canyon::io::vio_csv_header() << '\n';
      } else if (ends_with(topic, "timesync")) {
        raw << "t_ns,gps_week,gps_tow_s\n";
      }
    }
  }
  std::int64_t bad = 0;
  const auto monitor_start = canyon::core::pipeline_now_ns();
  canyon::pipeline::MonitorModel model(monitor_start);

  std::unique_ptr<pl::SolutionReader> solution_reader;
  std::unique_ptr<pl::TimingReader> timing_reader;
  std::unique_ptr<pl::RtcmReader> rtcm_reader;
  std::unique_ptr<pl::BridgedReader> bridged_reader;
  std::unique_ptr<pl::PriorReader> prior_reader;
  std::unique_ptr<pl::FloatReader> float_reader;
  std::unique_ptr<pl::AlignmentReader> alignment_reader;
  const auto on_solution = [&](canyon::msg::Solution&& m) {
    const std::int64_t now = canyon::core::pipeline_now_ns();
    const std::lock_guard lock(mutex);
    count_one();
    if (g_tool == "monitor") {
      model.add_solution(pl::to_sample(m, now));
      return;
    }
    if (g_tool == "echo") {
      std::printf("%s\n", pl::describe(m).c_str());
      std::fflush(stdout);
      return;
    }
    if (!pos && !nmea) {
      // CSV: every sample, those without a solution (status 0) too, so that the sequence numbers account for every
      // epoch; received_monotonic_ns is this recorder's clock (CLOCK_MONOTONIC, shared by a host's namespaces).
      char line[360];
      std::snprintf(line, sizeof line, "%llu,%d,%.3f,%d,%.4f,%.4f,%.4f,%.9f,%.9f,%.4f,%d,%.2f,%.2f,%lld\n",
                    static_cast<unsigned long long>(m.sequence_number()), m.gps_week(), m.gps_tow_s(), m.status(),
                    m.p_E_m()[0], m.p_E_m()[1], m.p_E_m()[2], m.lat_deg(), m.lon_deg(), m.height_m(),
                    m.num_satellites(), m.ratio(), m.age_s(), static_cast<long long>(now));
      raw << line << std::flush;  // followed live (a line a second): each sample reaches the file at once
      if (m.status() != 0 && !pl::from_msg(m)) ++bad;
      return;
    }
    if (m.status() == 0) return;  // no solution: not a record
    auto s = pl::from_msg(m);
    if (!s) {
      ++bad;
      if (error.empty()) error = s.error().to_string();
      return;
    }
    if (pos) {
      if (auto w = pos->write(*s); !w && error.empty()) error = w.error().to_string();
    } else if (auto w = nmea->write(*s, m.hdop()); !w && error.empty()) {
      error = w.error().to_string();
    }
  };
  const auto on_timing = [&](canyon::msg::StageTiming&& m) {
    const std::lock_guard lock(mutex);
    count_one();
    if (g_tool == "monitor") {
      model.add_timing(pl::to_sample(m));
    } else if (g_tool == "echo") {
      std::printf("%s\n", pl::describe(m).c_str());
      std::fflush(stdout);
    } else {
      const auto& st = m.stamps();
      raw << m.sequence_number() << ',' << m.gps_week() << ',' << m.gps_tow_s() << ',' << st.arrival_monotonic_ns();
      for (std::size_t i = 0; i < 6; ++i) raw << ',' << st.enter_monotonic_ns()[i] << ',' << st.exit_monotonic_ns()[i];
      raw << '\n';
    }
  };
  if (g_tool == "monitor" || solutions) {
    auto r = pl::SolutionReader::create(**participant, g_tool == "monitor" ? solution_topic : topic,
                                        canyon::dds::profile::kSolutionReader, on_solution);
    if (!r) return fail(r.error().to_string(), kExitRuntime);
    solution_reader = std::move(*r);
  }
  if (g_tool == "monitor" || ends_with(topic, "timing")) {
    auto r = pl::TimingReader::create(**participant, g_tool == "monitor" ? timing_topic : topic,
                                      canyon::dds::profile::kTimingReader, on_timing);
    if (!r) return fail(r.error().to_string(), kExitRuntime);
    timing_reader = std::move(*r);
  }
  if (g_tool != "monitor" && ends_with(topic, "rtcm")) {
    auto r = pl::RtcmReader::create(
        **participant, topic, canyon::dds::profile::kRtcmReader, [&](canyon::msg::RtcmFrame&& m) {
          const std::lock_guard lock(mutex);
          count_one();
          auto f = pl::from_msg(m);
          if (!f) {
            ++bad;
            if (error.empty()) error = f.error().to_string();
            return;
          }
          if (g_tool == "echo") {
            std::printf("rtcm #%llu message %u station %u %d %.3f %zu bytes\n",
                        static_cast<unsigned long long>(m.sequence_number()), m.message_number(), m.station_id(),
                        m.gps_week(), m.gps_tow_s(), f->bytes.size());
            std::fflush(stdout);
          } else {
            raw.write(reinterpret_cast<const char*>(f->bytes.data()), static_cast<std::streamsize>(f->bytes.size()));
          }
        });
    if (!r) return fail(r.error().to_string(), kExitRuntime);
    rtcm_reader = std::move(*r);
  }
  // Stage outputs: one line of text per sample (echo) or per record line (record).
  const auto text_sample = [&](const std::string& line) {
    const std::lock_guard lock(mutex);
    count_one();
    if (g_tool == "echo") {
      std::printf("%s\n", line.c_str());
      std::fflush(stdout);
    } else {
      raw << line << '\n';
    }
  };
  if (g_tool != "monitor" && ends_with(topic, "bridged")) {
    auto r = pl::BridgedReader::create(**participant, topic, canyon::dds::profile::kStageReader,
                                       [&](canyon::msg::BridgedEpoch&& m) { text_sample(pl::describe(m)); });
    if (!r) return fail(r.error().to_string(), kExitRuntime);
    bridged_reader = std::move(*r);
  }
  if (g_tool != "monitor" && ends_with(topic, "prior")) {
    auto r = pl::PriorReader::create(**participant, topic, canyon::dds::profile::kStageReader,
                                     [&](canyon::msg::Prior&& m) { text_sample(pl::describe(m)); });
    if (!r) return fail(r.error().to_string(), kExitRuntime);
    prior_reader = std::move(*r);
  }
  if (g_tool != "monitor" && ends_with(topic, "float")) {
    auto r = pl::FloatReader::create(**participant, topic, canyon::dds::profile::kStageReader,
                                     [&](canyon::msg::FloatSolution&& m) { text_sample(pl::describe(m)); });
    if (!r) return fail(r.error().to_string(), kExitRuntime);
    float_reader = std::move(*r);
  }
  if (g_tool != "monitor" && ends_with(topic, "alignment")) {
    auto r = pl::AlignmentReader::create(**participant, topic, canyon::dds::profile::kStageReader,
                                         [&](canyon::msg::Alignment&& m) { text_sample(pl::describe(m)); });
    if (!r) return fail(r.error().to_string(), kExitRuntime);
    alignment_reader = std::move(*r);
  }
  std::unique_ptr<pl::VioPoseReader> vio_reader;
  std::unique_ptr<pl::TimeSyncReader> timesync_reader;
  if (g_tool != "monitor" && ends_with(topic, "vio")) {
    auto r = pl::VioPoseReader::create(**participant, topic, canyon::dds::profile::kVioReader,
                                       [&](canyon::msg::VioPose&& m) {
                                         if (g_tool == "echo") return text_sample(pl::describe(m));
                                         auto pose = pl::from_msg(m);
                                         if (!pose) {
                                           const std::lock_guard lock(mutex);
                                           ++bad;
                                           if (error.empty()) error = pose.error().to_string();
                                           return;
                                         }
                                         text_sample(canyon::io::vio_csv_row(*pose));
                                       });
    if (!r) return fail(r.error().to_string(), kExitRuntime);
    vio_reader = std::move(*r);
  }
  if (g_tool != "monitor" && ends_with(topic, "timesync")) {
    auto r = pl::TimeSyncReader::create(
        **participant, topic, canyon::dds::profile::kVioReader, [&](canyon::msg::TimeSyncSample&& m) {
          if (g_tool == "echo") return text_sample(pl::describe(m));
          char line[96];
          std::snprintf(line, sizeof line, "%lld,%d,%.17g", static_cast<long long>(m.device_time_ns()), m.gps_week(),
                        m.gps_tow_s());
          text_sample(line);
        });
    if (!r) return fail(r.error().to_string(), kExitRuntime);
    timesync_reader = std::move(*r);
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  const auto matched = [&] {
    int n = 0;
    if (solution_reader) n += solution_reader->matched();
    if (timing_reader) n += timing_reader->matched();
    if (rtcm_reader) n += rtcm_reader->matched();
    if (bridged_reader) n += bridged_reader->matched();
    if (prior_reader) n += prior_reader->matched();
    if (float_reader) n += float_reader->matched();
    if (alignment_reader) n += alignment_reader->matched();
    if (vio_reader) n += vio_reader->matched();
    if (timesync_reader) n += timesync_reader->matched();
    return n;
  };
  const auto start = std::chrono::steady_clock::now();
  auto next_refresh = start + std::chrono::duration<double>(interval_s);
  bool seen_publisher = false;
  const auto report = [&] {
    const std::lock_guard lock(mutex);
    const std::int64_t now = canyon::core::pipeline_now_ns();
#ifdef CANYON_WITH_DASHBOARD
    // One snapshot for the terminal (--json) and the dashboard alike; the model makes only valid lines.
    const std::string line = (json || dashboard) ? model.json_line(now) : std::string();
    if (dashboard) (void)dashboard->push(line);
#else
    const std::string line = json ? model.json_line(now) : std::string();
#endif
    if (json) {
      std::printf("%s\n", line.c_str());
    } else {
      std::printf("\033[H\033[2J");
      for (const std::string& row : model.text(now)) std::printf("%s\n", row.c_str());
    }
    std::fflush(stdout);
  };
  while (!g_stop.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    const auto now = std::chrono::steady_clock::now();
    if (count > 0 && received.load() >= count) break;
    if (duration_s > 0 && now - start >= std::chrono::duration<double>(duration_s)) break;
    const int m = matched();
    if (m > 0) seen_publisher = true;
    if (until_gone && seen_publisher && m == 0) break;
    if (g_tool == "monitor" && now >= next_refresh) {
      report();
      next_refresh += std::chrono::duration<double>(interval_s);
    }
  }
  // Readers first (no callback after this), then the outputs.
  solution_reader.reset();
  timing_reader.reset();
  rtcm_reader.reset();
  bridged_reader.reset();
  prior_reader.reset();
  float_reader.reset();
  alignment_reader.reset();
  if (g_tool == "monitor") report();
  if (pos) {
    if (auto c = pos->close(); !c && error.empty()) error = c.error().to_string();
  }
  if (nmea) {
    if (auto c = nmea->close(); !c && error.empty()) error = c.error().to_string();
  }
  if (raw.is_open()) {
    raw.close();
    if (!raw && error.empty()) error = "cannot write " + out;
  }
  if (g_tool == "record") {
    std::fprintf(stderr, "canyon record: %lld samples of %s to %s%s\n", static_cast<long long>(received.load()),
                 topic.c_str(), out.c_str(),
                 bad > 0 ? (" (" + std::to_string(bad) + " malformed, skipped)").c_str() : "");
  }
  if (!error.empty()) return fail(error, kExitRuntime);
  return 0;
}

/// "record" for .../canyon-record, and so on; empty for any other name.
std::string tool_from_program_name(const std::string& program) {
  const std::string name = program.substr(program.find_last_of('/') + 1);  // npos + 1 == 0: no folder
  for (const char* tool : {"record", "echo", "monitor"}) {
    if (name == std::string("canyon-") + tool) return tool;
  }
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  g_tool = tool_from_program_name(argc > 0 ? argv[0] : "");
  if (g_tool.empty()) {
    std::cerr << "error: run this executable as canyon-record, canyon-echo or canyon-monitor (or through `canyon "
                 "record|echo|monitor`), not as '"
              << (argc > 0 ? argv[0] : "") << "'\n";
    return kExitUsage;
  }
  return canyon::apps::guarded_main("canyon-" + g_tool, kExitRuntime, run, argc, argv);
}
