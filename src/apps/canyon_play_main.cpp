// canyon-play: publishes an MCAP session recorded by canyon record (--out SESSION.mcap) on DDS again, at the recorded
// pace or faster (--pace), so that a field session re-runs at the desk (canyon::dds::PlayApp). `canyon play ...` runs
// this executable. SIGINT/SIGTERM stop it. Exit codes: 0 success, 1 input or runtime failure, 2 bad command line.

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "canyon/dds/play_app.hpp"

#include "main_guard.hpp"

namespace {

namespace dds = canyon::dds;

int run(int argc, char** argv) {
  CLI::App cli{"canyon-play: publish an MCAP session recorded by canyon record on DDS again"};
  dds::PlayOptions a;
  bool quiet = false;
  cli.add_option("session", a.session, "MCAP file (canyon record ... --out SESSION.mcap)")
      ->required()
      ->check(CLI::ExistingFile);
  cli.add_option("--pace", a.pace, "Replay speed: 1 as recorded, 10 ten times faster, 0 as fast as the writers take it")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--domain", a.domain, "DDS domain id")->check(CLI::Range(0, 232));
  cli.add_option("--profiles", a.profiles,
                 "Deployment profiles (transport and discovery, deploy/dds/*.xml) on top of the shipped "
                 "config/dds/canyon_profiles.xml");
  cli.add_option("--wait-for-readers", a.wait_readers, "Start once this many readers of each topic are matched")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--wait-timeout", a.wait_timeout_s, "Give up waiting for readers after this many seconds");
  cli.add_option("--linger", a.linger_s, "At the end, stay up to this many seconds while readers are matched")
      ->check(CLI::NonNegativeNumber);
  cli.add_flag("-q,--quiet", quiet, "Warnings and errors only");
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : dds::kExitUsage;
  }
  spdlog::set_pattern("[%Y-%m-%d %H:%M:%S.%e] [canyon-play] [%^%l%$] %v");
  if (quiet) spdlog::set_level(spdlog::level::warn);
  return dds::run_app<dds::PlayApp>(std::move(a), [](const dds::AppError& e) { spdlog::error("{}", e.what()); });
}

}  // namespace

int main(int argc, char** argv) {
  return canyon::apps::guarded_main("canyon-play", canyon::dds::kExitRuntime, run, argc, argv);
}
