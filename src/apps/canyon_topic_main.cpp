// canyon-record, canyon-echo and canyon-monitor (one executable, canyon-monitor, with canyon-record and canyon-echo
// links to it; the name it runs under selects the tool): consumers of the rover's and the base's DDS topics.
// `canyon record|echo|monitor ...` runs them; the application is canyon::dds::TopicApp (topic_app.hpp says what each
// tool does). All of them stop on SIGINT/SIGTERM, after --count samples, after --duration seconds, or once the
// publishers they matched are all gone (--until-gone, on by default for record and monitor).
// Exit codes: 0 success, 1 runtime failure, 2 bad command line.

#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "canyon/dds/topic_app.hpp"

#include "main_guard.hpp"

namespace {

namespace dds = canyon::dds;

void add_monitor_options(CLI::App& cli, dds::TopicOptions& o) {
  cli.add_option("--solution-topic", o.solution_topic, "Solution topic");
  cli.add_option("--timing-topic", o.timing_topic, "Stage timing topic");
  cli.add_flag("--json", o.json, "One JSON object per line (schema: include/canyon/pipeline/monitor_model.hpp)");
  cli.add_option("--interval", o.interval_s, "Refresh period (s)")->check(CLI::Range(0.05, 3600.0));
#ifdef CANYON_WITH_DASHBOARD
  cli.add_option("--http", o.http_port, "Also serve the live dashboard (web page, /events, /metrics) on this port")
      ->check(CLI::Range(0, 65535));
  cli.add_option("--http-host", o.dashboard.host, "Address the dashboard listens on (0.0.0.0: every interface)");
  cli.add_option("--web", o.dashboard.web_dir, "Folder of the bundled dashboard page (default: build/web/dist)");
#endif
}

int run(dds::TopicTool tool, int argc, char** argv) {
  const std::string name = dds::tool_name(tool);
  CLI::App cli{"canyon-" + name};
  dds::TopicOptions o;
  o.tool = tool;
  o.until_gone = tool != dds::TopicTool::Echo;
  std::vector<std::string> topics;
  if (tool != dds::TopicTool::Monitor) {
    cli.add_option("topic", topics,
                   "canyon/solution, canyon/timing, canyon/rtcm, canyon/bridged, canyon/alignment, canyon/prior, "
                   "canyon/float, canyon/vio or canyon/timesync (record to .mcap: any number of them, "
                   "canyon/observations, and the ROS 2 topics rt/canyon/fix, rt/canyon/odometry, rt/diagnostics, "
                   "rt/vio/odometry, rt/rtcm)")
        ->required();
  } else {
    add_monitor_options(cli, o);
  }
  if (tool == dds::TopicTool::Record) {
    cli.add_option(
           "--out", o.out,
           "Output file: .pos, .nmea or .csv (solutions), .rtcm3 (canyon/rtcm), .csv; .mcap: every topic given, "
           "as it came off the wire, with its schema (Foxglove, mcap tools, canyon play)")
        ->required();
    cli.add_option("--mcap-compression", o.mcap.compression,
                   ".mcap: zstd (indexed chunks, the default) or \"\" (unchunked, uncompressed messages)")
        ->check(CLI::IsMember({"zstd", ""}));
    cli.add_option("--mcap-chunk-kib", o.mcap_chunk_kib,
                   ".mcap with zstd: uncompressed KiB per chunk (a chunk reaches the file when full or at the end; "
                   "SIGINT and SIGTERM end the recording cleanly, a killed recorder loses its open chunk)")
        ->check(CLI::Range(1, 65536));
  }
  cli.add_option("--domain", o.domain, "DDS domain id")->check(CLI::Range(0, 232));
  cli.add_option("--profiles", o.profiles,
                 "Deployment profiles (transport and discovery, deploy/dds/*.xml) on top of the shipped "
                 "config/dds/canyon_profiles.xml");
  cli.add_option("--count", o.count, "Stop after this many samples (0: no limit)")->check(CLI::NonNegativeNumber);
  cli.add_option("--duration", o.duration_s, "Stop after this many seconds (0: no limit)")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--until-gone", o.until_gone, "Stop once every matched publisher has left (true/false)");
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : dds::kExitUsage;
  }
  if (!topics.empty()) {
    o.topic = topics.front();
    o.more_topics.assign(topics.begin() + 1, topics.end());
  }
#ifdef CANYON_WITH_DASHBOARD
  if (o.http_port >= 0 && o.dashboard.web_dir.empty()) {
    o.dashboard.web_dir = canyon::dashboard::find_web_dir(CANYON_WEB_DIST_DIR);
  }
#endif
  return dds::run_app<dds::TopicApp>(std::move(o), [&name](const dds::AppError& e) {
    std::cerr << "canyon " << name << ": error: " << e.what() << "\n";
  });
}

/// The tool for .../canyon-record, and so on; none for any other name.
std::optional<dds::TopicTool> tool_from_program_name(const std::string& program) {
  const std::string name = program.substr(program.find_last_of('/') + 1);  // npos + 1 == 0: no folder
  for (const dds::TopicTool tool : {dds::TopicTool::Record, dds::TopicTool::Echo, dds::TopicTool::Monitor}) {
    if (name == std::string("canyon-") + dds::tool_name(tool)) return tool;
  }
  return std::nullopt;
}

}  // namespace

int main(int argc, char** argv) {
  const auto tool = tool_from_program_name(argc > 0 ? argv[0] : "");
  if (!tool) {
    std::cerr << "error: run this executable as canyon-record, canyon-echo or canyon-monitor (or through `canyon "
                 "record|echo|monitor`), not as '"
              << (argc > 0 ? argv[0] : "") << "'\n";
    return canyon::dds::kExitUsage;
  }
  return canyon::apps::guarded_main(
      std::string("canyon-") + canyon::dds::tool_name(*tool), canyon::dds::kExitRuntime,
      [&tool](int c, char** v) { return run(*tool, c, v); }, argc, argv);
}
