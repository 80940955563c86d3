// bench_repair_truth: ambiguities started from the held position (slip repair and re-acquisition,
// rtk/ambiguity_prior.hpp) judged against the simulator's true integers, by the length of the gap they bridged; and
// the time to a correct fix after each blockage.
//
//   bench_repair_truth SCENARIO.yaml SEED... [--mode fusion|rtk] [--config FILE] [--max-sigma CYC] [--duration S]
//                      [--align-at S]
//
// Each seed of the scenario is simulated in memory with its signal truth, and fused with FILE (default
// config/fusion.yaml; with --mode rtk canyon rtk without the VIO, default config/rtk.yaml) with
// rtk.ambiguity_prior_max_sigma_cyc set to CYC (default 0.15, lambda/6.6) where the file leaves it off (--max-sigma 0:
// the file as it is). The VIO is the simulator's pose stream on GPST (no time-sync file). For every ambiguity started
// from the position between signals of one wavelength (an integer DD ambiguity), the true DD integer is
//   (N_rover,s - N_base,s) - (N_rover,r - N_base,r)
// from the simulator's channel ambiguities, and the start is wrong when it rounds to another integer. The gap is the
// time since the signal's last rover phase before this epoch: 0 for a slip while tracked (loss-of-lock bit), the
// outage otherwise; "new" when the signal had no phase before. A start on a signal (or against a reference) received
// only by reflection has no true integer in this sense (its phase carries the excess path) and is counted apart.
// A blockage is a run of at least 1 s below the line-of-sight ceiling (fewer than 5 satellites in line of sight, by
// the truth) after an epoch above it; its time to a correct fix runs from its end to the first fixed epoch within
// 10 cm (3D) of the truth before the next blockage.
// Every output fixed epoch's DD integers (the RTK filter's accepted fix) are judged the same way: right when each
// one between line-of-sight signals equals the true integer, and the epoch is counted by that and by its position
// (within 10 cm of the truth or beyond).
// Prints, over all seeds, the table of starts, a line "repairs=N wrong=M wrong_pct=X nlos=K ...", a line
// "fixed_epochs=N within_10cm: integers_right=A integers_wrong=B; beyond_10cm: ...", a line of the partial fixes'
// and the other floats' 3D errors "partial_fix_epochs=N error_3d_m median=X p95=Y within_10cm=K; float_epochs=..." and
// a line
// "blockages=N ... time_to_correct_fix_s median=X p90=Y max=Z".
// In fusion, per seed and over the seeds, the alignment at --align-at S (default 180 s after the start): the heading
// error of the aligned VIO attitude R_EO R_OI against the true R_EI (about the local vertical, deg) and the
// horizontal error of the lever arm t_IA in use against the scenario's (m, in the local level frame through the true
// attitude); "none" when no alignment holds then. Lines "alignment seed=N ..." and "alignment_at_s=S seeds=N
// aligned=K heading_error_deg median=X max=Y lever_arm_horizontal_error_m max=Z fine=F".

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <unistd.h>

#include "canyon/config/process_config.hpp"
#include "canyon/config/scenario_config.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/fusion/fusion_engine.hpp"
#include "canyon/fusion/vio_track.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/rtk/ambiguity_prior.hpp"
#include "canyon/rtk/engine.hpp"
#include "canyon/sim/simulator.hpp"

#include "sim_vio_samples.hpp"

