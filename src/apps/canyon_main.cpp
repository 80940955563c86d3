// The `canyon` command: subcommands for canyon's jobs. Exit codes: 0 success, 1 bad input or failed run,
// 2 bad command line or configuration.

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <malloc.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include "canyon/commands/check_fixes.hpp"
#include "canyon/commands/convert.hpp"
#include "canyon/commands/demo.hpp"
#include "canyon/commands/evaluate.hpp"
#include "canyon/commands/process.hpp"
#include "canyon/commands/simulate.hpp"
#include "canyon/config/base_config.hpp"
#include "canyon/config/process_config.hpp"
#include "canyon/config/rover_config.hpp"
#include "canyon/config/scenario_config.hpp"
#include "canyon/core/constants.hpp"
#include "canyon/core/satellite.hpp"
#include "canyon/core/solution.hpp"
#include "canyon/eval/leave_out.hpp"
#include "canyon/io/pos_file.hpp"

#include "main_guard.hpp"

namespace {

constexpr int kExitInput = 1;
constexpr int kExitUsage = 2;

/// A one-line progress bar on a terminal; nothing when stderr is not a terminal (logs, CI).
class ProgressBar {
 public:
  explicit ProgressBar(bool enabled) : enabled_(enabled && isatty(fileno(stderr)) != 0) {}
  void update(int epochs, double fraction) {
    if (!enabled_) return;
    const int percent = static_cast<int>(100.0 * std::clamp(fraction, 0.0, 1.0));
    if (percent == last_percent_ && fraction < 1.0) return;
    last_percent_ = percent;
    constexpr int kWidth = 40;
    const int filled = kWidth * percent / 100;
    std::fprintf(stderr, "\r[%.*s%*s] %3d%% %d epochs", filled, "########################################",
                 kWidth - filled, "", percent, epochs);
    std::fflush(stderr);
  }
  /// Ends the bar's line (after the last update).
  void finish() {
    if (enabled_ && last_percent_ >= 0) std::fprintf(stderr, "\n");
  }

