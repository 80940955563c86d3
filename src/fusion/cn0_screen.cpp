// NLOS screening by C/N0 (see cn0_screen.hpp).

#include "canyon/fusion/cn0_screen.hpp"

#include <algorithm>
#include <cmath>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"

namespace canyon::fusion {
namespace {

constexpr int kBands = 10;  // '0'..'9'
constexpr double kBinDb = 0.5;

int band_index(char band) {
  return band >= '0' && band <= '9' ? band - '0' : 0;
}

}  // namespace

std::string Cn0ScreenOptions::validate() const {
  if (!(margin_db > 0.0)) return "cn0_margin_db must be > 0";
  if (!(cross_system_db >= 0.0)) return "cn0_cross_system_db must be >= 0";
  if (!(quantile > 0.0 && quantile < 1.0)) return "cn0_quantile must be in (0, 1)";
  if (!(bin_deg >= 1.0 && bin_deg <= 90.0)) return "cn0_bin_deg must be in [1, 90]";
  if (min_samples < 1) return "cn0_min_samples must be >= 1";
  return {};
}

Cn0Screen::Cn0Screen(Cn0ScreenOptions options)
    : options_(options),
      elevation_bins_(std::min(kMaxElevationBins, static_cast<int>(std::ceil(90.0 / options_.bin_deg)))) {
  constexpr int kSystemBands = core::kNumConstellations * kBands;
  histograms_.resize(static_cast<std::size_t>(kSystemBands) * kMaxElevationBins);
  levels_.assign(histograms_.size(), -1.0);
  bin_levels_.assign(histograms_.size(), -1.0);
  own_levels_.assign(histograms_.size(), -1.0);
  band_group_.assign(kSystemBands, -1);
  for (int s = 0; s < core::kNumConstellations; ++s) {
    for (int b = 0; b < kBands; ++b) {
      const auto f_hz = core::carrier_frequency_hz(static_cast<core::Constellation>(s),
                                                   core::SignalCode{static_cast<char>('0' + b), 'C'}, 0);
      const int sb = s * kBands + b;
      if (f_hz) band_group_[static_cast<std::size_t>(sb)] = *f_hz > 1.4e9 ? 0 : 1;
    }
  }
}

int Cn0Screen::key(core::Constellation system, char band, double elevation_rad) const {
  const int bin = std::clamp(static_cast<int>(std::max(elevation_rad, 0.0) * core::kRadToDeg / options_.bin_deg), 0,
                             elevation_bins_ - 1);
  return (static_cast<int>(system) * kBands + band_index(band)) * kMaxElevationBins + bin;
}

void Cn0Screen::refresh_levels() {
  // Each bin's own quantile, then (monotone) the running maximum from the lowest bin up, then (cross_system) the
  // other constellations' levels of the same part of the L band, less cross_system_db.
  // own_levels_ is written and read for the seen (system, band) pairs only.
  for (const int sb : seen_bands_) {
    double running = -1.0;
    for (int bin = 0; bin < elevation_bins_; ++bin) {
      const int index = sb * kMaxElevationBins + bin;
      const auto k = static_cast<std::size_t>(index);
      const double level = bin_levels_[k];
      running = std::max(running, level);
      own_levels_[k] = options_.monotone ? running : level;
    }
  }
  for (const int sb : seen_bands_) {
    const int group = band_group_[static_cast<std::size_t>(sb)];
    for (int bin = 0; bin < elevation_bins_; ++bin) {
      const int index = sb * kMaxElevationBins + bin;
      const auto k = static_cast<std::size_t>(index);
      double level = own_levels_[k];
      if (options_.cross_system && group >= 0) {
        for (const int other : seen_bands_) {
          if (other / kBands == sb / kBands || band_group_[static_cast<std::size_t>(other)] != group) continue;
          const int their_index = other * kMaxElevationBins + bin;
          const double theirs = own_levels_[static_cast<std::size_t>(their_index)];
          if (theirs > 0.0) level = std::max(level, theirs - options_.cross_system_db);
        }
      }
      levels_[k] = level;
    }
  }
}

double Cn0Screen::bin_level_dbhz(const Histogram& h) const {
  if (h.total < options_.min_samples) return -1.0;
  const double target = options_.quantile * h.total;
  int cumulative = 0;
  for (int i = 0; i < kHistogramBins; ++i) {
    cumulative += h.counts[static_cast<std::size_t>(i)];
    if (cumulative >= target) return (i + 0.5) * kBinDb;
  }
  return (kHistogramBins - 0.5) * kBinDb;
}

int Cn0Screen::apply(core::ObsEpoch& epoch, const gnss::EphemerisStore& ephemerides,
                     const Eigen::Vector3d& p_E_approx_m) {
  gnss::EpochSatelliteStates states(ephemerides, epoch.time);
  return apply(epoch, states, p_E_approx_m);
}

int Cn0Screen::apply(core::ObsEpoch& epoch, gnss::EpochSatelliteStates& states, const Eigen::Vector3d& p_E_approx_m) {
  if (!options_.enabled) return 0;
  const core::Geodetic g = core::ecef_to_geodetic(p_E_approx_m);
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(g);
  learnt_.clear();
  int removed = 0;
  for (core::SatelliteObs& sat : epoch.sats) {
    double pseudorange_m = core::kNoValue;
    for (const core::SignalObs& s : sat.signals) {
      if (core::has_value(s.pseudorange_m)) {
        pseudorange_m = s.pseudorange_m;
        break;
      }
    }
    if (!core::has_value(pseudorange_m)) continue;
    const auto state = states.at_reception(sat.sat, pseudorange_m, false);
    if (!state) continue;
    const double elevation = core::elevation_rad(p_E_approx_m, g, R_NE, state->p_E_m);
    const auto before = sat.signals.size();
    std::erase_if(sat.signals, [&](const core::SignalObs& s) {
      if (!core::has_value(s.snr_dbhz)) return false;
      const int k = key(sat.sat.system, s.code.band, elevation);
      learnt_.push_back(Learnt{k, s.snr_dbhz});
      const double level = levels_[static_cast<std::size_t>(k)];
      return level > 0.0 && s.snr_dbhz < level - options_.margin_db;
    });
    removed += static_cast<int>(before - sat.signals.size());
  }
  std::erase_if(epoch.sats, [](const core::SatelliteObs& s) { return s.signals.empty(); });
  touched_.clear();
  for (const auto& [k, snr_dbhz] : learnt_) {
    Histogram& h = histograms_[static_cast<std::size_t>(k)];
    const int bin = std::clamp(static_cast<int>(snr_dbhz / kBinDb), 0, kHistogramBins - 1);
    ++h.counts[static_cast<std::size_t>(bin)];
    ++h.total;
    if (std::find(touched_.begin(), touched_.end(), k) == touched_.end()) touched_.push_back(k);
    const int sb = k / kMaxElevationBins;
    if (std::find(seen_bands_.begin(), seen_bands_.end(), sb) == seen_bands_.end()) seen_bands_.push_back(sb);
  }
  // Each histogram's quantile once, after all of the epoch's signals are counted.
  for (const int k : touched_) {
    bin_levels_[static_cast<std::size_t>(k)] = bin_level_dbhz(histograms_[static_cast<std::size_t>(k)]);
  }
  if (!learnt_.empty()) refresh_levels();
  return removed;
}

}  // namespace canyon::fusion