namespace {

namespace fs = std::filesystem;
using canyon::core::GpsTime;
using canyon::core::SatelliteId;
using canyon::core::SignalCode;

struct Args {
  std::string scenario;
  std::vector<std::uint64_t> seeds;
  std::string config;  // default: config/fusion.yaml, or config/rtk.yaml with --mode rtk
  double max_sigma_cyc = 0.15;
  double duration_s = 0.0;    // 0: the scenario's
  bool rtk = false;           // canyon rtk (no VIO) instead of fusion
  double align_at_s = 180.0;  // when the alignment is judged, after the start
};

std::optional<Args> parse_args(int argc, char** argv) {
  Args args;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--config" && has_value) {
      args.config = argv[++i];
    } else if (a == "--max-sigma" && has_value) {
      args.max_sigma_cyc = std::atof(argv[++i]);
    } else if (a == "--mode" && has_value) {
      const std::string mode = argv[++i];
      if (mode != "rtk" && mode != "fusion") return std::nullopt;
      args.rtk = mode == "rtk";
    } else if (a == "--align-at" && has_value) {
      args.align_at_s = std::atof(argv[++i]);
    } else if (a == "--duration" && has_value) {
      args.duration_s = std::atof(argv[++i]);
    } else if (args.scenario.empty()) {
      args.scenario = a;
    } else {
      char* end = nullptr;
      const unsigned long long seed = std::strtoull(a.c_str(), &end, 10);
      if (end == a.c_str() || *end != '\0') return std::nullopt;
      args.seeds.push_back(seed);
    }
  }
  if (args.scenario.empty() || args.seeds.empty() || !(args.max_sigma_cyc >= 0.0)) return std::nullopt;
  if (args.config.empty()) {
    args.config = std::string(CANYON_SOURCE_DIR) + (args.rtk ? "/config/rtk.yaml" : "/config/fusion.yaml");
  }
  return args;
}

/// The gap bins of the table: a slip while tracked, then outages by length, then a signal never seen before.
constexpr int kBins = 6;
const char* const kBinNames[kBins] = {"slip (tracked)", "gap <= 1 s", "gap 1-5 s", "gap 5-30 s", "gap > 30 s", "new"};
int gap_bin(std::optional<double> gap_s) {
  if (!gap_s) return 5;
  if (*gap_s <= 0.0) return 0;
  if (*gap_s <= 1.0) return 1;
  if (*gap_s <= 5.0) return 2;
  if (*gap_s <= 30.0) return 3;
  return 4;
}

struct Tally {
  int starts = 0;      // integer DD starts
  int judged = 0;      // both signals in line of sight with a true integer
  int wrong = 0;       // rounds to another integer than the true one
  int nlos = 0;        // the signal or its reference received by reflection
  int no_truth = 0;    // the simulator's truth lacks a signal (base epoch without it)
  int fractional = 0;  // between wavelengths (GLONASS): no integer
  double max_error_cyc = 0.0;
};

const canyon::sim::SignalTruth* find_signal(const canyon::sim::EpochTruth& epoch, const SatelliteId& sat,
                                            double wavelength_m) {
  for (const canyon::sim::SignalTruth& s : epoch.signals) {
    if (s.sat == sat && std::abs(s.wavelength_m - wavelength_m) < 1e-9) return &s;
  }
  return nullptr;
}

/// The true DD integer (N_rover,s - N_base,s) - (N_rover,r - N_base,r) of satellite s against reference r on the
/// wavelength `lambda_m`, from the rover and base epochs' signal truth; none when a signal is missing or received
/// only by reflection.
struct TrueDd {
  enum class Kind { Known, Missing, Reflected };
  Kind kind = Kind::Missing;
  double cycles = 0.0;
};
TrueDd true_dd(const canyon::sim::EpochTruth& rover, const canyon::sim::EpochTruth& base, const SatelliteId& s,
               const SatelliteId& r, double lambda_m) {
  const canyon::sim::SignalTruth* rs = find_signal(rover, s, lambda_m);
  const canyon::sim::SignalTruth* bs = find_signal(base, s, lambda_m);
  const canyon::sim::SignalTruth* rr = find_signal(rover, r, lambda_m);
  const canyon::sim::SignalTruth* br = find_signal(base, r, lambda_m);
  if (rs == nullptr || bs == nullptr || rr == nullptr || br == nullptr) return {};
  if (!rs->direct || !rr->direct || !bs->direct || !br->direct) return {TrueDd::Kind::Reflected};
  return {TrueDd::Kind::Known,
          static_cast<double>((rs->ambiguity_cyc - bs->ambiguity_cyc) - (rr->ambiguity_cyc - br->ambiguity_cyc))};
}

