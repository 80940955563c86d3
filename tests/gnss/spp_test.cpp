// Single-point positioning on measurements synthesised from real broadcast ephemerides with the SPP model itself:
// exact recovery, one clock per constellation, RAIM exclusion of a faulty satellite, too few satellites, DOP.

#include "canyon/gnss/spp.hpp"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/gnss/atmosphere.hpp"
#include "canyon/io/rinex_nav.hpp"
#include "canyon/io/rinex_obs.hpp"

namespace canyon::gnss {
namespace {

namespace fs = std::filesystem;
using core::Constellation;

constexpr double kMaxPositionErrorM = 1e-3;

const fs::path kDir = fs::path(CANYON_SHARED_DATA_DIR) / "matrtklib-static";

/// Real ephemerides and satellites of matrtklib-static (5 constellations), with pseudoranges replaced by the
/// model's prediction for a receiver at `p_E_true` with clock offsets `clock_m` per constellation.
struct Scenario {
  std::optional<EphemerisStore> store;
  core::ObsEpoch epoch;
  Eigen::Vector3d p_E_true{-3739933.2, 3505483.3, 3611720.3};
};

Scenario make_scenario(const std::array<double, 5>& clock_m) {
  Scenario s;
  auto nav = io::read_rinex_nav((kDir / "base.nav").string());
  auto obs = io::read_rinex_obs((kDir / "rover.obs").string());
  if (!nav || !obs) return s;
  s.store.emplace(nav->nav);
  s.epoch = obs->epochs.at(10);
  const core::Geodetic rcv = core::ecef_to_geodetic(s.p_E_true);
  const core::KlobucharParams klob = s.store->nav().gps_klobuchar.value_or(default_klobuchar());
  for (core::SatelliteObs& sat : s.epoch.sats) {
    for (core::SignalObs& sig : sat.signals) {
      if (!core::has_value(sig.pseudorange_m)) continue;
      // Iterate the model to self-consistency: the transmission time depends on the pseudorange.
      double p = sig.pseudorange_m;
      for (int it = 0; it < 4; ++it) {
        const auto st = s.store->state_at_reception(sat.sat, s.epoch.time, p);
        if (!st) break;
        const double range = geometric_range_m(st->p_E_m, s.p_E_true);
        const core::AzEl azel = core::azimuth_elevation(s.p_E_true, rcv, st->p_E_m);
        const int channel =
            sat.sat.system == Constellation::Glonass ? s.store->glonass_channel(sat.sat.prn) : core::kNoGlonassChannel;
        const double f = core::carrier_frequency_hz(sat.sat.system, sig.code, channel).value_or(1575.42e6);
        const int clock = sat.sat.system == Constellation::Qzss ? 0 : static_cast<int>(sat.sat.system);
        p = range + clock_m[static_cast<std::size_t>(clock)] - core::kSpeedOfLightMps * st->clock_bias_s +
            core::kSpeedOfLightMps * s.store->group_delay_s(sat.sat, sig.code, s.epoch.time) +
            std::pow(1575.42e6 / f, 2) * klobuchar_delay_m(s.epoch.time, rcv, azel, klob) +
            saastamoinen_delay_m(rcv, azel.elevation_rad);
      }
      sig.pseudorange_m = p;
    }
  }
  return s;
}

class SppSynthetic : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(kDir)) GTEST_SKIP() << "shared dataset not present: " << kDir;
  }
};

