#pragma once
// Cycle-slip detection on the carrier phases of one receiver, epoch by epoch.
//
// The RTK engine keeps one single-differenced ambiguity per (satellite, frequency) and resets it when the phase of
// either receiver may have slipped. One CycleSlipDetector per receiver is fed every epoch of that receiver; update()
// returns the (satellite, frequency) pairs whose phase may have slipped since that pair's previous epoch. Only
// signals with a finite carrier phase and a positive wavelength count as observed; a pair seen for the first time
// (or again after reset()) is not a slip: the engine initialises new ambiguities anyway.
//
// Tests, in this order; a pair gets one event, the first that fires:
//  1. Outage: the pair was not observed in more than `max_missed_epochs` consecutive update() calls, or the time
//     since its previous observation exceeds `max_gap_s`, or time did not advance (dt <= 0, or not finite).
//     value = dt (s). Phase continuity over such a gap cannot be checked reliably.
//  2. LossOfLock: LLI bit 0 set in this epoch. value = LLI bits. (LLI bit 2 means "BOC tracking" in RINEX 3 and
//     "anti-spoofing" in RINEX 2: ignored.)
//  3. HalfCycleChange: LLI bit 1 (half-cycle ambiguity unresolved) differs from the pair's previous epoch: the
//     receiver may have added or removed half a cycle. value = LLI bits.
//  4. GeometryFree: per satellite, the geometry-free phase L_GF = lambda_a phi_a - lambda_b phi_b (m) of each pair
//     of frequencies (a = the lowest frequency observed, b each other one) observed at both this epoch and one same
//     previous epoch. Geometry, clocks and troposphere cancel; what is left is the ionosphere
//     (-(1 - f_a^2 / f_b^2) I_a), the constant ambiguities and noise, so
//         |L_GF(t) - L_GF(t_prev)| > gf_threshold_m + gf_iono_rate_mps * (t - t_prev)
//     flags both frequencies a and b (the combination cannot tell which one slipped). The threshold grows with the
//     gap because the ionosphere keeps changing: 2 mm/s ~ 1.1 TECU/min on GPS L1/L2 (1 TECU -> 0.105 m of L_GF),
//     a fast, low-elevation, active-ionosphere rate. value = the jump (m). Blind to slips with lambda_a n_a ~=
//     lambda_b n_b (e.g. GPS 77 L1 and 60 L2 cycles), which the Doppler test covers when Doppler exists.
//  5. DopplerPhase: per pair with phase and Doppler at both epochs, the residual of the phase change against the
//     Doppler-integrated one (trapezoid rule; RINEX phase grows with range, Doppler is positive for approach):
//         r = lambda (phi(t) - phi(t_prev)) + lambda (D(t) + D(t_prev)) / 2 * dt        (m)
//     A receiver clock jump of delta seconds (e.g. the 1 ms steps of receivers that hold their clock within 1 ms)
//     moves the phase of every satellite by c delta and moves the measurement instant by -delta, i.e. the range by
//     -rho_dot delta; with -lambda D ~= rho_dot + c (receiver clock drift, common to all), the jump shows as
//         r_s = k (c + lambda_s Dbar_s),   k ~= delta, the same for every signal of the receiver.
//     k is estimated as the median of r_s / (c + lambda_s Dbar_s) over the pairs not flagged by tests 1-4 (needs
//     signals of at least `doppler_min_satellites` satellites, else the test is skipped this epoch) and removed:
//         |r_s - k (c + lambda_s Dbar_s)| > doppler_threshold_m + doppler_threshold_rate_mps * dt
//     flags the pair. For small common modes (clock drift mismodelling, mm) this is the plain median in metres.
//     The constant term covers the unmodelled change of acceleration of the receiver along the line of sight
//     within one interval (walking or driving at 1 Hz: decimetres) and phase noise; the rate term the Doppler
//     noise integrated over dt (0.05 m/s ~ 0.26 Hz on L1) and the satellite's range jerk. value = the residual (m).
//     Detects slips of more than ~3 L1 cycles at 1 Hz with the defaults; smaller ones only by the GF test.
//
// Half cycles: half_cycle_unresolved() tells whether the latest phase of a pair carries LLI bit 1; such a phase may
// be off by half a cycle and its ambiguity must not be fixed to an integer.

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "canyon/core/satellite.hpp"
#include "canyon/core/time.hpp"
#include "canyon/rtk/observables.hpp"

