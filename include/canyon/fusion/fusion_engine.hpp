#pragma once
// The paper's per-epoch fusion (Algorithm 1) on canyon's RTK filter. For each rover epoch i+1 at GPST t:
//   line 1     the epoch's data; the VIO pose at t (vio_track.hpp, interpolated on SE(3) at GPST: time_bridge.hpp)
//   line 2     AlignNewSegmentationOrReuseOldAlignment: alignment_schedule.hpp (fits: alignment.hpp)
//   lines 3-5  the VIO increment and the prior, Eqs. 3-6: vio_prediction.hpp, predict_with_vio(); the RTK filter
//              applies the increment to its whole state (rtk/time_update.hpp). Without an alignment (or VIO), the
//              filter's own motion model.
//   line 6     outlier satellite pruning in the update: innovation_gates.hpp, injected into the filter's update
//   line 7     the measurement update and the float solution: rtk/dd_update.hpp
//   line 8     float validation: float_validation.hpp
//   lines 9-17 MLAMBDA with the ratio test and, when it fails, further pruning of the satellites with the largest
//              integer least-squares residuals: rtk/ambiguity_resolution.hpp proposes the candidate fixes, the fusion
//              decides on each (resolve(); its decision beyond the paper: false_fix_guard.hpp)
//   lines 11, 16, 18  the output: fixed, else float
//   line 22    the prior when the float failed validation: vio_fill_in.hpp
//   line 24    the epoch's output: finish_epoch()
// Beyond the paper, each in its own file with its options and why it exists: cn0_screen.hpp (NLOS screening by C/N0,
// on the epoch's geometry: fusion_geometry.hpp), coarse_alignment.hpp, heading_state.hpp, integrity_check.hpp,
// heading_free_fill_in.hpp, false_fix_guard.hpp, prior_recovery.hpp, and the constant-velocity ablation
// (constant_velocity.hpp). docs/paper-map.md maps every equation and line to its function.

#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/core/solution.hpp"
#include "canyon/fusion/alignment_schedule.hpp"
#include "canyon/fusion/false_fix_guard.hpp"
#include "canyon/fusion/fusion_geometry.hpp"
#include "canyon/fusion/fusion_options.hpp"
#include "canyon/fusion/heading_free_fill_in.hpp"
#include "canyon/fusion/innovation_gates.hpp"
#include "canyon/fusion/integrity_check.hpp"
#include "canyon/fusion/prior_recovery.hpp"
#include "canyon/fusion/vio_prediction.hpp"
#include "canyon/fusion/vio_track.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/rtk/engine.hpp"

namespace canyon::fusion {

struct FusionEpoch {
  core::Solution solution;  ///< Fixed, Float, VioFillIn, or (fallback) the RTK filter's
  double hdop = 0.0;
  bool aided = false;                        ///< the VIO (or constant-velocity) prediction was used
  std::string note;                          ///< why the epoch is not fixed
  std::vector<core::SatelliteId> rejected;   ///< satellites gated out of the update (innovation, post-fit)
  std::vector<core::SatelliteId> ar_pruned;  ///< satellites pruned by the ambiguity resolution
  rtk::RtkEpoch rtk;                         ///< the RTK filter's epoch (float solution, prior, DD rows)
};

struct FusionStats {
  int epochs = 0;
  int aided = 0;
  int fixed = 0;
  int fill_in = 0;
  int fallback = 0;  ///< epochs solved by the RTK filter's own motion model (not aligned, no VIO)
  int no_vio = 0;    ///< epochs without a VIO pose
  int float_rejected_no_phase = 0;
  int float_rejected_post_fit = 0;
  int float_rejected_prior = 0;
  int guard_epochs = 0;               ///< epochs in which the false-fix guard refused at least one candidate
  int guard_candidates = 0;           ///< candidate fixes it refused
  int gated_rows = 0;                 ///< DD rows (code and phase) rejected by the innovation gates and post-fit checks
  int ambiguities_from_position = 0;  ///< ambiguities started from the position (rtk/ambiguity_prior.hpp)
  int cn0_screened = 0;               ///< signals removed by the C/N0 screen
  int undetermined_fix_epochs = 0;    ///< epochs in which a fix was refused for its position sigma
  int too_few_to_fix = 0;             ///< aided epochs whose fixable ambiguities came from fewer than 4 satellites
  int float_inconsistent = 0;         ///< aided epochs whose float failed the RTK filter's float consistency test
  int ar_pruned_epochs = 0;           ///< fixes obtained after pruning satellites by their ILS residual
  int reanchored = 0;                 ///< floats taken after max_prior_rejections (the prior had drifted)
  int widened = 0;                    ///< priors widened after gate_conflict_epochs
  double heading_folded_rad = 0.0;    ///< heading state: the sum of the heading corrections folded into T_EO
  double heading_sigma_rad = 0.0;     ///< heading state: the heading error's sigma after the last aided epoch
  double scale_error = 0.0;           ///< scale state: the VIO's scale error after the last aided epoch (relative)
  double scale_sigma = 0.0;           ///< scale state: its sigma
  int integrity_restarts = 0;         ///< integrity check: restarts from the single point
  int heading_free = 0;               ///< heading-free fill-in: epochs it filled
  AlignmentStats alignment;           ///< tries, rejections, accepted alignments, the calibration
  std::vector<std::string> notes;     ///< VIO segments, integrity restarts
};

class FusionEngine {
 public:
  FusionEngine(FusionOptions options, const rtk::RtkOptions& rtk_options, const gnss::EphemerisStore& ephemerides,
               const Eigen::Vector3d& p_E_base_m, VioTrack track);

