// The paper's Algorithm 1 on canyon's RTK engine (see fusion_engine.hpp).

#include "canyon/fusion/fusion_engine.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/core/statistics.hpp"
#include "canyon/fusion/vio_prediction.hpp"

namespace canyon::fusion {
namespace {

/// The heading error's sigma after an integrity restart: wide, but within what its linearised state handles.
constexpr double kRestartHeadingSigmaRad = 10.0 * core::kDegToRad;

std::string when(const core::GpsTime& t) {
  const core::GpsTime n = t.normalized();
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "GPST %d %.1f", n.week, n.tow_s);
  return buffer;
}

std::string format(const char* fmt, double a, double b = 0.0, double c = 0.0, double d = 0.0) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, fmt, a, b, c, d);
  return buffer;
}

/// d^T S^-1 d, or infinity if S is not positive definite.
double chi2(const Eigen::Vector3d& d, const Eigen::Matrix3d& S) {
  const Eigen::LLT<Eigen::Matrix3d> llt(0.5 * (S + S.transpose()));
  if (llt.info() != Eigen::Success) return std::numeric_limits<double>::infinity();
  return d.dot(llt.solve(d));
}

double sigma_3d(const Eigen::Matrix3d& P) {
  return std::sqrt(std::max(P.trace(), 0.0));
}

}  // namespace

const char* prediction_name(Prediction p) {
  return p == Prediction::Vio ? "vio" : "constant_velocity";
}

const char* innovation_gate_name(InnovationGate g) {
  switch (g) {
    case InnovationGate::Off: return "off";
    case InnovationGate::Paper: return "paper";
    case InnovationGate::ChiSquare: return "chi_square";
    case InnovationGate::Both: return "both";
  }
  return "?";
}

std::string FusionOptions::validate() const {
  if (const std::string e = time_sync.validate(); !e.empty()) return "time_sync: " + e;
  if (const std::string e = vio.validate(); !e.empty()) return "vio: " + e;
  if (const std::string e = alignment.validate(); !e.empty()) return "alignment: " + e;
  if (std::string e = cn0.validate(); !e.empty()) return e;
  if (!(alignment_window_s > 0.0)) return "alignment_window_s must be > 0";
  if (!(alignment_interval_s >= 0.0) || !(realign_interval_s >= 0.0)) {
    return "alignment_interval_s and realign_interval_s must be >= 0";
  }
  if (!(max_window_sigma_m > 0.0)) return "max_window_sigma_m must be > 0";
  if (!lever_arm_prior_m.allFinite() || lever_arm_prior_m.norm() > 10.0) {
    return "lever_arm_prior_m must be finite and shorter than 10 m";
  }
  if (!(coarse_window_s > 0.0) || !(coarse_min_spread_m > 0.0) || !(coarse_max_yaw_sigma_deg > 0.0)) {
    return "coarse_window_s, coarse_min_spread_m and coarse_max_yaw_sigma_deg must be > 0";
  }
  if (!(integrity_window_s > 0.0) || integrity_min_points < 1 || !(integrity_max_offset_m > 0.0)) {
    return "integrity_window_s and integrity_max_offset_m must be > 0 and integrity_min_points >= 1";
  }
  if (!(heading_random_walk_deg_per_sqrt_km >= 0.0) || !(fine_heading_sigma_deg > 0.0)) {
    return "heading_random_walk_deg_per_sqrt_km must be >= 0 and fine_heading_sigma_deg > 0";
  }
  if (!(constant_increment_sigma_m > 0.0)) return "constant_increment_sigma_m must be > 0";
  if (!(gate_motion_factor > 0.0) || !(min_gate_m > 0.0) || !(gate_sigmas > 0.0)) {
    return "gate_motion_factor, min_gate_m and gate_sigmas must be > 0";
  }
  if (max_prior_rejections < 0 || gate_conflict_epochs < 1 || !(reanchor_sigma_m > 0.0)) {
    return "max_prior_rejections must be >= 0, gate_conflict_epochs >= 1 and reanchor_sigma_m > 0";
  }
  if (!(max_fix_sigma_m > 0.0)) return "max_fix_sigma_m must be > 0";
  if (!(vio_keep_s > 0.0)) return "vio_keep_s must be > 0";
  if (!(max_post_fit_normalised > 0.0) || !(max_prior_chi2 > 0.0) || !(false_fix_chi2 > 0.0)) {
    return "max_post_fit_normalised, max_prior_chi2 and false_fix_chi2 must be > 0";
  }
  return {};
}

