// canyon-rover: the real-time rover. The rover's observations replayed from RINEX at real-time pace (or faster),
// base corrections from a RINEX file or from the DDS RtcmFrame topic, VIO from files or from the DDS VioPose and
// TimeSyncSample topics (pipeline/live_vio.hpp), through the six-stage threaded
// pipeline (pipeline/epoch_pipeline.hpp, the same stages as canyon process); solutions and stage timing published on
// DDS (idl/RoverPipeline.idl). `canyon rover ...` runs this executable; config/rover.yaml documents the configuration;
// the application is canyon::dds::RoverApp. SIGINT/SIGTERM stop it cleanly: ingest stops, the epochs in flight are
// finished and published. Exit codes: 0 success, 1 input or runtime failure, 2 bad command line or configuration.

#include <iostream>
#include <string>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "canyon/dds/rover_app.hpp"

#include "main_guard.hpp"

namespace {

namespace dds = canyon::dds;

/// Command-line overrides of rover.yaml.
struct Overrides {
  double pace = -1.0;
  std::string out;
  std::string pipeline_mode;
};

/// The configuration with the overrides applied and checked; the exit status if the program ends here.
std::optional<int> configure(dds::RoverOptions& options, const Overrides& o, bool print_config) {
  auto config = canyon::config::load_rover_config(options.config_file);
  if (!config) {
    spdlog::error("{}", config.error().to_string());
    return dds::kExitUsage;
  }
  if (o.pace >= 0.0) config->pace = o.pace;
  if (!o.out.empty()) config->estimator.out = o.out;
  if (!o.pipeline_mode.empty()) config->pipeline.threaded = o.pipeline_mode == "threaded";
  if (!o.pipeline_mode.empty() && !config->pipeline.threaded && config->pipeline.pinned()) {
    spdlog::warn("pipeline.cpu_affinity applies to the threaded pipeline only: ignored with --pipeline sequential");
    config->pipeline.cpu_affinity = {};
  }
  if (print_config) {
    std::cout << canyon::config::to_yaml(*config);
    return 0;
  }
  if (const std::string e = config->validate(); !e.empty()) {
    spdlog::error("{}: {}", options.config_file, e);
    return dds::kExitUsage;
  }
  if (const std::string e = config->pipeline.unavailable_cpu(); !e.empty()) {
    spdlog::error("{}: pipeline.{}", options.config_file, e);
    return dds::kExitUsage;
  }
  options.config = std::move(*config);
  return std::nullopt;
}

int run(int argc, char** argv) {
  CLI::App cli{"canyon-rover: the real-time rover pipeline (six stage threads, DDS in and out)"};
  dds::RoverOptions options;
  Overrides o;
  bool print_config = false;
  bool quiet = false;
  cli.add_option("--config", options.config_file, "YAML configuration (strict; config/rover.yaml documents every key)")
      ->required()
      ->check(CLI::ExistingFile);
  cli.add_flag("--print-config", print_config, "Print the effective configuration as YAML and exit");
  cli.add_option("--pace", o.pace, "Override input.pace (rover replay speed; 0 as fast as possible)")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--out", o.out, "Override estimator.out (.pos the rover writes itself)");
  cli.add_option("--pipeline", o.pipeline_mode, "Override pipeline.threaded: threaded or sequential")
      ->check(CLI::IsMember({"threaded", "sequential"}));
  cli.add_option("--wait-for-subscribers", options.wait_subscribers,
                 "Start once this many readers of the solution topic (and, with ros2.enabled, of the ROS 2 topics, "
                 "counted together) are matched (so they miss nothing)")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--wait-timeout", options.wait_timeout_s, "Give up waiting for subscribers after this many seconds");
  cli.add_flag("-q,--quiet", quiet, "Warnings and errors only");
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : dds::kExitUsage;
  }
  spdlog::set_pattern("[%Y-%m-%d %H:%M:%S.%e] [canyon-rover] [%^%l%$] %v");
  if (quiet) spdlog::set_level(spdlog::level::warn);
  if (const std::optional<int> done = configure(options, o, print_config)) return *done;
  return dds::run_app<dds::RoverApp>(std::move(options), [](const dds::AppError& e) { spdlog::error("{}", e.what()); });
}

}  // namespace

int main(int argc, char** argv) {
  return canyon::apps::guarded_main("canyon-rover", canyon::dds::kExitRuntime, run, argc, argv);
}
