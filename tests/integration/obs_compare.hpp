#pragma once
// Comparisons of observation and navigation data for the RTCM 3 / UBX peer tests: two epoch sequences signal by
// signal (carrier phase up to a constant integer per continuous arc, as RTCM MSM transmits it), and two sets of
// broadcast ephemerides record by record.

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "canyon/core/ephemeris.hpp"
#include "canyon/core/observation.hpp"

namespace canyon::test {

struct ObsTolerances {
  double pseudorange_m = 0.001;
  double phase_cyc = 0.002;  ///< of the fractional difference (integer part free per arc)
  double doppler_hz = 0.002;
  double snr_dbhz = 0.04;
  bool phase_integer_per_arc = true;  ///< false: phases must be equal (same source, no RTCM offset)
};

/// What two epoch sequences share and where they differ. `a` is the reference.
struct ObsComparison {
  int epochs_a = 0;
  int epochs_b = 0;
  int epochs_matched = 0;
  std::map<char, int> values;            ///< compared values by kind C L D S
  std::map<char, double> max_diff;       ///< largest |difference| (L: fractional part) by kind
  std::map<char, int> out_of_tolerance;  ///< values beyond the tolerance by kind
  std::map<std::string, int> missing;    ///< "G 1Z C": values of a absent from b, by system, signal and kind
  std::map<std::string, int> extra;      ///< values of b absent from a
  int arc_offset_changes = 0;            ///< integer phase offset changed within an arc (no LLI in b)
  int slips_lost = 0;                    ///< loss of lock in a, not in b
  int slips_added = 0;                   ///< loss of lock in b, not in a, except at a signal's first epoch in b
  int slips_added_first_epoch = 0;       ///< loss of lock in b at a signal's first epoch, not in a
  int half_cycle_mismatches = 0;         ///< LLI bit 1 differs
  std::vector<std::string> examples;     ///< the first differences, as text

