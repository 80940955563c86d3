#pragma once
// The paper's per-epoch fusion (Algorithm 1) on canyon's RTK engine.
//
// For each rover epoch i+1 at GPST t:
//  1. VIO pose at t (VioTrack, interpolated on SE(3)); a gap or a new VIO segment (reset) drops the alignment of the
//     old segment: the engine falls back to its own motion model until a window of the new segment aligns.
//  2. Alignment (alignment.hpp): until the first alignment, every alignment_interval_s, the last alignment_window_s
//     of RTK solutions (fixed or float, position sigma <= max_window_sigma_m) of the VIO segment are fitted with the
//     paper's two passes (T_EO from identity with t_IA = 0, then T_EO and t_IA jointly); the window qualifies when
//     its FER < 0.97 and the fit RMSE < 0.1 m. Afterwards every realign_interval_s a window of fixed solutions
//     refreshes T_EO with t_IA held (the VIO drifts). Beyond the paper, while no window qualifies, a coarse
//     gravity-aligned yaw fit of the last coarse_window_s of any RTK solutions, with its yaw uncertainty carried into
//     the prediction, aligns the VIO (coarse_alignment).
//  3. Prediction (vio_prediction.hpp, Eqs. 3-6): the engine's position state moves by dp_E = R_EO dp_O of the
//     antenna's VIO increment since the state's epoch, its covariance grows by R_EO cov(dp_O) R_EO^T, ambiguities
//     carry over (rtk::RtkAiding). Without an alignment: the engine's own time update (single point or dynamics).
//     Beyond the paper (heading_state): the alignment's heading error psi is one more filter state; the increment is
//     rotated by it about the local vertical (dp_E += (up x dp_E) psi), so that the updates learn it from how GNSS
//     corrects the VIO motion. After every aided epoch psi is folded into T_EO (rotated about the vertical through the
//     position) and the state restarts at zero with its variance kept; it starts at the coarse fit's yaw sigma or at
//     fine_heading_sigma_deg after a fine alignment, and walks by heading_random_walk_deg_per_sqrt_km with the
//     distance. Without it a fine alignment's heading is exact and a coarse one's sigma is added to every increment
//     as if independent from one increment to the next, which it is not: the fill-in then drifts sideways by the
//     whole error times the distance walked.
//  4. Outlier satellite pruning in the update: DD phase innovations beyond gate_motion_factor x |dp_E| (the paper: 5x
//     the VIO incremental motion, at least min_gate_m; applied to phase only: DD code noise is of that size) and/or
//     DD phase and code innovations beyond gate_sigmas sqrt(h P h^T + r) (chi-square gate).
//  Beyond the paper, before all that, the C/N0 screen (cn0_screen.hpp) removes suspected NLOS signals of aided epochs
//  (it learns from all: before the alignment the RTK engine needs every signal for the solutions it aligns with); it
//  runs with the epoch's geometry (fusion_geometry.hpp), which the pipeline builds ahead of the filter.
//  5. Float validation: at least one DD phase used; the largest DD post-fit residual, over the RTK engine's rejection
//     threshold, <= max_post_fit_normalised; the float position consistent with the prior,
//     (p_float - p_prior)^T P_prior^-1 (p_float - p_prior) <= max_prior_chi2. If it fails: the update is undone and
//     the epoch's output is the prior (aligned VIO fill-in, Q = 7). Beyond the paper, two recoveries from a prior
//     that drifted (a poor alignment, a long fill-in): after max_prior_rejections consecutive epochs failing only the
//     prior check, the float is taken; after gate_conflict_epochs consecutive epochs whose gates rejected more rows
//     than the update used, the next prior's position sigma is widened by reanchor_sigma_m.
//  6. MLAMBDA with the ratio test (rtk options, 3.0); when it fails the engine prunes the satellite with the largest
//     integer least-squares residual and solves again (Algorithm 1, lines 13-19; rtk partial_ar). Beyond the paper,
//     a false-fix guard rejects a candidate fix whose position disagrees with the prior:
//     (p_fix - p_prior)^T (P_prior + P_fix)^-1 (p_fix - p_prior) > false_fix_chi2, and a fix whose position sigma
//     (largest axis of P_fix) exceeds max_fix_sigma_m (a weak geometry; with fewer than 4 satellites the engine
//     tries no fix at all).
//  7. Output: fixed, else float (Algorithm 1).
//  8. Beyond the paper, an integrity check (integrity_check): the horizontal offset of the epoch's single-point
//     solution from the output, in local east and north, is kept over integrity_window_s of aided epochs; when the
//     median offset (per axis) of at least integrity_min_points of them exceeds integrity_max_offset_m, the fusion has
//     carried a wrong position along (an alignment to solutions far off, NLOS floats that pulled it away): the
//     position moves horizontally by that median (the single points' spread about it as its variance; the vertical
//     and the alignment stay), every ambiguity starts again and so does the heading error (at least 10 deg). Single
//     points in street canyons are tens of metres off for tens of seconds at a time (a 30 s
//     median up to 43 m on urban-severe), hence a median over a window and a bound above that.
//  9. Beyond the paper, a heading-free fill-in (heading_free_fill_in): before the VIO segment is aligned (a start in a
//     canyon, or after a VIO reset), an epoch without any GNSS solution gets the last solution of the segment moved
//     by the VIO's vertical motion (O is gravity-aligned), its horizontal motion of unknown direction standing as
//     the uncertainty: sigma h / sqrt(2) per horizontal axis, h the horizontal distance travelled since (Q = 7).
// Prediction "constant_velocity" (an ablation) replaces the VIO increment by v dt from the last two fixed or float
// solutions (none if they are more than 5 s apart or imply more than vio_max_speed_mps), with covariance
// (sigma_a^2 dt^3 / 3) I + (P_k + P_k-1) (dt / dt_k)^2, sigma_a the rtk option accel_sigma_h_mps2.