TEST_F(SppSynthetic, RecoversPositionAndOneClockPerConstellation) {
  const std::array<double, 5> clock_m = {1.5e5, 1.5e5 + 35.0, 1.5e5 - 12.0, 1.5e5 + 80.0, 0.0};
  Scenario s = make_scenario(clock_m);
  ASSERT_TRUE(s.store.has_value());
  auto sol = solve_spp(s.epoch, *s.store, SppOptions{});
  ASSERT_TRUE(sol.ok()) << sol.error().message;
  EXPECT_LT((sol->p_E_m - s.p_E_true).norm(), kMaxPositionErrorM);
  EXPECT_LT(sol->residual_rms_m, 1e-3);
  EXPECT_TRUE(sol->excluded_by_raim.empty());
  ASSERT_EQ(sol->clock_bias_m.size(), 4U);  // G (with J), R, E, C
  for (const auto& [system, bias_m] : sol->clock_bias_m) {
    EXPECT_NEAR(bias_m, clock_m[static_cast<std::size_t>(system)], 1e-3) << core::constellation_name(system);
  }
  EXPECT_GT(sol->num_satellites, 25);
  EXPECT_GT(sol->dop.gdop, sol->dop.pdop);
  EXPECT_GT(sol->dop.pdop, sol->dop.hdop);
  EXPECT_LT(sol->dop.pdop, 3.0);
  EXPECT_NEAR(sol->dop.pdop * sol->dop.pdop, sol->dop.hdop * sol->dop.hdop + sol->dop.vdop * sol->dop.vdop, 1e-9);
}

// From a prior a few metres from the answer the iteration converges on one linearisation and the ranges at the new
// position (spp.cpp, residuals_after_short_step()); farther priors take another linearisation first. The solution
// is the same as from the Earth's centre (noise-free data: to well below a micrometre) however far the prior.
TEST_F(SppSynthetic, APriorNearbyGivesTheSameSolutionAsAFullIteration) {
  const std::array<double, 5> clock_m = {2.0e4, 2.0e4 + 35.0, 2.0e4 - 12.0, 2.0e4 + 80.0, 0.0};
  Scenario s = make_scenario(clock_m);
  ASSERT_TRUE(s.store.has_value());
  auto cold = solve_spp(s.epoch, *s.store, SppOptions{});
  ASSERT_TRUE(cold.ok()) << cold.error().message;
  EXPECT_GT(cold->iterations, 2);
  for (const double offset_m : {3.0, 30.0, 95.0, 150.0}) {
    SCOPED_TRACE("prior " + std::to_string(offset_m) + " m off");
    const Eigen::Vector3d prior = cold->p_E_m + offset_m * Eigen::Vector3d(0.48, -0.6, 0.64);
    auto warm = solve_spp(s.epoch, *s.store, SppOptions{}, prior);
    ASSERT_TRUE(warm.ok()) << warm.error().message;
    EXPECT_LT((warm->p_E_m - cold->p_E_m).norm(), 1e-7);
    EXPECT_NEAR(warm->residual_rms_m, cold->residual_rms_m, 1e-7);
    for (std::size_t c = 0; c < warm->clock_bias_m.size(); ++c) {
      EXPECT_NEAR(warm->clock_bias_m[c].second, cold->clock_bias_m[c].second, 1e-7);
    }
    EXPECT_EQ(warm->iterations, offset_m < 10.0 ? 2 : 3);
  }
}

TEST_F(SppSynthetic, RaimExcludesTheFaultySatellite) {
  Scenario s = make_scenario({1e4, 1e4, 1e4, 1e4, 0.0});
  ASSERT_TRUE(s.store.has_value());
  // Only GPS: fewer satellites make the fault harder to isolate.
  SppOptions options;
  options.use_glonass = options.use_galileo = options.use_beidou = options.use_qzss = false;
  core::SatelliteId faulty{};
  for (core::SatelliteObs& sat : s.epoch.sats) {
    if (sat.sat.system != Constellation::Gps) continue;
    faulty = sat.sat;
    for (core::SignalObs& sig : sat.signals) sig.pseudorange_m += 80.0;  // an 80 m multipath/NLOS fault
    break;
  }
  auto sol = solve_spp(s.epoch, *s.store, options);
  ASSERT_TRUE(sol.ok()) << sol.error().message;
  ASSERT_EQ(sol->excluded_by_raim.size(), 1U);
  EXPECT_EQ(sol->excluded_by_raim.front(), faulty);
  EXPECT_LT((sol->p_E_m - s.p_E_true).norm(), kMaxPositionErrorM);
  // Without RAIM the fault pulls the solution by metres.
  options.raim_fde = false;
  auto biased = solve_spp(s.epoch, *s.store, options);
  ASSERT_TRUE(biased.ok());
  EXPECT_GT((biased->p_E_m - s.p_E_true).norm(), 1.0);
}

