#pragma once
// The VIO trajectory on GPST: poses T_OI with their covariances, split into segments, interpolated on SE(3) at
// GNSS epochs with the joint covariance of two interpolated poses.
//
// Segments. A new segment starts at a pose that is further from the previous one than a gap's threshold, the larger
// of max_gap_s and kGapIntervals times the stream's own pose interval (the median of the last intervals, so that a
// 1 Hz or 2 Hz VIO stream is used as it comes and a 10 Hz one keeps max_gap_s) (a gap), whose
// implied speed or rotation rate from the previous one exceeds max_speed_mps or max_rotation_rate_dps (a jump: the
// VIO reset or relocalised its odometry frame), or whose position covariance collapsed (trace below
// reset_covariance_ratio times the previous one's: the VIO restarted its covariance with its frame). T_EO belongs to
// one segment; the fusion re-aligns in a new one.
//
// Bridged gaps (max_bridged_gap_s, beyond the paper). A stream that stops and comes back in the same frame (a dropped
// link, a paused publisher) keeps its alignment: a gap up to max_bridged_gap_s after which the pose moved no faster
// than max_speed_mps and the covariance did not collapse stays in its segment. The poses either side are taken as
// uncorrelated (the increment across the gap gets both covariances) and the GNSS epochs inside it get the
// interpolation's error (interpolation_accel_mps2 over the whole gap: metres to hundreds of metres, no information).
// A VIO that restarted in a new frame after the gap shows it by a jump or a covariance reset (stitched, below).
//
// Stitching (stitch_frame_resets, beyond the paper). A jump (in position) or a covariance reset moves the VIO's
// odometry frame, not
// the device, whose pose is continuous over one pose interval: the poses from there on are mapped back into the
// frame before, T_OI <- F T_OI with F = T_pred T_first^-1 (T_pred: the pose before extrapolated by its last
// increment over the interval, T_first: the first pose in the new frame), and stay in the same segment, so the
// alignment holds through the reset. Their covariances are shifted by one matrix dP so that the first is
// P_before + Q (Q: the extrapolation's error, interpolation_accel_mps2 over the interval, per position axis) with
// cov(before, first) = P_before; increments inside the new frame keep their variances (dP cancels in them). A gap
// still starts a new segment (during a gap the device moves unseen), and so does a turn too fast with the position
// continuous (a frame rotated about anything but the device would move the position too: the device turned).
// A step of the time sync (time_bridge.hpp: the poses after it are mapped with another piece of the clock fit) is
// stitched the same way: the frame is the VIO's own, only the poses' times moved, so no increment spans the step and
// the alignment holds; the device's motion misplaced in time by the step (about its length times the speed) becomes
// part of F, for the GNSS to correct.
//
// Interpolation at time t between samples k and k+1 of one segment, a = (t - t_k) / (t_k+1 - t_k):
//   T(t) = T_k Exp(a Log(T_k^-1 T_k+1)),   xi(t) = J_T_Tk xi_k + J_T_Tk+1 xi_k+1   (core::se3_interpolate).
// At most extrapolation_s beyond the first or last sample of a segment, with a outside [0, 1].
//
// Joint covariance of two interpolated poses (from samples i, i+1 and j, j+1, i <= j): the covariances of the
// samples involved, Sigma_kk = P_k, Sigma_k,k+1 = C_k+1 (the file's cov(xi_k, xi_k+1); zero when absent), and for
// samples further apart the first-order propagation of an earlier pose's error through the relative motions in
// between (the Markov completion of the consecutive-pose covariances, exact for VIO whose drift is a random walk
// on the increments, as canyon's simulator and filter-based VIO):
//   Sigma_k,l = Sigma_k,l-1 A_l^T,  A_l = Ad(D_l^-1),  D_l = T_l-1^-1 T_l   (l > k + 1).
// Then cov([xi(t_a); xi(t_b)]) = J Sigma J^T with J the interpolation Jacobians (12 x 6 |samples|).
//
// Streaming (the live rover): poses are appended one by one (append(), segments assigned as they come, exactly as
// build() does) and the oldest forgotten (forget_before()); sample indices (VioPoseAt::lower) count every sample
// ever appended, so a pose interpolated before a forget stays valid as long as its samples are kept. covers(t) says
// when a pose at t is final: what pose_at(t) returns can no longer change with later samples.

