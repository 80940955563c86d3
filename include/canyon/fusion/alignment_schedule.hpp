#pragma once
// When the VIO is aligned to ECEF (Algorithm 1, line 2: AlignNewSegmentationOrReuseOldAlignment; the paper's Section
// "Alignment of VIO and GNSS with Extrinsics Calibration"; the fits themselves are in alignment.hpp).
//   - A VIO segment (vio_track.hpp: a gap, a jump or a reset starts a new one) drops the alignment of the old one: the
//     RTK filter's own motion model until a window of the new segment aligns.
//   - Until the first alignment, every interval_s, the last window_s of RTK solutions (fixed or float, 3D sigma <=
//     max_window_sigma_m) of the segment are fitted with the paper's two passes (T_EO from identity with t_IA = 0,
//     then T_EO and t_IA jointly: align_and_calibrate); the window qualifies when its FER < 0.97 and the fit's RMSE <
//     0.1 m. Afterwards every realign_interval_s a window of fixed solutions refreshes T_EO with t_IA held (realign:
//     the VIO drifts).
//   - Beyond the paper, while no fine alignment holds, the coarse alignment (coarse_alignment.hpp).
// The alignment that the paper runs after epoch k's solution runs at the start of epoch k+1's alignment stage
// (nothing happens in between, so the results are the same); flush() runs it at the end of the input.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/solution.hpp"
#include "canyon/core/time.hpp"
#include "canyon/fusion/alignment.hpp"
#include "canyon/fusion/coarse_alignment.hpp"
#include "canyon/fusion/heading_state.hpp"
#include "canyon/fusion/vio_track.hpp"

namespace canyon::fusion {

struct AlignmentScheduleOptions {
  AlignmentOptions fit;             ///< FER 0.97, RMSE 0.1 m (the paper's gates)
  double window_s = 6.0;            ///< an alignment window: the last this many seconds of solutions (s)
  double interval_s = 1.0;          ///< until aligned, try at most this often (s)
  double realign_interval_s = 5.0;  ///< once aligned, refresh T_EO this often (s)
  double max_window_sigma_m = 0.3;  ///< solutions with a larger 3-D position sigma do not join a window (m)
  bool calibrate_lever_arm = true;  ///< estimate t_IA in the first alignment (pass 2)
  Eigen::Vector3d lever_arm_prior_m = Eigen::Vector3d::Zero();  ///< t_IA prior (IMU frame, m)

  [[nodiscard]] std::string validate() const;
};

struct AlignmentEvent {
  core::GpsTime time;
  std::string kind;  ///< "coarse", "initial" (two passes, calibration), "align", "realign"
  int points = 0;
  double first_eigenvalue_ratio = 1.0;
  double rmse_m = 0.0;
  double rmse_without_calibration_m = 0.0;
  double yaw_sigma_deg = 0.0;  ///< coarse
};

struct AlignmentStats {
  int tries = 0;
  int rejected_fer = 0;
  int rejected_rmse = 0;
  std::vector<AlignmentEvent> events;          ///< accepted ones
  std::optional<AlignmentResult> calibration;  ///< the first (two-pass) alignment
  double cpu_s = 0.0;
};

class AlignmentSchedule {
 public:
  /// `fine_sigma_rad`: the heading sigma a fine alignment starts with (0: taken as exact; heading_state.hpp).
  AlignmentSchedule(const AlignmentScheduleOptions& options, const CoarseAlignmentOptions& coarse,
                    double fine_sigma_rad, AlignmentStats& stats);

  /// Algorithm 1, line 2, for epoch t: the pending (re)alignment of the last epoch, then a new VIO segment drops the
  /// alignment of the old one. The note of a new segment, if any.
  [[nodiscard]] std::optional<std::string> align_new_segment_or_reuse(const core::GpsTime& t,
                                                                      const std::optional<VioPoseAt>& pose);
  /// The alignment that holds for `pose`'s segment (nullptr if none).
  [[nodiscard]] VioAlignment* alignment_for(const std::optional<VioPoseAt>& pose);
  [[nodiscard]] std::optional<VioAlignment>& alignment() { return alignment_; }
  [[nodiscard]] const std::optional<VioAlignment>& alignment() const { return alignment_; }
  /// The lever arm t_IA in use (the prior until calibrated) (m, IMU frame).
  [[nodiscard]] const Eigen::Vector3d& lever_arm_m() const { return t_IA_m_; }

  /// An epoch's output joins the alignment windows (solutions with their VIO pose).
  void remember(const core::GpsTime& t, const std::optional<VioPoseAt>& pose, const core::Solution& solution,
                bool aided);
  /// After epoch t: its alignment is due at the next epoch's align_new_segment_or_reuse() (or flush()).
  void schedule(const core::GpsTime& t, const std::optional<VioPoseAt>& pose) { pending_ = Pending{t, pose}; }
  /// Runs the pending alignment now (end of the input).
  void flush();

 private:
  struct Pending {
    core::GpsTime time;
    std::optional<VioPoseAt> pose;
  };
  /// The paper's fits at the schedule, then the coarse one.
  void align(const core::GpsTime& t, int segment);
  void try_fine_alignment(const core::GpsTime& t, int segment);
  void try_coarse(const core::GpsTime& t, int segment);
  [[nodiscard]] std::vector<AlignmentPoint> window(const core::GpsTime& t, int segment, bool fixed_only) const;

  AlignmentScheduleOptions options_;
  CoarseAlignmentOptions coarse_;
  double fine_sigma_rad_;
  AlignmentStats& stats_;
  std::optional<VioAlignment> alignment_;
  Eigen::Vector3d t_IA_m_;
  bool calibrated_ = false;
  std::vector<WindowPoint> history_;  // recent solutions with their VIO poses (pruned to the longest window)
  std::optional<core::GpsTime> last_try_;
  std::optional<Pending> pending_;
  std::optional<int> last_segment_;
};

}  // namespace canyon::fusion
