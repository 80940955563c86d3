// Batch processing: read inputs, solve each epoch, write the .pos file.

#include "canyon/app/process.hpp"

#include <chrono>
#include <cstdio>

#include "canyon/core/geodesy.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/gnss/spp.hpp"
#include "canyon/io/rinex_nav.hpp"
#include "canyon/io/rinex_obs.hpp"

namespace canyon::app {
namespace {

constexpr std::size_t kMaxUnsolvedReasons = 100;

Result<core::NavigationData> read_navigation(const std::vector<std::string>& paths,
                                             std::vector<std::string>& warnings) {
  core::NavigationData nav;
  for (const std::string& path : paths) {
    auto file = io::read_rinex_nav(path);
    if (!file) return file.error();
    nav.merge(file->nav);
    warnings.insert(warnings.end(), file->warnings.begin(), file->warnings.end());
  }
  if (nav.kepler.empty() && nav.glonass.empty()) {
    return Error{"no ephemerides in the navigation file(s)", paths.front(), 0};
  }
  return nav;
}

std::vector<std::string> header_lines(const ProcessConfig& config) {
  std::vector<std::string> lines;
  lines.push_back("program   : canyon process (mode " + mode_name(config.mode) + ")");
  lines.push_back("inp file  : " + config.rover_obs);
  for (const std::string& n : config.nav) lines.push_back("inp file  : " + n);
  char mask[64];
  std::snprintf(mask, sizeof mask, "elev mask : %.1f deg", config.spp.elevation_mask_rad * 57.29577951308232);
  lines.emplace_back(mask);
  lines.push_back(std::string("ionos opt : ") + (config.spp.ionosphere_klobuchar ? "Broadcast" : "OFF"));
  lines.push_back(std::string("tropo opt : ") + (config.spp.troposphere_saastamoinen ? "Saastamoinen" : "OFF"));
  return lines;
}

core::Solution to_solution(const gnss::SppSolution& spp) {
  core::Solution s;
  s.time = spp.time;
  s.status = core::SolutionStatus::Single;
  s.p_E_m = spp.p_E_m;
  s.P_E_m2 = spp.P_E_m2;
  s.v_E_mps = spp.v_E_mps;
  s.num_satellites = spp.num_satellites;
  return s;
}

}  // namespace

Result<ProcessSummary> run_process(const ProcessConfig& config, const ProgressFn& progress) {
  const auto start = std::chrono::steady_clock::now();
  if (const std::string e = config.validate(); !e.empty()) return Error{e};
  ProcessSummary summary;

  auto nav = read_navigation(config.nav, summary.warnings);
  if (!nav) return nav.error();
  const gnss::EphemerisStore ephemerides(std::move(*nav));

  auto rover = io::read_rinex_obs(config.rover_obs);
  if (!rover) return rover.error();
  summary.warnings.insert(summary.warnings.end(), rover->warnings.begin(), rover->warnings.end());

  auto writer = io::PosWriter::create(config.out, {config.coordinates, config.time_format, header_lines(config)});
  if (!writer) return writer.error();

  std::optional<Eigen::Vector3d> last_p_E;
  const int total = static_cast<int>(rover->epochs.size());
  for (const core::ObsEpoch& epoch : rover->epochs) {
    ++summary.epochs;
    auto sol = gnss::solve_spp(epoch, ephemerides, config.spp, last_p_E);
    if (sol) {
      last_p_E = sol->p_E_m;
      if (Status w = writer->write(to_solution(*sol)); !w) return w.error();
      ++summary.solved;
    } else if (summary.unsolved_reasons.size() < kMaxUnsolvedReasons) {
      char when[48];
      std::snprintf(when, sizeof when, "%d %.3f: ", epoch.time.week, epoch.time.tow_s);
      summary.unsolved_reasons.push_back(when + sol.error().message);
    }
    if (progress) progress(summary.epochs, total);
  }
  if (Status c = writer->close(); !c) return c.error();
  summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace canyon::app