#include <deque>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/core/solution.hpp"
#include "canyon/fusion/alignment.hpp"
#include "canyon/fusion/cn0_screen.hpp"
#include "canyon/fusion/fusion_geometry.hpp"
#include "canyon/fusion/time_bridge.hpp"
#include "canyon/fusion/vio_prediction.hpp"
#include "canyon/fusion/vio_track.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/rtk/engine.hpp"

namespace canyon::fusion {

enum class Prediction { Vio, ConstantVelocity };
enum class InnovationGate { Off, Paper, ChiSquare, Both };

[[nodiscard]] const char* prediction_name(Prediction p);
[[nodiscard]] const char* innovation_gate_name(InnovationGate g);

struct FusionOptions {
  bool vio_on_gps_time = false;  ///< vio.csv t_ns is GPST ns since 1980-01-06 (no time-sync file needed)
  TimeBridgeOptions time_sync;
  VioTrackOptions vio;
  AlignmentOptions alignment;         ///< FER 0.97, RMSE 0.1 m (the paper's gates)
  double alignment_window_s = 6.0;    ///< an alignment window: the last this many seconds of solutions (s)
  double alignment_interval_s = 1.0;  ///< until aligned, try at most this often (s)
  double realign_interval_s = 5.0;    ///< once aligned, refresh T_EO this often (s)
  double max_window_sigma_m = 0.3;    ///< solutions with a larger 3-D position sigma do not join a window (m)
  bool calibrate_lever_arm = true;    ///< estimate t_IA in the first alignment (pass 2)
  Eigen::Vector3d lever_arm_prior_m = Eigen::Vector3d::Zero();  ///< t_IA prior (IMU frame, m)
  bool coarse_alignment = true;            ///< beyond the paper: gravity-aligned yaw fit while no window qualifies
  double coarse_window_s = 60.0;           ///< its window (s)
  double coarse_min_spread_m = 1.0;        ///< RMS horizontal spread it needs (m; its yaw sigma bound decides)
  double coarse_max_yaw_sigma_deg = 30.0;  ///< largest yaw uncertainty it accepts (deg)
  /// Beyond the paper: the heading error of the alignment as a filter state (rtk::RtkOptions::aiding_heading_state),
  /// learnt from how GNSS corrects the VIO increments and folded into T_EO after every epoch; false: the alignment's
  /// heading is taken as exact (fine) or its uncertainty is added to every increment as white noise (coarse).
  bool heading_state = true;
  double heading_random_walk_deg_per_sqrt_km = 1.0;  ///< VIO heading drift: the state's random walk (deg/sqrt(km))
  double fine_heading_sigma_deg = 1.0;               ///< heading sigma after a fine alignment (deg)
  bool integrity_check = true;           ///< beyond the paper: restart when the output leaves the single points (8.)
  double integrity_window_s = 30.0;      ///< its window of aided epochs (s)
  int integrity_min_points = 50;         ///< single points the window needs before it judges
  double integrity_max_offset_m = 60.0;  ///< median horizontal offset of the single points beyond which it restarts
  bool heading_free_fill_in = true;      ///< beyond the paper: before an alignment, the heading-free fill-in (9.)
  Prediction prediction = Prediction::Vio;
  bool vio_covariance = true;                ///< Eqs. 4-6; false: constant_increment_sigma_m per axis (ablation)
  double constant_increment_sigma_m = 0.05;  ///< (m)
  InnovationGate gate = InnovationGate::Both;
  double gate_motion_factor = 5.0;       ///< paper: 5 x the VIO incremental motion
  double min_gate_m = 0.5;               ///< the motion gate is at least this (standing still) (m)
  double gate_sigmas = 4.0;              ///< chi-square gate: |v| <= this x sqrt(h P h^T + r)
  double max_post_fit_normalised = 1.0;  ///< float validation: largest DD post-fit residual over the RTK engine's
                                         ///< rejection threshold (1: the engine's own max_post_fit_sigmas)
  double max_prior_chi2 = 16.27;         ///< float validation: chi-square(3) of the float against the prior (0.999)
  bool false_fix_guard = true;           ///< beyond the paper: fixes must agree with the prior
  double false_fix_chi2 = 16.27;         ///< chi-square(3) bound of the guard (0.999)
  double max_fix_sigma_m = 0.1;          ///< a fix whose position sigma (largest axis) exceeds this is not taken:
                                         ///< its DD geometry leaves the position poorly determined
  Cn0ScreenOptions cn0;                  ///< beyond the paper: NLOS screening by C/N0 (cn0_screen.hpp)
  int max_prior_rejections = 5;          ///< after this many consecutive epochs whose float failed only the prior
                                         ///< check, the float is taken: GNSS re-anchors a drifted VIO prior
  int gate_conflict_epochs = 5;          ///< after this many consecutive epochs in which the gates rejected more DD
                                         ///< rows than the update used, the prior is widened by reanchor_sigma_m
  double reanchor_sigma_m = 2.0;         ///< (m, per axis)
  double vio_keep_s = 120.0;             ///< VIO samples older than this before the epoch are forgotten (s)