#include <optional>
#include <string>
#include <vector>

#include "canyon/core/result.hpp"
#include "canyon/core/se3.hpp"
#include "canyon/core/time.hpp"
#include "canyon/fusion/time_bridge.hpp"
#include "canyon/io/vio_file.hpp"

namespace canyon::fusion {

using Matrix12d = Eigen::Matrix<double, 12, 12>;

struct VioTrackOptions {
  double max_gap_s = 0.5;                ///< consecutive poses further apart in time: a gap (new segment) (s)
  double max_speed_mps = 30.0;           ///< a larger implied speed between consecutive poses: a reset (m/s)
  double max_rotation_rate_dps = 720.0;  ///< a larger implied rotation rate: a reset (deg/s)
  double reset_covariance_ratio = 0.01;  ///< position covariance trace falling below this ratio: a reset
  double extrapolation_s = 0.05;         ///< largest extrapolation beyond a segment's first or last pose (s)
  bool use_cross_covariance = true;      ///< false: consecutive-pose cross-covariances taken as zero
  /// Acceleration the constant-twist interpolation between two poses misses (1 sigma, m/s^2): a pose interpolated at
  /// fraction x of an interval dt gets a position variance (q x (1 - x) dt^2 / 2)^2 per axis (q dt^2 / 8 at the
  /// midpoint: 1.25 mm at 10 Hz, 12.5 cm at 1 Hz for q = 1). Two poses in one interval share its missed
  /// acceleration, so their errors are fully correlated (an increment within an interval gets only the difference);
  /// poses in different intervals are taken as independent. 0: interpolation taken as exact.
  double interpolation_accel_mps2 = 1.0;
  bool stitch_frame_resets = true;  ///< map a jump's or reset's new frame back into the old one (above)
  double max_bridged_gap_s = 60.0;  ///< a longer gap is a new segment; a shorter one in the same frame is bridged (s)

  [[nodiscard]] std::string validate() const;
};

/// A gap is longer than this many of the stream's own pose intervals (and than max_gap_s).
inline constexpr double kGapIntervals = 3.0;

/// The stream's own pose interval, to judge gaps by: the median of the last kWindow intervals between poses.
class PoseIntervals {
 public:
  static constexpr int kWindow = 21;
  /// The interval before `dt_s` joins: the median of those seen; for the first, dt_s up to 1 s (a stream of 1 Hz
  /// and faster is taken at its rate; a longer first interval is judged against 1 s).
  [[nodiscard]] double nominal_s(double dt_s) const;
  void add(double dt_s);

 private:
  std::vector<double> recent_;  // at most kWindow, oldest first
};

/// The correction from the VIO's current odometry frame to the one it is stitched to (identity until a reset).
struct FrameStitch {
  core::Pose F;                                ///< T_OI (stitched) = F T_OI (as given)
  core::Matrix6d dP = core::Matrix6d::Zero();  ///< added to each P and C_previous
  int count = 0;                               ///< resets stitched
};

struct VioTrackSample {
  double t_s = 0.0;  ///< GPST seconds after the track's reference time
  core::Pose T_OI;
  core::Matrix6d P = core::Matrix6d::Zero();
  core::Matrix6d C_previous = core::Matrix6d::Zero();  ///< cov(xi of the previous sample, xi of this one)
  int segment = 0;
  int line = 0;         ///< in the VIO file
  int clock_piece = 0;  ///< the time bridge's piece (or steps seen) that mapped it: a change is a new segment
};

/// A pose interpolated at one time: T = T_k Exp(a Log(T_k^-1 T_k+1)) with the Jacobians on both samples.
struct VioPoseAt {
  double t_s = 0.0;
  int lower = 0;  ///< index of sample k (k + 1 is the upper one)
  double a = 0.0;
  int segment = 0;
  core::Pose T_OI;
  core::Matrix6d J_lower = core::Matrix6d::Identity();
  core::Matrix6d J_upper = core::Matrix6d::Zero();
};

class VioTrack {
 public:
  /// Maps the file's device times to GPST, keeps the poses, splits segments. `notes` receive one line per gap or
  /// reset. Error if no pose is left.
  static Result<VioTrack> build(const io::VioFile& file, const TimeBridge& bridge, const VioTrackOptions& options,
                                std::vector<std::string>& notes);
  /// From samples directly (tests); times relative to `reference`.
  static VioTrack from_samples(std::vector<VioTrackSample> samples, core::GpsTime reference,
                               const VioTrackOptions& options = {});
  /// An empty track that poses are appended to (the reference time is the first pose's).
  static VioTrack streaming(const VioTrackOptions& options);