namespace canyon::rtk {

enum class SlipCause : std::uint8_t { LossOfLock, HalfCycleChange, GeometryFree, DopplerPhase, Outage };

/// "LossOfLock", "HalfCycleChange", ...
[[nodiscard]] const char* to_string(SlipCause cause);

struct SlipEvent {
  core::SatelliteId sat;
  int frequency = 0;  ///< frequency rank, as in SignalObservable
  SlipCause cause = SlipCause::LossOfLock;
  /// The test statistic: Outage dt (s); LossOfLock and HalfCycleChange the LLI bits; GeometryFree the jump of
  /// L_GF (m); DopplerPhase the residual after the common mode (m).
  double value = 0.0;
};

struct CycleSlipOptions {
  bool use_lli = true;  ///< tests 1-2 of the LLI bits (LossOfLock, HalfCycleChange)
  /// Outage after more than this many consecutive update() calls without the pair, >= 0.
  int max_missed_epochs = 3;
  /// Outage when more than this time passed since the pair's previous observation (s), > 0. Must exceed the
  /// receiver's interval (30 s files are common): 60 s.
  double max_gap_s = 60.0;
  /// Geometry-free jump threshold at dt -> 0 (m), > 0; 0.05 m as RTKLIB's default slip threshold.
  double gf_threshold_m = 0.05;
  /// Growth of the geometry-free threshold with the time between the two epochs (m/s), >= 0.
  double gf_iono_rate_mps = 0.002;
  bool use_doppler = true;  ///< test 5 where Doppler exists
  /// Doppler-phase residual threshold at dt -> 0 (m), > 0.
  double doppler_threshold_m = 0.5;
  /// Growth of the Doppler-phase threshold with dt (m/s), >= 0.
  double doppler_threshold_rate_mps = 0.05;
  /// Fewest satellites with a Doppler-phase residual to estimate the receiver's common mode, >= 3.
  int doppler_min_satellites = 4;

  /// Empty if valid, else the violated rule, e.g. "max_gap_s must be > 0".
  [[nodiscard]] std::string validate() const;
};

/// Cycle-slip detector of one receiver (see the file comment). Not thread-safe; one instance per receiver.
class CycleSlipDetector {
 public:
  /// `options` must be valid (options.validate() empty): an invalid one is a programmer error (asserted).
  explicit CycleSlipDetector(CycleSlipOptions options = {});

  /// Feeds one epoch of one receiver; returns the (satellite, frequency) pairs whose carrier phase has (possibly)
  /// slipped since that pair's previous epoch, sorted by satellite then frequency, one event per pair (the first
  /// cause found). Signals without a finite phase or with a non-positive wavelength are ignored; duplicates of a
  /// pair after the first are ignored.
  std::vector<SlipEvent> update(const ReceiverObservables& epoch);

  /// True while the latest phase of (sat, frequency), in the latest epoch, carries LLI bit 1 (half-cycle ambiguity
  /// unresolved): such an ambiguity is not fixable.
  [[nodiscard]] bool half_cycle_unresolved(core::SatelliteId sat, int frequency) const;

  /// Forgets every pair (the next epoch starts afresh, with no events).
  void reset();

  [[nodiscard]] const CycleSlipOptions& options() const { return options_; }

 public:
  using Key = std::pair<core::SatelliteId, int>;  ///< (satellite, frequency rank)

 private:
  struct PairState {
    core::GpsTime time;
    std::int64_t epoch_index = 0;
    double wavelength_m = 0.0;
    double phase_cyc = 0.0;
    double doppler_hz = 0.0;  ///< NaN if absent
    std::uint8_t lli = 0;
  };
  struct Current;

  [[nodiscard]] std::vector<Current> collect(const ReceiverObservables& epoch) const;
  void test_continuity(std::vector<Current>& signals, core::GpsTime time) const;
  void test_geometry_free(std::vector<Current>& signals, core::GpsTime time) const;
  void test_doppler(std::vector<Current>& signals, core::GpsTime time) const;

  CycleSlipOptions options_;
  std::map<Key, PairState> pairs_;
  std::int64_t epoch_index_ = 0;  ///< number of update() calls so far
};

}  // namespace canyon::rtk
