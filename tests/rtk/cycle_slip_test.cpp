// Cycle-slip detector: each cause on synthetic observables (with a receiver clock model, ionosphere and noise of
// realistic size), then counts per cause over every epoch of the shared real datasets.

#include "canyon/rtk/cycle_slip.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"
#include "canyon/core/observation.hpp"

namespace canyon::rtk {
namespace {

using core::Constellation;
using core::SatelliteId;

constexpr double kC = core::kSpeedOfLightMps;
constexpr double kF1Hz = 1575.42e6;
constexpr double kF2Hz = 1227.60e6;
constexpr double kLambda1M = kC / kF1Hz;
constexpr double kLambda2M = kC / kF2Hz;

/// A synthetic sky: per satellite range rho(t) = rho0 + v t + a t^2 / 2 + j t^3 / 6 and L1 ionospheric delay
/// I(t) = I0 + Idot t; a receiver clock dt_r(t) = bias + drift t (+ jumps). The measurement with time tag T is
/// taken at true time t = T - dt_r:
///   phi_f = (rho(t) - I_f(t) + c dt_r) / lambda_f + N_f,    D_f = -(rho_dot(t) - I_f_dot + c drift) / lambda_f,
/// with I_2 = I_1 f1^2 / f2^2, white phase noise (m) and Doppler noise (m/s).
struct Sky {
  struct Satellite {
    SatelliteId sat;
    double rho0_m, v_mps, a_mps2, j_mps3, iono0_m, iono_rate_mps;
    std::array<double, 2> ambiguity_cyc;
  };
  std::vector<Satellite> satellites;
  double clock_bias_s = 1e-4;
  double clock_drift = 2e-7;  // s/s
  double clock_jump_s = 0.0;  // added from `clock_jump_time_s` on
  double clock_jump_time_s = std::numeric_limits<double>::infinity();
  double phase_noise_m = 0.0;
  double doppler_noise_mps = 0.0;
  int num_frequencies = 2;
  bool with_doppler = true;
  std::mt19937_64 rng{42};

  explicit Sky(int num_satellites) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int i = 0; i < num_satellites; ++i) {
      Satellite s;
      s.sat = SatelliteId{Constellation::Gps, static_cast<std::uint8_t>(2 + 3 * i)};
      s.rho0_m = 2.2e7 + 2.0e6 * u(rng);
      s.v_mps = 750.0 * u(rng);
      s.a_mps2 = 0.12 * u(rng);
      s.j_mps3 = 2e-5 * u(rng);
      s.iono0_m = 5.0 + 3.0 * u(rng);
      s.iono_rate_mps = 3e-4 * u(rng);  // ~0.5 TECU/min of L1 delay change
      s.ambiguity_cyc = {std::round(1e6 * u(rng)), std::round(1e6 * u(rng))};
      satellites.push_back(s);
    }
  }

  [[nodiscard]] double clock_s(double tag_s) const {
    return clock_bias_s + clock_drift * tag_s + (tag_s >= clock_jump_time_s ? clock_jump_s : 0.0);
  }

