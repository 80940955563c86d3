// The built-in constellation as any reader sees it: written to RINEX 3, read back, evaluated with canyon's
// broadcast ephemeris code. Records of one satellite describe one orbit (no jump when the selected record changes),
// orbits are where the real constellations fly, and the sky over a city is populated as it should be.

#include "canyon/sim/constellation.hpp"

#include <cmath>
#include <map>

#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/io/rinex_nav.hpp"

#include "io/rinex_test_util.hpp"

namespace canyon::sim {
namespace {

using core::Constellation;

constexpr double kMaxRecordJumpM = 0.005;  // position of two consecutive records at their midpoint
constexpr double kMaxRecordClockJumpS = 1e-11;

core::NavigationData written_and_read(const ConstellationOptions& options, core::GpsTime t0, double span_s) {
  io::test::TempDir tmp;
  const std::string path = tmp.file("nav.rnx");
  EXPECT_TRUE(io::write_rinex_nav(path, builtin_navigation(options, t0, t0 + span_s)).ok());
  auto nav = io::read_rinex_nav(path);
  EXPECT_TRUE(nav.ok()) << nav.error().to_string();
  EXPECT_TRUE(nav->warnings.empty());
  return nav->nav;
}

ConstellationOptions all_systems() {
  ConstellationOptions o;
  o.use_beidou = true;
  return o;
}

TEST(ConstellationTest, RecordsOfOneSatelliteDescribeOneOrbit) {
  const core::GpsTime t0 = core::calendar_to_gps({2023, 6, 14, 18, 0, 0.0});
  const core::NavigationData nav = written_and_read(all_systems(), t0, 7200.0);
  // Each satellite's consecutive records evaluated at the midpoint between their reference times.
  std::map<int, std::vector<const core::KeplerEphemeris*>> kepler;
  for (const auto& e : nav.kepler) kepler[e.sat.index()].push_back(&e);
  int pairs = 0;
  for (const auto& [index, records] : kepler) {
    for (std::size_t k = 0; k + 1 < records.size(); ++k) {
      core::NavigationData one, two;
      one.kepler = {*records[k]};
      two.kepler = {*records[k + 1]};
      const core::GpsTime mid = records[k + 1]->toe + 1.0;  // after both toes (Galileo selects only past ones)
      const auto a = gnss::EphemerisStore(one).state(records[k]->sat, mid);
      const auto b = gnss::EphemerisStore(two).state(records[k]->sat, mid);
      ASSERT_TRUE(a && b) << records[k]->sat.to_string();
      EXPECT_LT((a->p_E_m - b->p_E_m).norm(), kMaxRecordJumpM) << records[k]->sat.to_string();
      EXPECT_LT(std::abs(a->clock_bias_s - b->clock_bias_s), kMaxRecordClockJumpS) << records[k]->sat.to_string();
      ++pairs;
    }
  }
  EXPECT_GT(pairs, 300);
  std::map<int, std::vector<const core::GlonassEphemeris*>> glonass;
  for (const auto& g : nav.glonass) glonass[g.sat.index()].push_back(&g);
  ASSERT_EQ(glonass.size(), 24U);
  for (const auto& [index, records] : glonass) {
    for (std::size_t k = 0; k + 1 < records.size(); ++k) {
      core::NavigationData one, two;
      one.glonass = {*records[k]};
      two.glonass = {*records[k + 1]};
      const core::GpsTime mid = records[k]->toe + 0.5 * (records[k + 1]->toe - records[k]->toe);
      const auto a = gnss::EphemerisStore(one).state(records[k]->sat, mid);
      const auto b = gnss::EphemerisStore(two).state(records[k]->sat, mid);
      ASSERT_TRUE(a && b);
      EXPECT_LT((a->p_E_m - b->p_E_m).norm(), kMaxRecordJumpM) << records[k]->sat.to_string();
    }
  }
}

TEST(ConstellationTest, OrbitsAndSkyAreRealistic) {
  const core::GpsTime t0 = core::calendar_to_gps({2023, 6, 14, 0, 0, 0.0});
  const core::NavigationData nav = written_and_read(all_systems(), t0, 86400.0);
  const gnss::EphemerisStore store(nav);
  const core::Geodetic seattle{47.6062 * core::kDegToRad, -122.3321 * core::kDegToRad, 20.0};
  const Eigen::Vector3d p_rcv = core::geodetic_to_ecef(seattle);
  std::map<Constellation, double> radius_km;
  std::map<Constellation, int> visible, fewest;
  constexpr int kHours = 24;
  for (int hour = 0; hour < kHours; ++hour) {
    std::map<Constellation, int> now;
    for (const core::SatelliteId sat : builtin_satellites(all_systems())) {
      const auto s = store.state(sat, t0 + hour * 3600.0);
      ASSERT_TRUE(s) << sat.to_string() << " at hour " << hour;
      radius_km[sat.system] = s->p_E_m.norm() / 1e3;
      EXPECT_LT(std::abs(s->clock_bias_s), 1e-3);
      if (core::azimuth_elevation(p_rcv, seattle, s->p_E_m).elevation_rad > 10.0 * core::kDegToRad) {
        ++now[sat.system];
      }
    }
    for (const auto& [system, n] : now) {
      visible[system] += n;
      fewest[system] = hour == 0 ? n : std::min(fewest[system], n);
    }
  }
  EXPECT_NEAR(radius_km[Constellation::Gps], 26560.0, 450.0);
  EXPECT_NEAR(radius_km[Constellation::Glonass], 25510.0, 100.0);
  EXPECT_NEAR(radius_km[Constellation::Galileo], 29600.0, 450.0);
  EXPECT_NEAR(radius_km[Constellation::BeiDou], 27906.0, 450.0);
  // Satellites above 10 deg for a mid-latitude receiver over a day, as with the real constellations.
  EXPECT_NEAR(visible[Constellation::Gps] / double(kHours), 9.0, 1.5);
  EXPECT_NEAR(visible[Constellation::Glonass] / double(kHours), 7.0, 1.5);
  EXPECT_NEAR(visible[Constellation::Galileo] / double(kHours), 7.0, 1.5);
  EXPECT_GE(fewest[Constellation::Gps], 4);
  // GLONASS channels: antipodal slots share one, all in [-7, 6].
  for (int slot = 1; slot <= 4; ++slot) EXPECT_EQ(nav.glonass_channel(slot), nav.glonass_channel(slot + 4));
  for (int slot = 1; slot <= 24; ++slot) {
    EXPECT_GE(nav.glonass_channel(slot), -7);
    EXPECT_LE(nav.glonass_channel(slot), 6);
  }
}

TEST(ConstellationTest, SystemsDoNotChangeEachOther) {
  ConstellationOptions gps_only;
  gps_only.use_glonass = gps_only.use_galileo = false;
  const core::GpsTime t0 = core::calendar_to_gps({2023, 6, 14, 18, 0, 0.0});
  const auto a = builtin_navigation(gps_only, t0, t0 + 600.0);
  const auto b = builtin_navigation(all_systems(), t0, t0 + 600.0);
  ASSERT_TRUE(a.glonass.empty());
  for (const auto& e : a.kepler) {
    const auto it = std::find_if(b.kepler.begin(), b.kepler.end(),
                                 [&](const core::KeplerEphemeris& x) { return x.sat == e.sat && x.toe == e.toe; });
    ASSERT_NE(it, b.kepler.end());
    EXPECT_EQ(it->m0_rad, e.m0_rad);
    EXPECT_EQ(it->af0_s, e.af0_s);
  }
}

}  // namespace
}  // namespace canyon::sim