namespace {

/// The RTK engine's options with the heading error state when the fusion estimates it.
rtk::RtkOptions with_heading_state(rtk::RtkOptions rtk_options, const FusionOptions& options) {
  rtk_options.aiding_heading_state = options.heading_state && options.prediction == Prediction::Vio;
  return rtk_options;
}

}  // namespace

FusionEngine::FusionEngine(FusionOptions options, const rtk::RtkOptions& rtk_options,
                           const gnss::EphemerisStore& ephemerides, const Eigen::Vector3d& p_E_base_m, VioTrack track)
    : options_(std::move(options)),
      rtk_options_(rtk_options),
      ephemerides_(ephemerides),
      engine_(with_heading_state(rtk_options, options_), ephemerides, p_E_base_m),
      geometry_builder_(make_geometry_builder()),
      track_(std::move(track)),
      t_IA_m_(options_.lever_arm_prior_m) {}

std::optional<FusionEngine::EpochAiding> FusionEngine::make_aiding(const core::GpsTime& t,
                                                                   const std::optional<VioPoseAt>& pose) {
  prior_.reset();
  if (!engine_.has_position() || !engine_.state_time()) return std::nullopt;
  const core::GpsTime t_state = *engine_.state_time();
  EpochAiding epoch_aiding;
  rtk::ExternalMotion& aiding = epoch_aiding.motion;
  const Eigen::Vector3d p_state = engine_.position_E_m();
  if (options_.prediction == Prediction::Vio) {
    if (!alignment_ || !pose || pose->segment != alignment_->segment) return std::nullopt;
    const Eigen::Vector3d up_E =
        core::rotation_enu_from_ecef(core::ecef_to_geodetic(p_state)).row(2).transpose();  // local vertical
    const bool heading_state = options_.heading_state;
    const std::optional<VioIncrement> increment = increment_since(
        t_state, *pose, alignment_->T_EO.rotation(), heading_state ? 0.0 : alignment_->yaw_sigma_rad, up_E);
    if (!increment) return std::nullopt;
    const VioIncrement& inc = *increment;
    aiding.delta_p_E_m = inc.dp_E_m;
    if (heading_state) {
      const double walk_rad = options_.heading_random_walk_deg_per_sqrt_km * core::kDegToRad;
      aiding.dp_d_heading_E_m = up_E.cross(inc.dp_E_m);
      aiding.heading_noise_rad2 = walk_rad * walk_rad * inc.dp_E_m.norm() / 1000.0;
      aiding.heading_variance_rad2 = alignment_->yaw_sigma_rad * alignment_->yaw_sigma_rad;
      aiding.restart_heading = !alignment_->heading_started;
      alignment_->heading_started = true;
    }
    if (options_.vio_covariance) {
      aiding.Q_E_m2 = inc.cov_E_m2;
    } else {
      aiding.Q_E_m2 =
          Eigen::Matrix3d::Identity() * options_.constant_increment_sigma_m * options_.constant_increment_sigma_m;
    }
  } else {
    // Constant velocity from the last two solutions.
    if (last_solutions_.size() < 2) return std::nullopt;
    const core::Solution& a = last_solutions_[0];
    const core::Solution& b = last_solutions_[1];
    const double dt_k = b.time - a.time;
    const double dt = t - t_state;
    if (!(dt_k > 0.0) || dt_k > 5.0 || dt < 0.0) return std::nullopt;
    const Eigen::Vector3d v = (b.p_E_m - a.p_E_m) / dt_k;
    if (!(v.norm() <= options_.vio.max_speed_mps)) return std::nullopt;  // a jump between solutions, not a motion
    aiding.delta_p_E_m = v * dt;
    const double sa = rtk_options_.accel_sigma_h_mps2;
    aiding.Q_E_m2 =
        Eigen::Matrix3d::Identity() * sa * sa * dt * dt * dt / 3.0 + (a.P_E_m2 + b.P_E_m2) * (dt / dt_k) * (dt / dt_k);
  }
  if (widen_next_prior_) {
    aiding.Q_E_m2 += Eigen::Matrix3d::Identity() * options_.reanchor_sigma_m * options_.reanchor_sigma_m;
    widen_next_prior_ = false;
    ++stats_.widened;
  }
  Prior prior{p_state + aiding.delta_p_E_m, engine_.position_covariance_E_m2() + aiding.Q_E_m2};
  prior_ = prior;
  const double motion_m = aiding.delta_p_E_m.norm();
  if (options_.gate == InnovationGate::Paper || options_.gate == InnovationGate::Both) {
    epoch_aiding.gate.max_phase_innovation_m = std::max(options_.gate_motion_factor * motion_m, options_.min_gate_m);
  }
  if (options_.gate == InnovationGate::ChiSquare || options_.gate == InnovationGate::Both) {
    epoch_aiding.gate.max_normalised_innovation = options_.gate_sigmas;
  }
  return epoch_aiding;
}

