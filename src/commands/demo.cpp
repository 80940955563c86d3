// `canyon demo`: simulate, process with every mode, run RTKLIB as the baseline, evaluate (see demo.hpp).

#include "canyon/commands/demo.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include "canyon/commands/evaluate.hpp"
#include "canyon/commands/process.hpp"
#include "canyon/config/process_config.hpp"
#include "canyon/config/scenario_config.hpp"
#include "canyon/config/shipped_config.hpp"

extern char** environ;  // NOLINT(readability-redundant-declaration): POSIX declares it nowhere in a header

namespace canyon::commands {
namespace {

namespace fs = std::filesystem;

std::string path_in(const std::string& dir, const std::string& name) {
  return (fs::path(dir) / name).string();
}

Result<sim::Scenario> demo_scenario(const DemoConfig& config) {
  auto file = config::find_scenario_file(config.scenario);
  if (!file) return file.error();
  auto scenario = config::load_scenario(*file);
  if (!scenario) return scenario.error();
  if (config.seed) scenario->seed = *config.seed;
  if (config.duration_s) scenario->duration_s = *config.duration_s;
  return scenario;
}

/// Runs canyon process in `mode` on the scenario in `scenario_dir`, writing `out`.
Result<ProcessSummary> process_scenario(config::ProcessConfig config, const std::string& scenario_dir,
                                        const std::string& out) {
  config.rover_obs = path_in(scenario_dir, "rover.obs");
  config.base_obs = path_in(scenario_dir, "base.obs");
  config.vio = path_in(scenario_dir, "vio.csv");
  config.timesync = path_in(scenario_dir, "timesync.csv");
  config.nav = {path_in(scenario_dir, "nav.rnx")};
  config.out = out;
  return run_process(config);
}

Result<config::ProcessConfig> shipped_process_config(const std::string& name, config::ProcessMode mode) {
  auto file = config::find_shipped_config(name);
  if (!file) return file.error();
  auto loaded = config::load_process_config(*file);
  if (!loaded) return loaded.error();
  loaded->mode = mode;
  return loaded;
}

/// Runs `argv` (argv[0] found on PATH) with stdout and stderr into `log_path`. The exit status, or an Error if it
/// could not start (`not_found` set when the program is not installed).
Result<int> run_program(const std::vector<std::string>& argv, const std::string& log_path, bool& not_found) {
  not_found = false;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  std::vector<char*> args;
  args.reserve(argv.size() + 1);
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));  // NOLINT: POSIX signature
  args.push_back(nullptr);
  pid_t pid = 0;
  const int spawn_error = posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawn_error != 0) {
    not_found = spawn_error == ENOENT;
    return Error{"cannot run " + argv[0] + ": " + std::strerror(spawn_error)};
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return Error{"waiting for " + argv[0] + ": " + std::strerror(errno)};
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return Error{argv[0] + " was killed by signal " + std::to_string(WTERMSIG(status)) + " (log: " + log_path + ")"};
}

/// RTKLIB's kinematic solution of the scenario; false (with a note) when RTKLIB is not installed.
Result<bool> run_rtklib(const DemoConfig& config, const std::string& scenario_dir, const std::string& out,
                        std::vector<std::string>& notes) {
  auto conf = config::find_shipped_config(config.rtklib_config);
  if (!conf) return conf.error();
  const std::string log = path_in(config.out_dir, "rtklib.log");
  bool not_found = false;
  auto status = run_program({config.rtklib_program, "-k", *conf, "-o", out, path_in(scenario_dir, "rover.obs"),
                             path_in(scenario_dir, "base.obs"), path_in(scenario_dir, "nav.rnx")},
                            log, not_found);
  if (!status && not_found) {
    notes.push_back("RTKLIB's " + config.rtklib_program +
                    " is not installed: no RTKLIB baseline (Debian: apt-get install rtklib)");
    return false;
  }
  if (!status) return status.error();
  if (*status != 0 || !fs::exists(out)) {
    return Error{config.rtklib_program + " failed (exit status " + std::to_string(*status) + "); its messages are in " +
                 log};
  }
  return true;
}

void say(const DemoLog& log, const std::string& line) {
  if (log) log(line);
}

}  // namespace

Result<DemoSummary> run_demo(const DemoConfig& config, const DemoLog& log) {
  DemoSummary summary;
  auto scenario = demo_scenario(config);
  if (!scenario) return scenario.error();
  auto rtk = shipped_process_config(config.rtk_config, config::ProcessMode::Rtk);
  if (!rtk) return rtk.error();
  auto fusion = shipped_process_config(config.fusion_config, config::ProcessMode::Fusion);
  if (!fusion) return fusion.error();
  std::error_code ec;
  fs::create_directories(config.out_dir, ec);
  if (ec) return Error{"cannot create the output folder: " + ec.message(), config.out_dir, 0};
  const std::string scenario_dir = path_in(config.out_dir, "scenario");

  say(log, "simulate " + scenario->name + " (seed " + std::to_string(scenario->seed) + ", " +
               std::to_string(static_cast<int>(scenario->duration_s)) + " s) into " + scenario_dir);
  auto simulated = run_simulate(*scenario, scenario_dir);
  if (!simulated) return simulated.error();
  summary.simulation = *simulated;

  EvaluateConfig evaluate;
  const std::string rtklib_pos = path_in(config.out_dir, "rtklib.pos");
  if (config.run_rtklib) {
    say(log, "RTKLIB " + config.rtklib_program + " (kinematic, continuous AR, " + config.rtklib_config + ")");
    auto ran = run_rtklib(config, scenario_dir, rtklib_pos, summary.notes);
    if (!ran) return ran.error();
    if (*ran) {
      evaluate.solutions.push_back(rtklib_pos);
      evaluate.labels.emplace_back("RTKLIB");
    }
  }
  struct Mode {
    const char* label;
    const char* file;
    config::ProcessConfig config;
  };
  config::ProcessConfig spp;
  spp.mode = config::ProcessMode::Spp;
  std::vector<Mode> modes = {Mode{"canyon SPP", "spp.pos", spp}, Mode{"canyon RTK", "rtk.pos", *rtk}};
  if (scenario->vio.enabled) {
    modes.push_back(Mode{"canyon fusion", "fusion.pos", *fusion});
  } else {
    summary.notes.emplace_back("the scenario has no VIO (vio.enabled: false): no fusion");
  }
  for (const Mode& mode : modes) {
    say(log, std::string("canyon process --mode ") + config::mode_name(mode.config.mode));
    const std::string out = path_in(config.out_dir, mode.file);
    auto processed = process_scenario(mode.config, scenario_dir, out);
    if (!processed) return processed.error();
    evaluate.solutions.push_back(out);
    evaluate.labels.emplace_back(mode.label);
  }

  say(log, "canyon evaluate against " + path_in(scenario_dir, "truth.csv"));
  evaluate.truth = path_in(scenario_dir, "truth.csv");
  evaluate.city = path_in(scenario_dir, "city.geojson");
  evaluate.epochs = summary.simulation.rover_epochs;
  evaluate.out_dir = config.out_dir;
  auto evaluated = run_evaluate(evaluate);
  if (!evaluated) return evaluated.error();
  summary.table = evaluated->table;
  summary.notes.insert(summary.notes.end(), evaluated->warnings.begin(), evaluated->warnings.end());
  summary.written = evaluate.solutions;
  summary.written.insert(summary.written.end(), evaluated->written.begin(), evaluated->written.end());
  return summary;
}

}  // namespace canyon::commands
