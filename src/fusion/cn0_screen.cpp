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
  if (!(quantile > 0.0 && quantile < 1.0)) return "cn0_quantile must be in (0, 1)";
  if (!(bin_deg >= 1.0 && bin_deg <= 90.0)) return "cn0_bin_deg must be in [1, 90]";
  if (min_samples < 1) return "cn0_min_samples must be >= 1";
  return {};
}

Cn0Screen::Cn0Screen(Cn0ScreenOptions options) : options_(options) {
  histograms_.resize(static_cast<std::size_t>(core::kNumConstellations) * kBands * kMaxElevationBins);
  levels_.assign(histograms_.size(), -1.0);
}

int Cn0Screen::key(core::Constellation system, char band, double elevation_rad) const {
  const int bins = std::min(kMaxElevationBins, static_cast<int>(std::ceil(90.0 / options_.bin_deg)));
  const int bin =
      std::clamp(static_cast<int>(std::max(elevation_rad, 0.0) * core::kRadToDeg / options_.bin_deg), 0, bins - 1);
  return (static_cast<int>(system) * kBands + band_index(band)) * kMaxElevationBins + bin;
}

double Cn0Screen::level_dbhz(core::Constellation system, char band, double elevation_rad) const {
  const int k = key(system, band, elevation_rad);
  if (!options_.monotone) return levels_[static_cast<std::size_t>(k)];
  // The bins of one (system, band) are consecutive keys, lowest elevation first.
  const int lowest = k - k % kMaxElevationBins;
  double level = -1.0;
  for (int i = lowest; i <= k; ++i) level = std::max(level, levels_[static_cast<std::size_t>(i)]);
  return level;
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
  struct Seen {
    core::Constellation system;
    char band;
    double elevation_rad;
    double snr_dbhz;
  };
  std::vector<Seen> seen;
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
      seen.push_back(Seen{sat.sat.system, s.code.band, elevation, s.snr_dbhz});
      const double level = level_dbhz(sat.sat.system, s.code.band, elevation);
      return level > 0.0 && s.snr_dbhz < level - options_.margin_db;
    });
    removed += static_cast<int>(before - sat.signals.size());
  }
  std::erase_if(epoch.sats, [](const core::SatelliteObs& s) { return s.signals.empty(); });
  for (const Seen& s : seen) {
    const auto k = static_cast<std::size_t>(key(s.system, s.band, s.elevation_rad));
    Histogram& h = histograms_[k];
    const int bin = std::clamp(static_cast<int>(s.snr_dbhz / kBinDb), 0, kHistogramBins - 1);
    ++h.counts[static_cast<std::size_t>(bin)];
    ++h.total;
  }
  for (const Seen& s : seen) {  // the levels of the bins that learnt (a bin seen twice is computed twice)
    const auto k = static_cast<std::size_t>(key(s.system, s.band, s.elevation_rad));
    levels_[k] = bin_level_dbhz(histograms_[k]);
  }
  return removed;
}

}  // namespace canyon::fusion