  [[nodiscard]] std::string validate() const;
};

struct FusionEpoch {
  core::Solution solution;  ///< Fixed, Float, VioFillIn, or (fallback) the RTK engine's
  double hdop = 0.0;
  bool aided = false;                        ///< the VIO (or constant-velocity) prediction was used
  std::string note;                          ///< why the epoch is not fixed
  std::vector<core::SatelliteId> rejected;   ///< satellites gated out of the update (innovation, post-fit)
  std::vector<core::SatelliteId> ar_pruned;  ///< satellites pruned by the ambiguity resolution
  rtk::RtkEpoch rtk;                         ///< the RTK engine's epoch (float solution, prior, DD rows)
};

struct AlignmentEvent {
  core::GpsTime time;
  std::string kind;  ///< "coarse", "initial" (two passes, calibration), "realign"
  int points = 0;
  double first_eigenvalue_ratio = 1.0;
  double rmse_m = 0.0;
  double rmse_without_calibration_m = 0.0;
  double yaw_sigma_deg = 0.0;  ///< coarse
};

struct FusionStats {
  int epochs = 0;
  int aided = 0;
  int fixed = 0;
  int fill_in = 0;
  int fallback = 0;  ///< epochs solved by the RTK engine's own motion model (not aligned, no VIO)
  int no_vio = 0;    ///< epochs without a VIO pose
  int float_rejected_no_phase = 0;
  int float_rejected_post_fit = 0;
  int float_rejected_prior = 0;
  int guard_epochs = 0;             ///< epochs in which the false-fix guard rejected at least one candidate
  int guard_candidates = 0;         ///< candidate fixes it rejected
  int gated_rows = 0;               ///< DD rows (code and phase) rejected by the innovation gates and post-fit checks
  int cn0_screened = 0;             ///< signals removed by the C/N0 screen
  int undetermined_fix_epochs = 0;  ///< epochs in which a fix was refused for its position sigma
  int too_few_to_fix = 0;           ///< aided epochs whose fixable ambiguities came from fewer than 4 satellites
  int float_inconsistent = 0;       ///< aided epochs whose float failed the RTK engine's float consistency test
  int ar_pruned_epochs = 0;         ///< fixes obtained after pruning satellites by their ILS residual
  int reanchored = 0;               ///< floats taken after max_prior_rejections (the prior had drifted)
  int widened = 0;                  ///< priors widened after gate_conflict_epochs
  double heading_folded_rad = 0.0;  ///< heading_state: the sum of the heading corrections folded into T_EO
  double heading_sigma_rad = 0.0;   ///< heading_state: the heading error's sigma after the last aided epoch
  int integrity_restarts = 0;       ///< integrity_check: restarts from the single point
  int heading_free = 0;             ///< heading_free_fill_in: epochs it filled
  int alignment_tries = 0;
  int alignment_rejected_fer = 0;
  int alignment_rejected_rmse = 0;
  std::vector<AlignmentEvent> alignments;      ///< accepted ones
  std::optional<AlignmentResult> calibration;  ///< the first (two-pass) alignment
  double alignment_cpu_s = 0.0;
  std::vector<std::string> notes;  ///< VIO segments, alignment losses
};

/// The fusion's innovation gates on one epoch's DD rows (rtk::InnovationGate).
struct VioGates final : rtk::InnovationGate {
  std::optional<double> max_phase_innovation_m;     ///< DD phase innovations beyond are rejected (m)
  std::optional<double> max_code_innovation_m;      ///< DD code innovations beyond are rejected (m)
  std::optional<double> max_normalised_innovation;  ///< |v| / sqrt(h P h^T + r) beyond is rejected
  [[nodiscard]] bool passes(const rtk::DdInnovation& row) const override;
};

class FusionEngine {
 public:
  FusionEngine(FusionOptions options, const rtk::RtkOptions& rtk_options, const gnss::EphemerisStore& ephemerides,
               const Eigen::Vector3d& p_E_base_m, VioTrack track);

