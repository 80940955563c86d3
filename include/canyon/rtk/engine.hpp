#pragma once
// Kinematic RTK: an extended Kalman filter over the rover position and single-differenced carrier-phase
// ambiguities, double-differenced code and phase measurements, and MLAMBDA integer ambiguity resolution.
//
// State x = [p_E_u (3) | v_E_u, a_E_u (6, with dynamics) | N_sd (one per (satellite, frequency), cycles)
//            | I_sd (one per satellite, m, when the ionosphere is estimated)], where N_sd = N_rover - N_base.
//            Ambiguities are keyed by (satellite, frequency rank): added when both receivers track the
// pair, reset on a cycle slip or after an outage, removed when lost.
//
// Measurements, per group g = (constellation, frequency) with reference satellite r (highest elevation) and
// every other satellite s of the group, in metres:
//   DD phase: (lambda_s Phi_sd,s - lambda_r Phi_sd,r) = DD rho(p_E_u) + lambda_s N_sd,s - lambda_r N_sd,r + e
//   DD code:  (P_sd,s - P_sd,r)                       = DD rho(p_E_u) + e
// with SD = rover - base, rho the geometric range with the Sagnac term, minus the satellite clock, plus the
// Saastamoinen troposphere at each receiver (computed per receiver at its own transmission time, so that receivers
// whose time tags differ by milliseconds difference correctly). Receiver clocks cancel in the double differences.
// The differential ionosphere is neglected (short baselines) or, with IonosphereModel::Estimate, enters as
// -mu_s I_sd,s + mu_r I_sd,r on phase and with the opposite sign on code, mu = (f_1 / f)^2. Zero-difference variance
// per receiver, at that receiver's elevation el and C/N0:
//   sigma_phase^2 = a^2 + b^2 / sin^2(el)                      (elevation model, the default, as RTKLIB's)
//   sigma_phase^2 = a^2 + b^2 10^((snr_reference - C/N0) / 10)  (snr_weighting, SIGMA-epsilon: the C/N0 already
//                                                                holds the elevation through the antenna gain, and
//                                                                reflected signals arrive weaker)
//   sigma_code = code_phase_ratio * sigma_phase.
// The post-fit outlier tests below use the elevation model either way, so that weighting down a weak signal does not
// hide it from them.
// The DD covariance follows from the SD variances (correlated through the reference satellite).
//
// Outliers: DD innovations beyond max_phase_innovation_m / max_code_innovation_m are not used; after the update,
// the DD phase or code whose post-fit residual exceeds its threshold (max_post_fit_sigmas for phase,
// max_post_fit_code_sigmas for code, in measurement sigmas) by the largest factor is dropped for the epoch and the
// update redone from the prior (at most max_post_fit_rejections times). A code outlier (an NLOS signal, a code of
// another tracking mode) pulls the float position and with it every ambiguity; rejecting it keeps the float fixable.
// Float validation: when residuals are still beyond their thresholds after the rejections allowed, the epoch keeps
// its float solution and no fix is attempted.
//
// Cycle slips: each receiver's phases go through a CycleSlipDetector (loss of lock, half-cycle changes,
// geometry-free jumps, Doppler against phase, outages), owned by the geometry builder (rtk/epoch_geometry.hpp), which
// may run on another thread; a slip at either receiver re-initialises the SD ambiguity, and an unresolved half cycle
// at either receiver keeps it from being fixed.
//
// Time update: without dynamics (RTKLIB's "dynamics off") the position is re-initialised each epoch from the
// single-point solution with a large variance; with dynamics a constant-acceleration model with white jerk.
// Ambiguities carry over with a small random walk.
//
// External aiding (RtkAiding, per epoch; the VIO fusion of fusion/fusion_engine.hpp): the position's time update
// becomes p += delta_p_E_m, P_pp += Q_E_m2 with its correlations to the ambiguities kept (an EKF prediction with the
// external motion as the model). With RtkOptions::aiding_heading_state, one more state psi (rad, after the kinematic
// block) is the error of the aiding frame's heading: the increment is rotated by psi about the local vertical,
// p += delta_p_E_m + J psi with J = dp_d_heading_E_m (= up x delta_p), so P' = F P F^T with F = I + J e_psi^T; psi
// is a random walk, restarted (value 0, variance heading_variance_rad2, uncorrelated) when the aiding asks for it and
// after any epoch that was not aided. The DD measurements do not see psi: it is learnt through its correlation with
// the position that the increments build up. The epoch is solved even when the single-point solution fails; DD
// innovations are also gated by the aiding's thresholds; a fix is accepted only if the aiding's accept_fix agrees; and
// the prior is kept so that revert_to_prior() can undo the epoch's measurement update and ambiguity resolution.
//
// Ambiguity resolution: SD -> DD per group against the group's reference, MLAMBDA; none is tried when the fixable
// ambiguities come from fewer than 4 satellites (fixable_directions() < 3: the integers would leave the position open
// along a line, held there by the prior alone, which makes no fixed solution); a fix is accepted when it passes
// the ratio test, the bootstrapped success rate of the float covariance reaches min_success_rate (the ratio test
// alone accepts wrong single-frequency, single-epoch fixes), and no DD ambiguity also fixed at the last fix (no slip
// since) gets another integer. The fixed position from the conditional update x_b - Q_ba Q_a^-1 (a_float - a_fix).
// Float consistency (float_consistency_level): with a right model and right integers a, (a_float - a)^T Q_a^-1
// (a_float - a) is chi-square with n degrees of freedom; when even the best integer vector of the full set leaves a
// squared norm beyond the chi-square quantile of that level, no integer vector fits the float, whose covariance is too
// optimistic (reflections and multipath, errors correlated over minutes that the filter takes as white noise). The
// epoch's success rates (of the full set, its subsets and the pruned sets) are then computed with Q_a scaled by the
// variance factor k = norm / n, its a-posteriori estimate: a float that claims centimetres while it is decimetres off
// fixes no subset either. The ratio test does not see k (both norms scale alike). Off by default: on real receivers'
// data under open sky the float often fails the test (a low-cost receiver's code is noisier than the model) while
// its fixes agree with RTKLIB's, and the test would cost them (u-blox M8P, single frequency: 44 -> 16 fixed epochs);
// config/fusion.yaml and config/rtk-urban.yaml turn it on (0.001), where reflections make the float lie.
// A signal whose DD phase an innovation gate rejected is not fixed that epoch (as one the post-fit test rejected):
// its ambiguity is the prior's, not this epoch's.
// Modes: continuous, instantaneous (ambiguities re-initialised every epoch), fix-and-hold (the fixed DD ambiguities
// fed back as pseudo-measurements with a small variance). When the whole set is not accepted, partial fixing
// (partial_ar): the paper's pruning, dropping the satellite whose ambiguities contribute most to the integer
// least-squares residual, one at a time; then leaving out each (constellation, frequency) group and each
// constellation; a subset keeps at least min_partial_fraction of the ambiguities. Before pruning, partial fixing by
// the success rate: the most precise integer combinations of the full set (in its decorrelated space) whose
// bootstrapped success rate reaches min_success_rate, when they pass the ratio test: while a float solution
// converges, part of it is already determined. GLONASS ambiguities are fixed only when glonass_ar is on.

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/core/solution.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/gnss/satellite_states.hpp"
#include "canyon/gnss/spp.hpp"
#include "canyon/rtk/cycle_slip.hpp"
#include "canyon/rtk/epoch_geometry.hpp"
#include "canyon/rtk/lambda.hpp"
#include "canyon/rtk/observables.hpp"