  /// One rover epoch with the base epoch to use (nullptr if none). Error when no solution at all exists (no VIO
  /// prediction and no single-point solution). The stages below in order, then flush_alignment().
  Result<FusionEpoch> process(const core::ObsEpoch& rover, const core::ObsEpoch* base);

  // The stages of process(), for the staged pipeline (pipeline/epoch_pipeline.hpp). Per epoch, in this order:
  //   bridge(t) -> align(t, pose) -> predict() -> [if true] update() -> [if true] resolve() -> finish_epoch().
  // bridge() only reads the VIO track and may run ahead on another thread; the others change the engine's state and
  // run one epoch at a time.
  /// The VIO pose at GPST t (the track is on GPST through the time bridge), nullopt if none.
  [[nodiscard]] std::optional<VioPoseAt> bridge(const core::GpsTime& t) const;
  /// Algorithm 1, line 2: the pending (re)alignment of the previous epoch, this epoch's VIO segment bookkeeping.
  void align(const core::GpsTime& t, const std::optional<VioPoseAt>& pose);
  /// Algorithm 1, lines 3-5: the prior from the VIO (or the RTK filter's own motion model), the C/N0 screen's
  /// verdict on an aided epoch, the RTK filter's prediction. `geometry`: the epoch's geometry built ahead by a builder
  /// from make_geometry_builder() that saw every epoch before this one (nullptr: the engine builds it; do not mix the
  /// two in one run). Error as process(); true if the epoch goes on to update(), false if it goes straight to
  /// finish_epoch() (no base epoch, or the heading-free fill-in).
  Result<bool> predict(const core::ObsEpoch& rover, const core::ObsEpoch* base, const std::optional<VioPoseAt>& pose,
                       FusionGeometry* geometry = nullptr);
  /// A builder of the engine's epoch geometry (fusion_geometry.hpp), to run ahead of predict().
  [[nodiscard]] FusionGeometryBuilder make_geometry_builder() const;
  /// Algorithm 1, lines 6-7: the RTK filter's measurement update with the VIO gates; true if it goes on to resolve().
  bool update();
  /// Algorithm 1, lines 9-17: the RTK filter's candidate fixes, each decided by the fusion.
  void resolve();
  /// Algorithm 1, lines 8, 11, 16, 18, 22 and 24: float validation, the fill-in, the epoch's output; the alignment
  /// window's bookkeeping (after predict() succeeded, whatever update() and resolve() did).
  FusionEpoch finish_epoch();
  /// Runs an alignment left pending by the last epoch (end of the input).
  void flush_alignment() { schedule_.flush(); }

