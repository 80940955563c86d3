#pragma once
// The prior of a satellite's single-differenced ionosphere state (filter_state.hpp: I_sd in metres on the satellite's
// first frequency) when it joins the filter.
//
// Independent (iono_residual_sigma_per_10km_m = 0): I_sd ~ N(0, s0^2), s0 = iono_sigma_per_10km_m per 10 km of
// baseline, uncorrelated with every other state.
//
// From the others (iono_residual_sigma_per_10km_m = r > 0): over a baseline of tens of kilometres the SD slant delays
// of all satellites are mostly one differential vertical delay V seen through each one's obliquity (a thin shell at
// kShellHeightKm): I_sd,s = k_s V + e_s, k_s = M(el_s) (lambda_1,s / lambda_L1)^2, M(el) = 1 / sqrt(1 - (R cos el /
// (R + H))^2). A new state is then the others' estimate of V, mapped, plus its own residual:
//   I_sd,new = k_new sum_j w_j I_sd,j / k_j + e_new,  w_j proportional to k_j^2 / P_jj (summing to 1),
//   var(e_new) = (M(el_new) r baseline_10km)^2 (at least iono_sigma_min_m^2),
// added as a linear combination of the held states (FilterState::add_combination), so it stays correlated with them.
// The first state of a filter without any (the start) takes the independent prior; the ones admitted after it are
// tied to it. A satellite re-acquired after a blockage thus starts from the ionosphere the others measured, not from
// s0 (the "initialise its ionosphere from the others'", which its wide lane and narrow lane need to fix at
// 20 km). The estimator's shell (450 km) is a standard single-layer height, not any simulator's.

#include <vector>

#include "canyon/gnss/ephemeris.hpp"
#include "canyon/rtk/filter_state.hpp"
#include "canyon/rtk/single_difference.hpp"

namespace canyon::rtk {

inline constexpr double kShellHeightKm = 450.0;

/// Thin-shell obliquity factor M(el) >= 1 (slant / vertical delay).
[[nodiscard]] double ionosphere_obliquity(double elevation_rad);

struct IonospherePrior {
  double sigma_m = 0.0;           ///< s0: an independent state's prior sigma (m)
  double residual_sigma_m = 0.0;  ///< r baseline_10km, vertical (m); 0: every state independent
  double min_sigma_m = 0.0;       ///< a residual's sigma is at least this (m)
};

/// Adds an ionosphere state for every satellite of `sds` without one (in SD order), with the prior above.
void add_ionosphere_states(FilterState& state, const std::vector<SingleDiff>& sds, const IonospherePrior& prior,
                           const gnss::EphemerisStore& eph);

}  // namespace canyon::rtk