namespace canyon::rtk {

struct SingleDiff;  // one (satellite, frequency) rover-base single difference (engine.cpp)

enum class ArMode { Off, Continuous, Instantaneous, FixAndHold };

/// Differential ionosphere: neglected (short baselines), estimated as one single-differenced slant delay per
/// satellite (L1-band metres, scaled by (f_1 / f)^2 on other frequencies; it delays code and advances phase), or
/// Auto: estimated while the baseline is longer than iono_auto_baseline_km (off again below 80 % of it).
enum class IonosphereModel { Off, Estimate, Auto };

struct RtkOptions {
  ObservableOptions observables;  ///< systems, number of frequencies (1..3), excluded satellites
  ArMode ar_mode = ArMode::Continuous;
  double elevation_mask_rad = 15.0 * 0.017453292519943295;     ///< satellites below are not used
  double ar_elevation_mask_rad = 15.0 * 0.017453292519943295;  ///< ambiguities below are not fixed
  bool dynamics = false;                      ///< constant-acceleration model; false: position from SPP each epoch
  double accel_sigma_h_mps2 = 3.0;            ///< horizontal acceleration noise (m/s^2 per sqrt(s)) with dynamics
  double accel_sigma_v_mps2 = 1.0;            ///< vertical acceleration noise with dynamics
  double phase_sigma_m = 0.003;               ///< a: zenith-independent phase noise (m)
  double phase_sigma_el_m = 0.003;            ///< b: elevation-dependent phase noise (m), divided by sin(el)
  double code_phase_ratio = 100.0;            ///< code sigma / phase sigma
  bool snr_weighting = false;                 ///< b^2 10^((snr_reference - C/N0) / 10) instead of b^2 / sin^2(el)
  double snr_reference_dbhz = 45.0;           ///< C/N0 at which the SNR model's phase sigma is b (dB-Hz)
  double initial_ambiguity_sigma_cyc = 30.0;  ///< sigma of a new ambiguity (cycles)
  double ambiguity_noise_cyc = 1e-4;          ///< ambiguity random walk (cycles per sqrt(s))
  double initial_position_sigma_m = 30.0;     ///< sigma of the SPP position used as prior (m)
  double ratio_threshold = 3.0;               ///< ratio test threshold (the paper's 3.0)
  int min_fix_ambiguities = 4;                ///< fewer DD ambiguities are not fixed
  bool partial_ar = true;                     ///< when the full set fails, fix a subset (pruning, groups)
  int max_pruned_satellites = 6;              ///< partial fixing drops at most this many satellites one by one
  double min_success_rate = 0.99;             ///< bootstrapped success rate a fix needs besides the ratio test
  double float_consistency_level = 0.0;       ///< significance of the float consistency test (above); 0: no test
  double min_partial_fraction = 0.2;          ///< a partial fix keeps at least this fraction of the ambiguities
  double max_partial_fix_sigma_m = 0.05;      ///< a partial fix by the success rate must leave the position this
                                              ///< precise (3D sigma, m) to count as fixed
  int min_lock_epochs = 0;                    ///< epochs an ambiguity must be tracked before it is fixed
  bool glonass_ar = false;                    ///< fix GLONASS ambiguities (needs equal inter-frequency biases)
  double max_age_s = 30.0;                    ///< base observations older than this are not used
  double max_phase_innovation_m = 30.0;       ///< DD phase innovations beyond are rejected as outliers
  double max_code_innovation_m = 100.0;       ///< DD code innovations beyond are rejected as outliers
  double max_post_fit_sigmas = 4.0;           ///< DD phase post-fit residuals beyond (in sigmas) are rejected
  double max_post_fit_code_sigmas = 6.0;      ///< DD code post-fit residuals beyond (in sigmas) are rejected
  int max_post_fit_rejections = 3;            ///< at most this many signals (phase or code) rejected per epoch
  double hold_sigma_cyc = 0.001;              ///< fix-and-hold pseudo-measurement sigma (cycles)
  double max_outage_s = 5.0;                  ///< an ambiguity not observed for longer is re-initialised
  CycleSlipOptions slips;                     ///< cycle-slip detection at each receiver
  bool troposphere_saastamoinen = true;       ///< model the troposphere at each receiver (off: data without one)
  IonosphereModel ionosphere = IonosphereModel::Auto;  ///< differential ionosphere model
  double iono_auto_baseline_km = 10.0;  ///< with Auto, the ionosphere is estimated on baselines longer than this
  double iono_sigma_per_10km_m = 0.03;  ///< prior sigma of a SD ionosphere state per 10 km of baseline (m)
  double iono_sigma_min_m = 0.001;      ///< the prior sigma is at least this (m), whatever the baseline
  double iono_noise_m = 0.001;          ///< SD ionosphere random walk (m per sqrt(s))
  gnss::SppOptions spp;                 ///< single-point solution (prior and fallback)
  /// A heading-error state of the external aiding (see above); set by the aiding's owner (the fusion), not in YAML.
  bool aiding_heading_state = false;

