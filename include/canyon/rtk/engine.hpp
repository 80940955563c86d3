#pragma once
// Kinematic RTK: an extended Kalman filter over the rover position and the single-differenced carrier-phase
// ambiguities (and, on long baselines, ionosphere states), DD code and phase measurements, and MLAMBDA integer
// ambiguity resolution. The engine orchestrates its pieces, each with the model in its own header:
//   filter_state.hpp          the state x, P and its one owner: typed blocks, keyed states, snapshot/revert
//   epoch_geometry.hpp        the filter-independent part of an epoch (single point, observables, cycle slips)
//   time_update.hpp           the own motion model, or an external motion (the fusion's VIO increment)
//   single_difference.hpp     rover - base single differences at the prior, and their weights
//   ambiguity_states.hpp      keyed states added, reset on slips, removed after outages; which may be fixed
//   dd_update.hpp             DD rows, innovation gates (an injected policy), the Kalman update, post-fit checks
//   ambiguity_resolution.hpp  candidate fixes (full set, partial: last subset, success rate, pruning, exclusions),
//                             proposed one by one for the caller to decide; hold
// Per epoch, the stages of the staged pipeline (pipeline/epoch_pipeline.hpp): predict(), update(), then resolve()
// (rtk alone) or propose_fixes() ... conclude_fixes() (a caller that decides on each candidate: the fusion), then
// take_epoch(). process() runs them all.
//
// Differential ionosphere: neglected (short baselines), estimated as one single-differenced slant delay per
// satellite (L1-band metres), or Auto: estimated while the baseline (from the prior) is longer than
// iono_auto_baseline_km, off again below 80 % of it. The epoch is solved even without a single-point solution when an
// external motion gives the prior.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/core/solution.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/rtk/ambiguity_prior.hpp"
#include "canyon/rtk/ambiguity_resolution.hpp"
#include "canyon/rtk/ambiguity_states.hpp"
#include "canyon/rtk/dd_update.hpp"
#include "canyon/rtk/epoch_geometry.hpp"
#include "canyon/rtk/filter_state.hpp"
#include "canyon/rtk/rtk_options.hpp"
#include "canyon/rtk/single_difference.hpp"
#include "canyon/rtk/time_update.hpp"

namespace canyon::rtk {

/// A DD ambiguity of an accepted fix: N_sat - N_reference (state keys of the two SD ambiguities) = integer (cycles).
struct FixedAmbiguity {
  StateKey sat;
  StateKey reference;
  double integer = 0.0;
  double wavelength_m = 0.0;  ///< of the satellite's signal (the reference's is the same in a fixable DD group)
};

/// One epoch's result.
struct RtkEpoch {
  core::Solution solution;        ///< status Fixed, Float or Single
  int num_fixed_ambiguities = 0;  ///< DD ambiguities in the accepted fix (0 if not fixed)
  /// The accepted fix's DD integers (empty if not fixed, or when it fixed integer combinations of them).
  std::vector<FixedAmbiguity> fixed_ambiguities;
  int num_dd_measurements = 0;       ///< DD phase measurements used in the update
  int num_dd_code_measurements = 0;  ///< DD code measurements used in the update
  /// new or slipped ambiguities started from the position (ambiguity_prior.hpp)
  std::vector<AmbiguityStart> ambiguities_from_position;
  std::vector<core::SatelliteId> rejected;  ///< satellites whose measurements failed the innovation gate
  std::string note;                         ///< why the epoch is not fixed, if it is not (for --verbose)
  double hdop = 0.0;                        ///< of the single-point geometry, for NMEA GGA
  // The float solution and the post-fit check of the update (also when a fix is output).
  Eigen::Vector3d float_p_E_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d float_P_E_m2 = Eigen::Matrix3d::Zero();
  double max_post_fit_normalised = 0.0;      ///< largest DD post-fit residual (phase or code) over its rejection
                                             ///< threshold (max_post_fit_sigmas or _code_sigmas) after rejections
  std::vector<core::SatelliteId> ar_pruned;  ///< satellites partial fixing pruned by their ILS residual
  bool too_few_to_fix = false;  ///< the fixable ambiguities came from fewer than 4 satellites: no fix was tried
  /// The float consistency test's variance factor k (1: consistent, or not tested this epoch; > 1: the float fits no
  /// integer vector and the success rates were computed with Q_a scaled by k).
  double float_variance_factor = 1.0;
  // Epochs with an external motion: the prior (after the time update with it).
  bool aided = false;
  Eigen::Vector3d prior_p_E_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d prior_P_E_m2 = Eigen::Matrix3d::Zero();
};

/// The RTK filter. Feed rover epochs in time order with the base epoch to use (nullptr if none).
class RtkEngine {
 public:
  RtkEngine(RtkOptions options, const gnss::EphemerisStore& ephemerides, Eigen::Vector3d p_E_base_m);

