// Batch processing: read inputs, solve each epoch, write the .pos file.

#include "canyon/commands/process.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>

#include "canyon/core/geodesy.hpp"
#include "canyon/fusion/fusion_engine.hpp"
#include "canyon/fusion/time_bridge.hpp"
#include "canyon/fusion/vio_track.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/gnss/spp.hpp"
#include "canyon/io/nmea.hpp"
#include "canyon/io/obs_read_ahead.hpp"
#include "canyon/io/rinex_nav.hpp"
#include "canyon/io/rinex_obs.hpp"
#include "canyon/io/vio_file.hpp"
#include "canyon/pipeline/observation_stream.hpp"
#include "canyon/rtk/engine.hpp"

namespace canyon::commands {
namespace {

constexpr std::size_t kMaxEpochNotes = 100;

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
std::string glonass_ar_warning(const config::ProcessConfig& config, const io::RinexObsHeader& rover,
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

/// Tracking counts per satellite over epochs, for `exclude_most_observed`.
class SatelliteTally {
 public:
  explicit SatelliteTally(const core::ConstellationFlags& systems)
      : systems_(systems), count_(core::kMaxSatellites, 0), seen_(core::kMaxSatellites) {}

  void add(const core::ObsEpoch& epoch) {
    for (const core::SatelliteObs& sat : epoch.sats) {
      if (!sat.sat.valid() || !systems_.uses(sat.sat.system) || !is_tracked(sat)) continue;
      const int i = sat.sat.index();
      ++count_[static_cast<std::size_t>(i)];
      seen_[static_cast<std::size_t>(i)] = sat.sat;
    }
  }

  /// The `n` most tracked, most first; ties go to the lower satellite id.
  [[nodiscard]] std::vector<core::SatelliteId> most(int n) const {
    std::vector<core::SatelliteId> sats;
    for (std::size_t i = 0; i < count_.size(); ++i) {
      if (count_[i] > 0) sats.push_back(seen_[i]);
    }
    const auto count = [this](const core::SatelliteId& s) { return count_[static_cast<std::size_t>(s.index())]; };
    std::stable_sort(sats.begin(), sats.end(), [&count](const core::SatelliteId& a, const core::SatelliteId& b) {
      return count(a) > count(b) || (count(a) == count(b) && a < b);
    });
    if (static_cast<int>(sats.size()) > n) sats.resize(static_cast<std::size_t>(std::max(n, 0)));
    return sats;
  }

 private:
  core::ConstellationFlags systems_;
  std::vector<int> count_;
  std::vector<core::SatelliteId> seen_;
};

/// Applies `exclude_most_observed` with a first pass over the rover file: the satellites join both modes'
/// exclusion lists. Returns them.
Result<std::vector<core::SatelliteId>> exclude_most_observed(config::ProcessConfig& config,
                                                             const io::ObsFilter& filter) {
  if (config.exclude_most_observed <= 0) return std::vector<core::SatelliteId>{};
  const core::ConstellationFlags& systems = config.mode != config::ProcessMode::Spp
                                                ? static_cast<const core::ConstellationFlags&>(config.rtk.observables)
                                                : static_cast<const core::ConstellationFlags&>(config.spp);
  auto rover = pipeline::ObservationStream::open(config.rover_obs, filter);
  if (!rover) return rover.error();
  SatelliteTally tally(systems);
  for (;;) {
    auto epoch = rover->next();
    if (!epoch) return epoch.error();
    if (!*epoch) break;
    tally.add(**epoch);
  }
  std::vector<core::SatelliteId> sats = tally.most(config.exclude_most_observed);
  for (const core::SatelliteId& sat : sats) {
    config.spp.excluded.push_back(sat);
    config.rtk.observables.excluded.push_back(sat);
  }
  return sats;
}

std::vector<std::string> header_lines(const config::ProcessConfig& config,
                                      const std::vector<core::SatelliteId>& most_observed) {
  std::vector<std::string> lines;
  lines.push_back("program   : canyon process (mode " + config::mode_name(config.mode) + ")");
  lines.push_back("inp file  : " + config.rover_obs);
  if (config.mode != config::ProcessMode::Spp) lines.push_back("inp file  : " + config.base_obs);
  if (config.mode == config::ProcessMode::Fusion) {
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

/// Reports progress (epochs done, fraction of the rover file read).
void report(const ProgressFn& progress, const ProcessSummary& summary, const pipeline::ObservationStream& rover) {
  if (progress) progress(summary.epochs, rover.fraction_read());
}

Status run_spp(const config::ProcessConfig& config, const gnss::EphemerisStore& ephemerides,
               pipeline::ObservationStream& rover, Outputs& writer, ProcessSummary& summary,
               const ProgressFn& progress) {
  std::optional<Eigen::Vector3d> last_p_E;
  for (;;) {
    auto next = rover.next();
    if (!next) return next.error();
    if (!*next) break;
    const core::ObsEpoch& epoch = **next;
    ++summary.epochs;
    auto sol = gnss::solve_spp(epoch, ephemerides, config.spp, last_p_E);
    if (sol) {
      last_p_E = sol->p_E_m;
      if (Status w = writer.write(to_solution(*sol), sol->dop.hdop); !w) return w.error();
      ++summary.solved;
    } else {
      add_epoch_note(summary, epoch.time, "no solution", sol.error().message);
    }
    report(progress, summary, rover);
  }
  return Ok{};
}

/// Ingest for batch processing: the rover file epoch by epoch, each with its base epoch (BaseCursor).
class FileEpochSource final : public pipeline::EpochSource {
 public:
  FileEpochSource(pipeline::ObservationStream& rover, pipeline::BaseCursor& base) : rover_(rover), base_(base) {}

  Result<std::optional<pipeline::IngestedEpoch>> next() override {
    auto next = rover_.next();
    if (!next) return next.error();
    if (!*next) return std::optional<pipeline::IngestedEpoch>{};
    std::optional<pipeline::IngestedEpoch> item(std::in_place);
    item->rover = std::move(**next);
    auto base_epoch = base_.at(item->rover.time);
    if (!base_epoch) return base_epoch.error();
    if (*base_epoch != nullptr) item->base = **base_epoch;
    fraction_read_.store(rover_.fraction_read());
    return item;
  }
  [[nodiscard]] double fraction_read() const { return fraction_read_.load(); }

 private:
  pipeline::ObservationStream& rover_;
  pipeline::BaseCursor& base_;
  std::atomic<double> fraction_read_{0.0};
};

/// The solutions of rtk and fusion modes: through the staged pipeline (sequential unless `pipeline` says threaded)
/// to the outputs, with the summary's counts and notes.
Status run_staged(pipeline::EpochEstimator& estimator, pipeline::ObservationStream& rover, pipeline::BaseCursor& base,
                  Outputs& writer, ProcessSummary& summary, const ProgressFn& progress,
                  const pipeline::PipelineOptions& pipeline,
                  const std::function<void(const core::GpsTime&)>& on_epoch = {}) {
  FileEpochSource source(rover, base);
  const auto sink = [&](const pipeline::SolvedEpoch& solved) -> Status {
    const core::GpsTime& t = solved.epoch().rover.time;
    if (on_epoch) on_epoch(t);
    ++summary.epochs;
    if (solved.output) {
      const pipeline::EpochOutput& out = *solved.output;
      if (Status w = writer.write(out.solution, out.hdop); !w) return w.error();
      ++summary.solved;
      if (out.solution.status == core::SolutionStatus::Fixed) {
        ++summary.fixed;
      } else {
        if (core::exact_status(out.solution) == core::kPartialFixStatus) ++summary.partial_fixed;
        add_epoch_note(summary, t, status_word(out.solution.status), out.note);
      }
    } else {
      add_epoch_note(summary, t, "no solution", solved.output.error().message);
    }
    if (progress) progress(summary.epochs, source.fraction_read());
    return Ok{};
  };
  pipeline::EpochPipeline runner(source, estimator, sink, pipeline);
  return runner.run();
}

Status run_rtk(const config::ProcessConfig& config, const gnss::EphemerisStore& ephemerides,
               pipeline::ObservationStream& rover, pipeline::BaseCursor& base, const Eigen::Vector3d& p_E_base,
               Outputs& writer, ProcessSummary& summary, const ProgressFn& progress,
               const pipeline::PipelineOptions& pipeline) {
  rtk::RtkEngine engine(config.rtk_engine_options(), ephemerides, p_E_base);
  pipeline::RtkEstimator estimator(engine);
  return run_staged(estimator, rover, base, writer, summary, progress, pipeline);
}

std::string gps_text(const core::GpsTime& t) {
  const core::GpsTime n = t.normalized();
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%d %.3f", n.week, n.tow_s);
  return buffer;
}

/// The VIO track's rate and segment breaks: one line for the rate, the first kMaxSegmentNotes breaks, then one line
/// counting the rest by kind (a stream at the wrong rate or with many breaks says so in a few lines).
void report_vio_segments(const fusion::VioTrack& track, const fusion::VioTrackOptions& options,
                         const std::vector<std::string>& notes, ProcessSummary& summary) {
  constexpr std::size_t kMaxSegmentNotes = 10;
  const double interval_s = fusion::median_interval_s(track.samples());
  if (interval_s > 0.0) {
    char line[200];
    std::snprintf(line, sizeof line,
                  "fusion: VIO poses every %.3f s (%.1f Hz, median): a gap is longer than %.2f s (vio_max_gap_s or "
                  "%.0f intervals); %d VIO segment(s)",
                  interval_s, 1.0 / interval_s, std::max(options.max_gap_s, fusion::kGapIntervals * interval_s),
                  fusion::kGapIntervals, track.segments());
    summary.report.emplace_back(line);
  }
  for (std::size_t i = 0; i < notes.size() && i < kMaxSegmentNotes; ++i) {
    summary.report.push_back("fusion: " + notes[i]);
  }
  if (notes.size() <= kMaxSegmentNotes) return;
  int gaps = 0;
  int jumps = 0;
  int steps = 0;
  for (std::size_t i = kMaxSegmentNotes; i < notes.size(); ++i) {
    if (notes[i].rfind("VIO gap", 0) == 0) ++gaps;
    if (notes[i].rfind("VIO jump", 0) == 0) ++jumps;
    if (notes[i].rfind("VIO time-sync step", 0) == 0) ++steps;
  }
  const auto rest = static_cast<int>(notes.size() - kMaxSegmentNotes);
  summary.report.push_back("fusion: ... and " + std::to_string(rest) + " more VIO segment breaks (" +
                           std::to_string(gaps) + " gaps, " + std::to_string(jumps) + " jumps, " +
                           std::to_string(steps) + " time-sync steps, " + std::to_string(rest - gaps - jumps - steps) +
                           " covariance resets)");
}

/// The VIO track with the causal time bridge (fusion.timesync_mode: causal): every pose mapped as the live rover maps
/// it (fusion::CausalTimeBridge), so that `canyon process` reproduces a rover fed over DDS.
Result<fusion::VioTrack> load_vio_causal(const config::ProcessConfig& config, const io::VioFile& vio,
                                         ProcessSummary& summary) {
  fusion::CausalTimeBridge bridge = fusion::CausalTimeBridge::gps_clock();
  if (!config.fusion.vio_on_gps_time) {
    auto sync = io::read_timesync_csv(config.timesync);
    if (!sync) return sync.error();
    summary.warnings.insert(summary.warnings.end(), sync->warnings.begin(), sync->warnings.end());
    bridge = fusion::CausalTimeBridge(config.fusion.time_sync);
    for (const io::TimeSyncPair& pair : sync->pairs) {
      if (Status s = bridge.add(pair); !s) {
        summary.warnings.push_back(config.timesync + ":" + std::to_string(pair.line) + ": " + s.error().message);
      }
    }
  }
  fusion::VioTrack track = fusion::VioTrack::streaming(config.fusion.vio);
  std::vector<std::string> notes;
  int unmapped = 0;
  int unmapped_run = 0;
  for (const io::VioRecord& record : vio.records) {
    auto t = bridge.to_gps(record.t_ns);
    if (!t) {
      // The first pose of each run of unmapped ones says why.
      if (unmapped_run++ == 0) {
        summary.report.push_back("fusion: " + config.vio + ":" + std::to_string(record.line) +
                                 ": pose not mapped to GPST: " + t.error().message);
      }
      ++unmapped;
      continue;
    }
    unmapped_run = 0;
    std::string note;
    // A fit cannot reorder poses a few ms apart; after a time-sync step back in GPST the first poses are dropped.
    (void)track.append(record, *t, &note, bridge.steps_seen());
    if (!note.empty()) notes.push_back(note);
  }
  if (unmapped > 0) {
    summary.report.push_back("fusion: " + std::to_string(unmapped) +
                             " VIO poses not mapped to GPST by the causal time bridge (not used; why above)");
  }
  if (bridge.ignored_steps() > 0) {
    summary.report.push_back("fusion: " + bridge.ignored_step_note() + " (" + std::to_string(bridge.ignored_steps()) +
                             " such step(s))");
  }
  if (track.empty()) return Error{"no VIO pose mapped to GPST by the causal time bridge", config.vio, 0};
  report_vio_segments(track, config.fusion.vio, notes, summary);
  if (const std::optional<fusion::TimeBridgeFit>& fit = bridge.fit()) {
    char line[200];
    std::snprintf(line, sizeof line,
                  "fusion: causal time bridge (pairs %.1f s older than each pose, at most %d): last fit from %d "
                  "pairs, drift %.2f ppm, residual RMS %.3f ms",
                  config.fusion.time_sync.causal_hold_s, config.fusion.time_sync.causal_window_pairs, fit->pairs,
                  fit->bridge.drift_ppm(), fit->residual_rms_s * 1e3);
    summary.report.emplace_back(line);
  }
  return track;
}

/// The VIO trajectory on GPST: vio.csv through the time bridge (timesync.csv, unless the VIO is on GPST), split into
/// segments.
Result<fusion::VioTrack> load_vio(const config::ProcessConfig& config, ProcessSummary& summary) {
  auto vio = io::read_vio_csv(config.vio);
  if (!vio) return vio.error();
  summary.warnings.insert(summary.warnings.end(), vio->warnings.begin(), vio->warnings.end());
  if (!vio->has_cross_covariance) {
    summary.warnings.push_back(config.vio +
                               ": no cross-covariance columns: consecutive VIO poses taken as uncorrelated (the "
                               "increments' covariance is then the sum of the poses' covariances, pessimistic)");
  }
  if (config.fusion.time_sync.causal) return load_vio_causal(config, *vio, summary);
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
  report_vio_segments(*track, config.fusion.vio, notes, summary);
  return track;
}

Status run_fusion(const config::ProcessConfig& config, const gnss::EphemerisStore& ephemerides,
                  pipeline::ObservationStream& rover, pipeline::BaseCursor& base, const Eigen::Vector3d& p_E_base,
                  Outputs& writer, ProcessSummary& summary, const ProgressFn& progress,
                  const pipeline::PipelineOptions& pipeline) {
  auto track = load_vio(config, summary);
  if (!track) return track.error();
  const core::GpsTime vio_first = track->first_time();
  const core::GpsTime vio_last = track->last_time();
  fusion::FusionEngine engine(config.fusion, config.rtk_engine_options(), ephemerides, p_E_base, std::move(*track));
  pipeline::FusionEstimator estimator(engine);
  std::optional<core::GpsTime> first;
  core::GpsTime last;
  int overlapping = 0;
  const auto on_epoch = [&](const core::GpsTime& t) {
    if (!first) first = t;
    last = t;
    if (!(t < vio_first) && !(vio_last < t)) ++overlapping;
  };
  if (Status s = run_staged(estimator, rover, base, writer, summary, progress, pipeline, on_epoch); !s) return s;
  if (first && overlapping == 0) {
    return Error{"the VIO (GPST " + gps_text(vio_first) + " to " + gps_text(vio_last) +
                     ") does not overlap the rover epochs (GPST " + gps_text(*first) + " to " + gps_text(last) +
                     "): wrong file, or wrong time sync" + (config.fusion.vio_on_gps_time ? " (vio_clock: gps)" : ""),
                 config.vio, 0};
  }
  const std::vector<std::string> lines = engine.report();
  summary.report.insert(summary.report.end(), lines.begin(), lines.end());
  return Ok{};
}

}  // namespace

std::vector<core::SatelliteId> most_observed_satellites(const std::vector<core::ObsEpoch>& epochs, int n,
                                                        const core::ConstellationFlags& systems) {
  SatelliteTally tally(systems);
  for (const core::ObsEpoch& epoch : epochs) tally.add(epoch);
  return tally.most(n);
}

namespace {

/// What the observation files are read for: the constellations of either solution, and the frequencies the mode
/// uses (single point: the first; RTK: as configured). The rest is not parsed.
io::ObsFilter observation_filter(const config::ProcessConfig& config) {
  io::ObsFilter filter;
  const core::ConstellationFlags& spp = config.spp;
  filter.systems = spp;
  filter.max_frequency_rank = 0;
  if (config.mode != config::ProcessMode::Spp) {
    const core::ConstellationFlags& rtk = config.rtk.observables;
    filter.systems.use_gps = spp.use_gps || rtk.use_gps;
    filter.systems.use_glonass = spp.use_glonass || rtk.use_glonass;
    filter.systems.use_galileo = spp.use_galileo || rtk.use_galileo;
    filter.systems.use_beidou = spp.use_beidou || rtk.use_beidou;
    filter.systems.use_qzss = spp.use_qzss || rtk.use_qzss;
    filter.max_frequency_rank = config.rtk.observables.num_frequencies - 1;
  }
  return filter;
}

}  // namespace

Result<ProcessSummary> run_process(const config::ProcessConfig& input_config, const ProgressFn& progress,
                                   const pipeline::PipelineOptions& pipeline) {
  const auto start = std::chrono::steady_clock::now();
  if (const std::string e = input_config.validate(); !e.empty()) return Error{e};
  config::ProcessConfig config = input_config;
  ProcessSummary summary;

  // The observation files start parsing on their own threads while the navigation files are read; errors are
  // still reported navigation first. The bridge-ahead pipeline (rtk and fusion modes) parses them on its ingest
  // thread instead: two busy threads are what two cores run best.
  const io::ObsFilter filter = observation_filter(config);
  const bool read_ahead = config.mode == config::ProcessMode::Spp || pipeline.threaded || !pipeline.bridge_ahead;
  auto rover = pipeline::ObservationStream::open(config.rover_obs, filter, std::nullopt, read_ahead);
  std::optional<Result<pipeline::ObservationStream>> base_stream;
  if (config.mode != config::ProcessMode::Spp) {
    // An RTCM 3 base file dates its epochs from the rover's first epoch.
    const std::optional<core::GpsTime> reference = rover ? rover->header().first_obs : std::nullopt;
    base_stream.emplace(pipeline::ObservationStream::open(config.base_obs, filter, reference, read_ahead));
  }

  auto nav = read_navigation(config.nav, summary.warnings);
  if (!nav) return nav.error();
  const gnss::EphemerisStore ephemerides(std::move(*nav));

  auto excluded = exclude_most_observed(config, filter);
  if (!excluded) return excluded.error();
  summary.excluded_most_observed = std::move(*excluded);
  if (!rover) return rover.error();

  std::optional<pipeline::BaseCursor> base;
  Eigen::Vector3d p_E_base = Eigen::Vector3d::Zero();
  if (base_stream) {
    if (!*base_stream) return base_stream->error();
    if (config.base_position_E_m) {
      p_E_base = *config.base_position_E_m;
    } else if ((*base_stream)->header().receiver.approx_position_E_m) {
      p_E_base = *(*base_stream)->header().receiver.approx_position_E_m;
    } else {
      return Error{
          "no base position: the base file has no APPROX POSITION XYZ; give --base-pos X,Y,Z or "
          "'base_position:'",
          config.base_obs, 0};
    }
    if (std::string w = glonass_ar_warning(config, rover->header(), (*base_stream)->header()); !w.empty()) {
      summary.warnings.push_back(std::move(w));
    }
    base.emplace(std::move(**base_stream));
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
    case config::ProcessMode::Rtk:
      run = run_rtk(config, ephemerides, *rover, *base, p_E_base, outputs, summary, progress, pipeline);
      break;
    case config::ProcessMode::Fusion:
      run = run_fusion(config, ephemerides, *rover, *base, p_E_base, outputs, summary, progress, pipeline);
      break;
    case config::ProcessMode::Spp: run = run_spp(config, ephemerides, *rover, outputs, summary, progress); break;
  }
  if (!run) return run.error();
  if (Status c = outputs.close(); !c) return c.error();
  rover->append_warnings(summary.warnings);
  if (base) {
    pipeline::ObservationStream& b = base->stream();
    b.append_warnings(summary.warnings);
    if (rover->first_time() && b.first_time() && std::abs(*rover->first_time() - *b.first_time()) > 86400.0 &&
        std::abs(*rover->last_time() - *b.last_time()) > 86400.0) {
      summary.warnings.push_back(config.base_obs + ": base observations do not overlap the rover's (another day?)");
    }
  }
  summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace canyon::commands

namespace canyon::commands {

Result<core::NavigationData> load_navigation(const std::vector<std::string>& paths,
                                             std::vector<std::string>& warnings) {
  return read_navigation(paths, warnings);
}

io::ObsFilter process_observation_filter(const config::ProcessConfig& config) {
  return observation_filter(config);
}

Result<fusion::VioTrack> load_vio_track(const config::ProcessConfig& config, ProcessSummary& summary) {
  return load_vio(config, summary);
}

std::vector<std::string> pos_header_lines(const config::ProcessConfig& config) {
  return header_lines(config, {});
}

}  // namespace canyon::commands