  /// Epoch with time tag `tag_s` seconds after the start of GPS week 2200.
  ReceiverObservables epoch(double tag_s) {
    std::normal_distribution<double> n01(0.0, 1.0);
    ReceiverObservables out;
    out.time = core::GpsTime{2200, 1000.0 + tag_s};
    const double dt_r = clock_s(tag_s);
    const double t = tag_s - dt_r;
    for (const Satellite& s : satellites) {
      const double rho = s.rho0_m + s.v_mps * t + 0.5 * s.a_mps2 * t * t + s.j_mps3 * t * t * t / 6.0;
      const double rho_dot = s.v_mps + s.a_mps2 * t + 0.5 * s.j_mps3 * t * t;
      const double iono1 = s.iono0_m + s.iono_rate_mps * t;
      for (int f = 0; f < num_frequencies; ++f) {
        const double lambda = f == 0 ? kLambda1M : kLambda2M;
        const double k_iono = f == 0 ? 1.0 : (kF1Hz * kF1Hz) / (kF2Hz * kF2Hz);
        SignalObservable o;
        o.sat = s.sat;
        o.frequency = f;
        o.code = core::SignalCode{f == 0 ? '1' : '2', f == 0 ? 'C' : 'W'};
        o.wavelength_m = lambda;
        o.carrier_phase_cyc = (rho - k_iono * iono1 + kC * dt_r + phase_noise_m * n01(rng)) / lambda +
                              s.ambiguity_cyc[static_cast<std::size_t>(f)];
        if (with_doppler) {
          o.doppler_hz =
              -(rho_dot - k_iono * s.iono_rate_mps + kC * clock_drift + doppler_noise_mps * n01(rng)) / lambda;
        }
        o.pseudorange_m = rho + k_iono * iono1 + kC * dt_r;
        o.snr_dbhz = 45.0;
        out.signals.push_back(o);
      }
    }
    return out;
  }
};

SignalObservable& signal(ReceiverObservables& e, SatelliteId sat, int frequency) {
  for (SignalObservable& s : e.signals) {
    if (s.sat == sat && s.frequency == frequency) return s;
  }
  ADD_FAILURE() << "no signal " << sat.to_string() << " f" << frequency;
  return e.signals.front();
}

std::string describe(const std::vector<SlipEvent>& events) {
  std::string out;
  for (const SlipEvent& e : events) {
    out += e.sat.to_string() + " f" + std::to_string(e.frequency) + " " + to_string(e.cause) + " " +
           std::to_string(e.value) + "; ";
  }
  return out;
}

/// Runs `epochs` epochs at `interval_s`, calling `edit(k, epoch)` before each update; returns events per epoch.
template <typename Edit>
std::vector<std::vector<SlipEvent>> run(Sky& sky, CycleSlipDetector& detector, int epochs, double interval_s,
                                        Edit edit) {
  std::vector<std::vector<SlipEvent>> out;
  for (int k = 0; k < epochs; ++k) {
    ReceiverObservables e = sky.epoch(k * interval_s);
    edit(k, e);
    out.push_back(detector.update(e));
  }
  return out;
}

std::size_t total(const std::vector<std::vector<SlipEvent>>& per_epoch) {
  std::size_t n = 0;
  for (const auto& e : per_epoch) n += e.size();
  return n;
}

Sky realistic_sky(int num_satellites = 8) {
  Sky sky(num_satellites);
  sky.phase_noise_m = 0.003;
  sky.doppler_noise_mps = 0.02;
  return sky;
}

TEST(CycleSlipOptions, ValidateNamesTheBrokenRule) {
  EXPECT_EQ(CycleSlipOptions{}.validate(), "");
  CycleSlipOptions o;
  o.max_gap_s = 0.0;
  EXPECT_NE(o.validate().find("max_gap_s"), std::string::npos);
  o = {};
  o.gf_threshold_m = std::nan("");
  EXPECT_NE(o.validate().find("gf_threshold_m"), std::string::npos);
  o = {};
  o.doppler_min_satellites = 2;
  EXPECT_NE(o.validate().find("doppler_min_satellites"), std::string::npos);
  o = {};
  o.max_missed_epochs = -1;
  EXPECT_NE(o.validate().find("max_missed_epochs"), std::string::npos);
}

TEST(CycleSlip, RealisticNoiseAndIonosphereGiveNoEvents) {
  Sky sky = realistic_sky();
  CycleSlipDetector detector;
  const auto events = run(sky, detector, 600, 1.0, [](int, ReceiverObservables&) {});
  EXPECT_EQ(total(events), 0u);
  // Also at 30 s without Doppler (as RINEX 2 files of geodetic receivers).
  Sky sparse = realistic_sky();
  sparse.with_doppler = false;
  CycleSlipDetector detector30;
  EXPECT_EQ(total(run(sparse, detector30, 120, 30.0, [](int, ReceiverObservables&) {})), 0u);
}