/// One start judged against the truth at rover epoch `rover` and base epoch `base`.
void judge(const canyon::rtk::AmbiguityStart& start, const canyon::sim::EpochTruth& rover,
           const canyon::sim::EpochTruth& base, Tally& tally) {
  if (!start.integer) {
    ++tally.fractional;
    return;
  }
  ++tally.starts;
  // An integer DD ambiguity: the reference has the signal's wavelength.
  const TrueDd dd = true_dd(rover, base, start.key.sat, start.reference.sat, start.wavelength_m);
  if (dd.kind == TrueDd::Kind::Missing) {
    ++tally.no_truth;
    return;
  }
  if (dd.kind == TrueDd::Kind::Reflected) {
    ++tally.nlos;
    return;
  }
  const double truth = dd.cycles;
  ++tally.judged;
  const double error_cyc = start.dd_cyc - truth;
  tally.max_error_cyc = std::max(tally.max_error_cyc, std::abs(error_cyc));
  if (std::round(start.dd_cyc) != truth) {
    ++tally.wrong;
    std::printf("  wrong start at %.1f s: %s frequency %d against %s: %.3f cycles (sigma %.3f), true %.0f\n", rover.t_s,
                start.key.sat.to_string().c_str(), start.key.frequency, start.reference.sat.to_string().c_str(),
                start.dd_cyc, start.dd_sigma_cyc, truth);
  }
}

/// The last time each rover signal (satellite, wavelength) had phase, before the epoch being processed.
using LastPhase = std::map<std::pair<SatelliteId, SignalCode>, GpsTime>;

std::optional<double> gap_of(const LastPhase& last, const canyon::sim::EpochTruth& rover,
                             const canyon::rtk::AmbiguityStart& start, const GpsTime& t, double epoch_s) {
  const canyon::sim::SignalTruth* s = find_signal(rover, start.key.sat, start.wavelength_m);
  if (s == nullptr) return std::nullopt;
  const auto it = last.find({s->sat, s->code});
  if (it == last.end()) return std::nullopt;
  const double gap_s = (t - it->second) - epoch_s;
  return gap_s < 0.5 * epoch_s ? 0.0 : gap_s;
}

void note_phases(const canyon::core::ObsEpoch& epoch, LastPhase& last) {
  for (const canyon::core::SatelliteObs& sat : epoch.sats) {
    for (const canyon::core::SignalObs& s : sat.signals) {
      if (canyon::core::has_value(s.carrier_phase_cyc)) last[{sat.sat, s.code}] = epoch.time;
    }
  }
}

/// Blockages: runs of at least kMinBlockage_s below the line-of-sight ceiling (fewer than
/// sim::kLineOfSightCeilingSatellites satellites in line of sight) after an epoch above it, and the time from each
/// one's end to the first correct fix (fixed, within 10 cm 3D of the truth) before the next one begins.
constexpr double kMinBlockage_s = 1.0;
struct Blockages {
  int count = 0;
  int fixed_before = 0;  // a correct fix in the 5 s before the blockage
  int not_refixed = 0;   // no correct fix before the next blockage or the end
  std::vector<double> refix_s;
};

/// Fixed epochs by their DD integers against the true ones and by their position against the truth.
struct FixedTally {
  int epochs = 0;
  int correct_right = 0;                // within 10 cm, every judged integer right
  int correct_wrong = 0;                // within 10 cm, some integer wrong
  int off_right = 0;                    // beyond 10 cm, every judged integer right
  int off_wrong = 0;                    // beyond 10 cm, some integer wrong
  int on_reflections = 0;               // some integer of a reflected signal (no true integer), none judged wrong
  int combinations = 0;                 // fixed integer combinations, not listed
  std::vector<double> partial_error_m;  // 3D error of each partial fix (a float conditioned on fixed combinations)
  std::vector<double> float_error_m;    // 3D error of each other float
};