  /// One rover epoch with the base epoch to use (nullptr if none). Error when no solution at all exists (no VIO
  /// prediction and no single-point solution). The same as the stages below in order, then flush_alignment().
  Result<FusionEpoch> process(const core::ObsEpoch& rover, const core::ObsEpoch* base);

  // The stages of process(), for the staged pipeline (pipeline/epoch_pipeline.hpp). Per epoch, in this order:
  //   bridge(t) -> align(t, pose) -> predict() -> [if true] update() -> [if true] resolve() -> finish_epoch().
  // bridge() only reads the VIO track and may run ahead on another thread; the others change the engine's state and
  // run one epoch at a time. The alignment that the paper runs after epoch k's solution runs at the start of align()
  // of epoch k+1 (nothing happens in between, so the results are the same); flush_alignment() runs it at the end.
  /// Time bridge: the VIO pose at GPST t (the track is on GPST through the time bridge), nullopt if none.
  [[nodiscard]] std::optional<VioPoseAt> bridge(const core::GpsTime& t) const;
  /// Alignment: the pending alignment of the previous epoch (T_EO, t_IA), then this epoch's VIO segment bookkeeping.
  void align(const core::GpsTime& t, const std::optional<VioPoseAt>& pose);
  /// Prediction: the VIO increment (Eqs. 3-6) as the RTK engine's aiding, the C/N0 screen's verdict on an aided
  /// epoch, the RTK engine's prediction (rtk::RtkEngine::predict). `geometry`: the epoch's geometry built ahead by a
  /// builder from make_geometry_builder() that saw every epoch before this one (nullptr: the engine builds it; do not
  /// mix the two in one run); the prediction may move its observables. Error as process(); true if the epoch goes on
  /// to update(), false if it goes straight to finish_epoch() (no base epoch, or the heading-free fill-in).
  Result<bool> predict(const core::ObsEpoch& rover, const core::ObsEpoch* base, const std::optional<VioPoseAt>& pose,
                       FusionGeometry* geometry = nullptr);
  /// A builder of the engine's epoch geometry (fusion_geometry.hpp), to run ahead of predict().
  [[nodiscard]] FusionGeometryBuilder make_geometry_builder() const;
  /// Update: the RTK engine's gated measurement update; true if the epoch goes on to resolve().
  bool update();
  /// Ambiguity resolution: the RTK engine's MLAMBDA with pruning and the false-fix guard.
  void resolve();
  /// Float validation, the fill-in, the epoch's output and the alignment window bookkeeping (after predict()
  /// succeeded, whatever update() and resolve() did).
  FusionEpoch finish_epoch();
  /// Runs an alignment left pending by the last epoch (end of the input).
  void flush_alignment();

