// Integer ambiguity resolution: what the resolver keeps from epoch to epoch, and the candidates a search makes (the
// search's order of steps is in fix_search.cpp; see ambiguity_resolution.hpp).

#include "canyon/rtk/ambiguity_resolution.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Cholesky>

#include "canyon/core/statistics.hpp"

namespace canyon::rtk {

AmbiguityResolver::AmbiguityResolver(const RtkOptions& options)
    : options_(options),
      consistency_z_(
          options.float_consistency_level > 0.0 ? core::normal_upper_quantile(options.float_consistency_level) : 0.0) {}

FixSearch AmbiguityResolver::search(const FilterState& state, const std::vector<SingleDiff>& sds) {
  return FixSearch(*this, state, sds);
}

AmbiguityResolver::DdKey AmbiguityResolver::dd_key(const FilterState& state, const DdPair& dd) const {
  return {state.key_at(dd.first), state.key_at(dd.second)};
}

std::vector<AmbiguityResolver::DdKey> AmbiguityResolver::dd_keys(const FilterState& state,
                                                                 const std::vector<DdPair>& dd) const {
  std::vector<DdKey> keys;
  keys.reserve(dd.size());
  for (const auto& pair : dd) keys.push_back(dd_key(state, pair));
  return keys;
}

void AmbiguityResolver::forget(const StateKey& key) {
  for (auto it = last_fix_.begin(); it != last_fix_.end();) {
    it = (it->first.first == key || it->first.second == key) ? last_fix_.erase(it) : std::next(it);
  }
}

void AmbiguityResolver::commit(const FixCandidate& fix, FilterState& state) {
  // The integers of the DD ambiguities, for the next fixes to agree with (combinations fix no DD ambiguity as such).
  last_fix_.clear();
  if (!fix.combinations) {
    for (std::size_t k = 0; k < fix.dd.size(); ++k) {
      last_fix_[dd_key(state, fix.dd[k])] = fix.a_fix[static_cast<Eigen::Index>(k)];
    }
  }
  hold(fix, state, options_.hold_sigma_cyc);
}

void AmbiguityResolver::hold(const FixCandidate& fix, FilterState& state, double sigma_cyc) const {
  if (options_.ar_mode == ArMode::FixAndHold) {
    // Hold: the fixed DD ambiguities (or combinations) as pseudo-measurements with a small variance, into the float
    // filter.
    const double var = sigma_cyc * sigma_cyc;
    const auto nd = fix.a_fix.size();
    const Eigen::MatrixXd S = fix.Q_a + var * Eigen::MatrixXd::Identity(nd, nd);
    const Eigen::LLT<Eigen::MatrixXd> hold(S);
    const Eigen::VectorXd b = hold.solve(fix.a_float - fix.a_fix);
    const Eigen::MatrixXd B = hold.solve(fix.PDt.transpose());
    state.condition(fix.PDt, b, B);
  }
}

// ---- The candidates of a search ----

std::optional<FixCandidate> FixSearch::try_fix(const std::vector<DdPair>& dd, int min_size) const {
  const RtkOptions& options = resolver_.options_;
  const auto nd = static_cast<Eigen::Index>(dd.size());
  if (nd < std::max(min_size, options.min_fix_ambiguities)) return std::nullopt;
  const Eigen::VectorXd& x = state_.x();
  const Eigen::MatrixXd& P = state_.P();
  FixCandidate fix;
  fix.dd = dd;
  // D has +1 and -1 per row: D x, P D^T and D P D^T from columns of P, without dense products.
  fix.a_float.resize(nd);
  fix.PDt.resize(x.size(), nd);
  for (Eigen::Index k = 0; k < nd; ++k) {
    const auto [s, r] = dd[static_cast<std::size_t>(k)];
    fix.a_float[k] = x[s] - x[r];
    fix.PDt.col(k) = P.col(s) - P.col(r);
  }
  fix.Q_a.resize(nd, nd);
  for (Eigen::Index k = 0; k < nd; ++k) {
    const auto [s, r] = dd[static_cast<std::size_t>(k)];
    fix.Q_a.row(k) = fix.PDt.row(s) - fix.PDt.row(r);
  }
  fix.Q_a = 0.5 * (fix.Q_a + fix.Q_a.transpose()).eval();
  AmbiguityResolver::CarriedDecorrelation& carried = resolver_.carried_decorrelations_[resolver_.dd_keys(state_, dd)];
  carried.last_epoch = resolver_.epoch_;
  MlambdaOptions search_options;
  search_options.with_z = true;  // for the partial fix by the success rate
  auto search = mlambda(fix.a_float, fix.Q_a, search_options, &carried.warm);
  if (!search) return std::nullopt;
  fix.ratio = ratio_test(*search, options.ratio_threshold).ratio;
  fix.squared_norm = search->squared_norms[0];
  fix.success_rate = success_rate(search->conditional_variances);
  fix.a_fix = search->candidates.col(0);
  fix.Z = std::move(search->Z);
  fix.d = std::move(search->conditional_variances);
  return fix;
}

std::optional<FixCandidate> FixSearch::last_subset() const {
  const AmbiguityResolver::LastFix& last_fix = resolver_.last_fix_;
  if (last_fix.empty()) return std::nullopt;
  std::vector<DdPair> dd;
  for (const auto& pair : all_) {
    if (last_fix.count(resolver_.dd_key(state_, pair)) != 0) dd.push_back(pair);
  }
  if (dd.size() == all_.size()) return std::nullopt;  // the full set, tried already
  return try_fix(dd, min_size_);
}

double FixSearch::success_rate(const Eigen::VectorXd& d) const {
  const double factor = resolver_.float_variance_factor_;
  return factor > 1.0 ? bootstrap_success_rate(d * factor) : bootstrap_success_rate(d);
}

void FixSearch::test_float_consistency(FixCandidate& full) {
  if (!(resolver_.consistency_z_ > 0.0)) return;
  const auto n = static_cast<double>(full.a_fix.size());
  if (!(full.squared_norm > core::chi_square_upper_quantile(n, resolver_.consistency_z_))) return;
  resolver_.float_variance_factor_ = full.squared_norm / n;
  full.success_rate = success_rate(full.d);
}

bool FixSearch::agrees_with_last_fix(const FixCandidate& fix) const {
  if (fix.combinations) return true;  // no DD integers to compare
  for (std::size_t k = 0; k < fix.dd.size(); ++k) {
    const auto it = resolver_.last_fix_.find(resolver_.dd_key(state_, fix.dd[k]));
    if (it != resolver_.last_fix_.end() && it->second != fix.a_fix[static_cast<Eigen::Index>(k)]) return false;
  }
  return true;
}

core::SatelliteId FixSearch::satellite_of_state(int index) const {
  return state_.key_at(index).sat;
}

int FixSearch::fixable_directions(const std::vector<DdPair>& dd) const {
  // Each DD pair (s, reference) pins one direction; with V satellites joined into C groups by the pairs, V - C
  // (three satellites: 2). Satellites joined by their pairs: a union-find over few.
  std::vector<core::SatelliteId> sats;
  std::vector<int> group;
  const auto node = [&](const core::SatelliteId& sat) {
    const auto it = std::find(sats.begin(), sats.end(), sat);
    if (it != sats.end()) return static_cast<int>(it - sats.begin());
    sats.push_back(sat);
    group.push_back(static_cast<int>(group.size()));
    return static_cast<int>(group.size()) - 1;
  };
  const auto root = [&](int i) {
    while (group[static_cast<std::size_t>(i)] != i) i = group[static_cast<std::size_t>(i)];
    return i;
  };
  for (const auto& [s, r] : dd) {
    const int a = node(satellite_of_state(s));
    const int b = node(satellite_of_state(r));
    group[static_cast<std::size_t>(root(a))] = root(b);
  }
  int groups = 0;
  for (std::size_t i = 0; i < group.size(); ++i) groups += root(static_cast<int>(i)) == static_cast<int>(i) ? 1 : 0;
  return static_cast<int>(sats.size()) - groups;
}

bool FixSearch::passes_own_tests(const FixCandidate& fix) const {
  // A subset (partial fixing) from fewer than 4 satellites leaves the position open as the whole epoch's would.
  if (!fix.combinations && fixable_directions(fix.dd) < 3) return false;
  if (!agrees_with_last_fix(fix)) return false;
  const RtkOptions& options = resolver_.options_;
  return fix.ratio >= options.ratio_threshold && fix.success_rate >= options.min_success_rate;
}

std::string FixSearch::rejection_reason(const FixCandidate& fix) const {
  const RtkOptions& options = resolver_.options_;
  char figures[96];
  std::snprintf(figures, sizeof figures, " (%d ambiguities, ratio %.1f, success rate %.3f",
                static_cast<int>(fix.a_fix.size()), fix.ratio, fix.success_rate);
  std::string numbers = figures;
  if (resolver_.float_variance_factor_ > 1.0) {
    std::snprintf(figures, sizeof figures,
                  " with the float covariance scaled by %.1f: no integer vector fits the float",
                  resolver_.float_variance_factor_);
    numbers += figures;
  }
  numbers += ")";
  if (fix.ratio < options.ratio_threshold) return std::string("ratio test failed") + numbers;
  if (fix.success_rate < options.min_success_rate) return std::string("success rate too low") + numbers;
  if (!agrees_with_last_fix(fix)) return std::string("contradicts the last fix") + numbers;
  if (!fix.combinations && fixable_directions(fix.dd) < 3) return std::string("fewer than 4 satellites") + numbers;
  return std::string("refused by the aiding (its false-fix guard or position check)") + numbers;
}

void FixSearch::compute_position(FixCandidate& fix) const {
  const Eigen::LLT<Eigen::MatrixXd> llt(fix.Q_a);
  fix.position_ok = llt.info() == Eigen::Success;
  if (!fix.position_ok) return;
  // Only the position rows of P D^T are needed (the whole x_fix, P_fix would cost n^2 nd).
  const Eigen::Matrix<double, 3, Eigen::Dynamic> B = fix.PDt.topRows<3>();  // cov(p, a)
  fix.p_E_m = state_.x().head<3>() - B * llt.solve(fix.a_float - fix.a_fix);
  fix.P_E_m2 = state_.P().topLeftCorner<3, 3>() - B * llt.solve(B.transpose());
}

}  // namespace canyon::rtk
