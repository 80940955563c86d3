// Batch processing: read inputs, solve each epoch, write the .pos file.

#include "canyon/app/process.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "canyon/core/geodesy.hpp"
#include "canyon/fusion/fusion_engine.hpp"
#include "canyon/fusion/time_bridge.hpp"
#include "canyon/fusion/vio_track.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/gnss/spp.hpp"
#include "canyon/io/nmea.hpp"
#include "canyon/io/rinex_nav.hpp"
#include "canyon/io/rinex_obs.hpp"
#include "canyon/io/vio_file.hpp"
#include "canyon/rtk/engine.hpp"

namespace canyon::app {
namespace {

constexpr std::size_t kMaxEpochNotes = 100;

/// The epochs of an observation file as observations: flag 6 epochs hold cycle-slip records (slip counts in the
/// observation fields), not observations, and are dropped; after a power failure (flag 1) every phase may have
/// slipped and gets the loss-of-lock bit. One warning per file for each.
void keep_observations(io::RinexObsFile& file, const std::string& path, std::vector<std::string>& warnings) {
  const auto slip_records = std::count_if(file.epochs.begin(), file.epochs.end(), [](const core::ObsEpoch& e) {
    return e.flag == core::EpochFlag::CycleSlipRecords;
  });
  if (slip_records > 0) {
    std::erase_if(file.epochs, [](const core::ObsEpoch& e) { return e.flag == core::EpochFlag::CycleSlipRecords; });
    warnings.push_back(path + ": " + std::to_string(slip_records) +
                       " epochs of cycle-slip records (flag 6) are not observations, not used");
  }
  int power_failures = 0;
  for (core::ObsEpoch& epoch : file.epochs) {
    if (epoch.flag != core::EpochFlag::PowerFailure) continue;
    ++power_failures;
    for (core::SatelliteObs& sat : epoch.sats) {
      for (core::SignalObs& signal : sat.signals) signal.lli |= core::kLliLossOfLock;
    }
  }
  if (power_failures > 0) {
    warnings.push_back(path + ": " + std::to_string(power_failures) +
                       " epochs after a power failure (flag 1): all their phases taken as lost lock");
  }
}

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

/// GLONASS ambiguities are integers only if the receivers' inter-frequency phase biases cancel, i.e. for receivers of
/// one type: a warning when GLONASS AR is on and the RINEX headers name different receiver types.
std::string glonass_ar_warning(const ProcessConfig& config, const io::RinexObsHeader& rover,
                               const io::RinexObsHeader& base) {
  if (!config.rtk.glonass_ar || !config.rtk.observables.use_glonass) return {};
  const std::string& r = rover.receiver.receiver_type;
  const std::string& b = base.receiver.receiver_type;
  if (r == b) return {};
  std::string w = "glonass_ar is on but the rover receiver '";
  w += r;
  w += "' and the base receiver '";
  w += b;
  w += "' differ: their GLONASS inter-frequency phase biases need not cancel and GLONASS fixes may be wrong "
       "(set glonass_ar: off)";
  return w;
}

bool is_tracked(const core::SatelliteObs& sat) {
  return std::any_of(sat.signals.begin(), sat.signals.end(), [](const core::SignalObs& s) {
    return core::has_value(s.pseudorange_m) || core::has_value(s.carrier_phase_cyc);
  });
}

/// Applies `exclude_most_observed`: the satellites join both modes' exclusion lists. Returns them.
std::vector<core::SatelliteId> exclude_most_observed(ProcessConfig& config, const std::vector<core::ObsEpoch>& rover) {
  if (config.exclude_most_observed <= 0) return {};
  const core::ConstellationFlags& systems = config.mode != ProcessMode::Spp
                                                ? static_cast<const core::ConstellationFlags&>(config.rtk.observables)
                                                : static_cast<const core::ConstellationFlags&>(config.spp);
  std::vector<core::SatelliteId> sats = most_observed_satellites(rover, config.exclude_most_observed, systems);
  for (const core::SatelliteId& sat : sats) {
    config.spp.excluded.push_back(sat);
    config.rtk.observables.excluded.push_back(sat);
  }
  return sats;
}

std::vector<std::string> header_lines(const ProcessConfig& config,
                                      const std::vector<core::SatelliteId>& most_observed) {
  std::vector<std::string> lines;
  lines.push_back("program   : canyon process (mode " + mode_name(config.mode) + ")");
  lines.push_back("inp file  : " + config.rover_obs);
  if (config.mode != ProcessMode::Spp) lines.push_back("inp file  : " + config.base_obs);
  if (config.mode == ProcessMode::Fusion) {
    lines.push_back("inp file  : " + config.vio);
    if (!config.timesync.empty()) lines.push_back("inp file  : " + config.timesync);
  }
  for (const std::string& n : config.nav) lines.push_back("inp file  : " + n);
  char mask[64];
  std::snprintf(mask, sizeof mask, "elev mask : %.1f deg", config.spp.elevation_mask_rad * 57.29577951308232);
  lines.emplace_back(mask);
  lines.push_back(std::string("ionos opt : ") + (config.spp.ionosphere_klobuchar ? "Broadcast" : "OFF"));
  lines.push_back(std::string("tropo opt : ") + (config.spp.troposphere_saastamoinen ? "Saastamoinen" : "OFF"));
  if (!most_observed.empty()) {
    std::string line = "excl sats : ";
    for (const core::SatelliteId& sat : most_observed) line += sat.to_string() + " ";
    line += "(the " + std::to_string(most_observed.size()) + " most observed)";
    lines.push_back(std::move(line));
  }
  return lines;
}

/// The base epoch to use at rover time t: the latest one not later than t (plus a small tolerance for receivers
/// whose time tags differ by milliseconds), or nullptr.
const core::ObsEpoch* base_epoch_at(const std::vector<core::ObsEpoch>& base, std::size_t& cursor,
                                    const core::GpsTime& t) {
  constexpr double kToleranceS = 0.05;
  while (cursor + 1 < base.size() && base[cursor + 1].time - t <= kToleranceS) ++cursor;
  if (cursor < base.size() && base[cursor].time - t <= kToleranceS) return &base[cursor];
  return nullptr;
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

/// The solution outputs: the .pos file and, when configured, NMEA GGA.
struct Outputs {
  io::PosWriter pos;
  std::optional<io::NmeaWriter> nmea;

  Status write(const core::Solution& solution, double hdop) {
    if (Status s = pos.write(solution); !s) return s;
    if (nmea) return nmea->write(solution, hdop);
    return Ok{};
  }
  Status close() {
    if (Status s = pos.close(); !s) return s;
    if (nmea) return nmea->close();
    return Ok{};
  }
};

/// Notes why an epoch got no solution ("no solution: ...") or a solution below the mode's best ("float: ...").
void add_epoch_note(ProcessSummary& summary, const core::GpsTime& t, const char* outcome, const std::string& reason) {
  if (summary.epoch_notes.size() >= kMaxEpochNotes) return;
  char when[48];
  std::snprintf(when, sizeof when, "%d %.3f: ", t.week, t.tow_s);
  std::string note = when;
  note += outcome;
  note += ": ";
  note += reason;
  summary.epoch_notes.push_back(std::move(note));
}

const char* status_word(core::SolutionStatus status) {
  switch (status) {
    case core::SolutionStatus::Fixed: return "fixed";
    case core::SolutionStatus::Float: return "float";
    case core::SolutionStatus::Single: return "single";
    case core::SolutionStatus::VioFillIn: return "VIO fill-in";
    default: return "other";
  }
}

Status run_spp(const ProcessConfig& config, const gnss::EphemerisStore& ephemerides,
               const std::vector<core::ObsEpoch>& rover, Outputs& writer, ProcessSummary& summary,
               const ProgressFn& progress) {
  std::optional<Eigen::Vector3d> last_p_E;
  const int total = static_cast<int>(rover.size());
  for (const core::ObsEpoch& epoch : rover) {
    ++summary.epochs;
    auto sol = gnss::solve_spp(epoch, ephemerides, config.spp, last_p_E);
    if (sol) {
      last_p_E = sol->p_E_m;
      if (Status w = writer.write(to_solution(*sol), sol->dop.hdop); !w) return w.error();
      ++summary.solved;
    } else {
      add_epoch_note(summary, epoch.time, "no solution", sol.error().message);
    }
    if (progress) progress(summary.epochs, total);
  }
  return Ok{};
}

Status run_rtk(const ProcessConfig& config, const gnss::EphemerisStore& ephemerides,
               const std::vector<core::ObsEpoch>& rover, const std::vector<core::ObsEpoch>& base,
               const Eigen::Vector3d& p_E_base, Outputs& writer, ProcessSummary& summary, const ProgressFn& progress) {
  rtk::RtkOptions options = config.rtk;
  rtk::RtkEngine engine(options, ephemerides, p_E_base);
  std::size_t cursor = 0;
  const int total = static_cast<int>(rover.size());
  for (const core::ObsEpoch& epoch : rover) {
    ++summary.epochs;
    auto result = engine.process(epoch, base_epoch_at(base, cursor, epoch.time));
    if (result) {
      if (Status w = writer.write(result->solution, result->hdop); !w) return w.error();
      ++summary.solved;
      if (result->solution.status == core::SolutionStatus::Fixed) ++summary.fixed;
      if (result->solution.status != core::SolutionStatus::Fixed) {
        add_epoch_note(summary, epoch.time, status_word(result->solution.status), result->note);
      }
    } else {
      add_epoch_note(summary, epoch.time, "no solution", result.error().message);
    }
    if (progress) progress(summary.epochs, total);
  }
  return Ok{};
}

std::string gps_text(const core::GpsTime& t) {
  const core::GpsTime n = t.normalized();
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%d %.3f", n.week, n.tow_s);
  return buffer;
}

/// The VIO trajectory on GPST: vio.csv through the time bridge (timesync.csv, unless the VIO is on GPST), split into
/// segments. Error (naming the file) when the VIO does not overlap the rover epochs at all.
Result<fusion::VioTrack> load_vio(const ProcessConfig& config, const std::vector<core::ObsEpoch>& rover,
                                  ProcessSummary& summary) {
  auto vio = io::read_vio_csv(config.vio);
  if (!vio) return vio.error();
  summary.warnings.insert(summary.warnings.end(), vio->warnings.begin(), vio->warnings.end());
  if (!vio->has_cross_covariance) {
    summary.warnings.push_back(config.vio +
                               ": no cross-covariance columns: consecutive VIO poses taken as uncorrelated (the "
                               "increments' covariance is then the sum of the poses' covariances, pessimistic)");
  }
  fusion::TimeBridge bridge = fusion::TimeBridge::gps_clock();
  char line[200];
  if (config.fusion.vio_on_gps_time) {
    summary.report.emplace_back("fusion: VIO time stamps taken as GPST (vio_clock: gps), no time sync");
  } else {
    auto sync = io::read_timesync_csv(config.timesync);
    if (!sync) return sync.error();
    summary.warnings.insert(summary.warnings.end(), sync->warnings.begin(), sync->warnings.end());
    auto fit = fusion::fit_time_bridge(sync->pairs, config.fusion.time_sync);
    if (!fit) return Error{fit.error().message, config.timesync, 0};
    for (const std::string& w : fit->warnings) summary.warnings.push_back(config.timesync + ": " + w);
    bridge = fit->bridge;
    std::snprintf(line, sizeof line,
                  "fusion: time bridge from %d pairs: device clock drift %.2f ppm, residual RMS %.3f ms (max %.3f "
                  "ms), %zu outlier pairs rejected",
                  fit->pairs, bridge.drift_ppm(), fit->residual_rms_s * 1e3, fit->max_residual_s * 1e3,
                  fit->outlier_lines.size());
    summary.report.emplace_back(line);
    if (!fit->outlier_lines.empty()) {
      std::string lines = "fusion: time-sync outliers at lines";
      for (std::size_t i = 0; i < fit->outlier_lines.size() && i < 10; ++i) {
        lines += ' ';
        lines += std::to_string(fit->outlier_lines[i]);
      }
      if (fit->outlier_lines.size() > 10) lines += " ...";
      summary.report.push_back(lines);
    }
  }
  std::vector<std::string> notes;
  auto track = fusion::VioTrack::build(*vio, bridge, config.fusion.vio, notes);
  if (!track) return Error{track.error().message, config.vio, 0};
  for (const std::string& n : notes) summary.report.push_back("fusion: " + n);
  if (!rover.empty() &&
      (track->last_time() - rover.front().time < 0.0 || rover.back().time - track->first_time() < 0.0)) {
    return Error{"the VIO (GPST " + gps_text(track->first_time()) + " to " + gps_text(track->last_time()) +
                     ") does not overlap the rover epochs (GPST " + gps_text(rover.front().time) + " to " +
                     gps_text(rover.back().time) + "): wrong file, or wrong time sync" +
                     (config.fusion.vio_on_gps_time ? " (vio_clock: gps)" : ""),
                 config.vio, 0};
  }
  return track;
}

Status run_fusion(const ProcessConfig& config, const gnss::EphemerisStore& ephemerides,
                  const std::vector<core::ObsEpoch>& rover, const std::vector<core::ObsEpoch>& base,
                  const Eigen::Vector3d& p_E_base, Outputs& writer, ProcessSummary& summary,
                  const ProgressFn& progress) {
  auto track = load_vio(config, rover, summary);
  if (!track) return track.error();
  fusion::FusionEngine engine(config.fusion, config.rtk, ephemerides, p_E_base, std::move(*track));
  std::size_t cursor = 0;
  const int total = static_cast<int>(rover.size());
  for (const core::ObsEpoch& epoch : rover) {
    ++summary.epochs;
    auto result = engine.process(epoch, base_epoch_at(base, cursor, epoch.time));
    if (result) {
      if (Status w = writer.write(result->solution, result->hdop); !w) return w.error();
      ++summary.solved;
      if (result->solution.status == core::SolutionStatus::Fixed) {
        ++summary.fixed;
      } else {
        add_epoch_note(summary, epoch.time, status_word(result->solution.status), result->note);
      }
    } else {
      add_epoch_note(summary, epoch.time, "no solution", result.error().message);
    }
    if (progress) progress(summary.epochs, total);
  }
  const std::vector<std::string> report = engine.report();
  summary.report.insert(summary.report.end(), report.begin(), report.end());
  return Ok{};
}

}  // namespace

std::vector<core::SatelliteId> most_observed_satellites(const std::vector<core::ObsEpoch>& epochs, int n,
                                                        const core::ConstellationFlags& systems) {
  std::vector<int> count(core::kMaxSatellites, 0);
  std::vector<core::SatelliteId> seen(core::kMaxSatellites);
  for (const core::ObsEpoch& epoch : epochs) {
    for (const core::SatelliteObs& sat : epoch.sats) {
      if (!sat.sat.valid() || !systems.uses(sat.sat.system) || !is_tracked(sat)) continue;
      const int i = sat.sat.index();
      ++count[i];
      seen[i] = sat.sat;
    }
  }
  std::vector<core::SatelliteId> sats;
  for (int i = 0; i < core::kMaxSatellites; ++i) {
    if (count[i] > 0) sats.push_back(seen[i]);
  }
  std::stable_sort(sats.begin(), sats.end(), [&count](const core::SatelliteId& a, const core::SatelliteId& b) {
    return count[a.index()] > count[b.index()] || (count[a.index()] == count[b.index()] && a < b);
  });
  if (static_cast<int>(sats.size()) > n) sats.resize(static_cast<std::size_t>(std::max(n, 0)));
  return sats;
}

Result<ProcessSummary> run_process(const ProcessConfig& input_config, const ProgressFn& progress) {
  const auto start = std::chrono::steady_clock::now();
  if (const std::string e = input_config.validate(); !e.empty()) return Error{e};
  ProcessConfig config = input_config;
  ProcessSummary summary;

  auto nav = read_navigation(config.nav, summary.warnings);
  if (!nav) return nav.error();
  const gnss::EphemerisStore ephemerides(std::move(*nav));

  auto rover = io::read_rinex_obs(config.rover_obs);
  if (!rover) return rover.error();
  summary.warnings.insert(summary.warnings.end(), rover->warnings.begin(), rover->warnings.end());
  keep_observations(*rover, config.rover_obs, summary.warnings);
  summary.excluded_most_observed = exclude_most_observed(config, rover->epochs);

  std::optional<io::RinexObsFile> base;
  Eigen::Vector3d p_E_base = Eigen::Vector3d::Zero();
  if (config.mode != ProcessMode::Spp) {
    auto base_file = io::read_rinex_obs(config.base_obs);
    if (!base_file) return base_file.error();
    summary.warnings.insert(summary.warnings.end(), base_file->warnings.begin(), base_file->warnings.end());
    keep_observations(*base_file, config.base_obs, summary.warnings);
    if (config.base_position_E_m) {
      p_E_base = *config.base_position_E_m;
    } else if (base_file->header.receiver.approx_position_E_m) {
      p_E_base = *base_file->header.receiver.approx_position_E_m;
    } else {
      return Error{
          "no base position: the base file has no APPROX POSITION XYZ; give --base-pos X,Y,Z or "
          "'base_position:'",
          config.base_obs, 0};
    }
    if (!rover->epochs.empty() && !base_file->epochs.empty() &&
        std::abs(rover->epochs.front().time - base_file->epochs.front().time) > 86400.0 &&
        std::abs(rover->epochs.back().time - base_file->epochs.back().time) > 86400.0) {
      summary.warnings.push_back(config.base_obs + ": base observations do not overlap the rover's (another day?)");
    }
    if (std::string w = glonass_ar_warning(config, rover->header, base_file->header); !w.empty()) {
      summary.warnings.push_back(std::move(w));
    }
    base = std::move(*base_file);
  }

  auto pos = io::PosWriter::create(
      config.out, {config.coordinates, config.time_format, header_lines(config, summary.excluded_most_observed)});
  if (!pos) return pos.error();
  Outputs outputs{std::move(*pos), std::nullopt};
  if (!config.nmea_out.empty()) {
    auto nmea = io::NmeaWriter::create(config.nmea_out);
    if (!nmea) return nmea.error();
    outputs.nmea = std::move(*nmea);
  }
  Status run = Ok{};
  switch (config.mode) {
    case ProcessMode::Rtk:
      run = run_rtk(config, ephemerides, rover->epochs, base->epochs, p_E_base, outputs, summary, progress);
      break;
    case ProcessMode::Fusion:
      run = run_fusion(config, ephemerides, rover->epochs, base->epochs, p_E_base, outputs, summary, progress);
      break;
    case ProcessMode::Spp: run = run_spp(config, ephemerides, rover->epochs, outputs, summary, progress); break;
  }
  if (!run) return run.error();
  if (Status c = outputs.close(); !c) return c.error();
  summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace canyon::app
