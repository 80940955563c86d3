// The prior of a new ionosphere state (see ionosphere_prior.hpp).

#include "canyon/rtk/ionosphere_prior.hpp"

#include <algorithm>
#include <cmath>

#include "canyon/core/constants.hpp"

namespace canyon::rtk {

namespace {

constexpr double kEarthRadiusKm = 6371.0;
constexpr double kL1Hz = 1575.42e6;

/// k_s: the state's delay (metres on the satellite's first frequency) per metre of vertical L1 delay.
double slant_factor(const SingleDiff& sd, const gnss::EphemerisStore& eph) {
  const double ratio = first_wavelength_m(eph, sd.sat) / (core::kSpeedOfLightMps / kL1Hz);
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
  for (std::size_t i = 0; i < sds.size(); ++i) {
    if (!missing(i)) continue;
    const SingleDiff& sd = sds[i];
    // The held states of this epoch's satellites, each an estimate of V = I_j / k_j with variance P_jj / k_j^2.
    std::vector<FilterState::Term> terms;
    double weight_sum = 0.0;
    for (std::size_t j = 0; j < sds.size(); ++j) {
      if (j > 0 && sds[j - 1].sat == sds[j].sat) continue;
      const int index = state.index({sds[j].sat, StateKey::kIonosphere});
      if (index < 0) continue;
      const double k = slant_factor(sds[j], eph);
      const double weight = k * k / state.P()(index, index);
      terms.push_back({index, weight / k});
      weight_sum += weight;
    }
    const StateKey key{sd.sat, StateKey::kIonosphere};
    if (terms.empty() || !(weight_sum > 0.0) || !std::isfinite(weight_sum)) {
      state.add({{key, 0.0, prior.sigma_m * prior.sigma_m}});
      continue;
    }
    const double k_new = slant_factor(sd, eph);
    for (FilterState::Term& t : terms) t.weight *= k_new / weight_sum;
    const double residual_m =
        std::max(ionosphere_obliquity(sd.elevation_rad) * prior.residual_sigma_m, prior.min_sigma_m);
    state.add_combination(key, terms, residual_m * residual_m);
  }
}

}  // namespace canyon::rtk
