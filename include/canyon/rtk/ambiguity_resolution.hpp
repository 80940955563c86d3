#pragma once
// Integer ambiguity resolution of the RTK filter: rtk proposes candidate fixes, the caller decides.
//
// The single-differenced ambiguities become double differences per (constellation, frequency) group against the
// group's reference (its highest fixable satellite), a = D x, Q_a = D P D^T, and MLAMBDA (lambda.hpp) searches the
// integers. A candidate passes rtk's own tests when
//   - its ambiguities pin the position (they come from at least 4 satellites: fixable_directions() >= 3; an epoch
//     whose fixable ambiguities give fewer is not searched at all),
//   - it passes the ratio test (ratio_threshold, the paper's 3.0) and its bootstrapped success rate reaches
//     min_success_rate (the ratio test alone accepts wrong single-frequency, single-epoch fixes),
//   - no DD ambiguity also fixed at the last fix (no slip since) gets another integer.
// Float consistency (float_consistency_level > 0): with a right model and right integers,
// (a_float - a)^T Q_a^-1 (a_float - a) is chi-square with n degrees of freedom; when even the best integer vector of
// the full set leaves a squared norm beyond that quantile, no integer vector fits the float, whose covariance is too
// optimistic (reflections, multipath correlated over minutes). The epoch's success rates are then computed with Q_a
// scaled by k = norm / n (the ratio test does not see k).
//
// The candidates, in the order proposed (FixSearch), the first accepted ending the search (except where noted):
//   1. while the same full set failed at the last epochs (fewer than 10 ago), the subset of the last fix;
//   2. the full set;
//   then, with partial_ar, partial fixing:
//   3. the subset of the last fix still tracked (in continuous mode it usually passes again);
//   4. by the success rate (Teunissen's partial ambiguity resolution): in the decorrelated space z = Z^T a of the full
//      set's search, the longest trailing run of levels whose bootstrapped success rate stays >= min_success_rate,
//      fixed as integer combinations; if it leaves the position less precise than max_partial_fix_sigma_m (3D sigma)
//      it is no fix but conditions the float ("imprecise"), and the search goes on;
//   5. the paper's pruning (Algorithm 1, lines 13-14): the satellite whose DD ambiguities contribute most to the
//      integer least-squares residual of the best candidate is dropped, and the rest searched again, at most
//      max_pruned_satellites times;
//   6. without each (constellation, frequency) group, then without each constellation that has several (signals two
//      receivers track differently); every one is proposed, the accepted one with the most ambiguities (then the
//      highest ratio) is the fix;
//   7. if none of 6 was accepted, pruning (as 5) of the 3 rejected subsets of 6 closest to passing (highest ratio);
//      the best accepted of those.
// A subset keeps at least min_partial_fraction of the ambiguities. GLONASS ambiguities are fixed only with glonass_ar.
// The fixed position is the conditional update x_b - Q_ba Q_a^-1 (a_float - a_fix) (position rows only). In
// fix-and-hold the accepted integers are fed back into the filter as pseudo-measurements of sigma hold_sigma_cyc, and
// with partial_hold_sigma_cyc > 0 the imprecise combinations of step 4 too, of that sigma, at epochs of at least
// partial_hold_min_satellites satellites (cascaded fixing: the most precise combinations, wide-lane-like, held while
// the rest converge; in an open square this is what turns a float of 5.5 cm into a fix).

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/satellite.hpp"
#include "canyon/rtk/filter_state.hpp"
#include "canyon/rtk/lambda.hpp"
#include "canyon/rtk/rtk_options.hpp"
#include "canyon/rtk/single_difference.hpp"