  /// Empty if valid, else the violated rule.
  [[nodiscard]] std::string validate() const;
};

/// Aiding of one epoch by an external motion sensor (see the model above).
struct RtkAiding {
  Eigen::Vector3d delta_p_E_m = Eigen::Vector3d::Zero();  ///< position increment since the state's last epoch (m)
  Eigen::Matrix3d Q_E_m2 = Eigen::Matrix3d::Zero();       ///< its covariance, added to the position's (m^2)
  std::optional<double> max_phase_innovation_m;           ///< DD phase innovations beyond are rejected (m)
  std::optional<double> max_code_innovation_m;            ///< DD code innovations beyond are rejected (m)
  std::optional<double> max_normalised_innovation;        ///< |v| / sqrt(h P h^T + r) beyond is rejected
  /// A candidate fix's position and covariance; false rejects it. Empty: no check.
  std::function<bool(const Eigen::Vector3d&, const Eigen::Matrix3d&)> accept_fix;
  // With RtkOptions::aiding_heading_state only:
  Eigen::Vector3d dp_d_heading_E_m = Eigen::Vector3d::Zero();  ///< d(delta_p) / d(heading error): up x delta_p (m/rad)
  double heading_noise_rad2 = 0.0;     ///< random walk of the heading error over this increment (rad^2)
  double heading_variance_rad2 = 0.0;  ///< variance of the heading error when its state (re)starts (rad^2)
  bool restart_heading = false;        ///< the aiding frame changed (a new alignment): restart the heading state
};

/// One epoch's result.
struct RtkEpoch {
  core::Solution solution;                  ///< status Fixed, Float or Single
  int num_fixed_ambiguities = 0;            ///< DD ambiguities in the accepted fix (0 if not fixed)
  int num_dd_measurements = 0;              ///< DD phase measurements used in the update
  int num_dd_code_measurements = 0;         ///< DD code measurements used in the update
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
  // Aided epochs: the prior (after the time update with the aiding).
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