/// The verdict on one fixed epoch's integers: -1 some wrong, 0 some on a reflection (none wrong), 1 all right,
/// 2 none listed (combinations).
int judge_integers(const std::vector<canyon::rtk::FixedAmbiguity>& fixed, const canyon::sim::EpochTruth& rover,
                   const canyon::sim::EpochTruth& base) {
  if (fixed.empty()) return 2;
  bool reflected = false;
  for (const canyon::rtk::FixedAmbiguity& f : fixed) {
    const TrueDd dd = true_dd(rover, base, f.sat.sat, f.reference.sat, f.wavelength_m);
    if (dd.kind != TrueDd::Kind::Known) {
      reflected = true;  // no true integer (a missing signal counts here too)
      continue;
    }
    const double truth = dd.cycles;
    if (f.integer != truth) return -1;
  }
  return reflected ? 0 : 1;
}

void tally_fixed(int verdict, bool correct, FixedTally& t) {
  ++t.epochs;
  if (verdict == 2) {
    ++t.combinations;
  } else if (verdict == 0) {
    ++t.on_reflections;
  } else if (correct) {
    ++(verdict == 1 ? t.correct_right : t.correct_wrong);
  } else {
    ++(verdict == 1 ? t.off_right : t.off_wrong);
  }
}

int line_of_sight_satellites(const canyon::sim::EpochTruth& epoch) {
  std::vector<SatelliteId> sats;
  for (const canyon::sim::SignalTruth& s : epoch.signals) {
    if (s.direct && std::find(sats.begin(), sats.end(), s.sat) == sats.end()) sats.push_back(s.sat);
  }
  return static_cast<int>(sats.size());
}

/// The blockages of one run from its per-epoch line-of-sight verdicts and correct fixes.
void tally_blockages(const std::vector<bool>& clear, const std::vector<bool>& correct, double epoch_s, Blockages& out) {
  const auto min_epochs = static_cast<std::size_t>(std::lround(kMinBlockage_s / epoch_s));
  std::vector<std::pair<std::size_t, std::size_t>> runs;  // [first blocked epoch, first clear epoch after it)
  for (std::size_t k = 1; k < clear.size(); ++k) {
    if (clear[k] || !clear[k - 1]) continue;
    std::size_t end = k;
    while (end < clear.size() && !clear[end]) ++end;
    if (end - k >= min_epochs && end < clear.size()) runs.emplace_back(k, end);
  }
  const auto before_s = static_cast<std::size_t>(std::lround(5.0 / epoch_s));
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const auto [first, end] = runs[r];
    ++out.count;
    const std::size_t from = first > before_s ? first - before_s : 0;
    if (std::find(correct.begin() + static_cast<std::ptrdiff_t>(from),
                  correct.begin() + static_cast<std::ptrdiff_t>(first),
                  true) != correct.begin() + static_cast<std::ptrdiff_t>(first)) {
      ++out.fixed_before;
    }
    const std::size_t limit = r + 1 < runs.size() ? runs[r + 1].first : correct.size();
    std::size_t j = end;
    while (j < limit && !correct[j]) ++j;
    if (j < limit) {
      out.refix_s.push_back(static_cast<double>(j - end) * epoch_s);
    } else {
      ++out.not_refixed;
    }
  }
}

/// The alignment judged at one epoch against the truth (fusion).
struct AlignmentCheck {
  bool aligned = false;
  bool fine = false;
  double heading_error_deg = 0.0;
  double lever_arm_horizontal_error_m = 0.0;
};

/// The aligned VIO attitude R_EO R_OI of the VIO sample nearest `t` against the true attitude `truth`, and the lever
/// arm in use against the scenario's `t_IA_true_m`.
AlignmentCheck check_alignment(const canyon::fusion::FusionEngine& fusion,
                               const std::vector<canyon::sim::VioSample>& vio, const canyon::sim::TruthSample& truth,
                               const Eigen::Vector3d& t_IA_true_m) {
  AlignmentCheck check;
  const std::optional<canyon::fusion::VioAlignment>& alignment = fusion.alignment();
  const auto nearest = std::min_element(vio.begin(), vio.end(), [&](const auto& a, const auto& b) {
    return std::abs(a.time - truth.time) < std::abs(b.time - truth.time);
  });
  if (!alignment || nearest == vio.end()) return check;
  check.aligned = true;
  check.fine = alignment->fine;
  const Eigen::Matrix3d R_NE = canyon::core::rotation_enu_from_ecef(canyon::core::ecef_to_geodetic(truth.p_E_m));
  const Eigen::Matrix3d R_EI_true = truth.q_EI.toRotationMatrix();
  const Eigen::Matrix3d R_EI = alignment->T_EO.rotation() * nearest->T_OI.rotation();
  const Eigen::Matrix3d dR_N = R_NE * R_EI * R_EI_true.transpose() * R_NE.transpose();
  check.heading_error_deg = std::abs(std::atan2(dR_N(1, 0), dR_N(0, 0))) * 180.0 / M_PI;
  const Eigen::Vector3d d_N = R_NE * R_EI_true * (fusion.lever_arm_m() - t_IA_true_m);
  check.lever_arm_horizontal_error_m = d_N.head<2>().norm();
  return check;
}