 private:
  bool enabled_;
  int last_percent_ = -1;
};

struct ProcessArgs {
  std::string config_file;
  std::string mode;
  std::string rover;
  std::string base;
  std::string vio;
  std::string timesync;
  std::string base_pos;
  std::string exclude_sats;
  int exclude_most_observed = -1;
  std::vector<std::string> nav;
  std::string out;
  std::string nmea;
  std::string coordinates;
  std::string time_format;
  double elevation_mask_deg = -1.0;
  bool print_config = false;
  CLI::Option* describe_config = nullptr;  ///< given: print the keys of describe_what's configuration
  std::string describe_what;               ///< process (also when empty), rover, base or scenario
  bool quiet = false;
  bool verbose = false;
  std::string pipeline = "bridge-ahead";
  std::string session;      ///< process only: a recorded MCAP session whose rover inputs are processed
  std::string session_dir;  ///< where its inputs are written (kept); empty: a temporary folder (removed)
};

/// The options of canyon process that check-fixes shares: configuration, inputs, outputs, exclusions, pipeline.
void add_process_options(CLI::App* cmd, ProcessArgs& args) {
  cmd->add_option("--config", args.config_file, "YAML configuration (strict: unknown keys are errors)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--mode", args.mode, "Processing mode: spp, rtk or fusion (RTK aided by VIO, the paper's method)")
      ->check(CLI::IsMember({"spp", "rtk", "fusion"}));
  cmd->add_option("--rover", args.rover, "Rover RINEX observation file (2.x/3.x, may be gzip-compressed)");
  cmd->add_option("--base", args.base, "Base RINEX observation file (rtk, fusion)");
  cmd->add_option("--vio", args.vio, "VIO poses, vio.csv (fusion; DESIGN.md file contract)");
  cmd->add_option("--timesync", args.timesync, "The VIO device's GPS time-sync pairs, timesync.csv (fusion)");
  cmd->add_option("--base-pos", args.base_pos, "Base antenna ECEF X,Y,Z in metres (default: base file header)");
  cmd->add_option("--exclude-sats", args.exclude_sats, "Satellites never used, e.g. G05,E11");
  cmd->add_option("--exclude-most-observed", args.exclude_most_observed,
                  "Leave out the N satellites tracked in the most rover epochs (the paper's exclusion experiment)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--nav", args.nav, "RINEX navigation file (repeat for several)");
  cmd->add_option("--out", args.out, "Solution file, RTKLIB .pos format");
  cmd->add_option("--nmea", args.nmea, "Also write the solutions as NMEA GGA sentences to this file");
  cmd->add_option("--coordinates", args.coordinates, "Output coordinates: llh or ecef")
      ->check(CLI::IsMember({"llh", "ecef"}));
  cmd->add_option("--time-format", args.time_format, "Output time: tow (GPST week, s) or calendar")
      ->check(CLI::IsMember({"tow", "calendar"}));
  cmd->add_option("--elevation-mask-deg", args.elevation_mask_deg, "Elevation mask (deg), default 15")
      ->check(CLI::Range(0.0, 89.9));
  cmd->add_option("--pipeline", args.pipeline,
                  "rtk and fusion: run the six stages bridge-ahead (the default: ingest and the time bridge on a "
                  "second thread, ahead of the other four), sequential (one thread) or threaded (six threads and "
                  "queues, as canyon rover); all three give the same solutions")
      ->check(CLI::IsMember({"bridge-ahead", "sequential", "threaded"}));
  cmd->add_flag("-q,--quiet", args.quiet, "No progress bar and no summary line");
  cmd->add_flag("-v,--verbose", args.verbose, "Log why epochs got no solution or, in rtk mode, no fix (first 100)");
}

void add_process_command(CLI::App& app, ProcessArgs& args) {
  CLI::App* cmd = app.add_subcommand("process", "Process recorded observations into a solution file (.pos)");
  add_process_options(cmd, args);
  cmd->add_option("--session", args.session,
                  "A session recorded by canyon record (SESSION.mcap) as the input: the rover's epochs "
                  "(canyon/observations), the base's RTCM 3 (canyon/rtcm) and its ephemerides unless --nav is given, "
                  "the VIO (canyon/vio, canyon/timesync), each unless given (--base BASE.obs ...); runs "
                  "canyon-play --extract")
      ->check(CLI::ExistingFile);
  cmd->add_option("--session-dir", args.session_dir,
                  "--session: write the extracted inputs into this folder and keep them (default: a temporary one)");
  cmd->add_flag("--print-config", args.print_config, "Print the effective configuration as YAML and exit");
  args.describe_config =
      cmd->add_option("--describe-config", args.describe_what,
                      "Print every configuration key with its unit, default and meaning, and exit: of canyon process "
                      "(the default), or of rover, base or a simulation scenario")
          ->expected(0, 1)
          ->check(CLI::IsMember({"process", "rover", "base", "scenario"}));
}

/// Input defects are often repeated every epoch: the first few warnings, and a count of the rest ("... and N
/// `rest`"), unless `verbose`.
void print_warnings(const std::vector<std::string>& warnings, bool verbose, const char* rest) {
  constexpr std::size_t kMaxWarningsShown = 5;
  for (std::size_t i = 0; i < warnings.size() && (verbose || i < kMaxWarningsShown); ++i) {
    std::fprintf(stderr, "canyon: warning: %s\n", warnings[i].c_str());
  }
  if (!verbose && warnings.size() > kMaxWarningsShown) {
    std::fprintf(stderr, "canyon: warning: ... and %zu %s (-v shows all)\n", warnings.size() - kMaxWarningsShown, rest);
  }
}

/// --describe-config [WHAT]: the keys of a configuration, from the tables that parse it; process's defaults are
/// those of `mode` (--mode; spp without it).
int print_key_descriptions(const std::string& what, const std::string& mode) {
  namespace config = canyon::config;
  if (what == "rover") {
    std::cout << "# canyon rover --config FILE: every key (strict YAML; estimator: holds canyon process's keys)\n"
              << config::format_descriptions(config::describe_rover_config());
  } else if (what == "base") {
    std::cout << "# canyon base --config FILE: every key (strict YAML)\n"
              << config::format_descriptions(config::describe_base_config());
  } else if (what == "scenario") {
    std::cout << "# canyon simulate --scenario FILE.yaml: every key (strict YAML)\n"
              << config::format_descriptions(config::describe_scenario());
  } else {
    const config::ProcessMode process_mode = config::mode_from_name(mode).value_or(config::ProcessMode::Spp);
    std::cout << "# canyon process --config FILE: every key (strict YAML; the command line overrides the file); "
              << "defaults of mode " << config::mode_name(process_mode)
              << " (--mode rtk or fusion shows theirs; a file's mode: sets its defaults)\n"
              << config::format_descriptions(config::describe_process_config(process_mode));
  }
  return 0;
}

/// The configuration of canyon process and check-fixes: the mode's defaults, the file, then the command line. An
/// exit code when it cannot be built (the error printed).
std::optional<int> build_process_config(const ProcessArgs& args, canyon::config::ProcessConfig& config) {
  // Defaults: the recommended set-up of the mode (--mode, else the file's mode:, else spp), then the file, then the
  // command line.
  std::optional<canyon::config::ProcessMode> mode;
  if (!args.mode.empty()) mode = canyon::config::mode_from_name(args.mode);  // CLI checked the name
  config = canyon::config::process_defaults(mode.value_or(canyon::config::ProcessMode::Spp));
  if (!args.config_file.empty()) {
    auto loaded = canyon::config::load_process_config(args.config_file, mode);
    if (!loaded) {
      std::cerr << "canyon: error: " << loaded.error().to_string() << "\n";
      return kExitUsage;
    }
    config = std::move(*loaded);
  }
  if (!args.rover.empty()) config.rover_obs = args.rover;
  if (!args.base.empty()) config.base_obs = args.base;
  if (!args.vio.empty()) config.vio = args.vio;
  if (!args.timesync.empty()) config.timesync = args.timesync;
  if (!args.base_pos.empty()) {
    double x = 0, y = 0, z = 0;
    char tail = 0;
    if (std::sscanf(args.base_pos.c_str(), "%lf,%lf,%lf%c", &x, &y, &z, &tail) != 3) {
      std::cerr << "canyon: error: --base-pos must be X,Y,Z (ECEF metres), not '" << args.base_pos << "'\n";
      return kExitUsage;
    }
    config.base_position_E_m = Eigen::Vector3d(x, y, z);
  }
  if (!args.exclude_sats.empty()) {
    std::vector<canyon::core::SatelliteId> excluded;
    std::string item;
    for (std::size_t start = 0; start <= args.exclude_sats.size();) {
      const std::size_t comma = std::min(args.exclude_sats.find(',', start), args.exclude_sats.size());
      item = args.exclude_sats.substr(start, comma - start);
      const auto sat = canyon::core::parse_satellite(item);
      if (!sat) {
        std::cerr << "canyon: error: --exclude-sats: '" << item << "' is not a satellite (e.g. G05,E11)\n";
        return kExitUsage;
      }
      excluded.push_back(*sat);
      start = comma + 1;
    }
    config.spp.excluded = excluded;
    config.rtk.observables.excluded = excluded;
  }
  if (args.exclude_most_observed >= 0) config.exclude_most_observed = args.exclude_most_observed;
  if (!args.nav.empty()) config.nav = args.nav;
  if (!args.out.empty()) config.out = args.out;
  if (!args.nmea.empty()) config.nmea_out = args.nmea;
  if (!args.coordinates.empty()) {
    config.coordinates =
        args.coordinates == "ecef" ? canyon::io::PosCoordinates::Ecef : canyon::io::PosCoordinates::Llh;
  }
  if (!args.time_format.empty()) {
    config.time_format =
        args.time_format == "calendar" ? canyon::io::PosTimeFormat::Calendar : canyon::io::PosTimeFormat::WeekTow;
  }
  if (args.elevation_mask_deg >= 0.0) config.spp.elevation_mask_rad = args.elevation_mask_deg * canyon::core::kDegToRad;
  return std::nullopt;
}

std::string sibling_program(const std::string& command);

/// --session: the session's rover inputs written into `dir` by canyon-play --extract (the DDS side decodes the
/// recorded messages), and `args` pointed at those the command line does not give (--base BASE.obs with a session
/// recorded without the base's RTCM, say); the VIO only in fusion mode. An exit status when that fails.
std::optional<int> take_session_inputs(ProcessArgs& args, const canyon::config::ProcessConfig& config,
                                       const std::string& dir) {
  const std::string program = sibling_program("play");
  std::vector<std::string> words{program, "--extract", dir, args.session};
  if (args.quiet) words.emplace_back("-q");
  std::vector<char*> argv;
  argv.reserve(words.size() + 1);
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, program.c_str(), nullptr, nullptr, argv.data(), environ) != 0) {
    std::cerr << "canyon: error: --session runs " << program << ", which cannot be started (build canyon-play)\n";
    return kExitUsage;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return kExitInput;
  const auto in_dir = [&](const char* name) {
    const std::string path = dir + "/" + name;
    return access(path.c_str(), R_OK) == 0 ? path : std::string();
  };
  const auto fill = [](std::string& given, const std::string& extracted) {
    if (given.empty()) given = extracted;
  };
  fill(args.rover, in_dir("rover.obs"));
  if (config.mode != canyon::config::ProcessMode::Spp) fill(args.base, in_dir("base.rtcm3"));
  if (config.mode == canyon::config::ProcessMode::Fusion) {
    fill(args.vio, in_dir("vio.csv"));
    fill(args.timesync, in_dir("timesync.csv"));
  }
  if (args.nav.empty() && !in_dir("nav.rnx").empty()) args.nav.push_back(in_dir("nav.rnx"));
  return std::nullopt;
}

