#pragma once
// Satellite position, velocity and clock from broadcast ephemerides.
//
// Kepler orbits (GPS, Galileo, BeiDou MEO/IGSO and GEO, QZSS) per the ICDs; GLONASS by 4th-order Runge-Kutta
// integration of the PZ-90 state with J2 and the broadcast lunisolar acceleration. Positions are in the ECEF frame
// at the instant of transmission (the Earth-rotation correction during signal flight depends on the receiver and is
// applied by geometric_range_m()). Clock bias includes the relativistic eccentricity correction and excludes group
// delays (see group_delay_s()). Kepler velocity and clock drift are central differences (+-1 ms) of the analytic
// position and clock; GLONASS velocity is the integrated state and its drift gamma_n.
//
// Selection (select_kepler/select_glonass): usable health (or options.use_unhealthy), |t - toe| within the maximum
// age, nearest toe; on a tie, the latest transmitted record. Galileo additionally: I/NAV records (data source bit 0
// or 9) are preferred to F/NAV whenever one is usable, and only records whose toe has passed (toe < t) are used --
// the rule RTKLIB 2.4.3 applies, matched so that canyon and RTKLIB pick the same record (tests/gnss/
// ephemeris_reference_test.cpp); a Galileo toe marks the start of a record's use, so a future toe is a record not
// broadcast yet.

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/ephemeris.hpp"
#include "canyon/core/satellite.hpp"
#include "canyon/core/time.hpp"

namespace canyon::gnss {

struct SatelliteState {
  core::SatelliteId sat;
  Eigen::Vector3d p_E_m = Eigen::Vector3d::Zero();    ///< ECEF at transmission time
  Eigen::Vector3d v_E_mps = Eigen::Vector3d::Zero();  ///< ECEF velocity (rotating frame)
  double clock_bias_s = 0.0;  ///< satellite clock minus system time, relativity included, no group delay
  double clock_drift_sps = 0.0;
  double variance_m2 = 0.0;  ///< ephemeris/clock error variance from URA/SISA
  int iode = 0;
  int glonass_channel = core::kNoGlonassChannel;
};

struct EphemerisOptions {
  bool use_unhealthy = false;  ///< also use satellites flagged unhealthy
  /// Maximum |t - toe| (s) per system before an ephemeris is too old; GLONASS 30 min, Kepler orbits 4 h (BeiDou 6 h
  /// in RTKLIB; here as for GPS unless the fit interval says more).
  double max_age_kepler_s = 4.0 * 3600.0 + 60.0;
  double max_age_glonass_s = 1800.0 + 60.0;
};

/// Owns the navigation data and answers satellite states. Thread-compatible (const methods are safe to share): the
/// memos that spare repeated work (each satellite's Kepler selection, GLONASS integration steps) are per thread.
class EphemerisStore {
 public:
  explicit EphemerisStore(core::NavigationData nav, EphemerisOptions options = {});

  /// The ephemeris to use for `sat` at GPST `t` (rules in the file comment). nullptr if none.
  [[nodiscard]] const core::KeplerEphemeris* select_kepler(core::SatelliteId sat, core::GpsTime t) const;
  [[nodiscard]] const core::GlonassEphemeris* select_glonass(core::SatelliteId sat, core::GpsTime t) const;

  /// Broadcast state of `sat` at GPST transmission time `t_tx`. nullopt if no usable ephemeris. With
  /// `with_velocity` false, velocity and clock drift of Kepler orbits are left zero (one orbit evaluation less).
  [[nodiscard]] std::optional<SatelliteState> state(core::SatelliteId sat, core::GpsTime t_tx,
                                                    bool with_velocity = true) const;

  /// Satellite clock polynomial af0 + af1 dt + af2 dt^2 (GLONASS -tau_n + gamma_n dt) at GPST `t`, without the
  /// relativistic term: cheap, for the transmission-time iteration. nullopt if no usable ephemeris.
  [[nodiscard]] std::optional<double> clock_polynomial_s(core::SatelliteId sat, core::GpsTime t) const;