/// One epoch's solution and the RTK filter's epoch under it.
struct Step {
  canyon::core::Solution solution;
  canyon::rtk::RtkEpoch rtk;
};

bool run_seed(const Args& args, std::uint64_t seed, Tally (&tallies)[kBins], Blockages& blockages, FixedTally& fixed,
              std::optional<AlignmentCheck>& alignment) {
  auto scenario = canyon::config::load_scenario(args.scenario);
  if (!scenario) {
    std::fprintf(stderr, "bench_repair_truth: %s\n", scenario.error().to_string().c_str());
    return false;
  }
  scenario->seed = seed;
  if (args.duration_s > 0.0) scenario->duration_s = args.duration_s;
  auto config = canyon::config::load_process_config(
      args.config, args.rtk ? canyon::config::ProcessMode::Rtk : canyon::config::ProcessMode::Fusion);
  if (!config) {
    std::fprintf(stderr, "bench_repair_truth: %s\n", config.error().to_string().c_str());
    return false;
  }
  if (!(config->rtk.ambiguity_prior_max_sigma_cyc > 0.0))
    config->rtk.ambiguity_prior_max_sigma_cyc = args.max_sigma_cyc;
  const fs::path dir = fs::temp_directory_path() / ("canyon_repair_truth_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  canyon::sim::SimulationOptions options;
  options.keep_signal_truth = true;
  auto sim = canyon::sim::simulate(*scenario, (dir / "nav.rnx").string(), options);
  fs::remove_all(dir);
  if (!sim) {
    std::fprintf(stderr, "bench_repair_truth: %s\n", sim.error().to_string().c_str());
    return false;
  }
  const canyon::gnss::EphemerisStore eph(sim->nav);
  const GpsTime start = scenario->start;
  std::optional<canyon::fusion::FusionEngine> fusion;
  std::optional<canyon::rtk::RtkEngine> rtk;
  if (args.rtk) {
    rtk.emplace(config->rtk, eph, sim->base_p_E_m);
  } else {
    fusion.emplace(config->fusion, config->rtk, eph, sim->base_p_E_m,
                   canyon::fusion::VioTrack::from_samples(canyon::test::track_samples(sim->vio.poses, start), start));
  }
  const auto step = [&](const canyon::core::ObsEpoch& rover,
                        const canyon::core::ObsEpoch* base) -> std::optional<Step> {
    if (rtk) {
      auto out = rtk->process(rover, base);
      if (!out) return std::nullopt;
      return Step{out->solution, std::move(*out)};
    }
    auto out = fusion->process(rover, base);
    if (!out) return std::nullopt;
    return Step{out->solution, std::move(out->rtk)};
  };
  const double epoch_s = 1.0 / scenario->rover_rate_hz;
  LastPhase last;
  std::vector<bool> clear, correct;
  std::size_t base = 0;
  for (std::size_t k = 0; k < sim->rover.epochs.size(); ++k) {
    const canyon::core::ObsEpoch& e = sim->rover.epochs[k];
    base = canyon::test::base_epoch_for(*sim, base, e.time);
    const std::optional<Step> out = step(e, &sim->base.epochs[base]);
    const bool is_fixed = out && out->solution.status == canyon::core::SolutionStatus::Fixed;
    const bool within = is_fixed && (out->solution.p_E_m - sim->truth[k].p_E_m).norm() <= 0.10;
    clear.push_back(line_of_sight_satellites(sim->rover.truth[k]) >= canyon::sim::kLineOfSightCeilingSatellites);
    correct.push_back(within);
    if (out && out->solution.status == canyon::core::SolutionStatus::Float) {
      const double error_m = (out->solution.p_E_m - sim->truth[k].p_E_m).norm();
      const bool partial = canyon::core::exact_status(out->solution) == canyon::core::kPartialFixStatus;
      (partial ? fixed.partial_error_m : fixed.float_error_m).push_back(error_m);
    }
    if (is_fixed) {
      tally_fixed(judge_integers(out->rtk.fixed_ambiguities, sim->rover.truth[k], sim->base.truth[base]), within,
                  fixed);
    }
    if (out) {
      for (const canyon::rtk::AmbiguityStart& s : out->rtk.ambiguities_from_position) {
        const int bin = gap_bin(gap_of(last, sim->rover.truth[k], s, e.time, epoch_s));
        judge(s, sim->rover.truth[k], sim->base.truth[base], tallies[bin]);
      }
    }
    note_phases(e, last);
    if (fusion && !alignment && e.time - start >= args.align_at_s) {
      alignment = check_alignment(*fusion, sim->vio.poses, sim->truth[k], scenario->vio.t_IA_m);
    }
  }
  tally_blockages(clear, correct, epoch_s, blockages);
  return true;
}

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto i = static_cast<std::size_t>(std::lround(q * static_cast<double>(values.size() - 1)));
  return values[i];
}