  ~RtkEngine();
  RtkEngine(RtkEngine&&) noexcept;
  RtkEngine& operator=(RtkEngine&&) = delete;
  RtkEngine(const RtkEngine&) = delete;
  RtkEngine& operator=(const RtkEngine&) = delete;

  /// Processes one rover epoch, accepting every candidate fix that passes rtk's own tests. Error only if not even a
  /// single-point solution exists (and, with an external motion, no prior). predict(), update(gate), resolve(),
  /// take_epoch().
  Result<RtkEpoch> process(const core::ObsEpoch& rover, const core::ObsEpoch* base,
                           const ExternalMotion* motion = nullptr, const InnovationGate* gate = nullptr);

  // ---- the stages (each after the one before, on the same epoch) ----
  /// Prediction: single-point solution, time update (with `motion`, or the engine's own motion model),
  /// observables, cycle slips, single differences, keyed-state bookkeeping. Error as process(); true if the epoch
  /// goes on to update(), false if its result is final (no base, base too old). `motion` is ignored until the
  /// position holds an estimate. `geometry`: the epoch's geometry built ahead by a builder of geometry_options()
  /// that saw every epoch before this one (nullptr: the engine builds it; do not mix the two on one engine); the
  /// engine may change it (it adds satellite states).
  Result<bool> predict(const core::ObsEpoch& rover, const core::ObsEpoch* base, const ExternalMotion* motion = nullptr,
                       EpochGeometry* geometry = nullptr);
  /// Measurement update (dd_update.hpp) with `gate` on an epoch predicted with an external motion, and the float
  /// solution; true if the epoch goes on to ambiguity resolution (AR on, float consistent), false if it is final.
  bool update(const InnovationGate* gate = nullptr);
  /// Ambiguity resolution, every candidate that passes rtk's own tests accepted: propose_fixes(), conclude_fixes().
  void resolve();
  /// Ambiguity resolution with the caller deciding: the epoch's search (FixSearch: next() and decide() until next()
  /// returns nullptr), then conclude_fixes().
  FixSearch& propose_fixes();
  /// The fixed solution of the accepted candidate, if any (and fix-and-hold), into the epoch's result.
  void conclude_fixes();
  /// The epoch's result (after predict() returned true or false).
  RtkEpoch take_epoch();