int run_process_files(const ProcessArgs& args);

int run_process_command(const ProcessArgs& given) {
  if (given.session.empty()) return run_process_files(given);
  ProcessArgs args = given;
  std::string dir = args.session_dir;
  if (dir.empty()) {
    std::string pattern = "/tmp/canyon-session-XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) {
      std::cerr << "canyon: error: cannot create a temporary folder: " << std::strerror(errno) << "\n";
      return kExitInput;
    }
    dir = pattern;
  }
  // The mode decides which of the session's inputs are used: the configuration as the command line and file give it.
  canyon::config::ProcessConfig mode_config;
  std::optional<int> failed = build_process_config(args, mode_config);
  if (!failed) failed = take_session_inputs(args, mode_config, dir);
  const int status = failed ? *failed : run_process_files(args);
  if (args.session_dir.empty()) {
    std::error_code ignored;
    std::filesystem::remove_all(dir, ignored);
  }
  return status;
}

int run_process_files(const ProcessArgs& args) {
  using canyon::config::ProcessConfig;
  if (args.describe_config != nullptr && args.describe_config->count() > 0) {
    return print_key_descriptions(args.describe_what, args.mode);
  }
  ProcessConfig config;
  if (const std::optional<int> exit = build_process_config(args, config)) return *exit;
  if (args.print_config) {
    std::cout << canyon::config::to_yaml(config);
    return 0;
  }
  if (const std::string e = config.validate(); !e.empty()) {
    std::cerr << "canyon: error: " << e << "\n";
    return kExitUsage;
  }
  ProgressBar bar(!args.quiet);
  canyon::pipeline::PipelineOptions pipeline;
  pipeline.threaded = args.pipeline == "threaded";
  pipeline.bridge_ahead = args.pipeline == "bridge-ahead";
  auto summary = canyon::commands::run_process(
      config, [&bar](int epochs, double fraction) { bar.update(epochs, fraction); }, pipeline);
  bar.finish();
  if (!summary) {
    std::cerr << "canyon: error: " << summary.error().to_string() << "\n";
    return kExitInput;
  }
  print_warnings(summary->warnings, args.verbose, "more input warnings");
  if (!summary->excluded_most_observed.empty() && !args.quiet) {
    std::string sats;
    for (const auto& sat : summary->excluded_most_observed) {
      sats += ' ';
      sats += sat.to_string();
    }
    std::fprintf(stderr, "canyon process: left out the %zu most observed satellites:%s\n",
                 summary->excluded_most_observed.size(), sats.c_str());
  }
  if (args.verbose) {
    for (const std::string& note : summary->epoch_notes) std::fprintf(stderr, "canyon: %s\n", note.c_str());
  }
  if (!args.quiet) {
    for (const std::string& line : summary->report) std::fprintf(stderr, "canyon process: %s\n", line.c_str());
  }
  if (!args.quiet) {
    const double percent = summary->epochs > 0 ? 100.0 * summary->solved / summary->epochs : 0.0;
    std::string fixed;
    if (config.mode != canyon::config::ProcessMode::Spp) {
      char buffer[64];
      std::snprintf(buffer, sizeof buffer, ", %d fixed (%.1f %%)", summary->fixed,
                    summary->epochs > 0 ? 100.0 * summary->fixed / summary->epochs : 0.0);
      fixed = buffer;
      if (summary->partial_fixed > 0) {
        std::snprintf(buffer, sizeof buffer, ", %d partial fixes (float, Q 2)", summary->partial_fixed);
        fixed += buffer;
      }
    }
    std::fprintf(stderr, "canyon process: %d epochs, %d solved (%.1f %%)%s, %.2f s wall, solution: %s\n",
                 summary->epochs, summary->solved, percent, fixed.c_str(), summary->wall_s, config.out.c_str());
  }
  return summary->solved > 0 ? 0 : kExitInput;
}