std::size_t within_10cm(const std::vector<double>& errors_m) {
  return static_cast<std::size_t>(std::count_if(errors_m.begin(), errors_m.end(), [](double e) { return e <= 0.10; }));
}

void print_fixed(const FixedTally& t) {
  std::printf(
      "fixed_epochs=%d within_10cm: integers_right=%d integers_wrong=%d; beyond_10cm: integers_right=%d "
      "integers_wrong=%d; on_reflections=%d combinations=%d\n",
      t.epochs, t.correct_right, t.correct_wrong, t.off_right, t.off_wrong, t.on_reflections, t.combinations);
  std::printf(
      "partial_fix_epochs=%zu error_3d_m median=%.3f p95=%.3f within_10cm=%zu; float_epochs=%zu error_3d_m "
      "median=%.3f p95=%.3f within_10cm=%zu\n",
      t.partial_error_m.size(), percentile(t.partial_error_m, 0.5), percentile(t.partial_error_m, 0.95),
      within_10cm(t.partial_error_m), t.float_error_m.size(), percentile(t.float_error_m, 0.5),
      percentile(t.float_error_m, 0.95), within_10cm(t.float_error_m));
}

void print_blockages(const Blockages& b) {
  const auto refixed = static_cast<int>(b.refix_s.size());
  std::printf(
      "blockages=%d (>= %.0f s below the line-of-sight ceiling) fixed_before=%d refixed=%d not_refixed=%d "
      "time_to_correct_fix_s median=%.1f p90=%.1f max=%.1f\n",
      b.count, kMinBlockage_s, b.fixed_before, refixed, b.not_refixed, percentile(b.refix_s, 0.5),
      percentile(b.refix_s, 0.9), percentile(b.refix_s, 1.0));
}

void print_table(const Tally (&tallies)[kBins]) {
  std::printf("%-16s %8s %8s %8s %9s %8s %8s %10s %14s\n", "gap", "starts", "judged", "wrong", "wrong_pct", "nlos",
              "no_truth", "fractional", "max_err_cyc");
  Tally all;
  for (int b = 0; b < kBins; ++b) {
    const Tally& t = tallies[b];
    std::printf("%-16s %8d %8d %8d %8.2f%% %8d %8d %10d %14.3f\n", kBinNames[b], t.starts, t.judged, t.wrong,
                t.judged > 0 ? 100.0 * t.wrong / t.judged : 0.0, t.nlos, t.no_truth, t.fractional, t.max_error_cyc);
    all.starts += t.starts;
    all.judged += t.judged;
    all.wrong += t.wrong;
    all.nlos += t.nlos;
    all.no_truth += t.no_truth;
    all.fractional += t.fractional;
    all.max_error_cyc = std::max(all.max_error_cyc, t.max_error_cyc);
  }
  std::printf("repairs=%d judged=%d wrong=%d wrong_pct=%.2f nlos=%d fractional=%d max_err_cyc=%.3f\n", all.starts,
              all.judged, all.wrong, all.judged > 0 ? 100.0 * all.wrong / all.judged : 0.0, all.nlos, all.fractional,
              all.max_error_cyc);
}

