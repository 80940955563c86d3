#pragma once
// NLOS screening by C/N0 (beyond the paper). A signal received only by reflection (NLOS) arrives weaker than a
// line-of-sight signal from the same elevation: the reflection loses power (typically 10 dB or more off a wall).
// Its code and phase then carry the full excess path, which neither the innovation gates nor the ratio test see
// reliably once the filter has drifted with it. The screen learns the line-of-sight level of the rover's receiver
// from the data, as a high quantile of the C/N0 seen so far per (constellation, band, elevation bin), and removes
// the signals more than margin_db below that level before the update.
//
//   level(system, band, bin) = quantile q of the C/N0 histogram (0.5 dB bins) of the signals seen in that bin so far;
//   a signal is screened out if its bin has at least min_samples signals and C/N0 < level - margin_db.
// With monotone (the default), a bin's level is the largest of its own and those of the bins below it: an antenna's
// gain, hence the line-of-sight C/N0, does not fall with elevation, while in a deep canyon most signals of a middle
// elevation arrive by reflection and the quantile of their own bin learns the NLOS level (urban-severe, 35-40 deg:
// 33.8 dB-Hz learnt against 44.9 dB-Hz of line of sight, every NLOS signal there kept). With cross_system (off by
// default), a bin's level is also at least cross_system_db below the other constellations' level at that elevation in
// the same part of the L band (upper, 1.5-1.6 GHz: L1, G1, E1, B1; lower, 1.16-1.28 GHz: L2, L5, G2, E5, B2): one
// antenna receives them all with the same gain pattern, and their signal powers differ by a few dB (the ICDs' minimum
// received powers: GPS L1 C/A -158.5 dBW, GLONASS G1 -161, Galileo E1 -157). A constellation whose satellites a canyon
// shows only by reflection at some elevation learns no line-of-sight level there on its own. Off by default: it takes
// receivers whose constellations differ by less than that, and in the simulated canyons it removes nearly every NLOS
// signal after the first minute but moves the accuracy both ways (README: urban-severe, 30 seeds).
// Elevations come from the broadcast orbits and the receiver's approximate position. The learning is causal (each
// epoch's signals are added after the epoch is screened), so the batch and real-time runs agree.

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/observation.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/gnss/satellite_states.hpp"

namespace canyon::fusion {

struct Cn0ScreenOptions {
  bool enabled = true;
  double margin_db = 7.0;        ///< screened when this far below the learnt line-of-sight level (dB)
  double quantile = 0.9;         ///< the learnt level: this quantile of the C/N0 in the bin (0..1)
  double bin_deg = 5.0;          ///< elevation bin width (deg)
  int min_samples = 50;          ///< bins with fewer signals screen nothing yet
  bool monotone = true;          ///< a bin's level is at least that of every lower bin (the antenna's gain pattern)
  bool cross_system = false;     ///< a bin's level is at least the other constellations' there minus cross_system_db
  double cross_system_db = 3.0;  ///< (dB)

  [[nodiscard]] std::string validate() const;
};

class Cn0Screen {
 public:
  explicit Cn0Screen(Cn0ScreenOptions options);

  /// Removes the suspected NLOS signals from `epoch` (a satellite left without signals is removed), then learns from
  /// the epoch's signals. Returns the number of signals removed.
  int apply(core::ObsEpoch& epoch, const gnss::EphemerisStore& ephemerides, const Eigen::Vector3d& p_E_approx_m);
  /// The same with the satellite states of the epoch's reception time (shared with other users of the epoch).
  int apply(core::ObsEpoch& epoch, gnss::EpochSatelliteStates& states, const Eigen::Vector3d& p_E_approx_m);

  /// Whether the screen removes anything (Cn0ScreenOptions::enabled).
  [[nodiscard]] bool enabled() const { return options_.enabled; }

 private:
  static constexpr int kHistogramBins = 140;    // 0.5 dB from 0 to 70 dB-Hz
  static constexpr int kMaxElevationBins = 90;  // up to 1-degree bins
  struct Histogram {
    std::array<int, kHistogramBins> counts{};
    int total = 0;
  };
  [[nodiscard]] int key(core::Constellation system, char band, double elevation_rad) const;
  /// The quantile of one histogram, or a negative value if it has too few samples.
  [[nodiscard]] double bin_level_dbhz(const Histogram& h) const;
  /// Recomputes the screening levels (levels_) from the bins' own levels of the (system, band) pairs seen so far.
  void refresh_levels();

  Cn0ScreenOptions options_;
  int elevation_bins_ = 0;
  std::vector<Histogram> histograms_;
  std::vector<int> band_group_;     // per (system, band): 0 upper L band, 1 lower, -1 unknown
  std::vector<int> seen_bands_;     // the (system, band) indices seen so far
  std::vector<double> bin_levels_;  // bin_level_dbhz of each histogram, refreshed when it learns
  std::vector<double> own_levels_;  // refresh_levels()'s scratch: a bin's level from its own (system, band)
  std::vector<double> levels_;      // the screening level of each histogram's bin (negative: none)
  struct Learnt {
    int key;  // the histogram of the signal's (system, band, elevation bin)
    double snr_dbhz;
  };
  std::vector<Learnt> learnt_;  // apply()'s scratch: the epoch's signals to learn from (kept: no allocation per epoch)
  std::vector<int> touched_;    // apply()'s scratch: the histograms those signals went to, each once
};

}  // namespace canyon::fusion