struct CheckFixesArgs {
  ProcessArgs process;
  canyon::commands::CheckFixesOptions options;
  std::string reference;  ///< another solution (.pos, e.g. RTKLIB's) whose fixed epochs are counted beside canyon's
};

void add_check_fixes_command(CLI::App& app, CheckFixesArgs& args) {
  CLI::App* cmd = app.add_subcommand(
      "check-fixes",
      "Check fixes without ground truth: solve again with the 1..N most-observed satellites left out and compare the "
      "fixes at the epochs fixed in both (a fix that moves is wrong in one of the two). Exit 3 when a run agrees at "
      "fewer than --min-agreement of its epochs");
  add_process_options(cmd, args.process);
  cmd->add_option("--leave-out", args.options.max_left_out, "Runs leaving out 1..N most-observed satellites (3)")
      ->check(CLI::Range(1, 10));
  cmd->add_option("--tolerance-m", args.options.tolerance_m, "A fix agrees within this 3-D distance (m, 0.05)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--min-agreement", args.options.min_agreement, "Share of agreeing epochs a run needs (0.95)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--reference", args.reference,
                  "Another solution of the same input (.pos, e.g. RTKLIB's): its fixed epochs are counted beside "
                  "canyon's")
      ->check(CLI::ExistingFile);
}

int run_check_fixes_command(const CheckFixesArgs& args) {
  canyon::config::ProcessConfig config;
  if (const std::optional<int> exit = build_process_config(args.process, config)) return *exit;
  const bool quiet = args.process.quiet;
  auto result = canyon::commands::check_fixes(config, args.options, [quiet](const std::string& run) {
    if (!quiet) std::fprintf(stderr, "canyon check-fixes: %s ...\n", run.c_str());
  });
  if (!result) {
    std::cerr << "canyon: error: " << result.error().to_string() << "\n";
    return kExitInput;
  }
  print_warnings(result->full.warnings, args.process.verbose, "more input warnings");
  std::printf("%s: %d epochs, %d fixed (%.1f %%)\n", config.out.c_str(), result->full.epochs, result->full.fixed,
              result->full.epochs > 0 ? 100.0 * result->full.fixed / result->full.epochs : 0.0);
  if (!args.reference.empty()) {
    auto reference = canyon::io::read_pos_file(args.reference);
    if (!reference) {
      std::cerr << "canyon: error: " << reference.error().to_string() << "\n";
      return kExitInput;
    }
    const auto fixed = std::count_if(reference->begin(), reference->end(), [](const canyon::core::Solution& s) {
      return s.status == canyon::core::SolutionStatus::Fixed;
    });
    std::printf("%s: %ld fixed; canyon fixes %.2f times as many\n", args.reference.c_str(), static_cast<long>(fixed),
                fixed > 0 ? static_cast<double>(result->full.fixed) / static_cast<double>(fixed) : 0.0);
  }
  std::printf("%s", canyon::eval::format_leave_out(result->runs, args.options.min_agreement).c_str());
  constexpr int kExitInconsistent = 3;
  return result->consistent(args.options.min_agreement) ? 0 : kExitInconsistent;
}

struct SimulateArgs {
  std::string scenario;
  std::string vio_from_truth;
  std::string out;
  std::int64_t seed = -1;
  double duration_s = -1.0;
  bool quiet = false;
};