namespace canyon::rtk {

/// A DD ambiguity: (state index of satellite s's SD ambiguity, state index of its reference's).
using DdPair = std::pair<int, int>;

/// A candidate fix of a set of DD ambiguities.
struct FixCandidate {
  std::vector<DdPair> dd;  ///< the DD ambiguities
  Eigen::VectorXd a_float;
  Eigen::MatrixXd Q_a;    ///< D P D^T
  Eigen::MatrixXd PDt;    ///< P D^T
  Eigen::VectorXd a_fix;  ///< best integer candidate
  double ratio = 0.0;
  double squared_norm = 0.0;              ///< (a_float - a_fix)^T Q_a^-1 (a_float - a_fix) of the best candidate
  double success_rate = 0.0;              ///< bootstrapped success rate of the float model
  Eigen::MatrixXd Z;                      ///< the search's decorrelation: Z^T Q_a Z = L^T diag(d) L
  Eigen::VectorXd d;                      ///< its conditional variances (cycles^2)
  std::vector<core::SatelliteId> pruned;  ///< satellites pruned by their ILS residual to get this set
  /// The fixed quantities are integer combinations Z_S^T of the DD ambiguities dd (a_float = Z_S^T D x,
  /// PDt = P D^T Z_S) rather than the DD ambiguities themselves: a partial fix by the success rate.
  bool combinations = false;
  bool imprecise = false;  ///< combinations that leave the position less precise than max_partial_fix_sigma_m
  // The fixed position and its covariance (conditional update), when proposed; position_ok false if Q_a is not
  // positive definite.
  bool position_ok = false;
  Eigen::Vector3d p_E_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d P_E_m2 = Eigen::Matrix3d::Zero();
};

class FixSearch;

/// What ambiguity resolution keeps from epoch to epoch: the integers of the last fix (for the next ones to agree
/// with), the full set that failed last, and each searched set's decorrelation (a warm start).
class AmbiguityResolver {
 public:
  explicit AmbiguityResolver(const RtkOptions& options);

  /// The epoch's search over `sds` at `state` (after the measurement update); both must outlive it.
  [[nodiscard]] FixSearch search(const FilterState& state, const std::vector<SingleDiff>& sds);
  /// Takes the accepted `fix`: its DD integers become the last fix, and in fix-and-hold they condition `state`.
  void commit(const FixCandidate& fix, FilterState& state);
  /// In fix-and-hold, conditions `state` on `fix`'s integers with `sigma_cyc` (as commit() does with hold_sigma_cyc)
  /// without making them the last fix: an imprecise partial fix (partial_hold_sigma_cyc).
  void hold(const FixCandidate& fix, FilterState& state, double sigma_cyc) const;

  /// A DD ambiguity by the keys of its two SD ambiguities (satellite s, reference satellite).
  using DdKey = std::pair<StateKey, StateKey>;
  using LastFix = std::map<DdKey, double>;
  /// The integers of the last accepted fix (pairs leave with their states: forget()).
  [[nodiscard]] const LastFix& last_fix() const { return last_fix_; }
  void restore_last_fix(LastFix last_fix) { last_fix_ = std::move(last_fix); }
  /// A keyed state left the filter: the pairs it was part of are forgotten.
  void forget(const StateKey& key);
  void clear() { last_fix_.clear(); }

 private:
  friend class FixSearch;
  [[nodiscard]] DdKey dd_key(const FilterState& state, const DdPair& dd) const;
  [[nodiscard]] std::vector<DdKey> dd_keys(const FilterState& state, const std::vector<DdPair>& dd) const;

  RtkOptions options_;
  double consistency_z_ = 0.0;  // normal quantile of float_consistency_level (0: no test)
  LastFix last_fix_;
  static constexpr int kFullSetRetryEpochs = 10;
  std::vector<DdKey> failed_full_set_;  // the full DD set whose integer search last failed (empty: none)
  int epochs_since_full_set_ = 0;       // epochs since the full set was last searched
  // The decorrelation each DD set's integer search reached, carried to the next search of the same set (a warm
  // start: a few reduction swaps instead of hundreds, the same candidates); a set not searched in an epoch is
  // forgotten at the next.
  struct CarriedDecorrelation {
    MlambdaWarmStart warm;
    std::int64_t last_epoch = 0;  // epoch_ of its last search
  };
  std::map<std::vector<DdKey>, CarriedDecorrelation> carried_decorrelations_;
  std::int64_t epoch_ = 0;              // epochs searched
  double float_variance_factor_ = 1.0;  // of the full set's last search (float consistency)
};

/// One epoch's search (see the top of this file): next() proposes the candidates that pass rtk's own tests, one by
/// one, each with its fixed position; the caller accepts or refuses each with decide() (rtk alone accepts every
/// one: RtkEngine::resolve()). The search goes on as if rtk had refused a candidate the caller refuses.
class FixSearch {
 public:
  /// The next candidate to decide on; nullptr when the search is over.
  [[nodiscard]] const FixCandidate* next();
  /// The verdict on the candidate next() returned.
  void decide(bool accept);

