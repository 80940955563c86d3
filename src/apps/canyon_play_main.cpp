// canyon-play: publishes an MCAP session recorded by canyon record (--out SESSION.mcap) on DDS again, at the recorded
// pace or faster (--pace), so that a field session re-runs at the desk (canyon::dds::PlayApp). `canyon play ...` runs
// this executable. SIGINT/SIGTERM stop it. With --extract DIR it publishes nothing and writes the rover's inputs the
// session holds as the files canyon process reads (dds/session_files.hpp; canyon process --session runs this).
// Exit codes: 0 success, 1 input or runtime failure, 2 bad command line.

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "canyon/dds/play_app.hpp"
#include "canyon/dds/session_files.hpp"

#include "main_guard.hpp"

namespace {

namespace dds = canyon::dds;

int extract(const std::string& session, const std::string& dir) {
  const auto files = dds::extract_session(session, dir);
  if (!files) {
    spdlog::error("{}", files.error().to_string());
    return dds::kExitRuntime;
  }
  for (const std::string& problem : files->problems) spdlog::warn("{}", problem);
  for (const std::string& line : files->written) spdlog::info("{}", line);
  if (files->rover_obs.empty()) {
    spdlog::error(
        "{}: no rover observations (canyon/observations: record a rover run with "
        "dds.publish_observations: true)",
        session);
    return dds::kExitRuntime;
  }
  return dds::kExitOk;
}

int run(int argc, char** argv) {
  CLI::App cli{"canyon-play: publish an MCAP session recorded by canyon record on DDS again"};
  dds::PlayOptions a;
  bool quiet = false;
  cli.add_option("session", a.session, "MCAP file (canyon record ... --out SESSION.mcap)")
      ->required()
      ->check(CLI::ExistingFile);
  cli.add_option("--pace", a.pace, "Replay speed: 1 as recorded, 10 ten times faster, 0 as fast as the writers take it")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--topic", a.topics,
                 "Play only this topic (repeatable), e.g. the rover's inputs canyon/rtcm canyon/vio canyon/timesync to "
                 "run a rover on them again; default: every channel canyon knows");
  cli.add_option("--domain", a.domain, "DDS domain id")->check(CLI::Range(0, 232));
  cli.add_option("--profiles", a.profiles,
                 "Deployment profiles (transport and discovery, deploy/dds/*.xml) on top of the shipped "
                 "config/dds/canyon_profiles.xml");
  cli.add_option("--wait-for-readers", a.wait_readers, "Start once this many readers of each topic are matched")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--wait-timeout", a.wait_timeout_s, "Give up waiting for readers after this many seconds");
  cli.add_option("--linger", a.linger_s, "At the end, stay up to this many seconds while readers are matched")
      ->check(CLI::NonNegativeNumber);
  std::string extract_dir;
  cli.add_option("--extract", extract_dir,
                 "Publish nothing: write the rover's inputs the session holds (canyon/observations, rtcm, vio, "
                 "timesync) into this folder as rover.obs, base.rtcm3, nav.rnx, vio.csv, timesync.csv");
  cli.add_flag("-q,--quiet", quiet, "Warnings and errors only");
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : dds::kExitUsage;
  }
  spdlog::set_pattern("[%Y-%m-%d %H:%M:%S.%e] [canyon-play] [%^%l%$] %v");
  if (quiet) spdlog::set_level(spdlog::level::warn);
  if (!extract_dir.empty()) return extract(a.session, extract_dir);
  return dds::run_app<dds::PlayApp>(std::move(a), [](const dds::AppError& e) { spdlog::error("{}", e.what()); });
}

}  // namespace

int main(int argc, char** argv) {
  return canyon::apps::guarded_main("canyon-play", canyon::dds::kExitRuntime, run, argc, argv);
}
