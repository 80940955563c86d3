// Cycle-slip detection of one receiver (see cycle_slip.hpp for the tests and their maths).

#include "canyon/rtk/cycle_slip.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <optional>
#include <utility>

#include "canyon/core/constants.hpp"
#include "canyon/core/observation.hpp"
#include "canyon/core/statistics.hpp"

namespace canyon::rtk {

/// One usable signal of the epoch being processed, with the state of its pair (nullptr for a new pair).
struct CycleSlipDetector::Current {
  Key key;
  double wavelength_m = 0.0;
  double phase_cyc = 0.0;
  double doppler_hz = core::kNoValue;
  std::uint8_t lli = 0;
  const PairState* previous = nullptr;
  std::optional<SlipEvent> event;
};

namespace {

bool is_finite(double v) {
  return std::isfinite(v);
}

SlipEvent make_event(CycleSlipDetector::Key key, SlipCause cause, double value) {
  return SlipEvent{key.first, key.second, cause, value};
}

}  // namespace

const char* to_string(SlipCause cause) {
  switch (cause) {
    case SlipCause::LossOfLock: return "LossOfLock";
    case SlipCause::HalfCycleChange: return "HalfCycleChange";
    case SlipCause::GeometryFree: return "GeometryFree";
    case SlipCause::DopplerPhase: return "DopplerPhase";
    case SlipCause::Outage: return "Outage";
  }
  return "?";
}

std::string CycleSlipOptions::validate() const {
  if (max_missed_epochs < 0) return "max_missed_epochs must be >= 0";
  if (!(max_gap_s > 0.0 && is_finite(max_gap_s))) return "max_gap_s must be finite and > 0";
  if (!(gf_threshold_m > 0.0 && is_finite(gf_threshold_m))) return "gf_threshold_m must be finite and > 0";
  if (!(gf_iono_rate_mps >= 0.0 && is_finite(gf_iono_rate_mps))) return "gf_iono_rate_mps must be finite and >= 0";
  if (!(doppler_threshold_m > 0.0 && is_finite(doppler_threshold_m))) {
    return "doppler_threshold_m must be finite and > 0";
  }
  if (!(doppler_threshold_rate_mps >= 0.0 && is_finite(doppler_threshold_rate_mps))) {
    return "doppler_threshold_rate_mps must be finite and >= 0";
  }
  if (doppler_min_satellites < 3) return "doppler_min_satellites must be >= 3";
  return {};
}

CycleSlipDetector::CycleSlipDetector(CycleSlipOptions options) : options_(options) {
  assert(options_.validate().empty() && "invalid CycleSlipOptions");
}

void CycleSlipDetector::reset() {
  pairs_.clear();
  epoch_index_ = 0;
}

bool CycleSlipDetector::half_cycle_unresolved(core::SatelliteId sat, int frequency) const {
  const auto it = pairs_.find(Key{sat, frequency});
  if (it == pairs_.end() || it->second.epoch_index != epoch_index_) return false;
  return (it->second.lli & core::kLliHalfCycle) != 0;
}

std::vector<CycleSlipDetector::Current> CycleSlipDetector::collect(const ReceiverObservables& epoch) const {
  std::vector<Current> out;
  out.reserve(epoch.signals.size());
  for (const SignalObservable& s : epoch.signals) {
    if (!is_finite(s.carrier_phase_cyc) || !(s.wavelength_m > 0.0 && is_finite(s.wavelength_m))) continue;
    Current c;
    c.key = Key{s.sat, s.frequency};
    c.wavelength_m = s.wavelength_m;
    c.phase_cyc = s.carrier_phase_cyc;
    c.doppler_hz = is_finite(s.doppler_hz) ? s.doppler_hz : core::kNoValue;
    c.lli = s.lli;
    out.push_back(c);
  }
  // Sorted by pair, first occurrence of a duplicate kept (ReceiverObservables come sorted: nothing to move then).
  const auto by_key = [](const Current& a, const Current& b) { return a.key < b.key; };
  if (!std::is_sorted(out.begin(), out.end(), by_key)) std::stable_sort(out.begin(), out.end(), by_key);
  out.erase(std::unique(out.begin(), out.end(), [](const Current& a, const Current& b) { return a.key == b.key; }),
            out.end());
  for (Current& c : out) {
    const auto it = pairs_.find(c.key);
    if (it != pairs_.end()) c.previous = &it->second;
  }
  return out;
}

void CycleSlipDetector::test_continuity(std::vector<Current>& signals, core::GpsTime time) const {
  for (Current& c : signals) {
    if (c.previous == nullptr) continue;
    const PairState& p = *c.previous;
    const double dt_s = time - p.time;
    const std::int64_t missed = epoch_index_ - p.epoch_index - 1;  // epoch_index_ is the current epoch's
    if (!(dt_s > 0.0) || dt_s > options_.max_gap_s || missed > options_.max_missed_epochs) {
      c.event = make_event(c.key, SlipCause::Outage, dt_s);
      continue;
    }
    if (!options_.use_lli) continue;
    if ((c.lli & core::kLliLossOfLock) != 0) {
      c.event = make_event(c.key, SlipCause::LossOfLock, c.lli);
    } else if (((c.lli ^ p.lli) & core::kLliHalfCycle) != 0) {
      c.event = make_event(c.key, SlipCause::HalfCycleChange, c.lli);
    }
  }
}

void CycleSlipDetector::test_geometry_free(std::vector<Current>& signals, core::GpsTime time) const {
  // Signals are sorted by (satellite, frequency): walk satellite by satellite.
  std::vector<std::size_t> usable;  // per satellite, reused
  for (std::size_t first = 0; first < signals.size();) {
    std::size_t end = first;
    while (end < signals.size() && signals[end].key.first == signals[first].key.first) ++end;
    // Frequencies with a usable history (not new, no outage); the lowest is the reference.
    usable.clear();
    for (std::size_t i = first; i < end; ++i) {
      const Current& c = signals[i];
      if (c.previous != nullptr && !(c.event && c.event->cause == SlipCause::Outage)) usable.push_back(i);
    }
    for (std::size_t k = 1; k < usable.size(); ++k) {
      Current& a = signals[usable[0]];
      Current& b = signals[usable[k]];
      const PairState& pa = *a.previous;
      const PairState& pb = *b.previous;
      if (pa.epoch_index != pb.epoch_index) continue;  // not one same previous epoch
      const double gf_now_m = a.wavelength_m * a.phase_cyc - b.wavelength_m * b.phase_cyc;
      const double gf_prev_m = pa.wavelength_m * pa.phase_cyc - pb.wavelength_m * pb.phase_cyc;
      const double jump_m = gf_now_m - gf_prev_m;
      const double dt_s = time - pa.time;
      const double threshold_m = options_.gf_threshold_m + options_.gf_iono_rate_mps * dt_s;
      if (!(std::abs(jump_m) <= threshold_m)) {  // NaN (overflow) counts as a jump
        if (!a.event) a.event = make_event(a.key, SlipCause::GeometryFree, jump_m);
        if (!b.event) b.event = make_event(b.key, SlipCause::GeometryFree, jump_m);
      }
    }
    first = end;
  }
}

void CycleSlipDetector::test_doppler(std::vector<Current>& signals, core::GpsTime time) const {
  struct Residual {
    Current* signal;
    double residual_m;
    double scale_m_per_s;  // c + lambda Dbar: how a receiver clock jump of 1 s shows in the residual
    double dt_s;
  };
  std::vector<Residual> residuals;
  for (Current& c : signals) {
    if (c.previous == nullptr || c.event || !is_finite(c.doppler_hz) || !is_finite(c.previous->doppler_hz)) continue;
    const PairState& p = *c.previous;
    const double dt_s = time - p.time;
    const double mean_doppler_hz = 0.5 * (c.doppler_hz + p.doppler_hz);
    // Phases in metres with each epoch's own wavelength (GLONASS channels do not change within a pass anyway).
    const double residual_m =
        c.wavelength_m * c.phase_cyc - p.wavelength_m * p.phase_cyc + c.wavelength_m * mean_doppler_hz * dt_s;
    const double scale = core::kSpeedOfLightMps + c.wavelength_m * mean_doppler_hz;
    if (!is_finite(residual_m) || !(scale > 0.0)) continue;
    residuals.push_back(Residual{&c, residual_m, scale, dt_s});
  }
  std::vector<core::SatelliteId> satellites;
  satellites.reserve(residuals.size());
  for (const Residual& r : residuals) satellites.push_back(r.signal->key.first);
  satellites.erase(std::unique(satellites.begin(), satellites.end()), satellites.end());  // sorted already
  if (static_cast<int>(satellites.size()) < options_.doppler_min_satellites) return;

  std::vector<double> clock_jumps_s;
  clock_jumps_s.reserve(residuals.size());
  for (const Residual& r : residuals) clock_jumps_s.push_back(r.residual_m / r.scale_m_per_s);
  const double clock_jump_s = core::median_in_place(clock_jumps_s);
  for (const Residual& r : residuals) {
    const double corrected_m = r.residual_m - clock_jump_s * r.scale_m_per_s;
    const double threshold_m = options_.doppler_threshold_m + options_.doppler_threshold_rate_mps * r.dt_s;
    if (!(std::abs(corrected_m) <= threshold_m)) {
      r.signal->event = make_event(r.signal->key, SlipCause::DopplerPhase, corrected_m);
    }
  }
}

std::vector<SlipEvent> CycleSlipDetector::update(const ReceiverObservables& epoch) {
  ++epoch_index_;
  std::vector<Current> signals = collect(epoch);
  test_continuity(signals, epoch.time);
  test_geometry_free(signals, epoch.time);
  if (options_.use_doppler) test_doppler(signals, epoch.time);

  std::vector<SlipEvent> events;
  for (const Current& c : signals) {
    if (c.event) events.push_back(*c.event);
  }
  for (const Current& c : signals) {
    pairs_[c.key] = PairState{epoch.time, epoch_index_, c.wavelength_m, c.phase_cyc, c.doppler_hz, c.lli};
  }
  return events;
}

}  // namespace canyon::rtk