  // A live VIO stream (pipeline::LiveVio): poses appended while the stages run. The track is guarded by a reader-writer
  // lock: appends (the time bridge's thread) exclude the readers (bridge(), the prediction); forgetting happens in
  // align().
  /// Appends a pose at GPST t to the track (VioTrack::append); false if not after the last one.
  bool add_vio(const io::VioRecord& record, const core::GpsTime& t, std::string* note = nullptr);
  /// The track has the poses that make bridge(t) final (VioTrack::covers).
  [[nodiscard]] bool vio_covers(const core::GpsTime& t) const;
  /// The base position from the next epoch on (rtk::RtkEngine::set_base_position).
  void set_base_position(const Eigen::Vector3d& p_E_base_m) {
    engine_.set_base_position(p_E_base_m);
    geometry_builder_.set_base_position(p_E_base_m);
  }
  /// The lever arm t_IA in use (the prior until calibrated) (m, IMU frame).
  [[nodiscard]] const Eigen::Vector3d& lever_arm_m() const { return t_IA_m_; }

  [[nodiscard]] const FusionStats& stats() const { return stats_; }
  /// Human-readable summary: alignments, calibration and lever-arm observability, validation and guard counts.
  [[nodiscard]] std::vector<std::string> report() const;

 private:
  struct Alignment {
    core::Pose T_EO;
    int segment = 0;
    // The heading's sigma: a coarse fit's; after a fine one 0 (taken as exact) or, with heading_state,
    // fine_heading_sigma_deg; with heading_state the filter's from the first aided epoch on.
    double yaw_sigma_rad = 0.0;
    bool fine = false;
    core::GpsTime time;
    bool heading_started = false;  // heading_state: the filter's heading error has been restarted for it
  };
  struct WindowPoint {
    core::GpsTime time;
    core::Pose T_OI;
    Eigen::Vector3d p_E_m;
    core::SolutionStatus status = core::SolutionStatus::None;
    double sigma_m = 0.0;
    int segment = 0;
    bool aided = false;
  };
  struct Prior {
    Eigen::Vector3d p_E_m;
    Eigen::Matrix3d P_E_m2;
  };

  struct PendingAlignment {
    core::GpsTime time;
    std::optional<VioPoseAt> pose;
  };
  void count_fix_rejections();

