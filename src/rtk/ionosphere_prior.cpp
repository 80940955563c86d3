// The prior of a new ionosphere state (see ionosphere_prior.hpp).

#include "canyon/rtk/ionosphere_prior.hpp"

#include <algorithm>
#include <cmath>

#include "canyon/core/satellite.hpp"

namespace canyon::rtk {

namespace {

constexpr double kEarthRadiusKm = 6371.0;

/// k_s: the state's delay (metres on the satellite's first frequency) per metre of vertical L1 delay.
double slant_factor(const SingleDiff& sd, const gnss::EphemerisStore& eph) {
  static const double l1_wavelength_m = *core::wavelength_m(core::Constellation::Gps, core::SignalCode{'1', 'C'});
  const double ratio = first_wavelength_m(eph, sd.sat) / l1_wavelength_m;
  return ionosphere_obliquity(sd.elevation_rad) * ratio * ratio;
}

}  // namespace

double ionosphere_obliquity(double elevation_rad) {
  const double r = kEarthRadiusKm / (kEarthRadiusKm + kShellHeightKm) * std::cos(elevation_rad);
  return 1.0 / std::sqrt(1.0 - r * r);
}

void add_ionosphere_states(FilterState& state, const std::vector<SingleDiff>& sds, const IonospherePrior& prior,
                           const gnss::EphemerisStore& eph) {
  const auto missing = [&](std::size_t i) {
    return (i == 0 || sds[i - 1].sat != sds[i].sat) && !state.has({sds[i].sat, StateKey::kIonosphere});
  };
  if (prior.residual_sigma_m <= 0.0) {
    std::vector<FilterState::NewState> added;
    for (std::size_t i = 0; i < sds.size(); ++i) {
      if (missing(i)) added.push_back({{sds[i].sat, StateKey::kIonosphere}, 0.0, prior.sigma_m * prior.sigma_m});
    }
    state.add(added);
    return;
  }
  // k_s of each satellite (at its first SD), computed once: the held states are read in SD order for each new one.
  std::vector<double> k(sds.size(), 0.0);
  for (std::size_t i = 0; i < sds.size(); ++i) {
    if (i == 0 || sds[i - 1].sat != sds[i].sat) k[i] = slant_factor(sds[i], eph);
  }
  for (std::size_t i = 0; i < sds.size(); ++i) {
    if (!missing(i)) continue;
    // The held states of this epoch's satellites, each an estimate of V = I_j / k_j with variance P_jj / k_j^2.
    std::vector<FilterState::Term> terms;
    double weight_sum = 0.0;
    for (std::size_t j = 0; j < sds.size(); ++j) {
      if (j > 0 && sds[j - 1].sat == sds[j].sat) continue;
      const int index = state.index({sds[j].sat, StateKey::kIonosphere});
      if (index < 0) continue;
      const double weight = k[j] * k[j] / state.P()(index, index);
      terms.push_back({index, weight / k[j]});
      weight_sum += weight;
    }
    const StateKey key{sds[i].sat, StateKey::kIonosphere};
    if (terms.empty() || !(weight_sum > 0.0) || !std::isfinite(weight_sum)) {
      state.add({{key, 0.0, prior.sigma_m * prior.sigma_m}});
      continue;
    }
    for (FilterState::Term& t : terms) t.weight *= k[i] / weight_sum;
    const double residual_m =
        std::max(ionosphere_obliquity(sds[i].elevation_rad) * prior.residual_sigma_m, prior.min_sigma_m);
    state.add_combination(key, terms, residual_m * residual_m);
  }
}

}  // namespace canyon::rtk