  /// Processes one rover epoch. Error only if not even a single-point solution exists (and, when aided, no prior).
  /// The same as its three stages in order: predict(); if true, update(); if true, resolve(); then take_epoch().
  Result<RtkEpoch> process(const core::ObsEpoch& rover, const core::ObsEpoch* base, const RtkAiding* aiding = nullptr);

  // The stages of process(), for the staged pipeline (pipeline/epoch_pipeline.hpp); each runs after the one before on
  // the same epoch, and `aiding` must stay alive until resolve() or take_epoch().
  /// Prediction: single-point solution, time update (aided, or the engine's own motion model), observables, cycle
  /// slips, single differences, ambiguity bookkeeping. Error as process(); true if the epoch goes on to update(),
  /// false if its result is final (no base, base too old). `geometry`: the epoch's geometry built ahead by a builder
  /// of geometry_options() that saw every epoch before this one (nullptr: the engine builds it; do not mix the two
  /// on one engine). The engine may change it (it adds satellite states).
  Result<bool> predict(const core::ObsEpoch& rover, const core::ObsEpoch* base, const RtkAiding* aiding = nullptr,
                       EpochGeometry* geometry = nullptr);
  /// The options of the engine's own geometry builder, for a builder that runs ahead (predict()).
  [[nodiscard]] EpochGeometryBuilder::Options geometry_options() const;
  [[nodiscard]] const gnss::EphemerisStore& ephemerides() const { return eph_; }
  /// The base position in use (ECEF, m): the one the engine was made with, or the last set_base_position().
  [[nodiscard]] const Eigen::Vector3d& base_position_E_m() const { return p_E_base_m_; }
  /// The base position from the next epoch on (a streamed base's RTCM 1005/1006); between predict()s.
  void set_base_position(const Eigen::Vector3d& p_E_base_m);
  /// Measurement update (DD code and phase EKF with innovation gates and post-fit rejection) and the float solution;
  /// true if the epoch goes on to resolve() (AR on, float consistent), false if its result is final.
  bool update();
  /// Ambiguity resolution: MLAMBDA, ratio test, partial fixing, the fixed solution.
  void resolve();
  /// The epoch's result (after predict() returned true or false).
  RtkEpoch take_epoch();
  /// Undoes the measurement update and the ambiguity resolution of the last process() call, which must have been
  /// aided: the state goes back to that epoch's prior (ambiguities added or reset by slips that epoch stay).
  void revert_to_prior();
  /// GPST of the state: the last epoch whose time update ran; nullopt before the first.
  [[nodiscard]] const std::optional<core::GpsTime>& state_time() const { return last_time_; }
  /// Whether the position state holds an estimate (aiding needs one).
  [[nodiscard]] bool has_position() const { return initialised_; }
  /// The position state (float, ECEF) and its covariance at state_time().
  [[nodiscard]] Eigen::Vector3d position_E_m() const { return x_.head<3>(); }
  [[nodiscard]] Eigen::Matrix3d position_covariance_E_m2() const { return P_.topLeftCorner<3, 3>(); }
  /// The aiding's heading error state (rad) and its variance (rad^2), when it holds an estimate.
  struct HeadingError {
    double psi_rad = 0.0;
    double variance_rad2 = 0.0;
  };
  [[nodiscard]] std::optional<HeadingError> heading_error() const;
  /// heading_error(), then the state's value set to zero (its variance and correlations kept): the caller folds the
  /// estimate into the aiding's frame.
  std::optional<HeadingError> take_heading_error();
  /// Removes every ambiguity and ionosphere state (between epochs): the next epochs start them afresh, as after a
  /// loss of lock on every satellite.
  void reset_ambiguities() { clear_ambiguities(); }
  /// Sets the position state (between epochs), uncorrelated with the other states: a re-anchoring from outside.
  void set_position(const Eigen::Vector3d& p_E_m, const Eigen::Matrix3d& P_E_m2);

