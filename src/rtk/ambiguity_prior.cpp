// A new ambiguity started from the filter's position (see ambiguity_prior.hpp).

#include "canyon/rtk/ambiguity_prior.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace canyon::rtk {
namespace {

const SingleDiff* find_sd(const std::vector<SingleDiff>& sds, const StateKey& key) {
  const auto it = std::find_if(
      sds.begin(), sds.end(), [&](const SingleDiff& sd) { return sd.sat == key.sat && sd.frequency == key.frequency; });
  return it == sds.end() ? nullptr : &*it;
}

bool is_added(const std::vector<StateKey>& added, const StateKey& key) {
  return std::find(added.begin(), added.end(), key) != added.end();
}

/// The group's held ambiguity with phase at this epoch and the smallest variance (not one started this epoch).
const SingleDiff* reference_for(const FilterState& state, const std::vector<SingleDiff>& sds, const SingleDiff& sd,
                                const std::vector<StateKey>& added) {
  const SingleDiff* best = nullptr;
  double best_variance = 0.0;
  for (const SingleDiff& other : sds) {
    if (other.group != sd.group || other.sat == sd.sat || !core::has_value(other.phase_m)) continue;
    const StateKey key{other.sat, other.frequency};
    const int index = state.index(key);
    if (index < 0 || is_added(added, key)) continue;
    const double variance = state.P()(index, index);
    if (best == nullptr || variance < best_variance) {
      best = &other;
      best_variance = variance;
    }
  }
  return best;
}

/// The start of `sd`'s ambiguity against `ref` (cycles): N_s = offset + sum w_i x_i + e.
struct Start {
  std::vector<FilterState::Term> terms;
  double offset = 0.0;
  double residual_variance = 0.0;  ///< var(e) / lambda_s^2
};

Start start_against(const FilterState& state, const SingleDiff& sd, const SingleDiff& ref) {
  const double lambda = sd.wavelength_m;
  const Eigen::Vector3d h = -(sd.los_E - ref.los_E);
  const Eigen::Vector3d p0 = state.position_E_m();
  Start start;
  start.offset = (sd.phase_m - ref.phase_m + h.dot(p0)) / lambda;
  for (int axis = 0; axis < 3; ++axis) start.terms.push_back({FilterState::kPosition + axis, -h[axis] / lambda});
  start.terms.push_back({state.index({ref.sat, ref.frequency}), ref.wavelength_m / lambda});
  const int iono_s = state.index({sd.sat, StateKey::kIonosphere});
  const int iono_r = state.index({ref.sat, StateKey::kIonosphere});
  if (iono_s >= 0 && iono_r >= 0) {
    start.terms.push_back({iono_s, sd.iono_scale / lambda});
    start.terms.push_back({iono_r, -ref.iono_scale / lambda});
  }
  start.residual_variance = (sd.phase_variance_m2 + ref.phase_variance_m2) / (lambda * lambda);
  return start;
}

/// The variance of the start's DD ambiguity, N_s - (lambda_r / lambda_s) N_r (cycles^2): the start without its
/// reference term. A single difference's ambiguity holds the receiver's phase bias, common to the group and never
/// observed (its variance stays that of the code start); only the double difference is determined.
double dd_start_variance(const FilterState& state, const Start& start, int reference_index) {
  double variance = start.residual_variance;
  for (const FilterState::Term& a : start.terms) {
    if (a.index == reference_index) continue;
    for (const FilterState::Term& b : start.terms) {
      if (b.index != reference_index) variance += a.weight * b.weight * state.P()(a.index, b.index);
    }
  }
  return variance;
}

/// The start's DD ambiguity value, N_s - (lambda_r / lambda_s) N_r (cycles).
double dd_start_value(const FilterState& state, const Start& start, int reference_index) {
  double value = start.offset;
  for (const FilterState::Term& t : start.terms) {
    if (t.index != reference_index) value += t.weight * state.x()[t.index];
  }
  return value;
}

/// The start is usable: its DD sigma at most max_sigma_cyc and, between signals of one wavelength (an integer DD
/// ambiguity), its value within two of its sigmas of an integer (a reflected phase or a position that is off lands
/// anywhere in the cycle; a good start there with a probability of 95 %). Its DD value and sigma when usable.
std::optional<AmbiguityStart> usable_start(const FilterState& state, const Start& start, int reference_index,
                                           bool integer, double max_sigma_cyc) {
  const double variance = dd_start_variance(state, start, reference_index);
  if (variance > max_sigma_cyc * max_sigma_cyc) return std::nullopt;
  const double value = dd_start_value(state, start, reference_index);
  if (integer && std::abs(value - std::round(value)) > 2.0 * std::sqrt(variance)) return std::nullopt;
  AmbiguityStart usable;
  usable.dd_cyc = value;
  usable.dd_sigma_cyc = std::sqrt(variance);
  usable.integer = integer;
  return usable;
}

}  // namespace

std::vector<AmbiguityStart> start_ambiguities_from_position(FilterState& state, const std::vector<SingleDiff>& sds,
                                                            const std::vector<StateKey>& added, double max_sigma_cyc) {
  std::vector<AmbiguityStart> started;
  if (!(max_sigma_cyc > 0.0)) return started;
  for (const StateKey& key : added) {
    if (key.ionosphere() || key.code_bias() || !state.has(key)) continue;
    const SingleDiff* sd = find_sd(sds, key);
    if (sd == nullptr || !core::has_value(sd->phase_m)) continue;
    const SingleDiff* ref = reference_for(state, sds, *sd, added);
    if (ref == nullptr) continue;
    const StateKey reference{ref->sat, ref->frequency};
    // The terms do not hold the new state itself: the start is the same with or without it.
    std::optional<AmbiguityStart> usable = usable_start(state, start_against(state, *sd, *ref), state.index(reference),
                                                        sd->wavelength_m == ref->wavelength_m, max_sigma_cyc);
    if (!usable) continue;
    state.remove(key);  // the code start; the indices after it move, so the terms are formed again
    const Start start = start_against(state, *sd, *ref);
    state.add_combination(key, start.terms, start.residual_variance, start.offset);
    usable->key = key;
    usable->reference = reference;
    usable->wavelength_m = sd->wavelength_m;
    started.push_back(*usable);
  }
  return started;
}

}  // namespace canyon::rtk