TEST(CycleSlip, NewPairIsNotASlipEvenWithLossOfLock) {
  Sky sky = realistic_sky();
  CycleSlipDetector detector;
  ReceiverObservables e = sky.epoch(0.0);
  for (SignalObservable& s : e.signals) s.lli = core::kLliLossOfLock;
  EXPECT_TRUE(detector.update(e).empty());
}

TEST(CycleSlip, LossOfLockFlagsOnlyThatSignal) {
  Sky sky = realistic_sky();
  CycleSlipDetector detector;
  const SatelliteId g5 = sky.satellites[1].sat;
  const auto events = run(sky, detector, 10, 1.0, [&](int k, ReceiverObservables& e) {
    if (k == 5) signal(e, g5, 1).lli = core::kLliLossOfLock;
    if (k == 7) signal(e, g5, 0).lli = core::kLliBit2;  // BOC / anti-spoofing: ignored
  });
  ASSERT_EQ(events[5].size(), 1u) << describe(events[5]);
  EXPECT_EQ(events[5][0].sat, g5);
  EXPECT_EQ(events[5][0].frequency, 1);
  EXPECT_EQ(events[5][0].cause, SlipCause::LossOfLock);
  EXPECT_EQ(total(events), 1u);
}

TEST(CycleSlip, HalfCycleFlagChangesAreSlipsAndUnresolvedFlagIsReported) {
  Sky sky = realistic_sky();
  CycleSlipDetector detector;
  const SatelliteId sat = sky.satellites[2].sat;
  for (int k = 0; k < 12; ++k) {
    ReceiverObservables e = sky.epoch(k);
    const bool flagged = k >= 4 && k < 8;
    if (flagged) signal(e, sat, 0).lli = core::kLliHalfCycle;
    const auto events = detector.update(e);
    EXPECT_EQ(detector.half_cycle_unresolved(sat, 0), flagged) << "epoch " << k;
    EXPECT_FALSE(detector.half_cycle_unresolved(sat, 1));
    if (k == 4 || k == 8) {
      ASSERT_EQ(events.size(), 1u) << "epoch " << k << ": " << describe(events);
      EXPECT_EQ(events[0].cause, SlipCause::HalfCycleChange);
      EXPECT_EQ(events[0].sat, sat);
    } else {
      EXPECT_TRUE(events.empty()) << "epoch " << k << ": " << describe(events);
    }
  }
}

TEST(CycleSlip, GeometryFreeFlagsBothFrequenciesOfOneCycleOnL2) {
  Sky sky = realistic_sky();
  sky.with_doppler = false;  // the GF test alone
  CycleSlipDetector detector;
  const SatelliteId sat = sky.satellites[3].sat;
  const auto events = run(sky, detector, 20, 1.0, [&](int k, ReceiverObservables& e) {
    if (k >= 10) signal(e, sat, 1).carrier_phase_cyc += 1.0;
  });
  ASSERT_EQ(events[10].size(), 2u) << describe(events[10]);
  for (int f = 0; f < 2; ++f) {
    EXPECT_EQ(events[10][static_cast<std::size_t>(f)].sat, sat);
    EXPECT_EQ(events[10][static_cast<std::size_t>(f)].frequency, f);
    EXPECT_EQ(events[10][static_cast<std::size_t>(f)].cause, SlipCause::GeometryFree);
    EXPECT_NEAR(events[10][static_cast<std::size_t>(f)].value, -kLambda2M, 0.02);
  }
  EXPECT_EQ(total(events), 2u);
}