  struct EpochAiding {
    rtk::ExternalMotion motion;
    VioGates gate;
  };
  std::optional<EpochAiding> make_aiding(const core::GpsTime& t, const std::optional<VioPoseAt>& pose);
  bool accept_fix(const rtk::FixCandidate& fix);
  /// The antenna's VIO increment from the track's pose at GPST t_from to `pose` (vio_increment(), Eqs. 4-5), nullopt
  /// if the track has no pose at t_from in pose's segment.
  [[nodiscard]] std::optional<VioIncrement> increment_since(
      const core::GpsTime& t_from, const VioPoseAt& pose, const Eigen::Matrix3d& R_EO, double yaw_sigma_rad = 0.0,
      const Eigen::Vector3d& up_E = Eigen::Vector3d::UnitZ()) const;
  void update_alignment(const core::GpsTime& t, const std::optional<VioPoseAt>& pose);
  [[nodiscard]] std::vector<AlignmentPoint> window(const core::GpsTime& t, double span_s, int segment,
                                                   bool fixed_only) const;
  [[nodiscard]] std::string validate_float(const rtk::RtkEpoch& epoch) const;
  /// heading_state: the filter's heading error rotates T_EO about the local vertical at the position, the state
  /// starts again from zero with the same variance (a change of variables), the alignment keeps that sigma.
  void fold_heading_error();
  /// integrity_check: adds the epoch's single-point offset from `p_out_E_m` to the window and restarts when its
  /// median is beyond the bound.
  void check_integrity(const Eigen::Vector3d& p_out_E_m);
  /// The median of spp_offsets_ along one axis (0 east, 1 north).
  [[nodiscard]] double median_offset_m(int axis);
  /// Moves the position horizontally by the single points' median offset, with their spread as its variance, and
  /// restarts the ambiguities and the heading error.
  void restart_from_single_points(const Eigen::Vector3d& p_out_E_m, const Eigen::Matrix3d& R_NE,
                                  const Eigen::Vector2d& median_EN_m);
  /// heading_free_fill_in: the last solution of the VIO segment and the antenna's VIO motion since.
  struct HeadingFreeTrack {
    Eigen::Vector3d p_E_m;
    Eigen::Matrix3d P_E_m2;
    Eigen::Vector3d dp_O_m = Eigen::Vector3d::Zero();  // antenna displacement since, in O (z up) (m)
    double var_up_m2 = 0.0;                            // variance of its vertical component (m^2)
    core::GpsTime time;                                // of the last pose added
    int segment = 0;
  };
  /// The heading-free fill-in at t (9.), nullopt if there is none (option off, no anchor of the pose's segment).
  [[nodiscard]] std::optional<core::Solution> heading_free_solution(const core::GpsTime& t,
                                                                    const std::optional<VioPoseAt>& pose);
  /// finish_epoch() of an epoch that predict() gave the heading-free fill-in.
  FusionEpoch finish_heading_free();
  struct SppOffset {
    core::GpsTime time;
    Eigen::Vector2d d_EN_m;  // single point minus output, local east and north (m)
  };

  FusionOptions options_;
  rtk::RtkOptions rtk_options_;
  const gnss::EphemerisStore& ephemerides_;
  rtk::RtkEngine engine_;
  FusionGeometryBuilder geometry_builder_;  // predict() without a geometry built ahead
  VioTrack track_;
  mutable std::shared_mutex track_mutex_;  // see add_vio()
  std::optional<Alignment> alignment_;
  Eigen::Vector3d t_IA_m_;
  bool calibrated_ = false;
  std::vector<WindowPoint> history_;  // recent solutions with their VIO poses (pruned to the longest window)
  std::optional<core::GpsTime> last_alignment_try_;
  std::optional<core::GpsTime> last_coarse_try_;
  std::optional<Prior> prior_;  // of the epoch being processed
  int guard_rejections_epoch_ = 0;
  int undetermined_fixes_epoch_ = 0;
  int prior_rejections_ = 0;  // consecutive
  int gate_conflicts_ = 0;    // consecutive
  bool widen_next_prior_ = false;
  std::vector<core::Solution> last_solutions_;  // the last two outputs (constant-velocity prediction)
  std::optional<int> last_segment_;
  FusionStats stats_;
  // The epoch between the stages.
  core::GpsTime epoch_time_;
  std::optional<VioPoseAt> epoch_pose_;
  std::optional<EpochAiding> aiding_;  // alive from predict() to finish_epoch(): the RTK engine points to it
  std::optional<Eigen::Vector3d> epoch_spp_p_E_m_;  // the epoch's single point, if any
  std::deque<SppOffset> spp_offsets_;               // integrity_check's window
  std::vector<double> median_scratch_m_;            // its medians' working copy (kept: no allocation per epoch)
  std::optional<PendingAlignment> pending_alignment_;
  std::optional<HeadingFreeTrack> heading_free_;
  std::optional<core::Solution> heading_free_epoch_;  // the epoch's heading-free fill-in, from predict()
};

}  // namespace canyon::fusion