  [[nodiscard]] int total_out_of_tolerance() const {
    int n = 0;
    for (const auto& [kind, count] : out_of_tolerance) n += count;
    return n;
  }
};

namespace detail {

inline double observable(const core::SignalObs& s, char kind) {
  switch (kind) {
    case 'C': return s.pseudorange_m;
    case 'L': return s.carrier_phase_cyc;
    case 'D': return s.doppler_hz;
    case 'S': return s.snr_dbhz;
    default: return core::kNoValue;
  }
}

inline std::string key_text(const core::SatelliteId& sat, core::SignalCode code, char kind) {
  return std::string(1, core::system_letter(sat.system)) + " " + code.to_string() + " " + kind;
}

}  // namespace detail

/// Compares `b` against the reference `a`, epoch by epoch (matched by time within 1 us).
/// `lli_of_b` maps b's LLI digit to canyon's bits (for peers that write other values).
template <typename LliMap>
ObsComparison compare_obs(const std::vector<core::ObsEpoch>& a, const std::vector<core::ObsEpoch>& b,
                          const ObsTolerances& tol, LliMap lli_of_b) {
  ObsComparison r;
  r.epochs_a = static_cast<int>(a.size());
  r.epochs_b = static_cast<int>(b.size());
  std::map<std::tuple<int, char, char>, double> offset;  // current integer offset per signal
  std::set<std::tuple<int, char, char>> seen_b;
  std::size_t j = 0;
  auto example = [&](const std::string& text) {
    if (r.examples.size() < 10) r.examples.push_back(text);
  };
  for (const core::ObsEpoch& ea : a) {
    while (j < b.size() && b[j].time - ea.time < -1e-6) {
      for (const auto& sb : b[j].sats) {
        for (const auto& s : sb.signals) seen_b.insert({sb.sat.index(), s.code.band, s.code.attribute});
      }
      ++j;
    }
    if (j >= b.size() || std::abs(b[j].time - ea.time) > 1e-6) continue;
    const core::ObsEpoch& eb = b[j];
    ++r.epochs_matched;
    const std::string when = std::to_string(ea.time.week) + " " + std::to_string(ea.time.tow_s);
    for (const core::SatelliteObs& sa : ea.sats) {
      const core::SatelliteObs* sb = nullptr;
      for (const auto& s : eb.sats) {
        if (s.sat == sa.sat) sb = &s;
      }
      for (const core::SignalObs& x : sa.signals) {
        const core::SignalObs* y = sb != nullptr ? sb->find(x.code) : nullptr;
        const auto key = std::make_tuple(sa.sat.index(), x.code.band, x.code.attribute);
        const bool first_in_b = y != nullptr && seen_b.count(key) == 0;
        for (const char kind : {'C', 'L', 'D', 'S'}) {
          const double va = detail::observable(x, kind);
          if (!core::has_value(va)) continue;
          const double vb = y != nullptr ? detail::observable(*y, kind) : core::kNoValue;
          if (!core::has_value(vb)) {
            ++r.missing[detail::key_text(sa.sat, x.code, kind)];
            continue;
          }
          ++r.values[kind];
          double d = vb - va;
          double limit = kind == 'C' ? tol.pseudorange_m : kind == 'D' ? tol.doppler_hz : tol.snr_dbhz;
          if (kind == 'L') {
            limit = tol.phase_cyc;
            const double integer = tol.phase_integer_per_arc ? std::round(d) : 0.0;
            const bool slip_b = (lli_of_b(y->lli) & core::kLliLossOfLock) != 0;
            auto it = offset.find(key);
            if (it != offset.end() && it->second != integer && !slip_b && !first_in_b) {
              ++r.arc_offset_changes;
              example(when + " " + sa.sat.to_string() + " " + x.code.to_string() + ": phase offset changed in an arc");
            }
            offset[key] = integer;
            d -= integer;
          }
          const double ad = std::abs(d);
          r.max_diff[kind] = std::max(r.max_diff[kind], ad);
          if (ad > limit) {
            ++r.out_of_tolerance[kind];
            example(when + " " + sa.sat.to_string() + " " + kind + x.code.to_string() + ": " + std::to_string(va) +
                    " vs " + std::to_string(vb));
          }
        }
        if (y != nullptr && core::has_value(x.carrier_phase_cyc) && core::has_value(y->carrier_phase_cyc)) {
          const bool slip_a = (x.lli & core::kLliLossOfLock) != 0;
          const std::uint8_t lb = lli_of_b(y->lli);
          const bool slip_b = (lb & core::kLliLossOfLock) != 0;
          if (slip_a && !slip_b) {
            ++r.slips_lost;
            example(when + " " + sa.sat.to_string() + " " + x.code.to_string() + ": loss of lock lost");
          }
          if (!slip_a && slip_b) {
            if (first_in_b) {
              ++r.slips_added_first_epoch;
            } else {
              ++r.slips_added;
              example(when + " " + sa.sat.to_string() + " " + x.code.to_string() + ": loss of lock added");
            }
          }
          if (((x.lli ^ lb) & core::kLliHalfCycle) != 0) ++r.half_cycle_mismatches;
        }
      }
    }
    for (const core::SatelliteObs& sb : eb.sats) {
      const core::SatelliteObs* sa = nullptr;
      for (const auto& s : ea.sats) {
        if (s.sat == sb.sat) sa = &s;
      }
      for (const core::SignalObs& y : sb.signals) {
        seen_b.insert({sb.sat.index(), y.code.band, y.code.attribute});
        const core::SignalObs* x = sa != nullptr ? sa->find(y.code) : nullptr;
        for (const char kind : {'C', 'L', 'D', 'S'}) {
          if (core::has_value(detail::observable(y, kind)) &&
              (x == nullptr || !core::has_value(detail::observable(*x, kind)))) {
            ++r.extra[detail::key_text(sb.sat, y.code, kind)];
          }
        }
      }
    }
    ++j;
  }
  return r;
}

inline ObsComparison compare_obs(const std::vector<core::ObsEpoch>& a, const std::vector<core::ObsEpoch>& b,
                                 const ObsTolerances& tol) {
  return compare_obs(a, b, tol, [](std::uint8_t lli) { return lli; });
}

/// Loss of lock compared over windows, for a `b` that has epochs `a` lacks (a decoder that recovered more of a
/// corrupt log): a loss of lock of `a` at t means a slip in (t_prev, t], t_prev the previous epoch of `a` with that
/// signal's phase; `b` agrees if it flags one in the same window.
struct SlipWindows {
  int windows = 0;
  int agree = 0;
  int lost = 0;                        ///< `a` flags the window, `b` does not
  int added_seen_in_extra_epochs = 0;  ///< `b` flags it where `a` does not, and `b` has epochs in it that `a` lacks
  int added = 0;                       ///< `b` flags it where `a` does not, with the same epochs
};

inline SlipWindows compare_slip_windows(const std::vector<core::ObsEpoch>& a, const std::vector<core::ObsEpoch>& b) {
  using Key = std::tuple<int, char, char>;
  std::map<Key, std::vector<std::pair<double, bool>>> sa;
  std::map<Key, std::vector<std::pair<double, bool>>> sb;
  auto collect = [](const std::vector<core::ObsEpoch>& epochs, auto& out) {
    for (const auto& e : epochs) {
      for (const auto& s : e.sats) {
        for (const auto& g : s.signals) {
          if (!core::has_value(g.carrier_phase_cyc)) continue;
          out[{s.sat.index(), g.code.band, g.code.attribute}].emplace_back(e.time.seconds_since_epoch(),
                                                                           (g.lli & core::kLliLossOfLock) != 0);
        }
      }
    }
  };
  collect(a, sa);
  collect(b, sb);
  SlipWindows r;
  for (const auto& [key, list] : sa) {
    const auto& other = sb[key];
    double previous = -1e300;
    for (const auto& [t, slip] : list) {
      bool slip_b = false;
      int b_epochs = 0;
      for (const auto& [tb, s] : other) {
        if (tb > previous + 1e-6 && tb <= t + 1e-6) {
          slip_b = slip_b || s;
          ++b_epochs;
        }
      }
      ++r.windows;
      if (slip == slip_b) {
        ++r.agree;
      } else if (slip) {
        ++r.lost;
      } else if (b_epochs > 1) {
        ++r.added_seen_in_extra_epochs;
      } else {
        ++r.added;
      }
      previous = t;
    }
  }
  return r;
}

/// Ephemerides of `b` against the reference `a`, matched by satellite, toe and (Kepler) issue of data; Galileo
/// records also by message (I/NAV or F/NAV: data source bit 1).
struct NavComparison {
  int records_a = 0;
  int records_b = 0;
  int matched = 0;
  int mismatched = 0;  ///< matched records with a parameter beyond tolerance
  std::vector<std::string> examples;
};

namespace detail {

inline bool close(double x, double y, double relative, double absolute) {
  return std::abs(x - y) <= relative * std::max(std::abs(x), std::abs(y)) + absolute;
}

}  // namespace detail

/// Relative tolerance 1e-11 (RINEX D19.12 prints 12 digits) on every orbit and clock parameter, toc and health;
/// transmission times, accuracies and flags that RINEX writers fill differently are not compared.
inline NavComparison compare_nav(const core::NavigationData& a, const core::NavigationData& b,
                                 double relative = 1e-11) {
  NavComparison r;
  r.records_a = static_cast<int>(a.kepler.size() + a.glonass.size());
  r.records_b = static_cast<int>(b.kepler.size() + b.glonass.size());
  auto example = [&](const std::string& text) {
    if (r.examples.size() < 10) r.examples.push_back(text);
  };
  for (const core::KeplerEphemeris& x : a.kepler) {
    const core::KeplerEphemeris* y = nullptr;
    for (const auto& e : b.kepler) {
      if (e.sat == x.sat && std::abs(e.toe - x.toe) < 1.0 && e.iode == x.iode &&
          (x.sat.system != core::Constellation::Galileo || ((e.data_source ^ x.data_source) & 0x2) == 0)) {
        y = &e;
      }
    }
    if (y == nullptr) continue;
    ++r.matched;
    using detail::close;
    const double rel = relative;
    const bool ok = close(x.af0_s, y->af0_s, rel, 1e-20) && close(x.af1_sps, y->af1_sps, rel, 1e-24) &&
                    close(x.af2_sps2, y->af2_sps2, rel, 1e-30) && close(x.sqrt_a_sqrtm, y->sqrt_a_sqrtm, rel, 0) &&
                    close(x.e, y->e, rel, 1e-15) && close(x.i0_rad, y->i0_rad, rel, 1e-15) &&
                    close(x.omega0_rad, y->omega0_rad, rel, 1e-15) && close(x.omega_rad, y->omega_rad, rel, 1e-15) &&
                    close(x.m0_rad, y->m0_rad, rel, 1e-15) && close(x.delta_n_radps, y->delta_n_radps, rel, 1e-22) &&
                    close(x.omega_dot_radps, y->omega_dot_radps, rel, 1e-22) &&
                    close(x.idot_radps, y->idot_radps, rel, 1e-22) && close(x.cuc_rad, y->cuc_rad, rel, 1e-15) &&
                    close(x.cus_rad, y->cus_rad, rel, 1e-15) && close(x.cic_rad, y->cic_rad, rel, 1e-15) &&
                    close(x.cis_rad, y->cis_rad, rel, 1e-15) && close(x.crc_m, y->crc_m, rel, 1e-9) &&
                    close(x.crs_m, y->crs_m, rel, 1e-9) && close(x.tgd_s[0], y->tgd_s[0], rel, 1e-20) &&
                    std::abs(x.toc - y->toc) < 1e-3 && x.health == y->health;
    if (!ok) {
      ++r.mismatched;
      example(x.sat.to_string() + " toe " + std::to_string(x.toe.tow_s) + ": parameters differ");
    }
  }
  for (const core::GlonassEphemeris& x : a.glonass) {
    const core::GlonassEphemeris* y = nullptr;
    for (const auto& e : b.glonass) {
      if (e.sat == x.sat && std::abs(e.toe - x.toe) < 1.0) y = &e;
    }
    if (y == nullptr) continue;
    ++r.matched;
    using detail::close;
    // The message frame time is not compared: a decoder may keep any frame of the 30-minute interval (RTKLIB's
    // convbin keeps another one than the first).
    bool ok = x.frequency_channel == y->frequency_channel && close(x.tau_n_s, y->tau_n_s, relative, 1e-20) &&
              close(x.gamma_n, y->gamma_n, relative, 1e-25) && x.health == y->health;
    for (int i = 0; i < 3; ++i) {
      ok = ok && close(x.p_E_m[i], y->p_E_m[i], relative, 1e-6) && close(x.v_E_mps[i], y->v_E_mps[i], relative, 1e-9) &&
           close(x.a_E_mps2[i], y->a_E_mps2[i], relative, 1e-12);
    }
    if (!ok) {
      ++r.mismatched;
      example(x.sat.to_string() + " toe " + std::to_string(x.toe.tow_s) + ": parameters differ");
    }
  }
  return r;
}

}  // namespace canyon::test