 private:
  // Keyed states after the kinematic block: (satellite, frequency rank) for an ambiguity, (satellite, kIonoKey) for
  // the satellite's SD ionosphere.
  using AmbiguityKey = std::pair<core::SatelliteId, int>;
  static constexpr int kIonoKey = -1;
  struct AmbiguityInfo {
    int lock_epochs = 0;
    core::GpsTime last_seen;
  };
  void time_update(const core::GpsTime& t, const gnss::SppSolution& spp);
  /// Time update with external aiding: p += delta, P_pp += Q, ambiguity random walks (and the heading coupling).
  void aided_time_update(const core::GpsTime& t, const RtkAiding& aiding);
  /// p += J psi, P = F P F^T (F = I + J e_psi^T), psi's random walk; restarts psi first if asked or not live.
  void propagate_heading(const RtkAiding& aiding);
  /// The single differences of the epoch at the state's position (the rover's satellite states are added to the
  /// geometry's, shared with its single-point solution).
  [[nodiscard]] std::vector<SingleDiff> single_differences(EpochGeometry& geometry) const;
  /// Ambiguity bookkeeping: resets on the epoch's slips, removals after outages, new states, fixability.
  void update_ambiguities(std::vector<SingleDiff>& sds, const core::GpsTime& t, const SlipScan& slips);
  /// A keyed state to append: initial value and variance, uncorrelated with the other states.
  struct NewState {
    AmbiguityKey key;
    double value = 0.0;
    double variance = 0.0;
  };
  /// Appends the states in order, with one resize of x and P for all of them.
  void add_states(const std::vector<NewState>& states);
  /// EKF update with the DD code and phase, with post-fit rejection; returns the number of DD phase rows used.
  /// `consistent`: no post-fit residual is left beyond its threshold (the float solution passes validation).
  int measurement_update(std::vector<SingleDiff>& sds, std::vector<core::SatelliteId>& rejected, bool& consistent);
  struct PostFit {
    int worst_sd = -1;              // SD of the largest normalised post-fit residual
    double worst_normalised = 0.0;  // |residual| / (measurement sigma * threshold of its kind): beyond when > 1
    bool worst_is_code = false;     // the worst residual is a code one
  };
  int update_once(std::vector<SingleDiff>& sds, std::vector<core::SatelliteId>& rejected, PostFit& post_fit);
  /// A candidate fix of a set of DD ambiguities (state index of s, of its reference).
  struct Fix {
    std::vector<std::pair<int, int>> dd;  // DD ambiguities: (state index of s, of its reference)
    Eigen::VectorXd a_float;
    Eigen::MatrixXd Q_a;    // D P D^T
    Eigen::MatrixXd PDt;    // P D^T
    Eigen::VectorXd a_fix;  // best integer candidate
    double ratio = 0.0;
    double squared_norm = 0.0;              // (a_float - a_fix)^T Q_a^-1 (a_float - a_fix) of the best candidate
    double success_rate = 0.0;              // bootstrapped success rate of the float model
    Eigen::MatrixXd Z;                      // the search's decorrelation: Z^T Q_a Z = L^T diag(d) L
    Eigen::VectorXd d;                      // its conditional variances (cycles^2)
    std::vector<core::SatelliteId> pruned;  // satellites pruned by their ILS residual to get this set
    // The fixed quantities are integer combinations Z_S^T of the DD ambiguities dd (a_float = Z_S^T D x, PDt = P D^T
    // Z_S) rather than the DD ambiguities themselves: a partial fix by the success rate.
    bool combinations = false;
    bool imprecise = false;  // combinations that leave the position less precise than max_partial_fix_sigma_m
  };
  /// MLAMBDA on a set of DD ambiguities; nullopt if the set has fewer than max(min_size, min_fix_ambiguities).
  [[nodiscard]] std::optional<Fix> try_fix(const std::vector<std::pair<int, int>>& dd, int min_size) const;
  /// Partial fixing by the success rate (Teunissen's partial ambiguity resolution): in the decorrelated space
  /// z = Z^T a of the full set's search (Fix::Z), Q_z = L^T D L, the trailing levels k0..n-1 form a problem of their
  /// own (their factors are the trailing blocks of L and D) whose bootstrapped success rate is prod_{k >= k0} p_k.
  /// Fixes the largest such trailing set whose success rate reaches min_success_rate, if it has at least max(min_size,
  /// min_fix_ambiguities) members and passes the ratio test; nullopt otherwise. Fix::imprecise is set when the position
  /// it leaves has a 3D sigma above max_partial_fix_sigma_m (then it is no fix, but the float position conditioned on
  /// it is still the better float).
  [[nodiscard]] std::optional<Fix> success_rate_subset_fix(const Fix& full, int min_size) const;
  /// The float consistency test on the full set's search (see above), made with float_variance_factor_ at 1: sets
  /// it when the test fails, and rescales the set's success rate.
  void test_float_consistency(Fix& full);
  /// Bootstrapped success rate of conditional variances `d` scaled by float_variance_factor_.
  [[nodiscard]] double success_rate(const Eigen::VectorXd& d) const;
  /// Ratio test, success rate and agreement with the last fix (and the aiding's accept_fix when aided).
  [[nodiscard]] bool accepted(const Fix& fix) const;
  /// Why a fix is not accepted, with its figures (for --verbose).
  [[nodiscard]] std::string rejection_reason(const Fix& fix) const;
  /// Position and its covariance of a candidate fix (conditional update); false if Q_a is not positive definite.
  [[nodiscard]] bool fix_position(const Fix& fix, Eigen::Vector3d& p, Eigen::Matrix3d& P) const;
  /// A DD ambiguity by the keys of its two SD ambiguities (satellite s, reference satellite).
  using DdKey = std::pair<AmbiguityKey, AmbiguityKey>;
  [[nodiscard]] DdKey dd_key(const std::pair<int, int>& dd) const;
  [[nodiscard]] std::vector<DdKey> dd_keys(const std::vector<std::pair<int, int>>& dd) const;
  /// False if a DD ambiguity also fixed at the last fix (no slip since) gets another integer: a fix that contradicts
  /// its predecessor is a wrong fix of one of them, and is not taken.
  [[nodiscard]] bool agrees_with_last_fix(const Fix& fix) const;
  /// How many directions of the position the DD ambiguities `dd` can pin once fixed, at most: each is a satellite
  /// pair (s, reference), so with V satellites joined into C groups by the pairs, V - C (three satellites: 2). An
  /// epoch whose fixable ambiguities give fewer than 3 is not fixed: the position would stay open along a line, held
  /// there by the prior alone (single point, motion model or VIO), which makes no fixed solution.
  [[nodiscard]] int fixable_directions(const std::vector<std::pair<int, int>>& dd) const;
  /// Drops the satellite with the largest integer least-squares residual contribution until a fix is accepted (at
  /// most max_pruned_satellites); nullopt if none is.
  [[nodiscard]] std::optional<Fix> prune(Fix fix, int min_size) const;
  [[nodiscard]] core::SatelliteId satellite_of_state(int index) const;
  [[nodiscard]] core::SatelliteId satellite_of_largest_contribution(const std::vector<std::pair<int, int>>& dd,
                                                                    const Eigen::VectorXd& contributions) const;
  /// The DD ambiguities of `all` that the last fix fixed, if they are fewer than `all` and their fix is accepted.
  [[nodiscard]] std::optional<Fix> last_subset_fix(const std::vector<std::pair<int, int>>& all, int min_size) const;
  /// More ambiguities, then the higher ratio.
  [[nodiscard]] static bool better_fix(const Fix& l, const Fix& r);
  /// Partial fixing after the full set failed: pruning, then without each group or constellation.
  /// `imprecise`: set to a partial fix by the success rate that passed its tests but leaves the position less precise
  /// than max_partial_fix_sigma_m (not a fix, but a better float position). `last_subset_tried`: the subset of the
  /// last fix was searched this epoch already, and failed (the same search would fail again).
  [[nodiscard]] std::optional<Fix> partial_fix(const std::vector<SingleDiff>& sds, std::optional<Fix> full,
                                               int min_size, std::optional<Fix>& imprecise,
                                               bool last_subset_tried) const;
  /// MLAMBDA and the ratio test, then partial fixing without one group if the whole set fails; fills the fixed
  /// solution of `out` and returns true when fixed.
  bool resolve_ambiguities(const std::vector<SingleDiff>& sds, RtkEpoch& out);
  /// Whether the ionosphere is estimated at this epoch (Off, Estimate, or Auto by the baseline); turning it off
  /// removes the ionosphere states.
  void choose_ionosphere_model(double baseline_m);
  void add_ambiguity(const AmbiguityKey& key, double value, double variance);
  void remove_ambiguity(const AmbiguityKey& key);
  /// Removes every keyed state (ambiguities, ionosphere) at once: instantaneous mode, each epoch.
  void clear_ambiguities();
  [[nodiscard]] int ambiguity_index(const AmbiguityKey& key) const;
  /// Position (3), velocity and acceleration (6, with dynamics), the aiding's heading error (1, with
  /// aiding_heading_state): the states before the keyed ones.
  [[nodiscard]] int num_kinematic_states() const {
    return (options_.dynamics ? 9 : 3) + (options_.aiding_heading_state ? 1 : 0);
  }
  /// Index of the heading error state; -1 without aiding_heading_state.
  [[nodiscard]] int heading_index() const { return options_.aiding_heading_state ? (options_.dynamics ? 9 : 3) : -1; }

