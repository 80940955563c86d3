// Statistical and consistency tests of generated scenarios (fixed seeds, a few minutes of data each). The
// observations are read back from the written RINEX files and checked against ranges the test computes itself from
// truth.csv and nav.rnx (canyon's reader-side ephemeris code), or against the generator's per-signal truth:
//  - double-differenced line-of-sight code and phase residuals have the configured standard deviation (10 %);
//  - double-differenced phase minus range is an integer number of cycles within noise;
//  - Doppler agrees with the rate of the carrier phase;
//  - NLOS signals occur exactly where the city blocks the direct path (checked by brute force over all walls);
//  - every reacquisition after a loss carries the loss-of-lock flag;
//  - the same seed gives the same files byte for byte.

#include "canyon/sim/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <gtest/gtest.h>
#include <unistd.h>

#include "canyon/config/scenario_config.hpp"
#include "canyon/core/constants.hpp"
#include "canyon/eval/truth.hpp"
#include "canyon/gnss/atmosphere.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/io/rinex_nav.hpp"
#include "canyon/io/rinex_obs.hpp"
#include "canyon/sim/signal_model.hpp"

namespace canyon::sim {
namespace {

namespace fs = std::filesystem;
using core::Constellation;

constexpr double kSigmaTolerance = 0.10;                     // measured / configured standard deviation within 10 %
constexpr double kMaxFractionCyc = 0.15;                     // |DD phase - DD range / lambda - integer| (about 8 sigma)
constexpr double kMinElevationRad = 15.0 * core::kDegToRad;  // where the truth's troposphere is Saastamoinen's

Scenario shipped(const std::string& name) {
  auto s = config::load_scenario((fs::path(CANYON_SOURCE_DIR) / "config" / "scenarios" / (name + ".yaml")).string());
  EXPECT_TRUE(s.ok()) << s.error().to_string();
  return *s;
}

/// Open sky with only receiver noise: no atmosphere residual, orbit error or multipath, C/N0 at the reference level
/// on every signal (so the configured sigmas hold as they are), no random slips.
Scenario noise_only() {
  Scenario s = shipped("open-sky");
  s.duration_s = 180.0;
  s.atmosphere.vtec_tecu = 0.0;
  s.atmosphere.gradient_tecu_per_100km.setZero();
  s.atmosphere.wave_amplitude_tecu = 0.0;
  s.atmosphere.zwd_residual_m = s.atmosphere.zwd_difference_m = s.atmosphere.zwd_variation_m = 0.0;
  s.orbit_errors = OrbitErrorOptions{0.0, 0.0, 0.0, 0.0};
  s.reflections.multipath = false;
  for (ReceiverOptions* rx : {&s.rover_receiver, &s.base_receiver}) {
    rx->cn0_zenith_dbhz = rx->cn0_horizon_dbhz = rx->cn0_reference_dbhz = 45.0;
    rx->band2_cn0_offset_db = 0.0;
    rx->slip_rate_hz = 0.0;
  }
  return s;
}

/// A generated scenario written to a folder and read back.
struct Generated {
  std::string dir;
  Simulation sim;
  io::RinexObsFile rover;
  io::RinexObsFile base;
  core::NavigationData nav;
};

std::string temp_dir(const std::string& tag) {
  const fs::path p = fs::temp_directory_path() / ("canyon_sim_test_" + tag + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  return p.string();
}

std::unique_ptr<Generated> generate(const Scenario& scenario, const std::string& tag, bool keep_truth) {
  auto g = std::make_unique<Generated>();
  g->dir = temp_dir(tag);
  fs::create_directories(g->dir);
  SimulationOptions options;
  options.keep_signal_truth = keep_truth;
  auto sim = simulate(scenario, g->dir + "/nav.rnx", options);
  EXPECT_TRUE(sim.ok()) << sim.error().to_string();
  g->sim = std::move(*sim);
  EXPECT_TRUE(write_simulation(g->sim, g->dir).ok());
  auto rover = io::read_rinex_obs(g->dir + "/rover.obs");
  auto base = io::read_rinex_obs(g->dir + "/base.obs");
  auto nav = io::read_rinex_nav(g->dir + "/nav.rnx");
  EXPECT_TRUE(rover.ok() && base.ok() && nav.ok());
  g->rover = std::move(*rover);
  g->base = std::move(*base);
  g->nav = std::move(nav->nav);
  return g;
}

const Generated& noise_only_run() {
  static const std::unique_ptr<Generated> g = generate(noise_only(), "noise", false);
  return *g;
}

const Generated& urban_run() {
  static const std::unique_ptr<Generated> g = [] {
    Scenario s = shipped("urban-severe");
    s.duration_s = 120.0;
    return generate(s, "urban", true);
  }();
  return *g;
}

/// Geometric range the way a reader computes it: satellite at the transmission time implied by the pseudorange,
/// Earth rotation to first order (gnss::geometric_range_m).
std::optional<double> reader_range(const gnss::EphemerisStore& eph, core::SatelliteId sat, core::GpsTime tag,
                                   double pseudorange_m, const Eigen::Vector3d& p_E, double* elevation_rad) {
  const auto s = eph.state_at_reception(sat, tag, pseudorange_m, nullptr, false);
  if (!s) return std::nullopt;
  *elevation_rad = core::azimuth_elevation(p_E, core::ecef_to_geodetic(p_E), s->p_E_m).elevation_rad;
  return gnss::geometric_range_m(s->p_E_m, p_E);
}

/// One receiver's "observation minus range" per (satellite, signal) at one epoch.
struct Residual {
  double code_m = 0.0;
  double phase_cyc = 0.0;  ///< phase minus range / lambda
  double wavelength_m = 0.0;
  double elevation_rad = 0.0;
};
using Residuals = std::map<std::pair<core::SatelliteId, core::SignalCode>, Residual>;

Residuals residuals(const core::ObsEpoch& epoch, const gnss::EphemerisStore& eph, const Eigen::Vector3d& p_E) {
  Residuals out;
  const core::Geodetic g = core::ecef_to_geodetic(p_E);
  for (const core::SatelliteObs& sat : epoch.sats) {
    const int channel =
        sat.sat.system == Constellation::Glonass ? eph.glonass_channel(sat.sat.prn) : core::kNoGlonassChannel;
    for (const core::SignalObs& s : sat.signals) {
      const auto lambda = core::wavelength_m(sat.sat.system, s.code, channel);
      double el = 0.0;
      const auto rho = reader_range(eph, sat.sat, epoch.time, s.pseudorange_m, p_E, &el);
      if (!lambda || !rho || el < kMinElevationRad) continue;
      const double tropo_m = gnss::saastamoinen_delay_m(g, el);  // the only atmosphere left in noise_only()
      out[{sat.sat, s.code}] = {s.pseudorange_m - *rho - tropo_m, s.carrier_phase_cyc - (*rho + tropo_m) / *lambda,
                                *lambda, el};
    }
  }
  return out;
}

struct DoubleDifference {
  Constellation system;
  double code_m;
  double phase_cyc;
  double wavelength_m;
};

/// Double differences rover-base, satellite-reference for every system and signal, reference = highest elevation.
std::vector<DoubleDifference> double_differences(const Residuals& rover, const Residuals& base) {
  std::map<std::pair<Constellation, core::SignalCode>, std::vector<std::pair<Residual, Residual>>> groups;
  for (const auto& [key, r] : rover) {
    const auto b = base.find(key);
    if (b != base.end()) groups[{key.first.system, key.second}].emplace_back(r, b->second);
  }
  std::vector<DoubleDifference> out;
  for (auto& [group, pairs] : groups) {
    if (pairs.size() < 2) continue;
    std::sort(pairs.begin(), pairs.end(),
              [](const auto& a, const auto& b) { return a.first.elevation_rad > b.first.elevation_rad; });
    const auto& [ref_r, ref_b] = pairs.front();
    for (std::size_t k = 1; k < pairs.size(); ++k) {
      const auto& [r, b] = pairs[k];
      out.push_back({group.first, (r.code_m - b.code_m) - (ref_r.code_m - ref_b.code_m),
                     (r.phase_cyc - b.phase_cyc) - (ref_r.phase_cyc - ref_b.phase_cyc), r.wavelength_m});
    }
  }
  return out;
}

/// All double differences of the common rover/base epochs, the rover at its truth.csv position.
std::vector<DoubleDifference> all_double_differences(const Generated& g) {
  const gnss::EphemerisStore eph(g.nav);
  auto truth = eval::read_truth_csv(g.dir + "/truth.csv");
  EXPECT_TRUE(truth.ok());
  const Eigen::Vector3d p_base = *g.base.header.receiver.approx_position_E_m;
  std::map<double, const core::ObsEpoch*> base_at;
  for (const auto& e : g.base.epochs) base_at[e.time.seconds_since_epoch()] = &e;
  std::vector<DoubleDifference> out;
  for (const core::ObsEpoch& e : g.rover.epochs) {
    const auto b = base_at.find(e.time.seconds_since_epoch());
    if (b == base_at.end()) continue;
    const auto p_rover = truth->position_at(e.time);
    EXPECT_TRUE(p_rover.has_value());
    const auto dd = double_differences(residuals(e, eph, *p_rover), residuals(*b->second, eph, p_base));
    out.insert(out.end(), dd.begin(), dd.end());
  }
  return out;
}

double rms(const std::vector<double>& v) {
  double s = 0.0;
  for (const double x : v) s += x * x;
  return std::sqrt(s / static_cast<double>(v.size()));
}

TEST(SimulatorTest, DoubleDifferencedNoiseHasTheConfiguredSigma) {
  const Generated& g = noise_only_run();
  const Scenario& sc = g.sim.scenario;
  std::vector<double> code, phase;
  for (const DoubleDifference& dd : all_double_differences(g)) {
    code.push_back(dd.code_m);
    if (dd.system == Constellation::Glonass) continue;  // FDMA: a DD of two wavelengths is no integer
    phase.push_back((dd.phase_cyc - std::round(dd.phase_cyc)) * dd.wavelength_m);
  }
  ASSERT_GT(code.size(), 3000U);
  ASSERT_GT(phase.size(), 2000U);
  // Each DD holds two rover and two base observations.
  const double expected_code_m =
      std::sqrt(2.0 * std::pow(sc.rover_receiver.code_sigma_m, 2) + 2.0 * std::pow(sc.base_receiver.code_sigma_m, 2));
  const double expected_phase_m =
      std::sqrt(2.0 * std::pow(sc.rover_receiver.phase_sigma_m, 2) + 2.0 * std::pow(sc.base_receiver.phase_sigma_m, 2));
  EXPECT_NEAR(rms(code) / expected_code_m, 1.0, kSigmaTolerance) << "DD code rms " << rms(code) << " m";
  EXPECT_NEAR(rms(phase) / expected_phase_m, 1.0, kSigmaTolerance) << "DD phase rms " << rms(phase) << " m";
  std::printf("DD code sigma %.4f m (configured %.4f), DD phase sigma %.5f m (configured %.5f), %zu / %zu DDs\n",
              rms(code), expected_code_m, rms(phase), expected_phase_m, code.size(), phase.size());
}

TEST(SimulatorTest, DoubleDifferencedPhaseMinusRangeIsAnInteger) {
  const Generated& g = noise_only_run();
  int checked = 0;
  double worst = 0.0;
  for (const DoubleDifference& dd : all_double_differences(g)) {
    if (dd.system == Constellation::Glonass) continue;
    const double fraction = dd.phase_cyc - std::round(dd.phase_cyc);
    worst = std::max(worst, std::abs(fraction));
    ++checked;
  }
  EXPECT_GT(checked, 2000);
  EXPECT_LT(worst, kMaxFractionCyc);
}

TEST(SimulatorTest, LineOfSightPhaseIsIntegerWithTheFullErrorModel) {
  // Urban scenario with every error source: the generator's own per-signal truth (range, troposphere,
  // ionosphere, multipath) explains the phase up to an integer and the noise, for every line-of-sight signal.
  const Generated& g = urban_run();
  std::map<double, const EpochTruth*> base_at;
  for (const EpochTruth& e : g.sim.base.truth) base_at[e.tag.seconds_since_epoch()] = &e;
  // Phase minus model per signal, for both receivers (cycles).
  const auto model_residual = [](const SignalTruth& t, const core::SignalObs& obs) {
    const double model_m =
        t.range_m + t.receiver_clock_m - t.satellite_clock_m + t.troposphere_m - t.ionosphere_m + t.phase_multipath_m;
    return obs.carrier_phase_cyc - model_m / t.wavelength_m;
  };
  int checked = 0;
  double worst = 0.0;
  for (std::size_t k = 0; k < g.sim.rover.truth.size(); ++k) {
    const EpochTruth& rt = g.sim.rover.truth[k];
    const auto b = base_at.find(rt.tag.seconds_since_epoch());
    if (b == base_at.end()) continue;
    const std::size_t base_index = static_cast<std::size_t>(&*b->second - g.sim.base.truth.data());
    std::map<std::pair<Constellation, core::SignalCode>, std::vector<double>> sd;  // single differences
    for (const SignalTruth& t : rt.signals) {
      if (!t.direct || t.sat.system == Constellation::Glonass) continue;
      const SignalTruth* tb = nullptr;
      for (const SignalTruth& x : b->second->signals) {
        if (x.sat == t.sat && x.code == t.code) tb = &x;
      }
      if (tb == nullptr) continue;
      const core::SignalObs* obs_r = nullptr;
      const core::SignalObs* obs_b = nullptr;
      for (const auto& s : g.sim.rover.epochs[k].sats) {
        if (s.sat == t.sat) obs_r = s.find(t.code);
      }
      for (const auto& s : g.sim.base.epochs[base_index].sats) {
        if (s.sat == t.sat) obs_b = s.find(t.code);
      }
      ASSERT_NE(obs_r, nullptr);
      ASSERT_NE(obs_b, nullptr);
      sd[{t.sat.system, t.code}].push_back(model_residual(t, *obs_r) - model_residual(*tb, *obs_b));
    }
    for (const auto& [group, values] : sd) {
      for (std::size_t i = 1; i < values.size(); ++i) {
        const double dd = values[i] - values[0];
        worst = std::max(worst, std::abs(dd - std::round(dd)));
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 40);
  EXPECT_LT(worst, kMaxFractionCyc);
}

TEST(SimulatorTest, DopplerMatchesThePhaseRate) {
  const Generated& g = noise_only_run();
  std::vector<double> diff_mps;
  for (std::size_t k = 1; k < g.rover.epochs.size(); ++k) {
    const core::ObsEpoch& a = g.rover.epochs[k - 1];
    const core::ObsEpoch& b = g.rover.epochs[k];
    const double dt_s = b.time - a.time;
    for (const core::SatelliteObs& sb : b.sats) {
      for (const core::SatelliteObs& sa : a.sats) {
        if (sa.sat != sb.sat) continue;
        for (const core::SignalObs& xb : sb.signals) {
          const core::SignalObs* xa = sa.find(xb.code);
          if (xa == nullptr || xb.lli != 0) continue;
          const int channel =
              sb.sat.system == Constellation::Glonass ? g.nav.glonass_channel(sb.sat.prn) : core::kNoGlonassChannel;
          const double lambda = *core::wavelength_m(sb.sat.system, xb.code, channel);
          // RINEX: phase grows with the range, Doppler is positive for an approaching satellite.
          const double phase_rate_mps = lambda * (xb.carrier_phase_cyc - xa->carrier_phase_cyc) / dt_s;
          diff_mps.push_back(phase_rate_mps + lambda * 0.5 * (xa->doppler_hz + xb.doppler_hz));
        }
      }
    }
  }
  ASSERT_GT(diff_mps.size(), 10000U);
  double mean = 0.0;
  for (const double d : diff_mps) mean += d / static_cast<double>(diff_mps.size());
  EXPECT_LT(std::abs(mean), 0.005);
  EXPECT_LT(rms(diff_mps), 0.05);  // phase noise over 0.2 s, Doppler noise, head motion within the interval
}

/// Independent line-of-sight test: every wall of every building, no spatial index.
bool brute_force_blocked(const City& city, const Eigen::Vector3d& p, const Eigen::Vector3d& u) {
  const double h = std::hypot(u.x(), u.y());
  if (h < 1e-12) return false;
  const Eigen::Vector2d d = u.head<2>() / h;
  for (const Building& b : city.buildings()) {
    for (std::size_t i = 0; i < b.footprint_N_m.size(); ++i) {
      const Eigen::Vector2d a = b.footprint_N_m[i], c = b.footprint_N_m[(i + 1) % b.footprint_N_m.size()];
      const Eigen::Vector2d e = c - a;
      const double denom = d.x() * e.y() - d.y() * e.x();
      if (std::abs(denom) < 1e-12) continue;
      const Eigen::Vector2d ao = a - p.head<2>();
      const double s = (ao.x() * e.y() - ao.y() * e.x()) / denom;
      const double t = (ao.x() * d.y() - ao.y() * d.x()) / denom;
      if (s > 1e-6 && t >= 0.0 && t <= 1.0 && p.z() + s * u.z() / h < b.height_m) return true;
    }
  }
  return false;
}

TEST(SimulatorTest, NlosExactlyWhereTheCityBlocksTheDirectPath) {
  const Generated& g = urban_run();
  const City& city = g.sim.city;
  int nlos = 0, los = 0;
  for (std::size_t k = 0; k < g.sim.rover.truth.size(); k += 5) {  // every second
    const EpochTruth& e = g.sim.rover.truth[k];
    for (const SignalTruth& t : e.signals) {
      const bool blocked = brute_force_blocked(city, e.p_N_m, t.u_N);
      EXPECT_EQ(blocked, !t.direct) << t.sat.to_string() << " at " << e.t_s << " s";
      if (t.direct) {
        ++los;
        continue;
      }
      ++nlos;
      // The excess path is the specular reflection's 2 d (u . n) off a wall facing the antenna.
      bool found = false;
      for (const Wall& w : city.walls()) {
        const double d = (e.p_N_m.head<2>() - w.a_N_m).dot(w.normal_N);
        const double un = t.u_N.head<2>().dot(w.normal_N);
        if (d > 0.0 && un > 0.0 && std::abs(2.0 * d * un - t.nlos_excess_m) < 1e-6) found = true;
      }
      EXPECT_TRUE(found) << t.sat.to_string();
      EXPECT_GT(t.nlos_excess_m, 0.0);
    }
  }
  EXPECT_GT(nlos, 200);
  EXPECT_GT(los, 200);
}

/// C/N0 of a 60 s urban-severe run with the given NLOS loss spread, for seeds 1-8: the NLOS signals' deficits below
/// the line-of-sight model (dB), and the C/N0 of NLOS and of line-of-sight signals.
struct Cn0Sample {
  std::vector<double> nlos_deficit_db;
  std::vector<double> nlos_dbhz;
  std::vector<double> los_dbhz;
};

Cn0Sample cn0_sample(double spread_db) {
  Cn0Sample out;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    Scenario s = shipped("urban-severe");
    s.duration_s = 60.0;
    s.seed = seed;
    s.reflections.nlos_loss_spread_db = spread_db;
    const auto g = generate(s, "nlos-spread", true);
    for (const EpochTruth& e : g->sim.rover.truth) {
      for (const SignalTruth& t : e.signals) {
        if (t.direct) {
          out.los_dbhz.push_back(t.cn0_dbhz);
          continue;
        }
        const int band = t.code.band == '1' ? 0 : 1;
        out.nlos_deficit_db.push_back(line_of_sight_cn0_dbhz(s.rover_receiver, t.elevation_rad, band) - t.cn0_dbhz);
        out.nlos_dbhz.push_back(t.cn0_dbhz);
      }
    }
  }
  return out;
}

// With a loss spread, NLOS signals are not all the same dB down: some are as strong as line-of-sight ones (no C/N0
// threshold separates them), as in real streets; without it every one is exactly wall + extra loss down.
TEST(SimulatorTest, NlosLossSpreadOverlapsLineOfSightCn0) {
  const Scenario defaults = shipped("urban-severe");
  const double mean_db = defaults.reflections.wall_loss_db + defaults.reflections.nlos_extra_loss_db;
  for (const double spread_db : {0.0, 6.0}) {
    Cn0Sample c = cn0_sample(spread_db);
    const std::vector<double>& d = c.nlos_deficit_db;
    ASSERT_GT(d.size(), 2000U);
    double sum = 0.0, sum2 = 0.0;
    for (const double x : d) {
      sum += x;
      sum2 += x * x;
    }
    const double mean = sum / static_cast<double>(d.size());
    const double sigma = std::sqrt(std::max(0.0, sum2 / static_cast<double>(d.size()) - mean * mean));
    // The share of NLOS signals stronger than the weakest decile of line-of-sight ones: what a C/N0 screen set to
    // keep 90 % of the line of sight lets through.
    std::sort(c.los_dbhz.begin(), c.los_dbhz.end());
    const double los_p10 = c.los_dbhz[c.los_dbhz.size() / 10];
    const auto through = std::count_if(c.nlos_dbhz.begin(), c.nlos_dbhz.end(), [&](double x) { return x > los_p10; });
    const double share = static_cast<double>(through) / static_cast<double>(d.size());
    std::printf(
        "NLOS loss spread %.0f dB: %zu NLOS signal epochs, deficit %.2f +- %.2f dB; %.1f %% stronger than the "
        "weakest 10 %% of line of sight (%.1f dB-Hz)\n",
        spread_db, d.size(), mean, sigma, 100.0 * share, los_p10);
    if (spread_db == 0.0) {
      EXPECT_NEAR(mean, mean_db, 1e-9);
      EXPECT_LT(sigma, 1e-6);
      EXPECT_EQ(through, 0);
    } else {
      EXPECT_NEAR(mean, mean_db, 3.0);  // the weakest fall below tracking: the mean seen is lower
      EXPECT_GT(sigma, 4.0);
      EXPECT_LT(sigma, 7.0);
      EXPECT_GT(share, 0.03);
    }
  }
}

/// For each receiver file: every signal that comes back after missing from at least one epoch has LLI bit 0 set.
int check_reacquisitions(const io::RinexObsFile& file) {
  std::map<std::pair<core::SatelliteId, core::SignalCode>, std::size_t> last_seen;
  int reacquisitions = 0;
  for (std::size_t k = 0; k < file.epochs.size(); ++k) {
    for (const core::SatelliteObs& sat : file.epochs[k].sats) {
      for (const core::SignalObs& s : sat.signals) {
        const auto key = std::make_pair(sat.sat, s.code);
        const auto it = last_seen.find(key);
        if (it != last_seen.end() && it->second + 1 < k) {
          ++reacquisitions;
          EXPECT_TRUE((s.lli & core::kLliLossOfLock) != 0)
              << sat.sat.to_string() << " " << s.code.to_string() << " epoch " << k << " missing since " << it->second;
        }
        last_seen[key] = k;
      }
    }
  }
  return reacquisitions;
}

TEST(SimulatorTest, EveryReacquisitionCarriesALossOfLockFlag) {
  const Generated& g = urban_run();
  EXPECT_GT(check_reacquisitions(g.rover), 20);
  check_reacquisitions(g.base);
  // The file's flags are the generator's.
  int flagged = 0;
  for (const EpochTruth& e : g.sim.rover.truth) {
    for (const SignalTruth& t : e.signals) flagged += t.loss_of_lock ? 1 : 0;
  }
  int in_file = 0;
  for (const core::ObsEpoch& e : g.rover.epochs) {
    for (const core::SatelliteObs& s : e.sats) {
      for (const core::SignalObs& x : s.signals) in_file += (x.lli & core::kLliLossOfLock) != 0 ? 1 : 0;
    }
  }
  EXPECT_EQ(flagged, in_file);
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(SimulatorTest, SameSeedSameFilesByteForByte) {
  Scenario s = shipped("urban-severe");
  s.duration_s = 30.0;
  const auto a = generate(s, "det_a", false);
  const auto b = generate(s, "det_b", false);
  for (const char* name : {"nav.rnx", "rover.obs", "base.obs", "truth.csv", "city.geojson"}) {
    const std::string x = file_bytes(a->dir + "/" + name);
    EXPECT_FALSE(x.empty()) << name;
    EXPECT_TRUE(x == file_bytes(b->dir + "/" + name)) << name;
  }
  s.seed += 1;
  const auto c = generate(s, "det_c", false);
  EXPECT_FALSE(file_bytes(a->dir + "/rover.obs") == file_bytes(c->dir + "/rover.obs"));
  for (const auto* g : {a.get(), b.get(), c.get()}) fs::remove_all(g->dir);
}

TEST(SimulatorTest, FilesDescribeTheScenario) {
  const Generated& g = urban_run();
  const Scenario& sc = g.sim.scenario;
  EXPECT_EQ(g.rover.epochs.size(), static_cast<std::size_t>(sc.rover_epochs()));
  EXPECT_EQ(g.rover.epochs.front().time, sc.start);
  EXPECT_NEAR(g.rover.epochs[1].time - g.rover.epochs[0].time, 0.2, 1e-9);
  EXPECT_NEAR(g.base.epochs[1].time - g.base.epochs[0].time, 1.0 / sc.base.rate_hz, 1e-9);
  // Base header position = the true base, 20 km from the rover.
  EXPECT_LT((*g.base.header.receiver.approx_position_E_m - g.sim.base_p_E_m).norm(), 1e-3);
  EXPECT_NEAR((g.sim.base_p_E_m - g.sim.truth.front().p_E_m).norm(), 20000.0, 100.0);
  auto truth = eval::read_truth_csv(g.dir + "/truth.csv");
  ASSERT_TRUE(truth.ok()) << truth.error().to_string();
  EXPECT_EQ(truth->samples().size(), g.rover.epochs.size());
  // The walk: about 1.4 m/s, antenna about 1.7 m above the ground.
  const auto& samples = truth->samples();
  const double walked_m = (samples[50].p_E_m - samples[0].p_E_m).norm();
  EXPECT_NEAR(walked_m, 1.4 * 10.0, 1.0);
  const core::Geodetic start = core::ecef_to_geodetic(samples.front().p_E_m);
  EXPECT_NEAR(start.height_m - sc.origin.height_m, 1.7, 0.1);
  // Every satellite in the files has broadcast records in nav.rnx.
  const gnss::EphemerisStore eph(g.nav);
  for (const core::ObsEpoch& e : g.rover.epochs) {
    for (const core::SatelliteObs& s : e.sats) ASSERT_TRUE(eph.state(s.sat, e.time).has_value()) << s.sat.to_string();
  }
  const std::string city = file_bytes(g.dir + "/city.geojson");
  EXPECT_EQ(city.rfind("{\"type\":\"FeatureCollection\"", 0), 0U);
  EXPECT_NE(city.find("\"kind\":\"building\",\"height_m\":"), std::string::npos);
}

}  // namespace
}  // namespace canyon::sim
