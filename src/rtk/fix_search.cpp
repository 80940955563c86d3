// One epoch's search for a fix, step by step (the steps and their order: ambiguity_resolution.hpp). The search is a
// small state machine so that the caller can decide on each candidate between two steps: rtk proposes, the caller
// (the fusion's false-fix guard) decides, and a refusal sends the search on exactly as rtk's own would.

#include <algorithm>
#include <cassert>
#include <cmath>
#include <map>

#include "canyon/rtk/ambiguity_resolution.hpp"

namespace canyon::rtk {
namespace {

constexpr std::size_t kPrunedSubsets = 3;  // step 7 prunes at most this many rejected subsets of step 6

/// DD ambiguities (state index of s, state index of its group's reference) of the fixable SDs that neither
/// `excluded_group` nor `excluded_constellation` leaves out; the reference of each group is its highest fixable
/// satellite.
std::vector<DdPair> dd_ambiguities(const std::vector<SingleDiff>& sds, int excluded_group = -1,
                                   int excluded_constellation = -1) {
  const auto included = [&](const SingleDiff& sd) {
    return sd.fixable && sd.ambiguity >= 0 && sd.group != excluded_group &&
           sd.group / kMaxFrequencies != excluded_constellation;
  };
  std::map<int, int> reference;  // group -> SD index
  for (int i = 0; i < static_cast<int>(sds.size()); ++i) {
    const SingleDiff& sd = sds[static_cast<std::size_t>(i)];
    if (!included(sd)) continue;
    auto it = reference.find(sd.group);
    if (it == reference.end() || sd.elevation_rad > sds[static_cast<std::size_t>(it->second)].elevation_rad) {
      reference[sd.group] = i;
    }
  }
  std::vector<DdPair> dd;
  for (int i = 0; i < static_cast<int>(sds.size()); ++i) {
    const SingleDiff& sd = sds[static_cast<std::size_t>(i)];
    if (!included(sd)) continue;
    const int r = reference.at(sd.group);
    if (r != i) dd.emplace_back(sd.ambiguity, sds[static_cast<std::size_t>(r)].ambiguity);
  }
  return dd;
}

/// More ambiguities, then the higher ratio.
bool better_fix(const FixCandidate& l, const FixCandidate& r) {
  return l.a_fix.size() > r.a_fix.size() || (l.a_fix.size() == r.a_fix.size() && l.ratio > r.ratio);
}

}  // namespace

FixSearch::FixSearch(AmbiguityResolver& resolver, const FilterState& state, const std::vector<SingleDiff>& sds)
    : resolver_(resolver), state_(state), sds_(sds) {
  const RtkOptions& options = resolver_.options_;
  ++resolver_.epoch_;
  std::erase_if(resolver_.carried_decorrelations_,
                [&](const auto& entry) { return entry.second.last_epoch < resolver_.epoch_ - 1; });
  all_ = dd_ambiguities(sds_);
  if (static_cast<int>(all_.size()) < options.min_fix_ambiguities) {
    why_not_ = "too few ambiguities to fix: " + std::to_string(all_.size());
    return;
  }
  if (fixable_directions(all_) < 3) {
    why_not_ = "too few satellites to fix: their double differences leave the position open along a line";
    too_few_satellites_ = true;
    return;
  }
  // A subset keeps at least min_partial_fraction of the ambiguities: the position of a small subset rests on the
  // float ambiguities left out, which are biased when the full set fails.
  min_size_ = static_cast<int>(std::ceil(options.min_partial_fraction * static_cast<double>(all_.size())));
  all_keys_ = resolver_.dd_keys(state_, all_);
  // The same full set failed at the last epoch and a subset was fixed: the subset is tried first, and the full set
  // again only every kFullSetRetryEpochs epochs (or when the set changes). One epoch more of data seldom turns a
  // failing set around, and each integer search of the full set costs as much as the rest of the epoch.
  if (options.partial_ar && all_keys_ == resolver_.failed_full_set_ &&
      resolver_.epochs_since_full_set_ < AmbiguityResolver::kFullSetRetryEpochs) {
    step_ = Step::RetryLastSubset;
    last_subset_tried_ = true;
    ++resolver_.epochs_since_full_set_;
  } else {
    step_ = Step::FullSet;
  }
}

const FixCandidate* FixSearch::next() {
  assert(!pending_ && "decide() on the last candidate before asking for the next");
  while (step_ != Step::Done) {
    std::optional<FixCandidate> candidate = advance();
    if (!candidate) continue;
    if (!passes_own_tests(*candidate)) {
      conclude(std::move(*candidate), false);
      continue;
    }
    compute_position(*candidate);
    pending_ = std::move(candidate);
    return &*pending_;
  }
  return nullptr;
}

void FixSearch::decide(bool accept) {
  assert(pending_ && "decide() after next() returned a candidate");
  FixCandidate candidate = std::move(*pending_);
  pending_.reset();
  conclude(std::move(candidate), accept);
}

std::optional<FixCandidate> FixSearch::advance() {
  if (pruning_) return prune_step();
  switch (step_) {
    case Step::RetryLastSubset:
    case Step::LastSubset: {
      if (step_ == Step::LastSubset && last_subset_tried_) {
        step_ = Step::SuccessRateSubset;
        return std::nullopt;
      }
      auto candidate = last_subset();
      if (!candidate) step_ = step_ == Step::RetryLastSubset ? Step::FullSet : Step::SuccessRateSubset;
      return candidate;
    }
    case Step::FullSet: return full_set();
    case Step::SuccessRateSubset: return success_rate_subset();
    case Step::PruneFullSet:
      if (full_) {
        start_pruning(std::move(*full_), Pruning::FullSet);
        full_.reset();
      } else {
        step_ = Step::Exclusions;
      }
      return std::nullopt;
    case Step::Exclusions: return next_exclusion();
    case Step::PruneRejected:
      if (rejected_index_ < rejected_.size()) {
        start_pruning(std::move(rejected_[rejected_index_++]), Pruning::Rejected);
      } else {
        finish(std::move(best_accepted_));
      }
      return std::nullopt;
    case Step::Done: break;
  }
  return std::nullopt;
}

void FixSearch::conclude(FixCandidate candidate, bool accepted) {
  if (pruning_) {
    if (accepted) {
      pruning_over(std::move(candidate));
    } else {
      pruning_ = std::move(candidate);  // pruning goes on from the refused set
    }
    return;
  }
  const RtkOptions& options = resolver_.options_;
  switch (step_) {
    case Step::RetryLastSubset:
      if (accepted) return finish(std::move(candidate));
      step_ = Step::FullSet;
      return;
    case Step::FullSet:
      if (accepted) return finish(std::move(candidate));
      resolver_.failed_full_set_ = all_keys_;
      why_not_ = rejection_reason(candidate);
      full_ = std::move(candidate);
      step_ = options.partial_ar ? Step::LastSubset : Step::Done;
      return;
    case Step::LastSubset:
      if (accepted) return finish(std::move(candidate));
      step_ = Step::SuccessRateSubset;
      return;
    case Step::SuccessRateSubset:
      step_ = Step::PruneFullSet;
      if (!accepted || !candidate.position_ok) return;
      // A few precise combinations need not pin the position down: the fix counts only if they do (otherwise the
      // float position conditioned on them is still the better float).
      candidate.imprecise = !(std::sqrt(std::max(candidate.P_E_m2.trace(), 0.0)) <= options.max_partial_fix_sigma_m);
      if (!candidate.imprecise) return finish(std::move(candidate));
      imprecise_ = std::move(candidate);
      return;
    case Step::Exclusions:
      if (!accepted) {
        rejected_.push_back(std::move(candidate));
      } else if (!best_accepted_ || better_fix(candidate, *best_accepted_)) {
        best_accepted_ = std::move(candidate);
      }
      return;
    case Step::PruneFullSet:
    case Step::PruneRejected:
    case Step::Done: assert(false && "no candidate comes from this step"); return;
  }
}

void FixSearch::finish(std::optional<FixCandidate> fix) {
  if (fix) ratio_ = fix->ratio;
  fix_ = std::move(fix);
  step_ = Step::Done;
}

std::optional<FixCandidate> FixSearch::full_set() {
  const RtkOptions& options = resolver_.options_;
  resolver_.float_variance_factor_ = 1.0;  // the full set is tested afresh: its own success rate unscaled first
  std::optional<FixCandidate> full = try_fix(all_, options.min_fix_ambiguities);
  if (full) test_float_consistency(*full);
  float_variance_factor_out_ = resolver_.float_variance_factor_;
  resolver_.epochs_since_full_set_ = 0;
  resolver_.failed_full_set_.clear();
  if (full) {
    ratio_ = full->ratio;
  } else {
    resolver_.failed_full_set_ = all_keys_;
    why_not_ = "integer search failed";
    step_ = options.partial_ar ? Step::LastSubset : Step::Done;
  }
  return full;
}

std::optional<FixCandidate> FixSearch::success_rate_subset() {
  // Partial fixing by the success rate: in the decorrelated space z = Z^T a of the full set's search, Q_z = L^T D L,
  // the trailing levels k0..n-1 form a problem of their own (their factors are the trailing blocks of L and D) whose
  // bootstrapped success rate is prod_{k >= k0} p_k: the largest such trailing set whose success rate reaches
  // min_success_rate, if it has at least max(min_size, min_fix_ambiguities) members.
  if (!full_) {
    step_ = Step::Exclusions;
    return std::nullopt;
  }
  const RtkOptions& options = resolver_.options_;
  const FixCandidate& full = *full_;
  const auto n = full.a_float.size();
  step_ = Step::PruneFullSet;  // unless a candidate comes out below
  if (full.Z.rows() != n || full.d.size() != n) return std::nullopt;
  double success = 1.0;
  Eigen::Index k0 = n;
  while (k0 > 0) {
    const double with_next = success * success_rate(full.d.segment(k0 - 1, 1));
    if (with_next < options.min_success_rate) break;
    success = with_next;
    --k0;
  }
  const Eigen::Index m = n - k0;
  if (m == n || m < std::max(min_size_, options.min_fix_ambiguities)) return std::nullopt;
  const Eigen::MatrixXd Z_S = full.Z.rightCols(m);
  FixCandidate sub;
  sub.dd = full.dd;
  sub.combinations = true;
  sub.a_float = Z_S.transpose() * full.a_float;
  sub.Q_a = Z_S.transpose() * full.Q_a * Z_S;
  sub.Q_a = 0.5 * (sub.Q_a + sub.Q_a.transpose()).eval();
  sub.PDt = full.PDt * Z_S;
  auto search = mlambda(sub.a_float, sub.Q_a);
  if (!search) return std::nullopt;
  sub.ratio = ratio_test(*search, options.ratio_threshold).ratio;
  sub.squared_norm = search->squared_norms[0];
  sub.success_rate = success_rate(search->conditional_variances);
  sub.a_fix = search->candidates.col(0);
  step_ = Step::SuccessRateSubset;  // its verdict comes back to this step
  return sub;
}

void FixSearch::start_pruning(FixCandidate fix, Pruning target) {
  pruning_ = std::move(fix);
  pruning_target_ = target;
  pruned_count_ = 0;
}

std::optional<FixCandidate> FixSearch::prune_step() {
  // The paper's pruning: drop the satellite whose DD ambiguities contribute most to the integer least-squares
  // residual of the best candidate (the sum of their squared w-test statistics) and solve again. Satellite by
  // satellite, because what biases an ambiguity (multipath, reflection, a low elevation) biases all frequencies of
  // that satellite.
  const FixCandidate& fix = *pruning_;
  if (pruned_count_ >= resolver_.options_.max_pruned_satellites) {
    pruning_over(std::nullopt);
    return std::nullopt;
  }
  const auto contributions = ils_residual_contributions(fix.a_float, fix.Q_a, fix.a_fix);
  if (!contributions) {
    pruning_over(std::nullopt);
    return std::nullopt;
  }
  std::map<core::SatelliteId, double> per_satellite;
  for (std::size_t k = 0; k < fix.dd.size(); ++k) {
    per_satellite[satellite_of_state(fix.dd[k].first)] += (*contributions)[static_cast<Eigen::Index>(k)];
  }
  const core::SatelliteId worst =
      std::max_element(per_satellite.begin(), per_satellite.end(), [](const auto& l, const auto& r) {
        return l.second < r.second;
      })->first;
  std::vector<DdPair> dd = fix.dd;
  dd.erase(std::remove_if(dd.begin(), dd.end(), [&](const DdPair& p) { return satellite_of_state(p.first) == worst; }),
           dd.end());
  auto next = try_fix(dd, min_size_);
  if (!next) {
    pruning_over(std::nullopt);
    return std::nullopt;
  }
  next->pruned = fix.pruned;
  next->pruned.push_back(worst);
  ++pruned_count_;
  return next;
}

void FixSearch::pruning_over(std::optional<FixCandidate> accepted) {
  pruning_.reset();
  if (pruning_target_ == Pruning::FullSet) {
    if (accepted) return finish(std::move(accepted));
    step_ = Step::Exclusions;
    return;
  }
  if (accepted && (!best_accepted_ || better_fix(*accepted, *best_accepted_))) best_accepted_ = std::move(accepted);
}

std::optional<FixCandidate> FixSearch::next_exclusion() {
  // Leave out each (constellation, frequency) group, then each constellation that has more than one group
  // (dual-frequency signals that two receivers track differently, or a constellation biased as a whole).
  if (exclusion_index_ == 0 && exclusions_.empty()) {
    std::map<int, int> groups_per_constellation;
    std::map<int, bool> groups;
    for (const SingleDiff& sd : sds_) {
      if (!sd.fixable || sd.ambiguity < 0 || groups.count(sd.group) != 0) continue;
      groups[sd.group] = true;
      ++groups_per_constellation[sd.group / kMaxFrequencies];
    }
    for (const auto& entry : groups) exclusions_.push_back(Exclusion{entry.first, -1});
    if (groups_per_constellation.size() > 1) {
      for (const auto& [constellation, count] : groups_per_constellation) {
        if (count > 1) exclusions_.push_back(Exclusion{-1, constellation});
      }
    }
  }
  while (exclusion_index_ < exclusions_.size()) {
    const Exclusion& e = exclusions_[exclusion_index_++];
    if (auto candidate = try_fix(dd_ambiguities(sds_, e.group, e.constellation), min_size_)) return candidate;
  }
  if (best_accepted_) {
    finish(std::move(best_accepted_));
    return std::nullopt;
  }
  // Prune the subsets closest to passing (highest ratio first).
  std::sort(rejected_.begin(), rejected_.end(),
            [](const FixCandidate& l, const FixCandidate& r) { return l.ratio > r.ratio; });
  if (rejected_.size() > kPrunedSubsets) rejected_.resize(kPrunedSubsets);
  rejected_index_ = 0;
  step_ = Step::PruneRejected;
  return std::nullopt;
}

}  // namespace canyon::rtk