void add_simulate_command(CLI::App& app, SimulateArgs& args) {
  CLI::App* cmd = app.add_subcommand(
      "simulate", "Generate a scenario: rover and base RINEX, navigation, ground truth and city model");
  cmd->add_option(
      "--scenario", args.scenario,
      "Shipped scenario name (open-sky, light-blocked, urban-moderate, urban-severe, downtown-mild, downtown, "
      "downtown-vehicle) or a FILE.yaml (with --vio-from-truth: its vio section, default urban-severe's)");
  cmd->add_option("--vio-from-truth", args.vio_from_truth,
                  "Only make VIO (vio.csv, timesync.csv, vio_truth.yaml) of a device carried along this 6-DoF truth: "
                  "canyon truth.csv with qx,qy,qz,qw, or a Spirent PVA CSV with roll, pitch, yaw")
      ->check(CLI::ExistingFile);
  cmd->add_option("--seed", args.seed, "Random seed (default: the scenario's)")->check(CLI::Range(0LL, 1LL << 53));
  cmd->add_option("--duration", args.duration_s, "Duration in seconds (default: the scenario's)")
      ->check(CLI::Range(1.0, 86400.0));
  cmd->add_option("--out", args.out, "Output folder (created if needed)")->required();
  cmd->add_flag("-q,--quiet", args.quiet, "No summary line");
}

int run_vio_from_truth_command(const SimulateArgs& args) {
  canyon::sim::VioOptions vio;
  std::uint64_t seed = 1;
  if (!args.scenario.empty()) {
    auto file = canyon::config::find_scenario_file(args.scenario);
    if (!file) {
      std::cerr << "canyon: error: " << file.error().to_string() << "\n";
      return kExitUsage;
    }
    auto scenario = canyon::config::load_scenario(*file);
    if (!scenario) {
      std::cerr << "canyon: error: " << scenario.error().to_string() << "\n";
      return kExitUsage;
    }
    vio = scenario->vio;
    seed = scenario->seed;
  }
  if (args.seed >= 0) seed = static_cast<std::uint64_t>(args.seed);
  auto summary = canyon::commands::run_vio_from_truth(args.vio_from_truth, vio, seed, args.out);
  if (!summary) {
    std::cerr << "canyon: error: " << summary.error().to_string() << "\n";
    return kExitInput;
  }
  if (!args.quiet) {
    std::fprintf(stderr,
                 "canyon simulate: VIO from %s, seed %llu: %d poses, %d time-sync pairs over %.1f s, final VIO error "
                 "%.3f m, %.2f s wall, files in %s\n",
                 args.vio_from_truth.c_str(), static_cast<unsigned long long>(seed), summary->poses,
                 summary->timesync_pairs, summary->duration_s, summary->final_position_error_m, summary->wall_s,
                 args.out.c_str());
  }
  return 0;
}

int run_simulate_command(const SimulateArgs& args) {
  if (!args.vio_from_truth.empty()) return run_vio_from_truth_command(args);
  if (args.scenario.empty()) {
    std::cerr << "canyon: error: simulate needs --scenario (or --vio-from-truth TRUTH)\n";
    return kExitUsage;
  }
  auto file = canyon::config::find_scenario_file(args.scenario);
  if (!file) {
    std::cerr << "canyon: error: " << file.error().to_string() << "\n";
    return kExitUsage;
  }
  auto scenario = canyon::config::load_scenario(*file);
  if (!scenario) {
    std::cerr << "canyon: error: " << scenario.error().to_string() << "\n";
    return kExitUsage;
  }
  if (args.seed >= 0) scenario->seed = static_cast<std::uint64_t>(args.seed);
  if (args.duration_s > 0.0) scenario->duration_s = args.duration_s;
  auto summary = canyon::commands::run_simulate(*scenario, args.out);
  if (!summary) {
    std::cerr << "canyon: error: " << summary.error().to_string() << "\n";
    return kExitInput;
  }
  if (!args.quiet) {
    std::fprintf(stderr,
                 "canyon simulate: %s seed %llu: %d rover epochs, %d base epochs, %d rover signals (%.1f %% NLOS), "
                 "line-of-sight ceiling %.1f %% (epochs with >= 5 satellites tracking phase in line of sight), "
                 "%d lock losses, %d slips, %d buildings, route %.0f m, %.2f s wall, files in %s\n",
                 scenario->name.c_str(), static_cast<unsigned long long>(scenario->seed), summary->rover_epochs,
                 summary->base_epochs, summary->rover_signal_epochs, 100.0 * summary->nlos_fraction,
                 summary->rover_epochs > 0 ? 100.0 * summary->line_of_sight_epochs / summary->rover_epochs : 0.0,
                 summary->rover_losses, summary->rover_slips, summary->buildings, summary->route_length_m,
                 summary->wall_s, args.out.c_str());
  }
  return 0;
}

struct EvaluateArgs {
  canyon::commands::EvaluateConfig config;
  int epochs = 0;
  bool quiet = false;
};