  // ---- between epochs ----
  /// Undoes the measurement update and the ambiguity resolution of the last epoch, which must have been predicted
  /// with an external motion: the state goes back to that epoch's prior (states added or reset that epoch stay).
  void revert_to_prior();
  /// The options of the engine's own geometry builder, for a builder that runs ahead (predict()).
  [[nodiscard]] EpochGeometryBuilder::Options geometry_options() const;
  [[nodiscard]] const gnss::EphemerisStore& ephemerides() const { return eph_; }
  /// The base position in use (ECEF, m): the one the engine was made with, or the last set_base_position().
  [[nodiscard]] const Eigen::Vector3d& base_position_E_m() const { return p_E_base_m_; }
  /// The base position from the next epoch on (a streamed base's RTCM 1005/1006); between predict()s.
  void set_base_position(const Eigen::Vector3d& p_E_base_m);
  /// GPST of the state: the last epoch whose time update ran; nullopt before the first.
  [[nodiscard]] const std::optional<core::GpsTime>& state_time() const { return last_time_; }
  /// Whether the position state holds an estimate (an external motion needs one).
  [[nodiscard]] bool has_position() const { return initialised_; }
  /// The position state (float, ECEF) and its covariance at state_time().
  [[nodiscard]] Eigen::Vector3d position_E_m() const { return state_.position_E_m(); }
  [[nodiscard]] Eigen::Matrix3d position_covariance_E_m2() const { return state_.position_covariance_E_m2(); }
  /// The external motion's heading error state (rad) and its variance (rad^2), when it holds an estimate.
  struct HeadingError {
    double psi_rad = 0.0;
    double variance_rad2 = 0.0;
  };
  [[nodiscard]] std::optional<HeadingError> heading_error() const;
  /// heading_error(), then the state's value set to zero (its variance and correlations kept): the caller folds the
  /// estimate into the aiding's frame.
  std::optional<HeadingError> take_heading_error();
  /// The external motion's scale error state (relative) and its variance, when it holds an estimate.
  struct ScaleError {
    double s = 0.0;
    double variance = 0.0;
  };
  [[nodiscard]] std::optional<ScaleError> scale_error() const;
  /// Removes every ambiguity and ionosphere state (between epochs): the next epochs start them afresh, as after a
  /// loss of lock on every satellite.
  void reset_ambiguities();
  /// Sets the position state (between epochs), uncorrelated with the other states: a re-anchoring from outside.
  void set_position(const Eigen::Vector3d& p_E_m, const Eigen::Matrix3d& P_E_m2) { state_.set_position(p_E_m, P_E_m2); }
  /// The filter state (read only: tests, diagnostics).
  [[nodiscard]] const FilterState& state() const { return state_; }

 private:
  struct PendingEpoch;  // the epoch between the stages (engine.cpp)
  /// The epoch's solution from its single point, or (with `motion` and no single point) from the prior.
  void start_epoch(const core::ObsEpoch& rover, const Result<gnss::SppSolution>& spp, const ExternalMotion* motion);
  /// Instantaneous mode's reset, the ionosphere model, the time update, single differences, keyed states.
  void predict_states(const core::ObsEpoch& rover, EpochGeometry& geometry, const ExternalMotion* motion);
  /// Keyed states: resets on the epoch's slips, removals after outages, new states, fixability, indices.
  void track_states(std::vector<SingleDiff>& sds, const core::GpsTime& t, const SlipScan& slips);
  /// Whether the ionosphere is estimated at this epoch (Off, Estimate, or Auto by the baseline); turning it off
  /// removes the ionosphere states.
  void choose_ionosphere_model(double baseline_m);
  /// An imprecise partial fix held in the filter (partial_hold_sigma_cyc), where the epoch qualifies.
  void hold_imprecise(const FixCandidate& imprecise);
  /// Removes a keyed state from the filter, its bookkeeping and the last fix.
  void remove_state(const StateKey& key);

  RtkOptions options_;
  const gnss::EphemerisStore& eph_;
  Eigen::Vector3d p_E_base_m_;
  FilterState state_;
  AmbiguityStates states_;
  AmbiguityResolver resolver_;
  EpochGeometryBuilder geometry_builder_;  // predict() without a geometry built ahead (it owns the slip detectors)
  std::unique_ptr<PendingEpoch> pending_;
  std::optional<core::GpsTime> last_time_;
  bool initialised_ = false;
  AidingLive live_;              // the aiding error states hold estimates (aided since their restart)
  bool iono_estimated_ = false;  // ionosphere states in use at this epoch
  // The prior of an epoch with an external motion, kept for revert_to_prior().
  struct Prior {
    FilterState::Snapshot state;
    AmbiguityResolver::LastFix last_fix;
  };
  std::optional<Prior> prior_;
};

}  // namespace canyon::rtk
