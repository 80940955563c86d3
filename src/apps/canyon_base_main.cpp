// canyon-base: the base station. Reads the base receiver, produces RTCM 3 and publishes it as RtcmFrame samples on a
// DDS topic and on its NTRIP caster and TCP server (config/base.yaml documents every option). `canyon base ...`
// runs this executable; the application is canyon::dds::BaseApp. SIGINT/SIGTERM stop it cleanly (outputs flushed,
// DDS entities deleted). Exit codes: 0 success, 1 input or runtime failure, 2 bad command line or configuration.

#include <iostream>
#include <string>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "canyon/dds/base_app.hpp"

#include "main_guard.hpp"

namespace {

namespace dds = canyon::dds;

int run(int argc, char** argv) {
  CLI::App cli{"canyon-base: the base station publishing RTCM 3 corrections over DDS, NTRIP and TCP"};
  std::string config_file;
  bool print_config = false;
  dds::BaseOptions options;
  int ntrip_port = -1;
  int tcp_port = -1;
  double pace = -1.0;
  bool quiet = false;
  cli.add_option("--config", config_file, "YAML configuration (strict; config/base.yaml documents every key)")
      ->required()
      ->check(CLI::ExistingFile);
  cli.add_flag("--print-config", print_config, "Print the effective configuration as YAML and exit");
  cli.add_option("--wait-for-clients", options.wait_clients,
                 "Start once this many subscribers (NTRIP, TCP clients, DDS readers) are connected")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--wait-timeout", options.wait_timeout_s, "Give up waiting for subscribers after this many seconds");
  cli.add_option("--ntrip-port", ntrip_port, "Override outputs.ntrip.port (0: any free port)")
      ->check(CLI::Range(0, 65535));
  cli.add_option("--tcp-port", tcp_port, "Override outputs.tcp.port (0: any free port)")->check(CLI::Range(0, 65535));
  cli.add_option("--pace", pace, "Override input.pace (file replay speed; 0 as fast as possible)")
      ->check(CLI::NonNegativeNumber);
  cli.add_flag("-q,--quiet", quiet, "Warnings and errors only");
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : dds::kExitUsage;
  }
  spdlog::set_pattern("[%Y-%m-%d %H:%M:%S.%e] [canyon-base] [%^%l%$] %v");
  if (quiet) spdlog::set_level(spdlog::level::warn);

  auto config = canyon::config::load_base_config(config_file);
  if (!config) {
    spdlog::error("{}", config.error().to_string());
    return dds::kExitUsage;
  }
  if (ntrip_port >= 0) config->ntrip.port = ntrip_port;
  if (tcp_port >= 0) config->tcp.port = tcp_port;
  if (pace >= 0) config->input.pace = pace;
  if (print_config) {
    std::cout << canyon::config::to_yaml(*config);
    return 0;
  }
  if (const std::string e = config->validate(); !e.empty()) {
    spdlog::error("{}: {}", config_file, e);
    return dds::kExitUsage;
  }
  options.config = std::move(*config);
  return dds::run_app<dds::BaseApp>(std::move(options), [](const dds::AppError& e) { spdlog::error("{}", e.what()); });
}

}  // namespace

int main(int argc, char** argv) {
  return canyon::apps::guarded_main("canyon-base", canyon::dds::kExitRuntime, run, argc, argv);
}