void add_evaluate_command(CLI::App& app, EvaluateArgs& args) {
  CLI::App* cmd = app.add_subcommand(
      "evaluate",
      "Score solutions (.pos, canyon's or RTKLIB's) against a truth, side by side: table, Markdown, JSON, SVG plots");
  canyon::commands::EvaluateConfig& c = args.config;
  cmd->add_option("--truth", c.truth,
                  "Truth: canyon truth.csv, Spirent PVA .csv, a .pos file, or a static point ecef:X,Y,Z (m) or "
                  "llh:LAT,LON,H (deg, deg, m)")
      ->required();
  cmd->add_option("--solution", c.solutions, "Solution file, RTKLIB .pos in any of its output forms (repeat)")
      ->required();
  cmd->add_option("--label", c.labels,
                  "Column title of the solution given in the same position (repeat; all or none; default: file names)");
  auto* epochs = cmd->add_option("--epochs", args.epochs, "Number of rover epochs: the denominator of every rate")
                     ->check(CLI::PositiveNumber);
  cmd->add_option("--rover", c.rover_obs, "Rover RINEX observation file: its epochs are the rover epochs")
      ->excludes(epochs);
  cmd->add_option("--city", c.city, "City GeoJSON (canyon simulate's city.geojson) drawn under the trajectories");
  cmd->add_option("--out-dir", c.out_dir,
                  "Folder for evaluation.md, evaluation.json, trajectory.svg, ape.svg (default, when no output option "
                  "is given: evaluation/ beside the first solution)");
  cmd->add_option("--markdown", c.markdown, "Markdown table file (instead of DIR/evaluation.md)");
  cmd->add_option("--json", c.json, "JSON file (instead of DIR/evaluation.json)");
  cmd->add_option("--trajectory-svg", c.trajectory_svg, "Trajectory plot (instead of DIR/trajectory.svg)");
  cmd->add_option("--ape-svg", c.ape_svg, "Error-over-time plot (instead of DIR/ape.svg)");
  cmd->add_option("--kml", c.kml,
                  "KML 2.2 file for Google Earth: every solution's epochs coloured by status (fixed green, float "
                  "yellow, single red, VIO fill-in blue) and the truth as a white line");
  cmd->add_option("--gpx", c.gpx, "GPX 1.1 file: a track per solution and status, the truth as a track");
  cmd->add_option("--wrong-fix-m", c.wrong_fix_threshold_m,
                  "Fixed epochs with a larger 3D error are wrong fixes (m), default 0.10")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("-q,--quiet", args.quiet, "No table and no list of files written");
  cmd->footer(
      "Rover epochs (every rate's denominator): --epochs N, else the epochs of --rover OBS, else, for a truth "
      "trajectory, its epochs within the solutions' time span joined with the solutions' epochs (canyon simulate's "
      "truth.csv has one row per rover epoch), else (static truth) the union of the solutions' epochs.\n"
      "Rates: fixed/float/single/fill-in (Q 7) epochs and solved epochs (availability) over rover epochs; wrong-fix "
      "rate over fixed epochs with truth. APE: 3D and horizontal error (ENU at the truth, truth interpolated to each "
      "epoch); solved epochs the truth does not cover (its gaps) are counted as 'epochs without truth'.\n"
      "Exit status: 0 success, 1 bad input (file and line named), 2 bad command line.");
}

int run_evaluate_command(EvaluateArgs& args) {
  if (args.epochs > 0) args.config.epochs = args.epochs;
  if (const std::string broken = args.config.validate(); !broken.empty()) {
    std::cerr << "canyon: error: " << broken << "\n";
    return kExitUsage;
  }
  auto summary = canyon::commands::run_evaluate(args.config);
  if (!summary) {
    std::cerr << "canyon: error: " << summary.error().to_string() << "\n";
    return kExitInput;
  }
  for (const std::string& w : summary->warnings) std::fprintf(stderr, "canyon: warning: %s\n", w.c_str());
  if (!args.quiet) {
    std::fputs(summary->table.c_str(), stdout);
    std::fflush(stdout);  // the table before the list of files when both go to one pipe
    for (const std::string& path : summary->written) std::fprintf(stderr, "canyon evaluate: wrote %s\n", path.c_str());
  }
  return 0;
}

struct DemoArgs {
  canyon::commands::DemoConfig config;
  std::int64_t seed = -1;
  double duration_s = -1.0;
  bool no_rtklib = false;
};

void add_demo_command(CLI::App& app, DemoArgs& args) {
  CLI::App* cmd = app.add_subcommand(
      "demo",
      "canyon's main job, no external data: generate downtown, process it with SPP, RTK, fusion (VIO) and RTKLIB, "
      "evaluate");
  canyon::commands::DemoConfig& c = args.config;
  cmd->add_option("--scenario", c.scenario, "Shipped scenario name or a FILE.yaml (default downtown)");
  cmd->add_option("--seed", args.seed, "Random seed (default: the scenario's)")->check(CLI::Range(0LL, 1LL << 53));
  cmd->add_option("--duration", args.duration_s, "Duration in seconds (default: the scenario's, 600)")
      ->check(CLI::Range(1.0, 86400.0));
  cmd->add_option("--out", c.out_dir, "Output folder (default out/demo; created if needed)");
  cmd->add_option("--rtk-config", c.rtk_config,
                  "canyon's RTK configuration, a file in config/ (default " + c.rtk_config + ")");
  cmd->add_flag("--no-rtklib", args.no_rtklib, "Do not run RTKLIB's rnx2rtkp as the baseline");
  cmd->add_option("--rtklib-program", c.rtklib_program, "RTKLIB's rnx2rtkp to run (default: rnx2rtkp on PATH)");
  cmd->footer(
      "Writes DIR/scenario/ (canyon simulate's files), DIR/spp.pos, DIR/rtk.pos, DIR/fusion.pos, DIR/rtklib.pos (+ "
      "rtklib.log), and "
      "canyon evaluate's DIR/evaluation.md, evaluation.json, trajectory.svg, ape.svg; prints the side-by-side table.\n"
      "Exit status: 0 success, 1 a stage failed (named), 2 bad command line or scenario.");
}