  // A live VIO stream (pipeline::LiveVio): poses appended while the stages run. The track is guarded by a
  // reader-writer lock: appends (the time bridge's thread) exclude the readers (bridge(), the prediction); forgetting
  // happens in align().
  /// Appends a pose at GPST t to the track (VioTrack::append); false if not after the last one.
  bool add_vio(const io::VioRecord& record, const core::GpsTime& t, std::string* note = nullptr, int clock_piece = 0);
  /// The track has the poses that make bridge(t) final (VioTrack::covers).
  [[nodiscard]] bool vio_covers(const core::GpsTime& t) const;
  /// The base position from the next epoch on (rtk::RtkEngine::set_base_position).
  void set_base_position(const Eigen::Vector3d& p_E_base_m) {
    engine_.set_base_position(p_E_base_m);
    geometry_builder_.set_base_position(p_E_base_m);
  }
  /// The lever arm t_IA in use (the prior until calibrated) (m, IMU frame).
  [[nodiscard]] const Eigen::Vector3d& lever_arm_m() const { return schedule_.lever_arm_m(); }
  /// The alignment T_EO in use, with the filter's heading corrections folded in (nullopt before the first one).
  [[nodiscard]] const std::optional<VioAlignment>& alignment() const { return schedule_.alignment(); }

  [[nodiscard]] const FusionStats& stats() const { return stats_; }
  /// Human-readable summary: alignments, calibration and lever-arm observability, validation and guard counts
  /// (fusion_report.cpp).
  [[nodiscard]] std::vector<std::string> report() const;

 private:
  /// The epoch's motion from the VIO (or the ablation's constant velocity) with its prior and gates.
  struct EpochAiding {
    rtk::ExternalMotion motion;
    VioInnovationGates gates;
    Prior prior;
  };
  /// Algorithm 1, lines 3-5 (nullopt: the RTK filter's own motion model).
  [[nodiscard]] std::optional<EpochAiding> predict_prior(const core::GpsTime& t, const std::optional<VioPoseAt>& pose);
  [[nodiscard]] std::optional<MotionPrediction> predict_from_vio(const std::optional<VioPoseAt>& pose,
                                                                 rtk::ExternalMotion& motion);
  /// Beyond the paper: the VIO scale-error state's noise and (re)start (PredictionOptions::scale_state).
  void couple_scale(rtk::ExternalMotion& motion, const Eigen::Vector3d& dp_E_m, int segment);
  /// The antenna's VIO increment from the track's pose at GPST t_from to `pose` (Eqs. 4-5), nullopt if the track has
  /// no pose at t_from in pose's segment.
  [[nodiscard]] std::optional<VioPoseAt> pose_before(const core::GpsTime& t_from, const VioPoseAt& pose) const;
  /// Line 8 with the prior recovery: the float's verdict ("" if valid); an invalid float is undone.
  std::string validate_epoch_float(const rtk::RtkEpoch& epoch);
  /// The output of an aided epoch: the filter's (fixed or float), or the fill-in.
  void aided_output(const rtk::RtkEpoch& epoch, FusionEpoch& out);
  /// The beyond-the-paper bookkeeping after an output: heading fold, integrity, heading-free anchor, windows.
  void after_output(const FusionEpoch& out);
  /// The heading-free fill-in of an epoch the RTK filter could not solve, if any.
  [[nodiscard]] std::optional<core::Solution> heading_free_solution(const core::GpsTime& t,
                                                                    const std::optional<VioPoseAt>& pose);
  FusionEpoch finish_heading_free();
  /// finish_epoch() of an epoch the RTK filter solved (or failed to).
  FusionEpoch finish_solved_epoch();
  void count_fix_refusals();
  void check_integrity(const Eigen::Vector3d& p_out_E_m);

  FusionOptions options_;
  rtk::RtkOptions rtk_options_;
  const gnss::EphemerisStore& ephemerides_;
  rtk::RtkEngine engine_;
  FusionGeometryBuilder geometry_builder_;  // predict() without a geometry built ahead
  VioTrack track_;
  mutable std::shared_mutex track_mutex_;  // see add_vio()
  FusionStats stats_;
  AlignmentSchedule schedule_;
  FalseFixGuard guard_;
  PriorRecovery recovery_;
  IntegrityCheck integrity_;
  HeadingFreeFillIn heading_free_;
  std::vector<core::Solution> last_solutions_;  // the last two outputs (constant-velocity prediction)
  // The epoch between the stages.
  core::GpsTime epoch_time_;
  std::optional<VioPoseAt> epoch_pose_;
  std::optional<EpochAiding> aiding_;                 // from predict() to finish_epoch(): the filter points to it
  std::optional<Eigen::Vector3d> epoch_spp_p_E_m_;    // the epoch's single point, if any
  std::optional<core::Solution> heading_free_epoch_;  // the epoch's heading-free fill-in, from predict()
  int scale_segment_ = -1;                            // the VIO segment the scale state was learnt on
};

}  // namespace canyon::fusion