  /// Appends the pose of `record` at GPST t, its segment assigned as build() would (a new segment: `note`, if
  /// given, receives why); `clock_piece` counts the time-sync steps its mapping follows (CausalTimeBridge::
  /// steps_seen()): a change breaks the track there. False, and nothing appended, when t is not after the last pose's
  /// time.
  bool append(const io::VioRecord& record, const core::GpsTime& t, std::string* note = nullptr, int clock_piece = 0);
  /// Forgets the samples before GPST t except the last one before it (memory of a long live run).
  void forget_before(const core::GpsTime& t);
  /// pose_at(t) is final: a sample after t exists, and when it starts a segment, the one after it too.
  [[nodiscard]] bool covers(const core::GpsTime& t) const;
  [[nodiscard]] bool empty() const { return samples_.empty(); }

  /// The pose at GPST t, nullopt outside every segment (beyond extrapolation_s) or in a gap.
  [[nodiscard]] std::optional<VioPoseAt> pose_at(const core::GpsTime& t) const;
  /// Joint covariance of [xi(a); xi(b)] (12 x 12); a and b must be of one segment. `with_interpolation` false: without
  /// the interpolation's error (a filter that carries it as a state, vio_prediction.hpp).
  [[nodiscard]] Matrix12d joint_covariance(const VioPoseAt& a, const VioPoseAt& b,
                                           bool with_interpolation = true) const;
  /// Position sigma per axis of the interpolation error of `p` (interpolation_accel_mps2; 0 at a sample).
  [[nodiscard]] double interpolation_sigma_m(const VioPoseAt& p) const;
  /// Covariance of xi(a) alone.
  [[nodiscard]] core::Matrix6d covariance(const VioPoseAt& a) const;

  [[nodiscard]] const std::vector<VioTrackSample>& samples() const { return samples_; }
  [[nodiscard]] core::GpsTime reference() const { return reference_; }
  [[nodiscard]] core::GpsTime first_time() const { return reference_ + samples_.front().t_s; }
  [[nodiscard]] core::GpsTime last_time() const { return reference_ + samples_.back().t_s; }
  [[nodiscard]] int segments() const { return samples_.empty() ? 0 : samples_.back().segment + 1; }

 private:
  VioTrack(std::vector<VioTrackSample> samples, core::GpsTime reference, VioTrackOptions options)
      : samples_(std::move(samples)), reference_(reference), options_(options) {}
  /// cov(xi_k, xi_l) for samples k <= l of one segment (indices as in VioPoseAt).
  [[nodiscard]] core::Matrix6d sample_covariance(int k, int l) const;
  [[nodiscard]] const VioTrackSample& sample(int index) const {
    return samples_[static_cast<std::size_t>(index - forgotten_)];
  }

  std::vector<VioTrackSample> samples_;
  core::GpsTime reference_;
  VioTrackOptions options_;
  PoseIntervals intervals_;  // of the appended poses (streaming)
  FrameStitch stitch_;       // of the appended poses (streaming)
  int forgotten_ = 0;        // samples forgotten from the front: samples_[0] has index forgotten_
};

/// Why `next` starts a new segment after `previous` (a gap, a jump, a covariance reset), empty if it does not; a gap
/// is judged against max(options.max_gap_s, kGapIntervals nominal_interval_s); `kind`, if given, receives which.
enum class SegmentBreak { None, Gap, Jump, Turn, CovarianceReset, TimeSyncStep };
std::string segment_break(const VioTrackSample& previous, const VioTrackSample& next, const VioTrackOptions& options,
                          double nominal_interval_s = 0.0, SegmentBreak* kind = nullptr);

/// The median interval between consecutive samples (0 with fewer than two): the stream's rate, for reports.
[[nodiscard]] double median_interval_s(const std::vector<VioTrackSample>& samples);

/// Splits samples into segments (gaps, jumps, covariance resets), appending a note for each break.
void assign_segments(std::vector<VioTrackSample>& samples, const VioTrackOptions& options,
                     const core::GpsTime& reference, std::vector<std::string>* notes);

}  // namespace canyon::fusion