  struct PendingEpoch;  // the epoch between the stages (engine.cpp)

  RtkOptions options_;
  const gnss::EphemerisStore& eph_;
  std::unique_ptr<PendingEpoch> pending_;
  Eigen::Vector3d p_E_base_m_;
  Eigen::VectorXd x_;
  Eigen::MatrixXd P_;
  std::vector<AmbiguityKey> ambiguity_keys_;  // state index = num_kinematic_states() + position in this list
  std::map<AmbiguityKey, AmbiguityInfo> ambiguity_info_;
  std::optional<core::GpsTime> last_time_;
  bool initialised_ = false;
  bool heading_live_ = false;              // the heading error state holds an estimate (aided since its restart)
  EpochGeometryBuilder geometry_builder_;  // predict() without a geometry built ahead (it owns the slip detectors)
  std::map<DdKey, double> last_fix_;       // integers of the last accepted fix; pairs leave with their ambiguities
  // Aiding of the epoch being processed (nullptr otherwise), and the prior kept for revert_to_prior().
  const RtkAiding* aiding_ = nullptr;
  bool has_prior_ = false;
  Eigen::VectorXd prior_x_;
  Eigen::MatrixXd prior_P_;
  std::map<DdKey, double> prior_last_fix_;
  double last_post_fit_normalised_ = 0.0;
  int last_code_rows_ = 0;
  static constexpr int kFullSetRetryEpochs = 10;
  std::vector<DdKey> failed_full_set_;  // the full DD set whose integer search last failed (empty: none)
  // The decorrelation each DD set's integer search reached, carried to the next search of the same set (a warm
  // start: a few reduction swaps instead of hundreds, the same candidates); a set not searched in an epoch is
  // forgotten at the next. Only an accelerator, hence mutable in the const searches.
  struct CarriedDecorrelation {
    MlambdaWarmStart warm;
    std::int64_t last_epoch = 0;  // ar_epoch_ of its last search
  };
  mutable std::map<std::vector<DdKey>, CarriedDecorrelation> carried_decorrelations_;
  std::int64_t ar_epoch_ = 0;           // epochs through resolve_ambiguities
  int epochs_since_full_set_ = 0;       // epochs since the full set was last searched
  double float_variance_factor_ = 1.0;  // of the full set's last search (test_float_consistency)
  double consistency_z_ = 0.0;          // normal quantile of float_consistency_level (0: no test)
  bool iono_estimated_ = false;         // ionosphere states in use at this epoch
};

[[nodiscard]] const char* ar_mode_name(ArMode mode);
/// "off", "estimate" or "auto", as in the configuration.
[[nodiscard]] const char* ionosphere_model_name(IonosphereModel model);

}  // namespace canyon::rtk