void print_alignment(std::uint64_t seed, const AlignmentCheck& a) {
  if (!a.aligned) {
    std::printf("alignment seed=%llu none\n", static_cast<unsigned long long>(seed));
    return;
  }
  std::printf("alignment seed=%llu %s heading_error_deg=%.3f lever_arm_horizontal_error_m=%.4f\n",
              static_cast<unsigned long long>(seed), a.fine ? "fine" : "coarse", a.heading_error_deg,
              a.lever_arm_horizontal_error_m);
}

/// Over the seeds: how many were aligned at `at_s`, their heading errors and the worst lever-arm error.
void print_alignments(double at_s, std::size_t seeds, const std::vector<AlignmentCheck>& checks) {
  std::vector<double> heading_deg;
  double lever_max_m = 0.0;
  int fine = 0;
  for (const AlignmentCheck& a : checks) {
    if (!a.aligned) continue;
    heading_deg.push_back(a.heading_error_deg);
    lever_max_m = std::max(lever_max_m, a.lever_arm_horizontal_error_m);
    fine += a.fine ? 1 : 0;
  }
  std::printf(
      "alignment_at_s=%.0f seeds=%zu aligned=%zu heading_error_deg median=%.3f max=%.3f "
      "lever_arm_horizontal_error_m max=%.4f fine=%d\n",
      at_s, seeds, heading_deg.size(), percentile(heading_deg, 0.5), percentile(heading_deg, 1.0), lever_max_m, fine);
}

/// Runs every seed and prints the tables; false on an error (printed).
bool run(const Args& args) {
  Tally tallies[kBins];
  Blockages blockages;
  FixedTally fixed;
  std::vector<AlignmentCheck> alignments;
  for (const std::uint64_t seed : args.seeds) {
    Tally seed_tallies[kBins];
    std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
    std::optional<AlignmentCheck> alignment;
    if (!run_seed(args, seed, seed_tallies, blockages, fixed, alignment)) return false;
    if (alignment) {
      alignments.push_back(*alignment);
      print_alignment(seed, *alignment);
    }
    int starts = 0, wrong = 0;
    for (int b = 0; b < kBins; ++b) {
      starts += seed_tallies[b].starts;
      wrong += seed_tallies[b].wrong;
      tallies[b].starts += seed_tallies[b].starts;
      tallies[b].judged += seed_tallies[b].judged;
      tallies[b].wrong += seed_tallies[b].wrong;
      tallies[b].nlos += seed_tallies[b].nlos;
      tallies[b].no_truth += seed_tallies[b].no_truth;
      tallies[b].fractional += seed_tallies[b].fractional;
      tallies[b].max_error_cyc = std::max(tallies[b].max_error_cyc, seed_tallies[b].max_error_cyc);
    }
    std::printf("seed %llu: %d integer starts, %d wrong\n", static_cast<unsigned long long>(seed), starts, wrong);
    std::fflush(stdout);
  }
  print_table(tallies);
  print_fixed(fixed);
  print_blockages(blockages);
  if (!args.rtk) print_alignments(args.align_at_s, args.seeds.size(), alignments);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Args> args = parse_args(argc, argv);
  if (!args) {
    std::fprintf(
        stderr,
        "usage: bench_repair_truth SCENARIO.yaml SEED... [--mode fusion|rtk] [--config FILE] [--max-sigma CYC] "
        "[--duration S] [--align-at S]\n");
    return 2;
  }
  try {
    return run(*args) ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_repair_truth: error: %s\n", e.what());
    return 1;
  }
}