bool FusionEngine::accept_fix(const rtk::FixCandidate& fix) {
  if (!fix.position_ok) return false;
  const Eigen::Vector3d& p_fix = fix.p_E_m;
  const Eigen::Matrix3d& P_fix = fix.P_E_m2;
  const double bound = options_.false_fix_guard ? options_.false_fix_chi2 : -1.0;
  const double max_variance = options_.max_fix_sigma_m * options_.max_fix_sigma_m;
  if (Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(P_fix, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff() >
      max_variance) {
    ++undetermined_fixes_epoch_;
    return false;
  }
  if (bound < 0.0 || chi2(p_fix - prior_->p_E_m, prior_->P_E_m2 + P_fix) <= bound) return true;
  ++guard_rejections_epoch_;
  return false;
}

bool VioGates::passes(const rtk::DdInnovation& row) const {
  const std::optional<double>& fixed_gate = row.phase() ? max_phase_innovation_m : max_code_innovation_m;
  if (!fixed_gate && !max_normalised_innovation) return true;
  const double hPh = row.predicted_variance_m2();
  const double r = row.measurement_variance_m2();
  const double v = std::abs(row.innovation_m());
  // A fixed gate judges only rows whose prediction is good to a third of it (not a new ambiguity).
  if (fixed_gate && 9.0 * hPh <= *fixed_gate * *fixed_gate && v > *fixed_gate) return false;
  return !(max_normalised_innovation && v > *max_normalised_innovation * std::sqrt(hPh + r));
}

std::string FusionEngine::validate_float(const rtk::RtkEpoch& epoch) const {
  if (epoch.num_dd_measurements == 0) return "no double-differenced phase";
  if (epoch.max_post_fit_normalised > options_.max_post_fit_normalised) {
    return format("post-fit residual %.1f times the rejection threshold", epoch.max_post_fit_normalised);
  }
  const double c = chi2(epoch.float_p_E_m - epoch.prior_p_E_m, epoch.prior_P_E_m2);
  if (c > options_.max_prior_chi2) {
    return format("float %.2f m from the VIO prior (chi-square %.0f)", (epoch.float_p_E_m - epoch.prior_p_E_m).norm(),
                  c);
  }
  return {};
}

Result<FusionEpoch> FusionEngine::process(const core::ObsEpoch& rover, const core::ObsEpoch* base) {
  const std::optional<VioPoseAt> pose = bridge(rover.time);
  align(rover.time, pose);
  auto more = predict(rover, base, pose);
  if (more && *more && update()) resolve();
  Result<FusionEpoch> out = more ? Result<FusionEpoch>(finish_epoch()) : Result<FusionEpoch>(more.error());
  flush_alignment();
  return out;
}

std::optional<VioPoseAt> FusionEngine::bridge(const core::GpsTime& t) const {
  const std::shared_lock lock(track_mutex_);
  return track_.pose_at(t);
}

bool FusionEngine::add_vio(const io::VioRecord& record, const core::GpsTime& t, std::string* note) {
  const std::unique_lock lock(track_mutex_);
  return track_.append(record, t, note);
}

bool FusionEngine::vio_covers(const core::GpsTime& t) const {
  const std::shared_lock lock(track_mutex_);
  return track_.covers(t);
}

void FusionEngine::align(const core::GpsTime& t, const std::optional<VioPoseAt>& pose) {
  flush_alignment();
  {
    // Epochs still in the pipeline are later than t; the prediction reaches back to the last epoch only.
    const std::unique_lock lock(track_mutex_);
    track_.forget_before(t - options_.vio_keep_s);
  }
  ++stats_.epochs;
  if (!pose) ++stats_.no_vio;
  if (pose && last_segment_ && *last_segment_ != pose->segment) {
    stats_.notes.push_back(when(t) + ": new VIO segment " + std::to_string(pose->segment) +
                           " (gap or reset): RTK motion model until it aligns");
  }
  if (pose) last_segment_ = pose->segment;
  if (alignment_ && pose && pose->segment != alignment_->segment) alignment_.reset();
}

void FusionEngine::flush_alignment() {
  if (!pending_alignment_) return;
  const PendingAlignment pending = std::move(*pending_alignment_);
  pending_alignment_.reset();
  update_alignment(pending.time, pending.pose);
}

Result<bool> FusionEngine::predict(const core::ObsEpoch& rover, const core::ObsEpoch* base,
                                   const std::optional<VioPoseAt>& pose, FusionGeometry* geometry) {
  epoch_time_ = rover.time;
  epoch_pose_ = pose;
  heading_free_epoch_.reset();
  guard_rejections_epoch_ = 0;
  undetermined_fixes_epoch_ = 0;
  aiding_ = make_aiding(rover.time, pose);
  std::optional<FusionGeometry> own_geometry;
  if (geometry == nullptr) geometry = &own_geometry.emplace(geometry_builder_.build(rover, base));
  if (aiding_ && geometry->screened_rover_obs) {
    stats_.cn0_screened += geometry->screened;
    geometry->rtk.rover_obs = std::move(*geometry->screened_rover_obs);
    geometry->screened_rover_obs.reset();
  }
  epoch_spp_p_E_m_.reset();
  if (geometry->rtk.spp) epoch_spp_p_E_m_ = geometry->rtk.spp->p_E_m;
  auto more = engine_.predict(rover, base, aiding_ ? &aiding_->motion : nullptr, &geometry->rtk);
  if (!more) {
    if (!aiding_) heading_free_epoch_ = heading_free_solution(rover.time, pose);
    if (heading_free_epoch_) return false;  // finish_epoch() outputs it
    count_fix_rejections();
    pending_alignment_ = PendingAlignment{rover.time, pose};
  }
  return more;
}

FusionGeometryBuilder FusionEngine::make_geometry_builder() const {
  return FusionGeometryBuilder(engine_.geometry_options(), options_.cn0, ephemerides_, engine_.base_position_E_m());
}

bool FusionEngine::update() {
  return engine_.update(aiding_ ? &aiding_->gate : nullptr);
}

void FusionEngine::resolve() {
  if (!aiding_) {
    engine_.resolve();
    return;
  }
  rtk::FixSearch& search = engine_.propose_fixes();
  while (const rtk::FixCandidate* candidate = search.next()) search.decide(accept_fix(*candidate));
  engine_.conclude_fixes();
}

void FusionEngine::count_fix_rejections() {
  if (undetermined_fixes_epoch_ > 0) ++stats_.undetermined_fix_epochs;
  if (guard_rejections_epoch_ > 0) {
    ++stats_.guard_epochs;
    stats_.guard_candidates += guard_rejections_epoch_;
  }
}

std::optional<VioIncrement> FusionEngine::increment_since(const core::GpsTime& t_from, const VioPoseAt& pose,
                                                          const Eigen::Matrix3d& R_EO, double yaw_sigma_rad,
                                                          const Eigen::Vector3d& up_E) const {
  const std::shared_lock lock(track_mutex_);
  const std::optional<VioPoseAt> before = track_.pose_at(t_from);
  if (!before || before->segment != pose.segment) return std::nullopt;
  return vio_increment(before->T_OI, pose.T_OI, track_.joint_covariance(*before, pose), t_IA_m_, R_EO, yaw_sigma_rad,
                       up_E);
}

std::optional<core::Solution> FusionEngine::heading_free_solution(const core::GpsTime& t,
                                                                  const std::optional<VioPoseAt>& pose) {
  if (!options_.heading_free_fill_in || options_.prediction != Prediction::Vio || !pose || !heading_free_ ||
      heading_free_->segment != pose->segment) {
    return std::nullopt;
  }
  HeadingFreeTrack& track = *heading_free_;
  // R_EO = I: only the increment in O and its covariance are used, the vertical of which no heading changes.
  const std::optional<VioIncrement> inc = increment_since(track.time, *pose, Eigen::Matrix3d::Identity());
  if (!inc) return std::nullopt;
  track.dp_O_m += inc->dp_O_m;
  track.var_up_m2 += inc->cov_O_m2(2, 2);
  track.time = t;
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(core::ecef_to_geodetic(track.p_E_m));
  const double var_horizontal_m2 = track.dp_O_m.head<2>().squaredNorm() / 2.0;  // a circle of radius h
  core::Solution s;
  s.time = t;
  s.status = core::SolutionStatus::VioFillIn;
  s.p_E_m = track.p_E_m + R_NE.row(2).transpose() * track.dp_O_m.z();
  s.P_E_m2 = track.P_E_m2 + R_NE.transpose() *
                                Eigen::Vector3d(var_horizontal_m2, var_horizontal_m2, track.var_up_m2).asDiagonal() *
                                R_NE;
  return s;
}

FusionEpoch FusionEngine::finish_heading_free() {
  count_fix_rejections();
  FusionEpoch out;
  out.solution = *heading_free_epoch_;
  heading_free_epoch_.reset();
  out.note = "before an alignment: the heading unknown";  // the status says VIO fill-in
  ++stats_.heading_free;
  spp_offsets_.clear();
  pending_alignment_ = PendingAlignment{epoch_time_, epoch_pose_};
  return out;
}

FusionEpoch FusionEngine::finish_epoch() {
  if (heading_free_epoch_) return finish_heading_free();
  const rtk::RtkEpoch epoch = engine_.take_epoch();
  const rtk::RtkEpoch* result = &epoch;
  count_fix_rejections();
  FusionEpoch out;
  stats_.gated_rows += static_cast<int>(result->rejected.size());
  out.hdop = result->hdop;
  out.note = result->note;
  if (aiding_ && prior_) {
    out.aided = true;
    ++stats_.aided;
    std::string invalid;
    if (!result->aided) {
      invalid = result->note.empty() ? "no update" : result->note;  // returned before its time update: state kept
    } else {
      invalid = validate_float(*result);
      const bool only_prior = !invalid.empty() && result->num_dd_measurements > 0 &&
                              result->max_post_fit_normalised <= options_.max_post_fit_normalised;
      prior_rejections_ = only_prior ? prior_rejections_ + 1 : 0;
      if (only_prior && prior_rejections_ > options_.max_prior_rejections) {
        invalid.clear();  // the VIO prior drifted away from a consistent GNSS solution: GNSS re-anchors it
        prior_rejections_ = 0;
        ++stats_.reanchored;
      }
      if (!invalid.empty()) {
        if (result->num_dd_measurements == 0) {
          ++stats_.float_rejected_no_phase;
        } else if (!only_prior) {
          ++stats_.float_rejected_post_fit;
        } else {
          ++stats_.float_rejected_prior;
        }
        engine_.revert_to_prior();
      }
      const auto used = result->num_dd_measurements + result->num_dd_code_measurements;
      gate_conflicts_ = static_cast<int>(result->rejected.size()) > used ? gate_conflicts_ + 1 : 0;
      if (gate_conflicts_ >= options_.gate_conflict_epochs) {
        widen_next_prior_ = true;
        gate_conflicts_ = 0;
      }
    }
    if (!invalid.empty()) {
      // Algorithm 1, line 22: the prior, i.e. the aligned VIO fill-in.
      core::Solution& s = out.solution;
      s = result->solution;
      if (s.status == core::SolutionStatus::None) s.time = epoch_time_;
      s.status = core::SolutionStatus::VioFillIn;
      s.p_E_m = result->aided ? result->prior_p_E_m : prior_->p_E_m;
      s.P_E_m2 = result->aided ? result->prior_P_E_m2 : prior_->P_E_m2;
      s.ratio = 0.0;
      out.note = invalid;  // the status says VIO fill-in
      ++stats_.fill_in;
    } else {
      out.solution = result->solution;
      if (!result->ar_pruned.empty() && out.solution.status == core::SolutionStatus::Fixed) ++stats_.ar_pruned_epochs;
      if (result->too_few_to_fix) ++stats_.too_few_to_fix;
      if (result->float_variance_factor > 1.0) ++stats_.float_inconsistent;
    }
  } else {
    out.solution = result->solution;
    ++stats_.fallback;
  }
  if (out.solution.status == core::SolutionStatus::Fixed) ++stats_.fixed;
  if (out.aided) fold_heading_error();
  if (out.aided && out.solution.status != core::SolutionStatus::None) {
    check_integrity(out.solution.p_E_m);
  } else {
    spp_offsets_.clear();
  }
  out.rejected = result->rejected;
  out.ar_pruned = result->ar_pruned;
  out.rtk = epoch;

  // Remember the solution with its VIO pose for the alignment windows, and for the constant-velocity prediction.
  const std::optional<VioPoseAt>& pose = epoch_pose_;
  if (pose && out.solution.status != core::SolutionStatus::VioFillIn &&
      out.solution.status != core::SolutionStatus::None) {
    history_.push_back(WindowPoint{epoch_time_, pose->T_OI, out.solution.p_E_m, out.solution.status,
                                   sigma_3d(out.solution.P_E_m2), pose->segment, out.aided});
  }
  if (pose && out.solution.status != core::SolutionStatus::None) {
    heading_free_ = HeadingFreeTrack{out.solution.p_E_m, out.solution.P_E_m2, Eigen::Vector3d::Zero(), 0.0,
                                     epoch_time_,        pose->segment};
  }
  const double keep_s = std::max({options_.alignment_window_s, options_.coarse_window_s}) + 1.0;
  while (!history_.empty() && epoch_time_ - history_.front().time > keep_s) history_.erase(history_.begin());
  if (out.solution.status == core::SolutionStatus::Fixed || out.solution.status == core::SolutionStatus::Float) {
    last_solutions_.push_back(out.solution);
    if (last_solutions_.size() > 2) last_solutions_.erase(last_solutions_.begin());
  }
  pending_alignment_ = PendingAlignment{epoch_time_, pose};
  return out;
}

void FusionEngine::fold_heading_error() {
  if (!options_.heading_state || !alignment_) return;
  const std::optional<rtk::RtkEngine::HeadingError> heading = engine_.take_heading_error();
  if (!heading) return;
  const Eigen::Vector3d p_E_m = engine_.position_E_m();
  const Eigen::Vector3d up_E = core::rotation_enu_from_ecef(core::ecef_to_geodetic(p_E_m)).row(2).transpose();
  const Eigen::Quaterniond q_psi(Eigen::AngleAxisd(heading->psi_rad, up_E));
  core::Pose& T_EO = alignment_->T_EO;
  T_EO = core::Pose{(q_psi * T_EO.q).normalized(), q_psi * (T_EO.p - p_E_m) + p_E_m};
  alignment_->yaw_sigma_rad = std::sqrt(heading->variance_rad2);
  stats_.heading_folded_rad += heading->psi_rad;
  stats_.heading_sigma_rad = alignment_->yaw_sigma_rad;
}

void FusionEngine::check_integrity(const Eigen::Vector3d& p_out_E_m) {
  if (!options_.integrity_check || !epoch_spp_p_E_m_) return;
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(core::ecef_to_geodetic(p_out_E_m));
  spp_offsets_.push_back(SppOffset{epoch_time_, (R_NE * (*epoch_spp_p_E_m_ - p_out_E_m)).head<2>()});
  while (epoch_time_ - spp_offsets_.front().time > options_.integrity_window_s) spp_offsets_.pop_front();
  if (static_cast<int>(spp_offsets_.size()) < options_.integrity_min_points) return;
  const Eigen::Vector2d median_m(median_offset_m(0), median_offset_m(1));
  if (median_m.norm() <= options_.integrity_max_offset_m) return;
  stats_.notes.push_back(when(epoch_time_) +
                         format(": integrity: the single points are %.0f m from the output (median over %.0f s): "
                                "position moved to them, ambiguities and heading restarted",
                                median_m.norm(), options_.integrity_window_s));
  ++stats_.integrity_restarts;
  restart_from_single_points(p_out_E_m, R_NE, median_m);
  spp_offsets_.clear();
}

double FusionEngine::median_offset_m(int axis) {
  median_scratch_m_.clear();
  for (const SppOffset& o : spp_offsets_) median_scratch_m_.push_back(o.d_EN_m[axis]);
  return core::median_in_place(median_scratch_m_);
}

void FusionEngine::restart_from_single_points(const Eigen::Vector3d& p_out_E_m, const Eigen::Matrix3d& R_NE,
                                              const Eigen::Vector2d& median_EN_m) {
  // Horizontally the single points' median, with their spread about it as its variance; vertically the output's.
  Eigen::Vector2d spread2 = Eigen::Vector2d::Zero();
  for (const SppOffset& o : spp_offsets_) spread2 += (o.d_EN_m - median_EN_m).cwiseAbs2();
  spread2 /= static_cast<double>(spp_offsets_.size());
  Eigen::Matrix3d P_N = R_NE * engine_.position_covariance_E_m2() * R_NE.transpose();
  P_N.topRows<2>().setZero();
  P_N.leftCols<2>().setZero();
  P_N(0, 0) = spread2[0];
  P_N(1, 1) = spread2[1];
  engine_.set_position(p_out_E_m + R_NE.transpose() * Eigen::Vector3d(median_EN_m[0], median_EN_m[1], 0.0),
                       R_NE.transpose() * P_N * R_NE);
  // The ambiguities were fitted to the old position; the heading may have been learnt from it.
  engine_.reset_ambiguities();
  if (alignment_) {
    alignment_->heading_started = false;
    alignment_->yaw_sigma_rad = std::max(alignment_->yaw_sigma_rad, kRestartHeadingSigmaRad);
  }
}

std::vector<AlignmentPoint> FusionEngine::window(const core::GpsTime& t, double span_s, int segment,
                                                 bool fixed_only) const {
  std::vector<AlignmentPoint> points;
  for (const WindowPoint& w : history_) {
    if (t - w.time > span_s || w.segment != segment) continue;
    if (fixed_only ? w.status != core::SolutionStatus::Fixed
                   : (w.status != core::SolutionStatus::Fixed && w.status != core::SolutionStatus::Float)) {
      continue;
    }
    if (w.sigma_m > options_.max_window_sigma_m) continue;
    points.push_back(AlignmentPoint{w.T_OI, w.p_E_m});
  }
  return points;
}

void FusionEngine::update_alignment(const core::GpsTime& t, const std::optional<VioPoseAt>& pose) {
  if (!pose || options_.prediction != Prediction::Vio) return;
  const int segment = pose->segment;
  const bool fine = alignment_ && alignment_->fine;
  const double interval = fine ? options_.realign_interval_s : options_.alignment_interval_s;
  if (last_alignment_try_ && t - *last_alignment_try_ < interval) return;
  last_alignment_try_ = t;
  const auto start = std::chrono::steady_clock::now();
  // Fine alignment (the paper's): before any alignment the RTK solutions, fixed or float; afterwards fixed ones.
  const std::vector<AlignmentPoint> points = window(t, options_.alignment_window_s, segment, alignment_.has_value());
  if (static_cast<int>(points.size()) >= options_.alignment.min_points) {
    ++stats_.alignment_tries;
    std::vector<Eigen::Vector3d> positions;
    positions.reserve(points.size());
    for (const AlignmentPoint& p : points) positions.push_back(p.p_E_m);
    if (first_eigenvalue_ratio(positions) >= options_.alignment.max_first_eigenvalue_ratio) {
      ++stats_.alignment_rejected_fer;
    } else {
      const bool first = !calibrated_ && options_.calibrate_lever_arm;
      Result<AlignmentResult> fit =
          first  ? align_and_calibrate(points, options_.lever_arm_prior_m, true, options_.alignment)
          : fine ? realign(points, t_IA_m_, alignment_->T_EO, options_.alignment)
                 : align_and_calibrate(points, t_IA_m_, false, options_.alignment);
      if (fit && fit->qualifies(options_.alignment)) {
        if (first) {
          calibrated_ = true;
          t_IA_m_ = fit->t_IA_m;
          stats_.calibration = *fit;
        }
        const double fine_sigma_rad = options_.heading_state ? options_.fine_heading_sigma_deg * core::kDegToRad : 0.0;
        alignment_ = Alignment{fit->T_EO, segment, fine_sigma_rad, true, t};
        stats_.alignments.push_back(AlignmentEvent{t, first ? "initial" : (fine ? "realign" : "align"), fit->points,
                                                   fit->first_eigenvalue_ratio, fit->rmse_m,
                                                   fit->rmse_without_calibration_m, 0.0});
      } else if (fit) {
        ++stats_.alignment_rejected_rmse;
      }
    }
  }
  // Coarse alignment while no fine one holds: all RTK solutions before any alignment, fixed ones afterwards.
  if (options_.coarse_alignment && !(alignment_ && alignment_->fine)) {
    std::vector<AlignmentPoint> coarse_points;
    for (const WindowPoint& w : history_) {
      if (t - w.time > options_.coarse_window_s || w.segment != segment) continue;
      if (alignment_ && w.status != core::SolutionStatus::Fixed) continue;
      if (!alignment_ && w.aided) continue;
      coarse_points.push_back(AlignmentPoint{w.T_OI, w.p_E_m});
    }
    auto coarse = coarse_align(coarse_points, t_IA_m_, options_.alignment);
    const double max_sigma_rad = options_.coarse_max_yaw_sigma_deg * core::kDegToRad;
    if (coarse && coarse->spread_m >= options_.coarse_min_spread_m && coarse->yaw_sigma_rad <= max_sigma_rad &&
        (!alignment_ || coarse->yaw_sigma_rad < alignment_->yaw_sigma_rad)) {
      alignment_ = Alignment{coarse->T_EO, segment, coarse->yaw_sigma_rad, false, t};
      stats_.alignments.push_back(AlignmentEvent{t, "coarse", static_cast<int>(coarse_points.size()), 0.0,
                                                 coarse->rmse_m, coarse->rmse_m,
                                                 coarse->yaw_sigma_rad * core::kRadToDeg});
    }
  }
  stats_.alignment_cpu_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::vector<std::string> FusionEngine::report() const {
  std::vector<std::string> lines;
  const FusionStats& s = stats_;
  lines.push_back(
      format("fusion: %.0f epochs: %.0f VIO-aided, %.0f VIO fill-in (Q 7), %.0f RTK motion model "
             "(not aligned or no VIO)",
             s.epochs, s.aided, s.fill_in, s.fallback));
  lines.push_back(
      format("fusion: heading-free VIO fill-in (Q 7; not aligned, no GNSS solution): %.0f epochs", s.heading_free));
  lines.push_back(
      format("fusion: float validation failed: %.0f no DD phase, %.0f post-fit residuals, %.0f "
             "inconsistent with the VIO prior",
             s.float_rejected_no_phase, s.float_rejected_post_fit, s.float_rejected_prior));
  lines.push_back(
      format("fusion: false-fix guard fired in %.0f epochs (%.0f candidate fixes); %.0f fixes after ILS "
             "pruning; %.0f DD rows gated",
             s.guard_epochs, s.guard_candidates, s.ar_pruned_epochs, s.gated_rows) +
      format("; %.0f signals screened out by C/N0; %.0f epochs with fixes of a poorly determined position",
             s.cn0_screened, s.undetermined_fix_epochs) +
      format("; %.0f epochs with fewer than 4 satellites to fix (no fix tried)", s.too_few_to_fix) +
      format("; %.0f epochs whose float fit no integer vector (success rates scaled)", s.float_inconsistent));
  if (options_.heading_state) {
    lines.push_back(
        format("fusion: heading state: T_EO turned by %.2f deg in all by the filter's heading estimates, "
               "heading sigma %.2f deg at the end",
               s.heading_folded_rad * core::kRadToDeg, s.heading_sigma_rad * core::kRadToDeg));
  }
  if (options_.integrity_check) {
    lines.push_back(
        format("fusion: integrity check: %.0f restarts from the single point (median offset over %.0f s "
               "beyond %.0f m)",
               s.integrity_restarts, options_.integrity_window_s, options_.integrity_max_offset_m));
  }
  int coarse = 0, fine = 0;
  for (const AlignmentEvent& a : s.alignments) (a.kind == "coarse" ? coarse : fine) += 1;
  lines.push_back(format("fusion: alignments: %.0f fine of %.0f windows tried (%.0f with FER >= the limit, ", fine,
                         s.alignment_tries, s.alignment_rejected_fer) +
                  format("%.0f with RMSE >= the limit), %.0f coarse; %.3f s CPU", s.alignment_rejected_rmse, coarse,
                         s.alignment_cpu_s));
  // The first coarse alignment of each run of them, the last one, and every fine alignment but the re-alignments.
  const AlignmentEvent* last_coarse = nullptr;
  int coarse_run = 0;
  const auto coarse_line = [&lines](const AlignmentEvent& a, const char* what) {
    lines.push_back("fusion: " + when(a.time) + ": " + what + ", " + std::to_string(a.points) +
                    format(" solutions, yaw sigma %.2f deg, horizontal RMSE %.2f m", a.yaw_sigma_deg, a.rmse_m));
  };
  const auto flush_coarse = [&]() {
    if (last_coarse != nullptr && coarse_run > 1) coarse_line(*last_coarse, "last coarse alignment of this run");
    last_coarse = nullptr;
    coarse_run = 0;
  };
  for (const AlignmentEvent& a : s.alignments) {
    if (a.kind == "coarse") {
      if (coarse_run++ == 0) coarse_line(a, "coarse alignment");
      last_coarse = &a;
      continue;
    }
    flush_coarse();
    if (a.kind == "realign") continue;
    lines.push_back("fusion: " + when(a.time) + ": " + a.kind + " alignment, " + std::to_string(a.points) +
                    format(" solutions, FER %.3f, RMSE %.3f m (without calibration %.3f m)", a.first_eigenvalue_ratio,
                           a.rmse_m, a.rmse_without_calibration_m));
  }
  flush_coarse();
  if (s.calibration) {
    const Eigen::Vector3d& t = s.calibration->t_IA_m;
    lines.push_back(format("fusion: lever arm t_IA = [%.3f, %.3f, %.3f] m; ", t.x(), t.y(), t.z()) +
                    s.calibration->lever_arm.describe());
  }
  for (const std::string& note : s.notes) lines.push_back("fusion: " + note);
  return lines;
}

}  // namespace canyon::fusion