  /// State at the transmission time of a signal received at GPST `t_rx` with pseudorange `pseudorange_m`:
  /// t_tx = t_rx - P / c - dt_sat(t_tx), iterated on the clock polynomial. Writes t_tx if asked.
  [[nodiscard]] std::optional<SatelliteState> state_at_reception(core::SatelliteId sat, core::GpsTime t_rx,
                                                                 double pseudorange_m, core::GpsTime* t_tx = nullptr,
                                                                 bool with_velocity = true) const;

  /// Group delay (s) to subtract from a pseudorange on `signal` relative to the system's clock reference:
  /// GPS/QZSS TGD scaled by (f_L1 / f)^2; Galileo BGD(E1,E5a) for F/NAV, BGD(E1,E5b) for I/NAV; BeiDou TGD1/TGD2 on
  /// B1I/B2I (0 on B3I, the clock reference). 0 when unknown.
  [[nodiscard]] double group_delay_s(core::SatelliteId sat, core::SignalCode signal, core::GpsTime t) const;

  /// FDMA channel of a GLONASS slot (kNoGlonassChannel if no ephemeris carries it).
  [[nodiscard]] int glonass_channel(int slot) const;

  [[nodiscard]] const core::NavigationData& nav() const { return nav_; }

  /// Adds ephemerides that arrived while running (a receiver's or a base's stream): each record whose satellite,
  /// toe and IODE (GLONASS: satellite and toe) the store has not got yet, and the ionosphere parameters the store
  /// lacks. A record already held (from the navigation files, say) is kept, not replaced, so a stream repeating the
  /// files' ephemerides changes no selection. The number of records added. Not thread-safe: no other thread may read
  /// the store meanwhile (pointers from select_*() stay valid only until the next add()).
  int add(const core::NavigationData& fresh);
  /// Changes whenever add() adds a record (and only then): a cache of states computed from this store is still valid
  /// while it is unchanged.
  [[nodiscard]] std::uint64_t selection_stamp() const { return selection_stamp_; }

 private:
  void index_kepler(int i);
  void index_glonass(int i);
  /// The scan behind select_kepler(): index into nav_.kepler of the record to use, -1 if none.
  [[nodiscard]] int scan_kepler(core::SatelliteId sat, core::GpsTime t) const;
  /// Open interval (lo, hi) of offsets d (s) such that scan_kepler(sat, t + d) picks `index` too (see the .cpp).
  [[nodiscard]] std::pair<double, double> kepler_selection_interval(core::SatelliteId sat, core::GpsTime t,
                                                                    int index) const;

  /// What selection reads of a usable (healthy, or use_unhealthy) Kepler record, kept contiguous per satellite so
  /// that a selection, done three times per satellite state, walks a short array instead of the records.
  struct KeplerCandidate {
    core::GpsTime toe;
    core::GpsTime transmission_time;
    double max_age_s = 0.0;  // max(options.max_age_kepler_s, half the fit interval)
    int index = 0;           // into nav_.kepler
    bool galileo_inav = false;
  };

  core::NavigationData nav_;
  EphemerisOptions options_;
  // Per satellite (by SatelliteId::index()), in file order: Kepler candidates, GLONASS record indices into nav_.
  std::vector<std::vector<KeplerCandidate>> kepler_by_sat_;
  std::vector<std::vector<int>> glonass_by_sat_;
  // Identifies the candidate lists for the selection memo (select_kepler): a process-wide counter, renewed whenever
  // add() changes them; a copy shares it with its original, as it has the same lists.
  std::uint64_t selection_stamp_ = 0;
};

/// Geometric range (m) from a receiver at p_E_rcv to a satellite at p_E_sat (ECEF at transmission time), with the
/// Earth-rotation (Sagnac) correction for the signal's flight: the first-order term omega_e (x_s y_r - y_s x_r) / c of
/// rotating the satellite by omega_e * range / c about Z (remainder < 1 mm). Writes the unit line of sight rcv -> sat
/// if asked.
[[nodiscard]] double geometric_range_m(const Eigen::Vector3d& p_E_sat, const Eigen::Vector3d& p_E_rcv,
                                       Eigen::Vector3d* los_E = nullptr);

}  // namespace canyon::gnss
