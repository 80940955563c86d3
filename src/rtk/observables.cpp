// Observable selection for carrier-phase differencing (see observables.hpp).

#include "canyon/rtk/observables.hpp"

#include <algorithm>
#include <array>
#include <cstring>

#include "canyon/gnss/ephemeris.hpp"

namespace canyon::rtk {
namespace {

using core::Constellation;

/// Rank of a signal among the candidates of its (system, frequency): lower is better. Signals with carrier phase
/// come first, then by code priority.
int signal_rank(Constellation system, const core::SignalObs& s) {
  const char* priority = core::code_priority(system, s.code.band);
  const char* found = std::strchr(priority, s.code.attribute);
  const int code_rank = found != nullptr ? static_cast<int>(found - priority) : 50;
  return (core::has_value(s.carrier_phase_cyc) ? 0 : 100) + code_rank;
}

}  // namespace

const SignalObservable* ReceiverObservables::find(core::SatelliteId sat, int frequency) const {
  const auto it = std::lower_bound(signals.begin(), signals.end(), std::pair{sat, frequency},
                                   [](const SignalObservable& s, const std::pair<core::SatelliteId, int>& key) {
                                     return std::pair{s.sat, s.frequency} < key;
                                   });
  if (it == signals.end() || it->sat != sat || it->frequency != frequency) return nullptr;
  return &*it;
}

ReceiverObservables select_observables(const core::ObsEpoch& epoch, const gnss::EphemerisStore& eph,
                                       const ObservableOptions& options) {
  ReceiverObservables out;
  out.time = epoch.time;
  out.signals.reserve(epoch.sats.size() * static_cast<std::size_t>(options.num_frequencies));
  for (const core::SatelliteObs& sat_obs : epoch.sats) {
    const core::SatelliteId sat = sat_obs.sat;
    if (!options.uses(sat.system)) continue;
    if (std::find(options.excluded.begin(), options.excluded.end(), sat) != options.excluded.end()) continue;
    const int channel = sat.system == Constellation::Glonass ? eph.glonass_channel(sat.prn) : core::kNoGlonassChannel;
    std::array<const core::SignalObs*, kMaxFrequencies> best{};
    std::array<int, kMaxFrequencies> best_rank{};
    for (const core::SignalObs& s : sat_obs.signals) {
      const auto frequency = core::frequency_rank(sat.system, s.code.band);
      if (!frequency || *frequency >= options.num_frequencies) continue;
      if (!core::has_value(s.pseudorange_m) && !core::has_value(s.carrier_phase_cyc)) continue;
      const auto f = static_cast<std::size_t>(*frequency);
      const int rank = signal_rank(sat.system, s);
      if (best[f] == nullptr || rank < best_rank[f]) {
        best[f] = &s;
        best_rank[f] = rank;
      }
    }
    for (int f = 0; f < options.num_frequencies; ++f) {
      const core::SignalObs* s = best[static_cast<std::size_t>(f)];
      if (s == nullptr) continue;
      const auto wavelength = core::wavelength_m(sat.system, s->code, channel);
      if (!wavelength) continue;
      SignalObservable o;
      o.sat = sat;
      o.frequency = f;
      o.code = s->code;
      o.wavelength_m = *wavelength;
      o.pseudorange_m = s->pseudorange_m;
      o.carrier_phase_cyc = s->carrier_phase_cyc;
      o.doppler_hz = s->doppler_hz;
      o.snr_dbhz = s->snr_dbhz;
      o.lli = s->lli;
      out.signals.push_back(o);
    }
  }
  std::sort(out.signals.begin(), out.signals.end(), [](const SignalObservable& a, const SignalObservable& b) {
    return std::pair{a.sat, a.frequency} < std::pair{b.sat, b.frequency};
  });
  return out;
}

}  // namespace canyon::rtk