int run_demo_command(DemoArgs& args) {
  canyon::commands::DemoConfig& c = args.config;
  if (args.seed >= 0) c.seed = static_cast<std::uint64_t>(args.seed);
  if (args.duration_s > 0.0) c.duration_s = args.duration_s;
  c.run_rtklib = !args.no_rtklib;
  auto scenario = canyon::config::find_scenario_file(c.scenario);
  if (!scenario) {
    std::cerr << "canyon: error: " << scenario.error().to_string() << "\n";
    return kExitUsage;
  }
  auto summary = canyon::commands::run_demo(
      c, [](const std::string& stage) { std::fprintf(stderr, "canyon demo: %s\n", stage.c_str()); });
  if (!summary) {
    std::cerr << "canyon: error: " << summary.error().to_string() << "\n";
    return kExitInput;
  }
  for (const std::string& note : summary->notes) std::fprintf(stderr, "canyon demo: note: %s\n", note.c_str());
  std::fflush(stderr);
  std::fputs(summary->table.c_str(), stdout);
  std::fflush(stdout);
  for (const std::string& path : summary->written) std::fprintf(stderr, "canyon demo: wrote %s\n", path.c_str());
  return 0;
}

struct ConvertArgs {
  canyon::commands::ConvertConfig config;
  std::string time;
  std::string position;
  bool quiet = false;
  bool verbose = false;
};

void add_convert_command(CLI::App& app, ConvertArgs& args) {
  CLI::App* cmd = app.add_subcommand(
      "convert",
      "RTCM 3 or u-blox UBX (file or stdin) -> RINEX 3 observations and navigation; RINEX -> RTCM 3; solutions "
      "(.pos) -> KML, GPX");
  canyon::commands::ConvertConfig& c = args.config;
  cmd->add_option("input", c.input,
                  "Input: RTCM 3 / UBX stream file (may be .gz; '-' reads stdin; tcp://HOST:PORT or "
                  "ntrip://[USER[:PASS]@]HOST:PORT/MOUNT records a live stream) or RINEX observations")
      ->required();
  cmd->add_option("--from", c.from, "Input format: auto (default), rtcm3, ubx, rinex or pos (a solution file)")
      ->check(CLI::IsMember({"auto", "rtcm3", "ubx", "rinex", "pos"}));
  cmd->add_option("--kml", c.kml,
                  "Solution input: KML 2.2 track for Google Earth, epochs coloured by status (fixed green, float "
                  "yellow, single red, VIO fill-in blue; default with --from pos: INPUT.kml)");
  cmd->add_option("--gpx", c.gpx, "Solution input: GPX 1.1 file, a track per status");
  cmd->add_option("--obs-out", c.obs_out, "RINEX observation output (default: INPUT.obs)");
  cmd->add_option("--nav-out", c.nav_out, "RINEX navigation output (default: INPUT.nav)");
  cmd->add_option("--time", args.time,
                  "Approximate GPST of the data, 'YYYY-MM-DD HH:MM:SS' (RTCM 3 weeks; default: from an ephemeris in "
                  "the stream, else the current date)");
  cmd->add_option("--marker", c.marker, "RINEX marker name");
  cmd->add_option("--duration", c.duration_s, "Network input: record this many seconds (default: until idle)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--idle-timeout", c.idle_timeout_s,
                  "Network input: stop when no byte came for this many seconds (default 5)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--ntrip-version", c.ntrip_version, "Network input: NTRIP request version, 1 or 2 (default 2)")
      ->check(CLI::IsMember({1, 2}));
  cmd->add_option("--out", c.rtcm_out, "RTCM 3 output of a RINEX input (default: INPUT.rtcm3)");
  cmd->add_option("--nav", c.nav, "RINEX navigation file whose ephemerides go into the RTCM 3 stream (repeat)");
  cmd->add_option("--station-id", c.station_id, "RTCM 3 reference station id, 0-4095 (default 0)")
      ->check(CLI::Range(0, 4095));
  cmd->add_option("--msm", c.msm, "MSM type: 7 (default) or 4 (also 5, 6)")->check(CLI::Range(4, 7));
  cmd->add_option("--station-interval", c.station_interval_s, "1005 every this many seconds (0: once; default 10)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--ephemeris-interval", c.ephemeris_interval_s,
                  "Repeat each current ephemeris every this many seconds (default 0: each once, when current)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--position", args.position, "1005 antenna position ECEF X,Y,Z in metres (default: RINEX header)");
  cmd->add_flag("-q,--quiet", args.quiet, "No summary line");
  cmd->add_flag("-v,--verbose", args.verbose, "Every warning (default: the first five)");
  cmd->footer("Exit status: 0 success, 1 bad input (file and byte or line named), 2 bad command line.");
}

