// When the VIO is aligned (see alignment_schedule.hpp).

#include "canyon/fusion/alignment_schedule.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace canyon::fusion {
namespace {

double sigma_3d(const Eigen::Matrix3d& P) {
  return std::sqrt(std::max(P.trace(), 0.0));
}

}  // namespace

std::string AlignmentScheduleOptions::validate() const {
  if (const std::string e = fit.validate(); !e.empty()) return "alignment: " + e;
  if (!(window_s > 0.0)) return "alignment_window_s must be > 0";
  if (!(interval_s >= 0.0) || !(realign_interval_s >= 0.0)) {
    return "alignment_interval_s and realign_interval_s must be >= 0";
  }
  if (!(max_window_sigma_m > 0.0)) return "max_window_sigma_m must be > 0";
  if (!lever_arm_prior_m.allFinite() || lever_arm_prior_m.norm() > 10.0) {
    return "lever_arm_prior_m must be finite and shorter than 10 m";
  }
  return {};
}

AlignmentSchedule::AlignmentSchedule(const AlignmentScheduleOptions& options, const CoarseAlignmentOptions& coarse,
                                     double fine_sigma_rad, AlignmentStats& stats)
    : options_(options),
      coarse_(coarse),
      fine_sigma_rad_(fine_sigma_rad),
      stats_(stats),
      t_IA_m_(options.lever_arm_prior_m) {}

std::optional<std::string> AlignmentSchedule::align_new_segment_or_reuse(const core::GpsTime& t,
                                                                         const std::optional<VioPoseAt>& pose) {
  flush();
  std::optional<std::string> note;
  if (pose && last_segment_ && *last_segment_ != pose->segment) {
    note = core::format_gpst(t) + ": new VIO segment " + std::to_string(pose->segment) +
           " (gap or reset): RTK motion model until it aligns";
  }
  if (pose) last_segment_ = pose->segment;
  if (alignment_ && pose && pose->segment != alignment_->segment) alignment_.reset();
  return note;
}

VioAlignment* AlignmentSchedule::alignment_for(const std::optional<VioPoseAt>& pose) {
  if (!alignment_ || !pose || pose->segment != alignment_->segment) return nullptr;
  return &*alignment_;
}

void AlignmentSchedule::remember(const core::GpsTime& t, const std::optional<VioPoseAt>& pose,
                                 const core::Solution& solution, bool aided) {
  if (pose && solution.status != core::SolutionStatus::VioFillIn && solution.status != core::SolutionStatus::None) {
    history_.push_back(
        WindowPoint{t, pose->T_OI, solution.p_E_m, solution.status, sigma_3d(solution.P_E_m2), pose->segment, aided});
  }
  const double keep_s = std::max({options_.window_s, coarse_.window_s}) + 1.0;
  while (!history_.empty() && t - history_.front().time > keep_s) history_.erase(history_.begin());
}

void AlignmentSchedule::flush() {
  if (!pending_) return;
  const Pending pending = std::move(*pending_);
  pending_.reset();
  if (pending.pose) align(pending.time, pending.pose->segment);
}

void AlignmentSchedule::align(const core::GpsTime& t, int segment) {
  const bool fine = alignment_ && alignment_->fine;
  const double interval = fine ? options_.realign_interval_s : options_.interval_s;
  if (last_try_ && t - *last_try_ < interval) return;
  last_try_ = t;
  const auto start = std::chrono::steady_clock::now();
  try_fine_alignment(t, segment);
  // Coarse alignment while no fine one holds.
  if (coarse_.enabled && !(alignment_ && alignment_->fine)) try_coarse(t, segment);
  stats_.cpu_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void AlignmentSchedule::try_fine_alignment(const core::GpsTime& t, int segment) {
  // The paper's: before any alignment the RTK solutions, fixed or float; afterwards fixed ones.
  const bool fine = alignment_ && alignment_->fine;
  const std::vector<AlignmentPoint> points = window(t, segment, alignment_.has_value());
  if (static_cast<int>(points.size()) < options_.fit.min_points) return;
  ++stats_.tries;
  std::vector<Eigen::Vector3d> positions;
  positions.reserve(points.size());
  for (const AlignmentPoint& p : points) positions.push_back(p.p_E_m);
  if (first_eigenvalue_ratio(positions) >= options_.fit.max_first_eigenvalue_ratio) {
    ++stats_.rejected_fer;
    return;
  }
  const bool first = !calibrated_ && options_.calibrate_lever_arm;
  Result<AlignmentResult> fit = first  ? align_and_calibrate(points, options_.lever_arm_prior_m, true, options_.fit)
                                : fine ? realign(points, t_IA_m_, alignment_->T_EO, options_.fit)
                                       : align_and_calibrate(points, t_IA_m_, false, options_.fit);
  if (!fit) return;
  if (!fit->qualifies(options_.fit)) {
    ++stats_.rejected_rmse;
    return;
  }
  if (first) {
    calibrated_ = true;
    t_IA_m_ = fit->t_IA_m;
    stats_.calibration = *fit;
  }
  alignment_ = VioAlignment{fit->T_EO, segment, fine_sigma_rad_, true, t};
  stats_.events.push_back(AlignmentEvent{t, first ? "initial" : (fine ? "realign" : "align"), fit->points,
                                         fit->first_eigenvalue_ratio, fit->rmse_m, fit->rmse_without_calibration_m,
                                         0.0});
}

void AlignmentSchedule::try_coarse(const core::GpsTime& t, int segment) {
  int points = 0;
  const auto coarse = try_coarse_alignment(history_, t, segment, alignment_, t_IA_m_, coarse_, options_.fit, points);
  if (!coarse) return;
  alignment_ = VioAlignment{coarse->T_EO, segment, coarse->yaw_sigma_rad, false, t};
  stats_.events.push_back(AlignmentEvent{t, "coarse", points, 0.0, coarse->rmse_m, coarse->rmse_m,
                                         coarse->yaw_sigma_rad * core::kRadToDeg});
}

std::vector<AlignmentPoint> AlignmentSchedule::window(const core::GpsTime& t, int segment, bool fixed_only) const {
  std::vector<AlignmentPoint> points;
  for (const WindowPoint& w : history_) {
    if (t - w.time > options_.window_s || w.segment != segment) continue;
    if (fixed_only ? w.status != core::SolutionStatus::Fixed
                   : (w.status != core::SolutionStatus::Fixed && w.status != core::SolutionStatus::Float)) {
      continue;
    }
    if (w.sigma_m > options_.max_window_sigma_m) continue;
    points.push_back(AlignmentPoint{w.T_OI, w.p_E_m});
  }
  return points;
}

}  // namespace canyon::fusion
