// Ephemeris store unit tests: velocity and clock drift against numeric derivatives, GLONASS integration forward and
// back, BeiDou GEO and GPS orbit sanity, selection rules, transmission-time iteration, group delays, Sagnac range,
// and the per-epoch state table.

#include "canyon/gnss/ephemeris.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"
#include "canyon/gnss/satellite_states.hpp"

namespace canyon::gnss {
namespace {

using core::Constellation;
using core::GpsTime;

constexpr double kMaxVelErrorMps = 1e-3;

// Values from the matrtklib-static navigation file (G05, C01 GEO, R01), typed in.
core::KeplerEphemeris gps_g05() {
  core::KeplerEphemeris e;
  e.sat = {Constellation::Gps, 5};
  e.toc = {2320, 122400.0};
  e.toe = {2320, 122400.0};
  e.transmission_time = {2320, 115218.0};
  e.af0_s = -1.774230040610E-04;
  e.af1_sps = -1.364242052659E-12;
  e.iode = 72;
  e.crs_m = -9.821875000000E+01;
  e.delta_n_radps = 4.293035965037E-09;
  e.m0_rad = 1.714815412488E+00;
  e.cuc_rad = -5.291774868965E-06;
  e.e = 5.927642923780E-03;
  e.cus_rad = 1.830980181694E-06;
  e.sqrt_a_sqrtm = 5.153635631561E+03;
  e.toe_sow_s = 1.224000000000E+05;
  e.cic_rad = 3.352761268616E-08;
  e.omega0_rad = 2.520897825810E+00;
  e.cis_rad = -5.774199962616E-08;
  e.i0_rad = 9.719266524177E-01;
  e.crc_m = 3.536250000000E+02;
  e.omega_rad = 1.273307347665E+00;
  e.omega_dot_radps = -8.275344701323E-09;
  e.idot_radps = -2.610823036973E-10;
  e.accuracy_m = 2.0;
  e.tgd_s = {-1.071020960808E-08, 0.0};
  return e;
}

core::KeplerEphemeris bds_c01_geo() {
  core::KeplerEphemeris e;
  e.sat = {Constellation::BeiDou, 1};
  e.toc = {2320, 86400.0 + 28814.0};
  e.toe = {2320, 115214.0};
  e.transmission_time = e.toe;
  e.af0_s = 9.039411088452E-04;
  e.af1_sps = 2.186695269302E-12;
  e.iode = 1;
  e.crs_m = 3.987812500000E+02;
  e.delta_n_radps = 1.168655822063E-08;
  e.m0_rad = -7.785119710056E-01;
  e.cuc_rad = 1.305714249611E-05;
  e.e = 2.352053998038E-04;
  e.cus_rad = -1.721968874335E-05;
  e.sqrt_a_sqrtm = 6.493358730316E+03;
  e.toe_sow_s = 1.152000000000E+05;
  e.cic_rad = 3.771856427193E-08;
  e.omega0_rad = -1.376223151778E+00;
  e.cis_rad = -3.306195139885E-08;
  e.i0_rad = 6.493194956776E-02;
  e.crc_m = 5.192812500000E+02;
  e.omega_rad = 5.103894865136E-01;
  e.omega_dot_radps = -1.047865076358E-08;
  e.idot_radps = 2.235807416067E-10;
  e.accuracy_m = 2.0;
  e.tgd_s = {-4.9e-9, -1.0e-8};
  return e;
}

core::GlonassEphemeris glonass_r01() {
  core::GlonassEphemeris g;
  g.sat = {Constellation::Glonass, 1};
  g.toe = {2320, 86400.0 + 8 * 3600 + 15 * 60 + 18};
  g.frame_time = {2320, 115218.0};
  g.frequency_channel = 1;
  g.p_E_m = Eigen::Vector3d(-1.373688769531E+04, -3.309238281250E+03, 2.124241259766E+04) * 1e3;
  g.v_E_mps = Eigen::Vector3d(-1.554378509521E+00, -2.458472251892E+00, -1.386628150940E+00) * 1e3;
  g.a_E_mps2 = Eigen::Vector3d(9.313225746155E-10, 1.862645149231E-09, -1.862645149231E-09) * 1e3;
  g.tau_n_s = 8.934084326029E-05;
  g.gamma_n = 9.094947017729E-13;
  return g;
}

EphemerisStore store_of(std::vector<core::KeplerEphemeris> kepler, std::vector<core::GlonassEphemeris> glo = {},
                        EphemerisOptions options = {}) {
  core::NavigationData nav;
  nav.kepler = std::move(kepler);
  nav.glonass = std::move(glo);
  return EphemerisStore(std::move(nav), options);
}

void expect_velocity_is_derivative(const EphemerisStore& store, core::SatelliteId sat, GpsTime t) {
  const double h_s = 0.5;
  const auto s = store.state(sat, t), before = store.state(sat, t - h_s), after = store.state(sat, t + h_s);
  ASSERT_TRUE(s && before && after);
  const Eigen::Vector3d v_num = (after->p_E_m - before->p_E_m) / (2.0 * h_s);
  EXPECT_LT((s->v_E_mps - v_num).norm(), kMaxVelErrorMps) << sat.to_string();
  const double drift_num = (after->clock_bias_s - before->clock_bias_s) / (2.0 * h_s);
  EXPECT_NEAR(s->clock_drift_sps, drift_num, 1e-14) << sat.to_string();
}

TEST(Ephemeris, VelocityAndDriftAreDerivatives) {
  const EphemerisStore store = store_of({gps_g05(), bds_c01_geo()}, {glonass_r01()});
  for (const double dt_s : {-3000.0, -100.0, 0.0, 1234.5, 3600.0}) {
    expect_velocity_is_derivative(store, {Constellation::Gps, 5}, GpsTime{2320, 122400.0} + dt_s);
    expect_velocity_is_derivative(store, {Constellation::BeiDou, 1}, GpsTime{2320, 115214.0} + dt_s);
  }
  for (const double dt_s : {-1700.0, -45.0, 0.0, 30.0, 900.0, 1700.0}) {
    expect_velocity_is_derivative(store, {Constellation::Glonass, 1}, glonass_r01().toe + dt_s);
  }
}

TEST(Ephemeris, OrbitRadii) {
  const EphemerisStore store = store_of({gps_g05(), bds_c01_geo()});
  const auto g = store.state({Constellation::Gps, 5}, {2320, 123000.0});
  ASSERT_TRUE(g);
  EXPECT_NEAR(g->p_E_m.norm(), 26.56e6, 0.2e6);
  EXPECT_NEAR(g->v_E_mps.norm(), 3.0e3, 1.0e3);  // ECEF speed of a GPS satellite
  const auto c = store.state({Constellation::BeiDou, 1}, {2320, 116000.0});
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->p_E_m.norm(), 42.16e6, 0.05e6);
  EXPECT_LT(c->v_E_mps.norm(), 300.0);                // geostationary, inclined 3.7 deg: slow figure-eight in ECEF
  EXPECT_LT(std::abs(c->p_E_m.z()), 0.05 * 42.16e6);  // near the equator
}

TEST(Ephemeris, GlonassForwardAndBackAgree) {
  const core::GlonassEphemeris g = glonass_r01();
  const EphemerisStore store = store_of({}, {g});
  const double dt_s = 1500.0;
  const auto forward = store.state(g.sat, g.toe + dt_s);
  ASSERT_TRUE(forward);
  core::GlonassEphemeris moved = g;
  moved.toe = g.toe + dt_s;
  moved.p_E_m = forward->p_E_m;
  moved.v_E_mps = forward->v_E_mps;
  const EphemerisStore back_store = store_of({}, {moved});
  const auto back = back_store.state(g.sat, g.toe);
  ASSERT_TRUE(back);
  EXPECT_LT((back->p_E_m - g.p_E_m).norm(), 1e-3);
  EXPECT_LT((back->v_E_mps - g.v_E_mps).norm(), 1e-6);
  // Clock: RINEX stores -tau_n; clock = -tau_n + gamma_n (t - tb).
  EXPECT_DOUBLE_EQ(forward->clock_bias_s, g.tau_n_s + g.gamma_n * dt_s);
  EXPECT_EQ(forward->glonass_channel, 1);
}

// GLONASS states reuse the whole integration steps of the previous call for the same record (per thread). Queried in a
// scrambled order -- forward and backward of toe, on and beside whole steps, one record then another then the first
// again -- every state equals, bit for bit, the one a fresh thread computes by integrating from the toe.
TEST(Ephemeris, GlonassStatesDoNotDependOnEarlierQueries) {
  const core::GlonassEphemeris a = glonass_r01();
  core::GlonassEphemeris b = a;
  b.toe = a.toe + 1800.0;
  b.p_E_m += Eigen::Vector3d(1.0e3, -2.0e3, 0.5e3);
  const EphemerisStore early = store_of({}, {a});
  const EphemerisStore late = store_of({}, {b});
  std::vector<double> offsets_s = {0.0,  1e-10, 59.999, 60.0,    60.0 + 1e-10, 61.5,  119.9, 120.0, 600.0, 900.0,
                                   -0.5, -60.0, -61.0,  -600.25, 301.0,        302.0, 0.2,   0.4,   898.7, 240.0};
  std::mt19937 rng(11);
  std::shuffle(offsets_s.begin(), offsets_s.end(), rng);
  for (const auto* store : {&early, &late, &early}) {  // records in turn: the steps are kept for one at a time
    for (const double offset_s : offsets_s) {
      const core::GpsTime t = store->nav().glonass.front().toe + offset_s;
      const auto here = store->state(a.sat, t);
      std::optional<SatelliteState> fresh;
      std::thread([&] { fresh = store->state(a.sat, t); }).join();
      ASSERT_TRUE(here && fresh) << offset_s;
      for (int i = 0; i < 3; ++i) {
        EXPECT_EQ(here->p_E_m[i], fresh->p_E_m[i]) << "offset " << offset_s << " s, axis " << i;
        EXPECT_EQ(here->v_E_mps[i], fresh->v_E_mps[i]) << "offset " << offset_s << " s, axis " << i;
      }
    }
  }
}

TEST(Ephemeris, KeplerClockIncludesRelativity) {
  const core::KeplerEphemeris e = gps_g05();
  const EphemerisStore store = store_of({e});
  const GpsTime t = e.toc + 600.0;
  const auto s = store.state(e.sat, t);
  ASSERT_TRUE(s);
  const double poly_s = e.af0_s + e.af1_sps * 600.0;
  // |relativistic term| <= 2 sqrt(mu a) e / c^2 = 4.44e-10 e sqrt(a) ~ 13.5 ns for e = 0.0059.
  const double bound_s = 4.4428e-10 * e.e * e.sqrt_a_sqrtm;
  EXPECT_LE(std::abs(s->clock_bias_s - poly_s), bound_s * 1.001);
  EXPECT_GT(std::abs(s->clock_bias_s - poly_s), 0.0);
  EXPECT_DOUBLE_EQ(s->variance_m2, 4.0);
}

TEST(Ephemeris, SelectionRules) {
  core::KeplerEphemeris a = gps_g05(), b = gps_g05(), sick = gps_g05();
  a.toe = a.toc = {2320, 115200.0};
  a.iode = 10;
  b.toe = b.toc = {2320, 122400.0};
  b.iode = 11;
  sick.toe = sick.toc = {2320, 118800.0};
  sick.health = 1;
  sick.iode = 12;
  const EphemerisStore store = store_of({a, b, sick});
  EXPECT_EQ(store.select_kepler(a.sat, {2320, 118000.0})->iode, 10);  // nearest healthy toe
  EXPECT_EQ(store.select_kepler(a.sat, {2320, 119000.0})->iode, 11);
  EXPECT_EQ(store.select_kepler(a.sat, {2320, 122400.0 + 5 * 3600.0}), nullptr);  // too old
  EXPECT_EQ(store.select_kepler({Constellation::Gps, 6}, {2320, 118000.0}), nullptr);
  EphemerisOptions unhealthy;
  unhealthy.use_unhealthy = true;
  const EphemerisStore store2 = store_of({a, b, sick}, {}, unhealthy);
  EXPECT_EQ(store2.select_kepler(a.sat, {2320, 118800.0})->iode, 12);

  // Galileo: I/NAV preferred over F/NAV with the same toe; a toe not yet reached is not used.
  core::KeplerEphemeris inav = gps_g05(), fnav = gps_g05(), next = gps_g05();
  for (auto* e : {&inav, &fnav, &next}) e->sat = {Constellation::Galileo, 4};
  inav.data_source = 517;
  inav.iode = 1;
  fnav.data_source = 258;
  fnav.iode = 2;
  next.data_source = 517;
  next.iode = 3;
  next.toe = next.toc = inav.toe + 600.0;
  const EphemerisStore gal = store_of({fnav, inav, next});
  EXPECT_EQ(gal.select_kepler(inav.sat, inav.toe + 300.0)->iode, 1);
  EXPECT_EQ(gal.select_kepler(inav.sat, inav.toe + 599.0)->iode, 1);
  EXPECT_EQ(gal.select_kepler(inav.sat, inav.toe + 601.0)->iode, 3);
  const EphemerisStore fnav_only = store_of({fnav});
  EXPECT_EQ(fnav_only.select_kepler(inav.sat, inav.toe + 300.0)->iode, 2);
}

// The selection rules of the file comment, record by record, without any memo: the reference for the store.
const core::KeplerEphemeris* reference_selection(const std::vector<core::KeplerEphemeris>& records,
                                                 core::SatelliteId sat, core::GpsTime t, double max_age_s) {
  const bool galileo = sat.system == Constellation::Galileo;
  const auto inav = [](const core::KeplerEphemeris& e) { return (e.data_source & 0x201) != 0; };
  const core::KeplerEphemeris* best = nullptr;
  for (const core::KeplerEphemeris& e : records) {
    const double age_s = std::abs(t - e.toe);
    const double limit_s = std::max(max_age_s, e.fit_interval_h * 3600.0 / 2.0);
    if (e.sat != sat || e.health != 0 || age_s > limit_s || (galileo && !(e.toe < t))) continue;
    if (best != nullptr) {
      const double best_age_s = std::abs(t - best->toe);
      if (galileo && inav(*best) != inav(e)) {
        if (!inav(e)) continue;
      } else if (age_s > best_age_s || (age_s == best_age_s && e.transmission_time < best->transmission_time)) {
        continue;
      }
    }
    best = &e;
  }
  return best;
}

// select_kepler() remembers each satellite's last selection while the query time cannot change it: swept forward,
// backward and at random over two days -- across every toe, toe +- maximum age and midpoint between toes, and a
// microsecond either side of each -- it answers as the rules do record by record.
TEST(Ephemeris, RememberedSelectionEqualsTheRules) {
  std::vector<core::KeplerEphemeris> records;
  const core::GpsTime t0{2320, 100000.0};
  for (int k = 0; k < 14; ++k) {  // GPS every 2 h, one of them sent twice, one unhealthy, one with a long fit
    core::KeplerEphemeris e = gps_g05();
    e.toe = e.toc = t0 + 7200.0 * k;
    e.iode = k;
    e.transmission_time = e.toe - 60.0;
    e.health = k == 5 ? 1 : 0;
    e.fit_interval_h = k == 9 ? 12.0 : 4.0;
    records.push_back(e);
    if (k == 3) {
      e.iode = 100 + k;
      e.transmission_time = e.toe - 30.0;
      records.push_back(e);
    }
  }
  for (int k = 0; k < 60; ++k) {  // Galileo I/NAV every 10 min, F/NAV in between, a gap of two hours
    if (k >= 20 && k < 32) continue;
    core::KeplerEphemeris e = gps_g05();
    e.sat = {Constellation::Galileo, 4};
    e.toe = e.toc = t0 + 600.0 * k + (k % 2 == 0 ? 0.0 : 300.0);
    e.data_source = k % 3 == 0 ? 258 : 517;
    e.iode = 200 + k;
    e.transmission_time = e.toe - 10.0;
    records.push_back(e);
  }
  const EphemerisStore store = store_of(records);
  const double max_age_s = EphemerisOptions{}.max_age_kepler_s;

  std::vector<core::GpsTime> times;
  for (double dt_s = -20000.0; dt_s < 150000.0; dt_s += 97.3) times.push_back(t0 + dt_s);
  for (const core::KeplerEphemeris& e : records) {
    const double limit_s = std::max(max_age_s, e.fit_interval_h * 1800.0);
    for (const core::KeplerEphemeris& f : records) {
      if (f.sat != e.sat) continue;
      for (const double dt_s : {-1e-6, 0.0, 1e-6}) times.push_back(e.toe + (0.5 * (f.toe - e.toe) + dt_s));
    }
    for (const double edge_s : {-limit_s, 0.0, limit_s}) {
      for (const double dt_s : {-1e-6, 0.0, 1e-6}) times.push_back(e.toe + (edge_s + dt_s));
    }
  }
  std::sort(times.begin(), times.end());
  std::vector<core::GpsTime> order = times;
  std::reverse(order.begin(), order.end());
  order.insert(order.end(), times.begin(), times.end());
  std::vector<core::GpsTime> shuffled = times;
  std::mt19937 rng(7);
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  order.insert(order.end(), shuffled.begin(), shuffled.end());

  int mismatches = 0;
  for (const core::GpsTime& t : order) {
    for (const core::SatelliteId sat : {records.front().sat, records.back().sat}) {
      const core::KeplerEphemeris* expected = reference_selection(records, sat, t, max_age_s);
      const core::KeplerEphemeris* got = store.select_kepler(sat, t);
      const int expected_iode = expected != nullptr ? expected->iode : -1;
      const int got_iode = got != nullptr ? got->iode : -1;
      if (expected_iode != got_iode && ++mismatches <= 5) {
        ADD_FAILURE() << sat.to_string() << " at week " << t.week << " tow " << t.tow_s << ": selected " << got_iode
                      << ", the rules select " << expected_iode;
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(order.size(), 3000u);
}

// Ephemerides that arrive while running (a receiver's SFRBX, a base's RTCM) are added unless the store holds the
// same record: the selection then is that of a store built with all of them, and a repeat changes nothing.
TEST(Ephemeris, AddedRecordsAreSelectedAndRepeatsKeepTheHeldRecord) {
  core::KeplerEphemeris a = gps_g05(), b = gps_g05();
  a.toe = a.toc = {2320, 115200.0};
  a.iode = 10;
  b.toe = b.toc = {2320, 122400.0};
  b.iode = 11;
  EphemerisStore store = store_of({a});
  EXPECT_EQ(store.select_kepler(a.sat, {2320, 121000.0})->iode, 10);
  core::NavigationData fresh;
  fresh.kepler = {a, b};
  fresh.kepler[0].af0_s += 1e-3;  // same satellite, toe and IODE as the held record: not added
  fresh.gps_klobuchar = core::KlobucharParams{};
  EXPECT_EQ(store.add(fresh), 1);
  EXPECT_EQ(store.nav().kepler.size(), 2u);
  EXPECT_EQ(store.select_kepler(a.sat, {2320, 121000.0})->iode, 11);        // the added, nearer toe
  EXPECT_EQ(store.select_kepler(a.sat, {2320, 116000.0})->af0_s, a.af0_s);  // the held record, unchanged
  EXPECT_TRUE(store.nav().gps_klobuchar.has_value());
  EXPECT_EQ(store.add(fresh), 0);  // a repeat adds nothing

  // Unhealthy records are kept but not selected, as in a store built with them.
  core::KeplerEphemeris sick = gps_g05();
  sick.toe = sick.toc = {2320, 118800.0};
  sick.iode = 12;
  sick.health = 1;
  core::NavigationData more;
  more.kepler = {sick};
  EXPECT_EQ(store.add(more), 1);
  EXPECT_NE(store.select_kepler(a.sat, {2320, 118800.0})->iode, 12);
}

TEST(Ephemeris, QzssL1cbHealthBitDoesNotRejectTheSatellite) {
  // QZSS LNAV health bit 0 is the L1C/B signal's (set on every QZSS record of matrtklib-static); other bits count.
  core::KeplerEphemeris qzs = gps_g05();
  qzs.sat = {Constellation::Qzss, 2};
  qzs.health = 1;
  EXPECT_NE(store_of({qzs}).select_kepler(qzs.sat, qzs.toe), nullptr);
  qzs.health = 0x21;
  EXPECT_EQ(store_of({qzs}).select_kepler(qzs.sat, qzs.toe), nullptr);
  core::KeplerEphemeris gps = gps_g05();
  gps.health = 1;
  EXPECT_EQ(store_of({gps}).select_kepler(gps.sat, gps.toe), nullptr);
}

TEST(Ephemeris, StateAtReceptionSolvesLightTime) {
  const EphemerisStore store = store_of({gps_g05()});
  const GpsTime t_rx{2320, 123000.0};
  const double pseudorange_m = 22.0e6;
  GpsTime t_tx;
  const auto s = store.state_at_reception({Constellation::Gps, 5}, t_rx, pseudorange_m, &t_tx);
  ASSERT_TRUE(s);
  // The transmission time is iterated on the clock polynomial only: it may differ from the exact fixed point
  // t_tx = t_rx - P/c - dt_sat(t_tx) by the relativistic term (< 50 ns), which moves the satellite < 0.2 mm.
  GpsTime exact = t_rx - pseudorange_m / core::kSpeedOfLightMps;
  for (int i = 0; i < 5; ++i) {
    exact = t_rx - pseudorange_m / core::kSpeedOfLightMps - store.state({Constellation::Gps, 5}, exact)->clock_bias_s;
  }
  EXPECT_NEAR(t_tx - exact, 0.0, 5e-8);
  const auto s_exact = store.state({Constellation::Gps, 5}, exact);
  EXPECT_LT((s->p_E_m - s_exact->p_E_m).norm(), 2e-4);
  EXPECT_NEAR(s->clock_bias_s, s_exact->clock_bias_s, 1e-15);
}

TEST(EpochSatelliteStates, AnswersAsTheStoreAndKeepsVelocityWhenAskedFor) {
  const EphemerisStore store = store_of({gps_g05()}, {glonass_r01()});
  const GpsTime t_rx{2320, 123000.0};
  const core::SatelliteId g05{Constellation::Gps, 5};
  const core::SatelliteId r01{Constellation::Glonass, 1};
  EpochSatelliteStates states(store, t_rx);
  const auto expect_same = [](const std::optional<SatelliteState>& a, const std::optional<SatelliteState>& b) {
    ASSERT_EQ(a.has_value(), b.has_value());
    if (!a) return;
    EXPECT_EQ(a->p_E_m, b->p_E_m);
    EXPECT_EQ(a->v_E_mps, b->v_E_mps);
    EXPECT_EQ(a->clock_bias_s, b->clock_bias_s);
    EXPECT_EQ(a->clock_drift_sps, b->clock_drift_sps);
  };
  // First request without velocity, then with: the second is computed anew (velocity is not zero), then kept.
  expect_same(states.at_reception(g05, 22.0e6, false), store.state_at_reception(g05, t_rx, 22.0e6, nullptr, false));
  expect_same(states.at_reception(g05, 22.0e6, true), store.state_at_reception(g05, t_rx, 22.0e6, nullptr, true));
  expect_same(states.at_reception(g05, 22.0e6, false), store.state_at_reception(g05, t_rx, 22.0e6, nullptr, true));
  // Another pseudorange is another transmission time.
  expect_same(states.at_reception(g05, 23.0e6, false), store.state_at_reception(g05, t_rx, 23.0e6, nullptr, false));
  expect_same(states.at_reception(r01, 21.0e6, true), store.state_at_reception(r01, t_rx, 21.0e6, nullptr, true));
  // No ephemeris: nullopt, also when asked again.
  EXPECT_FALSE(states.at_reception({Constellation::Gps, 6}, 22.0e6, false));
  EXPECT_FALSE(states.at_reception({Constellation::Gps, 6}, 22.0e6, false));
}

TEST(Ephemeris, GroupDelays) {
  core::KeplerEphemeris gal = gps_g05();
  gal.sat = {Constellation::Galileo, 4};
  gal.data_source = 517;
  gal.tgd_s = {-1.6e-9, -2.3e-9};
  const EphemerisStore store = store_of({gps_g05(), bds_c01_geo(), gal});
  const GpsTime t{2320, 123000.0};  // after every toe (Galileo needs toe < t)
  const double tgd = gps_g05().tgd_s[0];
  EXPECT_DOUBLE_EQ(store.group_delay_s({Constellation::Gps, 5}, {'1', 'C'}, t), tgd);
  EXPECT_NEAR(store.group_delay_s({Constellation::Gps, 5}, {'2', 'W'}, t), tgd * std::pow(77.0 / 60.0, 2), 1e-20);
  EXPECT_DOUBLE_EQ(store.group_delay_s({Constellation::BeiDou, 1}, {'2', 'I'}, t), -4.9e-9);
  EXPECT_DOUBLE_EQ(store.group_delay_s({Constellation::BeiDou, 1}, {'7', 'I'}, t), -1.0e-8);
  EXPECT_DOUBLE_EQ(store.group_delay_s({Constellation::BeiDou, 1}, {'6', 'I'}, t), 0.0);
  EXPECT_DOUBLE_EQ(store.group_delay_s(gal.sat, {'1', 'C'}, t), -2.3e-9);  // I/NAV: BGD(E1,E5b)
  EXPECT_NEAR(store.group_delay_s(gal.sat, {'7', 'Q'}, t), -2.3e-9 * std::pow(1575.42 / 1207.14, 2), 1e-20);
  EXPECT_DOUBLE_EQ(store.group_delay_s({Constellation::Gps, 9}, {'1', 'C'}, t), 0.0);
}

TEST(Ephemeris, SagnacMatchesExactRotation) {
  const Eigen::Vector3d p_sat(15.0e6, 20.0e6, 8.0e6), p_rcv(-3.96e6, 3.38e6, 3.67e6);
  Eigen::Vector3d los;
  const double range_m = geometric_range_m(p_sat, p_rcv, &los);
  // Exact: rotate the satellite by -omega_e tau (the Earth turned during the flight), iterate on tau.
  double tau_s = (p_sat - p_rcv).norm() / core::kSpeedOfLightMps;
  double exact_m = 0.0;
  for (int i = 0; i < 5; ++i) {
    const double a = core::kEarthRotationRateRadps * tau_s;
    const Eigen::Vector3d p_rot(std::cos(a) * p_sat.x() + std::sin(a) * p_sat.y(),
                                -std::sin(a) * p_sat.x() + std::cos(a) * p_sat.y(), p_sat.z());
    exact_m = (p_rot - p_rcv).norm();
    tau_s = exact_m / core::kSpeedOfLightMps;
  }
  EXPECT_NEAR(range_m, exact_m, 1e-3);
  EXPECT_GT(std::abs(range_m - (p_sat - p_rcv).norm()), 1.0);  // the correction is tens of metres here
  EXPECT_NEAR(los.norm(), 1.0, 1e-12);
}

}  // namespace
}  // namespace canyon::gnss