TEST(CycleSlip, DopplerCatchesSlipsTheGeometryFreeCombinationCannotSee) {
  // 77 L1 and 60 L2 cycles: lambda1 77 - lambda2 60 = 0.0044 m, invisible to L_GF; 14.7 m in the Doppler test.
  Sky sky = realistic_sky();
  CycleSlipDetector detector;
  const SatelliteId sat = sky.satellites[0].sat;
  const auto events = run(sky, detector, 20, 1.0, [&](int k, ReceiverObservables& e) {
    if (k >= 10) {
      signal(e, sat, 0).carrier_phase_cyc += 77.0;
      signal(e, sat, 1).carrier_phase_cyc += 60.0;
    }
  });
  ASSERT_EQ(events[10].size(), 2u) << describe(events[10]);
  EXPECT_EQ(events[10][0].cause, SlipCause::DopplerPhase);
  EXPECT_NEAR(events[10][0].value, 77.0 * kLambda1M, 0.1);
  EXPECT_EQ(events[10][1].cause, SlipCause::DopplerPhase);
  EXPECT_NEAR(events[10][1].value, 60.0 * kLambda2M, 0.1);
  EXPECT_EQ(total(events), 2u);
}

TEST(CycleSlip, DopplerCatchesSingleFrequencySlipsAboveThreshold) {
  Sky sky = realistic_sky();
  sky.num_frequencies = 1;
  CycleSlipDetector detector;
  const SatelliteId sat = sky.satellites[4].sat;
  const int slip_cyc = 4;  // 0.76 m, above the 0.5 m default
  const auto events = run(sky, detector, 20, 1.0, [&](int k, ReceiverObservables& e) {
    if (k >= 10) signal(e, sat, 0).carrier_phase_cyc -= slip_cyc;
  });
  ASSERT_EQ(events[10].size(), 1u) << describe(events[10]);
  EXPECT_EQ(events[10][0].sat, sat);
  EXPECT_EQ(events[10][0].cause, SlipCause::DopplerPhase);
  EXPECT_NEAR(events[10][0].value, -slip_cyc * kLambda1M, 0.05);
  EXPECT_EQ(total(events), 1u);
}

TEST(CycleSlip, MillisecondClockJumpIsNotASlip) {
  for (const double jump_s : {1e-3, -1e-3}) {
    Sky sky = realistic_sky(10);
    sky.num_frequencies = 1;
    sky.clock_jump_s = jump_s;
    sky.clock_jump_time_s = 10.0;
    // The jump moves each satellite's phase by c delta - rho_dot delta: not the same in metres for all satellites
    // (up to +-0.75 m here), so the per-satellite scale of the common mode matters.
    double min_rate = 1e9, max_rate = -1e9;
    for (const auto& s : sky.satellites) {
      min_rate = std::min(min_rate, s.v_mps);
      max_rate = std::max(max_rate, s.v_mps);
    }
    ASSERT_GT((max_rate - min_rate) * 1e-3, CycleSlipOptions{}.doppler_threshold_m);
    CycleSlipDetector detector;
    const auto events = run(sky, detector, 20, 1.0, [](int, ReceiverObservables&) {});
    EXPECT_EQ(total(events), 0u) << "jump " << jump_s << ": " << describe(events[10]);

    // The same jump with one satellite slipping 5 cycles: only that one.
    Sky sky2 = realistic_sky(10);
    sky2.num_frequencies = 1;
    sky2.clock_jump_s = jump_s;
    sky2.clock_jump_time_s = 10.0;
    CycleSlipDetector detector2;
    const SatelliteId sat = sky2.satellites[6].sat;
    const auto events2 = run(sky2, detector2, 20, 1.0, [&](int k, ReceiverObservables& e) {
      if (k >= 10) signal(e, sat, 0).carrier_phase_cyc += 5.0;
    });
    ASSERT_EQ(events2[10].size(), 1u) << describe(events2[10]);
    EXPECT_EQ(events2[10][0].sat, sat);
    EXPECT_NEAR(events2[10][0].value, 5.0 * kLambda1M, 0.05);
    EXPECT_EQ(total(events2), 1u);
  }
}