  // After next() returned nullptr:
  /// The fix: the accepted candidate, if any.
  [[nodiscard]] const std::optional<FixCandidate>& fix() const { return fix_; }
  /// Integer combinations that passed but leave the position imprecise (no fix; the float conditioned on them).
  [[nodiscard]] const std::optional<FixCandidate>& imprecise() const { return imprecise_; }
  /// Why there is no fix (empty if fixed).
  [[nodiscard]] const std::string& why_not() const { return why_not_; }
  /// The fixable ambiguities came from fewer than 4 satellites: nothing was searched.
  [[nodiscard]] bool too_few_satellites() const { return too_few_satellites_; }
  /// The ratio of the fix, else of the full set (nullopt if neither was searched).
  [[nodiscard]] const std::optional<double>& ratio() const { return ratio_; }
  /// The float consistency test's variance factor when the full set was searched this epoch.
  [[nodiscard]] const std::optional<double>& float_variance_factor() const { return float_variance_factor_out_; }

 private:
  friend class AmbiguityResolver;
  FixSearch(AmbiguityResolver& resolver, const FilterState& state, const std::vector<SingleDiff>& sds);

  enum class Step {
    RetryLastSubset,
    FullSet,
    LastSubset,
    SuccessRateSubset,
    PruneFullSet,
    Exclusions,
    PruneRejected,
    Done
  };
  enum class Pruning { FullSet, Rejected };
  /// The current step's next candidate, or nullopt when the step moved on without one.
  std::optional<FixCandidate> advance();
  /// The verdict (rtk's own tests and the caller's) on the candidate the current step made.
  void conclude(FixCandidate candidate, bool accepted);
  // Steps (see the top of this file).
  std::optional<FixCandidate> full_set();
  std::optional<FixCandidate> success_rate_subset();
  std::optional<FixCandidate> prune_step();
  std::optional<FixCandidate> next_exclusion();
  void start_pruning(FixCandidate fix, Pruning target);
  void pruning_over(std::optional<FixCandidate> accepted);
  void finish(std::optional<FixCandidate> fix);
  // Candidates and tests.
  [[nodiscard]] std::optional<FixCandidate> try_fix(const std::vector<DdPair>& dd, int min_size) const;
  [[nodiscard]] std::optional<FixCandidate> last_subset() const;
  [[nodiscard]] bool passes_own_tests(const FixCandidate& fix) const;
  [[nodiscard]] std::string rejection_reason(const FixCandidate& fix) const;
  [[nodiscard]] double success_rate(const Eigen::VectorXd& d) const;
  [[nodiscard]] bool agrees_with_last_fix(const FixCandidate& fix) const;
  [[nodiscard]] int fixable_directions(const std::vector<DdPair>& dd) const;
  [[nodiscard]] core::SatelliteId satellite_of_state(int index) const;
  void test_float_consistency(FixCandidate& full);
  void compute_position(FixCandidate& fix) const;

  AmbiguityResolver& resolver_;
  const FilterState& state_;
  const std::vector<SingleDiff>& sds_;
  Step step_ = Step::Done;
  std::vector<DdPair> all_;  // the full set
  std::vector<AmbiguityResolver::DdKey> all_keys_;
  int min_size_ = 0;                // a subset keeps at least min_partial_fraction of the ambiguities
  bool last_subset_tried_ = false;  // step 1 ran (and failed): step 3 would search the same set again
  std::optional<FixCandidate> full_;
  std::optional<FixCandidate> pending_;  // proposed, awaiting decide()
  // Pruning (steps 5 and 7).
  std::optional<FixCandidate> pruning_;
  Pruning pruning_target_ = Pruning::FullSet;
  int pruned_count_ = 0;
  // Exclusions (steps 6 and 7).
  struct Exclusion {
    int group = -1;
    int constellation = -1;
  };
  std::vector<Exclusion> exclusions_;
  std::size_t exclusion_index_ = 0;
  std::vector<FixCandidate> rejected_;
  std::size_t rejected_index_ = 0;
  std::optional<FixCandidate> best_accepted_;
  // Outcome.
  std::optional<FixCandidate> fix_;
  std::optional<FixCandidate> imprecise_;
  std::string why_not_;
  bool too_few_satellites_ = false;
  std::optional<double> ratio_;
  std::optional<double> float_variance_factor_out_;
};

}  // namespace canyon::rtk