int run_convert_command(ConvertArgs& args) {
  canyon::commands::ConvertConfig& c = args.config;
  if (!args.time.empty()) {
    c.approx_time = canyon::core::parse_gps_calendar(args.time);
    if (!c.approx_time) {
      std::cerr << "canyon: error: --time must be 'YYYY-MM-DD HH:MM:SS', not '" << args.time << "'\n";
      return kExitUsage;
    }
  }
  if (!args.position.empty()) {
    double x = 0, y = 0, z = 0;
    char tail = 0;
    if (std::sscanf(args.position.c_str(), "%lf,%lf,%lf%c", &x, &y, &z, &tail) != 3) {
      std::cerr << "canyon: error: --position must be X,Y,Z (ECEF metres), not '" << args.position << "'\n";
      return kExitUsage;
    }
    c.position_E_m = Eigen::Vector3d(x, y, z);
  }
  if (const std::string e = c.validate(); !e.empty()) {
    std::cerr << "canyon: error: " << e << "\n";
    return kExitUsage;
  }
  auto summary = canyon::commands::run_convert(c);
  if (!summary) {
    std::cerr << "canyon: error: " << summary.error().to_string() << "\n";
    return kExitInput;
  }
  print_warnings(summary->warnings, args.verbose, "more");
  if (!args.quiet) {
    std::fprintf(stderr, "canyon convert: %s: %d epochs, %d ephemerides; %s\n", summary->direction.c_str(),
                 summary->epochs, summary->ephemerides, summary->statistics.c_str());
    for (const std::string& path : summary->written) std::fprintf(stderr, "canyon convert: wrote %s\n", path.c_str());
  }
  return 0;
}

int run_main(int argc, char** argv) {
  CLI::App app{"canyon: centimetre-level GNSS carrier-phase positioning fused with visual-inertial odometry"};
  app.require_subcommand(1);
  ProcessArgs process_args;
  add_process_command(app, process_args);
  SimulateArgs simulate_args;
  add_simulate_command(app, simulate_args);
  EvaluateArgs evaluate_args;
  add_evaluate_command(app, evaluate_args);
  DemoArgs demo_args;
  add_demo_command(app, demo_args);
  ConvertArgs convert_args;
  add_convert_command(app, convert_args);
  CheckFixesArgs check_fixes_args;
  add_check_fixes_command(app, check_fixes_args);
  // Listed for --help only: `canyon base ...` runs canyon-base before the command line is parsed (main()).
  app.add_subcommand("base",
                     "Base station publishing RTCM 3 on DDS, NTRIP and TCP (runs canyon-base; canyon base --help)")
      ->allow_extras();
  app.add_subcommand("rover", "Real-time rover: the staged pipeline over DDS (runs canyon-rover; canyon rover --help)")
      ->allow_extras();
  app.add_subcommand("vio", "Publish VIO poses and time-sync pairs from files on DDS, as a VIO node (runs canyon-vio)")
      ->allow_extras();
  app.add_subcommand("record",
                     "Record a DDS topic to a file: solutions to .pos/NMEA/CSV, others to a replayable log; any "
                     "set of topics to MCAP (runs canyon-record)")
      ->allow_extras();
  app.add_subcommand("echo", "Print the samples of a DDS topic (runs canyon-echo)")->allow_extras();
  app.add_subcommand("play", "Publish an MCAP session recorded by canyon record on DDS again (runs canyon-play)")
      ->allow_extras();
  app.add_subcommand("monitor",
                     "Stage and end-to-end latency, correction age, queues, drops, solution (runs "
                     "canyon-monitor)")
      ->allow_extras();
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitUsage;
  }
  if (app.got_subcommand("process")) return run_process_command(process_args);
  if (app.got_subcommand("simulate")) return run_simulate_command(simulate_args);
  if (app.got_subcommand("evaluate")) return run_evaluate_command(evaluate_args);
  if (app.got_subcommand("demo")) return run_demo_command(demo_args);
  if (app.got_subcommand("convert")) return run_convert_command(convert_args);
  if (app.got_subcommand("check-fixes")) return run_check_fixes_command(check_fixes_args);
  return kExitUsage;
}

}  // namespace

namespace {

/// canyon-COMMAND next to this executable.
std::string sibling_program(const std::string& command) {
  char self[4096];
  const ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
  std::string dir = ".";
  if (n > 0) {
    self[n] = '\0';
    dir = self;
    dir = dir.substr(0, dir.find_last_of('/'));
  }
  return dir + "/canyon-" + command;
}

}  // namespace

/// `canyon base ...` runs `canyon-base ...` (the DDS executable next to this one) with the same arguments.
int exec_dds_command(const std::string& command, int argc, char** argv) {
  const std::string program = sibling_program(command);
  if (access(program.c_str(), X_OK) != 0) {
    std::cerr << "canyon: error: '" << command << "' runs " << program
              << ", which is missing (build it: cmake --build build --target canyon-" << command << ")\n";
    return kExitUsage;
  }
  std::vector<char*> args;
  args.push_back(const_cast<char*>(program.c_str()));
  for (int i = 2; i < argc; ++i) args.push_back(argv[i]);
  args.push_back(nullptr);
  execv(program.c_str(), args.data());
  std::cerr << "canyon: error: cannot run " << program << ": " << std::strerror(errno) << "\n";
  return kExitInput;
}

int main(int argc, char** argv) {
  if (argc >= 2) {
    const std::string command = argv[1];
    for (const char* dds : {"base", "rover", "vio", "record", "echo", "monitor", "play"}) {
      if (command == dds) return exec_dds_command(command, argc, argv);
    }
  }
  // The heap grows in 16 MB steps and is not given back while the command runs: the reading threads' arenas would
  // otherwise grow and shrink by a page at a time, and on a virtual machine each of those system calls costs as much
  // as solving an epoch (cssrlib-kinematic: 196 mprotect calls, 10 ms of 45). Untouched pages cost no memory.
  mallopt(M_TOP_PAD, 16 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  // Bad input is reported through Result; an exception here is a bug or resource exhaustion: say so and fail.
  return canyon::apps::guarded_main("canyon", kExitInput, run_main, argc, argv);
}