TEST(CycleSlip, OutageAfterMissedEpochsOrLongGapOrTimeGoingBack) {
  Sky sky = realistic_sky();
  CycleSlipOptions options;
  CycleSlipDetector detector(options);
  const SatelliteId short_gap = sky.satellites[0].sat;  // missing for max_missed_epochs epochs: fine
  const SatelliteId long_gap = sky.satellites[1].sat;   // missing for one more
  auto drop = [](ReceiverObservables& e, SatelliteId sat) {
    std::erase_if(e.signals, [&](const SignalObservable& s) { return s.sat == sat; });
  };
  const int missed = options.max_missed_epochs;
  const auto events = run(sky, detector, 20, 1.0, [&](int k, ReceiverObservables& e) {
    if (k >= 5 && k < 5 + missed) drop(e, short_gap);
    if (k >= 5 && k < 6 + missed) drop(e, long_gap);
  });
  for (int k = 0; k < 20; ++k) {
    const auto& ev = events[static_cast<std::size_t>(k)];
    if (k == 6 + missed) {
      ASSERT_EQ(ev.size(), 2u) << describe(ev);
      for (const SlipEvent& e : ev) {
        EXPECT_EQ(e.sat, long_gap);
        EXPECT_EQ(e.cause, SlipCause::Outage);
        EXPECT_DOUBLE_EQ(e.value, missed + 2.0);
      }
    } else {
      EXPECT_TRUE(ev.empty()) << "epoch " << k << ": " << describe(ev);
    }
  }

  // A time gap longer than max_gap_s, then time going backwards: every pair.
  const std::size_t num_signals = sky.epoch(0).signals.size();
  EXPECT_EQ(detector.update(sky.epoch(19.0 + options.max_gap_s + 1.0)).size(), num_signals);
  const auto back = detector.update(sky.epoch(30.0));
  ASSERT_EQ(back.size(), num_signals);
  EXPECT_LT(back[0].value, 0.0);
  EXPECT_EQ(back[0].cause, SlipCause::Outage);
  // Same time tag twice: no time passed, continuity unknown.
  EXPECT_EQ(detector.update(sky.epoch(30.0)).size(), num_signals);
  EXPECT_TRUE(detector.update(sky.epoch(31.0)).empty());
}

TEST(CycleSlip, ResetForgetsEverything) {
  Sky sky = realistic_sky();
  CycleSlipDetector detector;
  ReceiverObservables e = sky.epoch(0.0);
  signal(e, sky.satellites[0].sat, 0).lli = core::kLliHalfCycle;
  detector.update(e);
  EXPECT_TRUE(detector.half_cycle_unresolved(sky.satellites[0].sat, 0));
  detector.reset();
  EXPECT_FALSE(detector.half_cycle_unresolved(sky.satellites[0].sat, 0));
  ReceiverObservables later = sky.epoch(500.0);  // would be an outage without the reset
  EXPECT_TRUE(detector.update(later).empty());
}

TEST(CycleSlip, BadInputDoesNotCrash) {
  Sky sky = realistic_sky();
  CycleSlipDetector detector;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 10; ++k) {
    ReceiverObservables e = sky.epoch(k);
    // Unsorted, duplicated, non-finite and nonsense values.
    std::reverse(e.signals.begin(), e.signals.end());
    e.signals.push_back(e.signals.front());
    e.signals[1].carrier_phase_cyc = k % 2 == 0 ? nan : inf;
    e.signals[2].wavelength_m = k % 3 == 0 ? 0.0 : -1.0;
    e.signals[3].doppler_hz = k % 2 == 0 ? inf : 1e300;
    e.signals[4].carrier_phase_cyc = k % 2 == 0 ? 1e300 : -1e300;
    e.signals[5].lli = 0xff;
    if (k == 6) e.time.tow_s = nan;
    const auto events = detector.update(e);
    for (std::size_t i = 1; i < events.size(); ++i) {
      EXPECT_LT(std::pair(events[i - 1].sat, events[i - 1].frequency), std::pair(events[i].sat, events[i].frequency));
    }
  }
  EXPECT_TRUE(detector.update(ReceiverObservables{}).empty());
}

}  // namespace
}  // namespace canyon::rtk