TEST_F(SppSynthetic, TooFewSatellitesIsAnErrorNotACrash) {
  Scenario s = make_scenario({0, 0, 0, 0, 0});
  ASSERT_TRUE(s.store.has_value());
  s.epoch.sats.resize(3);
  auto sol = solve_spp(s.epoch, *s.store, SppOptions{});
  ASSERT_FALSE(sol.ok());
  EXPECT_NE(sol.error().message.find("too few satellites"), std::string::npos);
  s.epoch.sats.clear();
  EXPECT_FALSE(solve_spp(s.epoch, *s.store, SppOptions{}).ok());
}

TEST_F(SppSynthetic, ExcludedSatellitesAndSystemsAreNotUsed) {
  Scenario s = make_scenario({0, 0, 0, 0, 0});
  ASSERT_TRUE(s.store.has_value());
  SppOptions options;
  options.use_beidou = false;
  options.excluded = {s.epoch.sats.front().sat};
  auto sol = solve_spp(s.epoch, *s.store, options);
  ASSERT_TRUE(sol.ok());
  for (const auto& sat : sol->used) {
    EXPECT_NE(sat.system, Constellation::BeiDou);
    EXPECT_NE(sat, options.excluded.front());
  }
}

TEST(SppOptionsTest, ValidateNamesTheRule) {
  SppOptions o;
  EXPECT_EQ(o.validate(), "");
  o.elevation_mask_rad = 2.0;
  EXPECT_NE(o.validate().find("elevation_mask_rad"), std::string::npos);
  o = SppOptions{};
  o.code_sigma_m = 0.0;
  EXPECT_NE(o.validate().find("code_sigma_m"), std::string::npos);
}

/// Doppler velocity on the hardware simulator against its exact truth velocity.
TEST(SppVelocity, MatchesSimulatorTruth) {
  const fs::path dir = fs::path(CANYON_SHARED_DATA_DIR) / "instinct-spirent-rtk-sim";
  if (!fs::exists(dir)) GTEST_SKIP() << "shared dataset not present: " << dir;
  auto obs = io::read_rinex_obs((dir / "iono-Klob_tropo-Saast/Rover-dynamic_MO_Spirent.obs").string());
  auto gps = io::read_rinex_nav((dir / "RINEX_GN_Spirent.23N").string());
  ASSERT_TRUE(obs.ok() && gps.ok());
  const EphemerisStore store(gps->nav);
  // Truth velocity at whole seconds from the 10 Hz PVA file (columns: ..., GpsToW, x, y, z, vx, vy, vz, ...).
  std::map<long, Eigen::Vector3d> truth_v;
  std::ifstream pva(dir / "Rover-dynamic_PVA_Spirent.csv");
  std::string line;
  std::getline(pva, line);
  while (std::getline(pva, line)) {
    std::vector<double> f;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) f.push_back(std::stod(cell));
    if (f.size() >= 10 && std::abs(f[3] - std::round(f[3])) < 1e-6) {
      truth_v[std::lround(f[3])] = Eigen::Vector3d(f[7], f[8], f[9]);
    }
  }
  double sum_sq = 0.0;
  int n = 0;
  std::optional<Eigen::Vector3d> last;
  for (const auto& epoch : obs->epochs) {
    auto sol = solve_spp(epoch, store, SppOptions{}, last);
    ASSERT_TRUE(sol.ok());
    last = sol->p_E_m;
    ASSERT_TRUE(sol->v_E_mps.has_value());
    const auto it = truth_v.find(std::lround(epoch.time.tow_s));
    if (it == truth_v.end()) continue;
    sum_sq += (*sol->v_E_mps - it->second).squaredNorm();
    ++n;
  }
  const double rms_mps = std::sqrt(sum_sq / n);
  std::cout << "[ SPP      ] Doppler velocity vs simulator truth: 3D RMS " << rms_mps << " m/s over " << n
            << " epochs\n";
  EXPECT_EQ(n, 601);
  EXPECT_LT(rms_mps, 0.05);
}

}  // namespace
}  // namespace canyon::gnss
