// canyon-base: the base station. Reads the base receiver, produces RTCM 3 and publishes it as RtcmFrame samples on a
// DDS topic and on its NTRIP caster and TCP server (config/base.yaml documents every option). `canyon base ...`
// runs this executable. SIGINT/SIGTERM stop it cleanly (outputs flushed, DDS entities deleted).
// Exit codes: 0 success, 1 input or runtime failure, 2 bad command line or configuration.

#include <atomic>
#include <csignal>
#include <iostream>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "canyon/base/base_station.hpp"
#include "canyon/config/base_config.hpp"
#include "canyon/dds/dds.hpp"
#include "canyon/dds/rtcm_frame.hpp"

#include "main_guard.hpp"

namespace {

constexpr int kExitRuntime = 1;
constexpr int kExitUsage = 2;

std::atomic<canyon::base::BaseStation*> g_base{nullptr};

extern "C" void on_signal(int /*signal*/) {
  if (canyon::base::BaseStation* base = g_base.load()) base->stop();
}

int run(int argc, char** argv) {
  CLI::App cli{"canyon-base: the base station publishing RTCM 3 corrections over DDS, NTRIP and TCP"};
  std::string config_file;
  bool print_config = false;
  int wait_clients = 0;
  double wait_timeout_s = 30.0;
  int ntrip_port = -1;
  int tcp_port = -1;
  double pace = -1.0;
  bool quiet = false;
  cli.add_option("--config", config_file, "YAML configuration (strict; config/base.yaml documents every key)")
      ->required()
      ->check(CLI::ExistingFile);
  cli.add_flag("--print-config", print_config, "Print the effective configuration as YAML and exit");
  cli.add_option("--wait-for-clients", wait_clients,
                 "Start once this many subscribers (NTRIP, TCP clients, DDS readers) are connected")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--wait-timeout", wait_timeout_s, "Give up waiting for subscribers after this many seconds");
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
    return code == 0 ? 0 : kExitUsage;
  }
  spdlog::set_pattern("[%Y-%m-%d %H:%M:%S.%e] [canyon-base] [%^%l%$] %v");
  if (quiet) spdlog::set_level(spdlog::level::warn);

  auto config = canyon::config::load_base_config(config_file);
  if (!config) {
    spdlog::error("{}", config.error().to_string());
    return kExitUsage;
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
    return kExitUsage;
  }

  // DDS first: its profiles must be loaded before any participant exists.
  std::unique_ptr<canyon::dds::DdsParticipant> participant;
  std::unique_ptr<canyon::dds::RtcmWriter> writer;
  if (config->dds.enabled) {
    if (auto s = canyon::dds::load_profiles(config->dds.profiles); !s.ok()) {
      spdlog::error("{}", s.error().to_string());
      return kExitUsage;
    }
    auto p = canyon::dds::DdsParticipant::create(
        config->dds.domain, canyon::dds::load_profiles(config->dds.profiles)->participant_profile());
    if (!p) {
      spdlog::error("{}", p.error().to_string());
      return kExitRuntime;
    }
    participant = std::move(*p);
    auto w = canyon::dds::RtcmWriter::create(*participant, config->dds.topic, canyon::dds::profile::kRtcmWriter);
    if (!w) {
      spdlog::error("{}", w.error().to_string());
      return kExitRuntime;
    }
    writer = std::move(*w);
    spdlog::info("DDS: publishing canyon::msg::RtcmFrame on topic '{}', domain {} (profiles {})", config->dds.topic,
                 config->dds.domain, config->dds.profiles.empty() ? "shipped" : config->dds.profiles);
  }

  auto base = canyon::base::BaseStation::create(*config, [](const std::string& line) { spdlog::info("{}", line); });
  if (!base) {
    spdlog::error("{}", base.error().to_string());
    return kExitRuntime;
  }
  std::uint64_t refused = 0;
  if (writer) {
    canyon::dds::RtcmWriter* w = writer.get();
    (*base)->add_sink([w, &refused](const canyon::base::BaseFrame& frame) {
      if (!canyon::dds::publish_rtcm_frame(*w, frame)) ++refused;
    });
    (*base)->set_subscriber_count([w] { return w->matched(); });
  }
  g_base.store(base->get());
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  if (wait_clients > 0) {
    spdlog::info("waiting for {} subscriber(s) (at most {} s)", wait_clients, wait_timeout_s);
    if (!(*base)->wait_for_clients(wait_clients, wait_timeout_s) && !(*base)->stop_requested()) {
      spdlog::warn("only some subscribers connected within {} s; starting anyway", wait_timeout_s);
    }
  }
  const auto status = (*base)->run();
  if (writer && !writer->wait_for_acknowledgments(5.0)) {
    spdlog::warn("DDS: not every frame was acknowledged by every reader within 5 s");
  }
  if (refused > 0) spdlog::warn("DDS: {} frames refused by the writer (history full)", refused);
  g_base.store(nullptr);
  if (!status.ok()) {
    spdlog::error("{}", status.error().to_string());
    return kExitRuntime;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return canyon::apps::guarded_main("canyon-base", kExitRuntime, run, argc, argv);
}
