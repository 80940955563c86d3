// The paper's Algorithm 1 on canyon's RTK filter (see fusion_engine.hpp; each line's function is in its own file).

#include "canyon/fusion/fusion_engine.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/fusion/constant_velocity.hpp"
#include "canyon/fusion/float_validation.hpp"
#include "canyon/fusion/heading_state.hpp"
#include "canyon/fusion/output_floor.hpp"
#include "canyon/fusion/vio_fill_in.hpp"

namespace canyon::fusion {
namespace {

/// The RTK filter's options with the aiding's error states (heading, scale, interpolation) the fusion estimates.
rtk::RtkOptions with_heading_state(rtk::RtkOptions rtk_options, const FusionOptions& options) {
  const bool vio = options.prediction.kind == Prediction::Vio;
  rtk_options.aiding_heading_state = options.heading.enabled && vio;
  rtk_options.aiding_scale_state = options.prediction.scale_state && vio;
  rtk_options.aiding_interpolation_state = options.prediction.interpolation_state && vio;
  return rtk_options;
}

/// The interpolation error's step between the VIO poses at the state's epoch (`before`) and at the next (`next`):
/// fully correlated inside one VIO interval (e' = sigma' / sigma e), independent across intervals.
void couple_interpolation(rtk::ExternalMotion& motion, const VioPoseAt& before, const VioPoseAt& next,
                          double sigma_before_m, double sigma_next_m) {
  motion.interpolation_variance_m2 = sigma_before_m * sigma_before_m;
  if (before.lower == next.lower && sigma_before_m > 0.0) {
    motion.interpolation_carry = sigma_next_m / sigma_before_m;
    motion.interpolation_noise_m2 = 0.0;
  } else {
    motion.interpolation_carry = 0.0;
    motion.interpolation_noise_m2 = sigma_next_m * sigma_next_m;
  }
}

/// The local vertical (unit, ECEF) at a position.
Eigen::Vector3d up_at(const Eigen::Vector3d& p_E_m) {
  return core::rotation_enu_from_ecef(core::ecef_to_geodetic(p_E_m)).row(2).transpose();
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
      schedule_(options_.alignment, options_.coarse,
                options_.heading.enabled ? options_.heading.fine_sigma_deg * core::kDegToRad : 0.0, stats_.alignment),
      guard_(options_.guard),
      recovery_(options_.recovery),
      integrity_(options_.integrity),
      heading_free_(options_.heading_free) {}

Result<FusionEpoch> FusionEngine::process(const core::ObsEpoch& rover, const core::ObsEpoch* base) {
  const std::optional<VioPoseAt> pose = bridge(rover.time);
  align(rover.time, pose);
  auto more = predict(rover, base, pose);
  if (more && *more && update()) resolve();
  Result<FusionEpoch> out = more ? Result<FusionEpoch>(finish_epoch()) : Result<FusionEpoch>(more.error());
  flush_alignment();
  return out;
}

// ---- Line 1: the VIO pose at the epoch ----

std::optional<VioPoseAt> FusionEngine::bridge(const core::GpsTime& t) const {
  const std::shared_lock lock(track_mutex_);
  return track_.pose_at(t);
}

bool FusionEngine::add_vio(const io::VioRecord& record, const core::GpsTime& t, std::string* note, int clock_piece) {
  const std::unique_lock lock(track_mutex_);
  return track_.append(record, t, note, clock_piece);
}

bool FusionEngine::vio_covers(const core::GpsTime& t) const {
  const std::shared_lock lock(track_mutex_);
  return track_.covers(t);
}

// ---- Line 2: align a new segment or reuse the old alignment ----

void FusionEngine::align(const core::GpsTime& t, const std::optional<VioPoseAt>& pose) {
  const std::optional<std::string> note = schedule_.align_new_segment_or_reuse(t, pose);
  {
    // Epochs still in the pipeline are later than t; the prediction reaches back to the last epoch only.
    const std::unique_lock lock(track_mutex_);
    track_.forget_before(t - options_.vio_keep_s);
  }
  ++stats_.epochs;
  if (!pose) ++stats_.no_vio;
  if (note) stats_.notes.push_back(*note);
}

// ---- Lines 3-5: the prior ----

Result<bool> FusionEngine::predict(const core::ObsEpoch& rover, const core::ObsEpoch* base,
                                   const std::optional<VioPoseAt>& pose, FusionGeometry* geometry) {
  epoch_time_ = rover.time;
  epoch_pose_ = pose;
  heading_free_epoch_.reset();
  guard_.start_epoch();
  aiding_ = predict_prior(rover.time, pose);
  std::optional<FusionGeometry> own_geometry;
  if (geometry == nullptr) geometry = &own_geometry.emplace(geometry_builder_.build(rover, base));
  if (aiding_ && geometry->screened_rover_obs) {
    // Beyond the paper: the C/N0 screen's verdict, on aided epochs only (cn0_screen.hpp).
    stats_.cn0_screened += geometry->screened;
    geometry->rtk.rover_obs = std::move(*geometry->screened_rover_obs);
    geometry->screened_rover_obs.reset();
  }
  epoch_spp_p_E_m_.reset();
  if (geometry->rtk.spp) epoch_spp_p_E_m_ = geometry->rtk.spp->p_E_m;
  auto more = engine_.predict(rover, base, aiding_ ? &aiding_->motion : nullptr, &geometry->rtk);
  if (more && *more && aiding_ && options_.prediction.interpolation_state) {
    // With the interpolation state the prior is the filter's own after the time update (the state's correlations
    // between the position and the interpolation error decide it).
    aiding_->prior = Prior{engine_.position_E_m(), engine_.position_covariance_E_m2()};
  }
  if (!more) {
    if (!aiding_) heading_free_epoch_ = heading_free_solution(rover.time, pose);
    if (heading_free_epoch_) return false;  // finish_epoch() outputs it
    count_fix_refusals();
    if (options_.prediction.kind == Prediction::Vio) schedule_.schedule(rover.time, pose);
  }
  return more;
}

std::optional<FusionEngine::EpochAiding> FusionEngine::predict_prior(const core::GpsTime& t,
                                                                     const std::optional<VioPoseAt>& pose) {
  if (!engine_.has_position() || !engine_.state_time()) return std::nullopt;
  EpochAiding aiding;
  std::optional<MotionPrediction> prediction;
  if (options_.prediction.kind == Prediction::Vio) {
    prediction = predict_from_vio(pose, aiding.motion);
  } else {
    prediction = predict_constant_velocity(last_solutions_, t, *engine_.state_time(), options_.vio.max_speed_mps,
                                           rtk_options_.accel_sigma_h_mps2);
    if (prediction) {
      const std::optional<double> widen = recovery_.take_widening();
      if (widen) ++stats_.widened;
      complete_prediction(*prediction, engine_.position_E_m(), engine_.position_covariance_E_m2(), widen);
    }
  }
  if (!prediction) return std::nullopt;
  aiding.motion.delta_p_E_m = prediction->dp_E_m;
  aiding.motion.Q_E_m2 = prediction->Q_E_m2;
  aiding.prior = prediction->prior;
  aiding.gates = VioInnovationGates(options_.gates, aiding.motion.delta_p_E_m.norm());  // line 6's gates
  return aiding;
}

std::optional<MotionPrediction> FusionEngine::predict_from_vio(const std::optional<VioPoseAt>& pose,
                                                               rtk::ExternalMotion& motion) {
  VioAlignment* alignment = schedule_.alignment_for(pose);
  if (alignment == nullptr) return std::nullopt;
  const Eigen::Vector3d p_state = engine_.position_E_m();
  const Eigen::Vector3d up_E = up_at(p_state);
  VioPredictionInput in;
  const bool interpolation_state = options_.prediction.interpolation_state;
  double sigma_before_m = 0.0;
  double sigma_next_m = 0.0;
  {
    const std::shared_lock lock(track_mutex_);
    const std::optional<VioPoseAt> before = track_.pose_at(*engine_.state_time());
    if (!before || before->segment != pose->segment) return std::nullopt;
    in.T_OI_i = before->T_OI;
    in.joint = track_.joint_covariance(*before, *pose, !interpolation_state);
    if (interpolation_state) {
      sigma_before_m = track_.interpolation_sigma_m(*before);
      sigma_next_m = track_.interpolation_sigma_m(*pose);
      couple_interpolation(motion, *before, *pose, sigma_before_m, sigma_next_m);
    }
  }
  const bool heading_state = options_.heading.enabled;
  in.p_E_m = p_state;
  in.P_E_m2 = engine_.position_covariance_E_m2();
  in.T_OI_next = pose->T_OI;
  in.t_IA_m = schedule_.lever_arm_m();
  in.R_EO = alignment->T_EO.rotation();
  in.yaw_sigma_rad = heading_state ? 0.0 : alignment->yaw_sigma_rad;
  in.up_E = up_E;
  const std::optional<double> widen = recovery_.take_widening();
  if (widen) ++stats_.widened;
  MotionPrediction prediction = predict_with_vio(in, options_.prediction, widen);  // Eqs. 3-6
  if (interpolation_state) {
    // The filter's prior replaces this one once the time update ran (predict()); until then, and for an epoch that
    // never gets there, the interpolation errors at both ends as in the increment's covariance.
    prediction.prior.P_E_m2 +=
        Eigen::Matrix3d::Identity() * (sigma_before_m * sigma_before_m + sigma_next_m * sigma_next_m);
  }
  if (heading_state) couple_heading(motion, prediction.increment.dp_E_m, up_E, *alignment, options_.heading);
  if (options_.prediction.scale_state) couple_scale(motion, prediction.increment.dp_E_m, pose->segment);
  return prediction;
}

void FusionEngine::couple_scale(rtk::ExternalMotion& motion, const Eigen::Vector3d& dp_E_m, int segment) {
  const PredictionOptions& o = options_.prediction;
  const double walk = o.vio_scale_random_walk_per_sqrt_km;
  motion.scale_noise = walk * walk * dp_E_m.norm() / 1000.0;
  motion.scale_variance = o.vio_scale_sigma * o.vio_scale_sigma;
  motion.restart_scale = scale_segment_ != segment;  // a new odometry segment may have a scale of its own
  scale_segment_ = segment;
}

FusionGeometryBuilder FusionEngine::make_geometry_builder() const {
  return FusionGeometryBuilder(engine_.geometry_options(), options_.cn0, ephemerides_, engine_.base_position_E_m());
}

// ---- Lines 6-7: outlier satellite pruning and the measurement update ----

bool FusionEngine::update() {
  return engine_.update(aiding_ ? &aiding_->gates : nullptr);
}

// ---- Lines 9-17: MLAMBDA, validation, further pruning ----

void FusionEngine::resolve() {
  if (!aiding_) {
    engine_.resolve();
    return;
  }
  rtk::FixSearch& search = engine_.propose_fixes();
  while (const rtk::FixCandidate* candidate = search.next()) search.decide(guard_.accepts(*candidate, aiding_->prior));
  engine_.conclude_fixes();
}

void FusionEngine::count_fix_refusals() {
  if (guard_.refused_as_undetermined() > 0) ++stats_.undetermined_fix_epochs;
  if (guard_.refused_by_prior() > 0) {
    ++stats_.guard_epochs;
    stats_.guard_candidates += guard_.refused_by_prior();
  }
}

// ---- Lines 8, 11, 16, 18, 22, 24: validation and the output ----

FusionEpoch FusionEngine::finish_epoch() {
  FusionEpoch out = heading_free_epoch_ ? finish_heading_free() : finish_solved_epoch();
  add_output_floor(out.solution, options_.output_floor);  // the output's covariance only (output_floor.hpp)
  return out;
}

FusionEpoch FusionEngine::finish_solved_epoch() {
  const rtk::RtkEpoch epoch = engine_.take_epoch();
  count_fix_refusals();
  FusionEpoch out;
  stats_.gated_rows += static_cast<int>(epoch.rejected.size());
  stats_.ambiguities_from_position += static_cast<int>(epoch.ambiguities_from_position.size());
  out.hdop = epoch.hdop;
  out.note = epoch.note;
  if (aiding_) {
    aided_output(epoch, out);
  } else {
    out.solution = epoch.solution;
    ++stats_.fallback;
  }
  if (out.solution.status == core::SolutionStatus::Fixed) ++stats_.fixed;
  out.rejected = epoch.rejected;
  out.ar_pruned = epoch.ar_pruned;
  after_output(out);
  out.rtk = epoch;
  return out;
}

void FusionEngine::aided_output(const rtk::RtkEpoch& epoch, FusionEpoch& out) {
  out.aided = true;
  ++stats_.aided;
  // Line 8 (the filter may have returned before its time update: no float, its state kept).
  const std::string invalid =
      !epoch.aided ? (epoch.note.empty() ? std::string("no update") : epoch.note) : validate_epoch_float(epoch);
  if (!invalid.empty()) {
    out.solution = vio_fill_in(epoch, aiding_->prior, epoch_time_);  // line 22
    out.note = invalid;                                              // the status says VIO fill-in
    ++stats_.fill_in;
    return;
  }
  out.solution = epoch.solution;  // lines 11, 16, 18: fixed, else float
  if (!epoch.ar_pruned.empty() && out.solution.status == core::SolutionStatus::Fixed) ++stats_.ar_pruned_epochs;
  if (epoch.too_few_to_fix) ++stats_.too_few_to_fix;
  if (epoch.float_variance_factor > 1.0) ++stats_.float_inconsistent;
}

std::string FusionEngine::validate_epoch_float(const rtk::RtkEpoch& epoch) {
  std::string invalid = validate_float(epoch, options_.validation);
  const bool only_prior = failed_on_prior_only(epoch, invalid, options_.validation);
  if (recovery_.reanchor(only_prior)) {
    invalid.clear();  // the VIO prior drifted away from a consistent GNSS solution: GNSS re-anchors it
    ++stats_.reanchored;
  }
  if (!invalid.empty()) {
    if (epoch.num_dd_measurements == 0) {
      ++stats_.float_rejected_no_phase;
    } else if (!only_prior) {
      ++stats_.float_rejected_post_fit;
    } else {
      ++stats_.float_rejected_prior;
    }
    engine_.revert_to_prior();
  }
  recovery_.count_gate_conflict(static_cast<int>(epoch.rejected.size()),
                                epoch.num_dd_measurements + epoch.num_dd_code_measurements);
  return invalid;
}

void FusionEngine::after_output(const FusionEpoch& out) {
  std::optional<VioAlignment>& alignment = schedule_.alignment();
  if (out.aided && options_.heading.enabled && alignment) {
    if (const std::optional<double> psi = fold_heading_error(engine_, *alignment)) {
      stats_.heading_folded_rad += *psi;
      stats_.heading_sigma_rad = alignment->yaw_sigma_rad;
    }
  }
  if (out.aided) {
    if (const std::optional<rtk::RtkEngine::ScaleError> scale = engine_.scale_error()) {
      stats_.scale_error = scale->s;
      stats_.scale_sigma = std::sqrt(scale->variance);
    }
  }
  if (out.aided && out.solution.status != core::SolutionStatus::None) {
    check_integrity(out.solution.p_E_m);
  } else {
    integrity_.clear();
  }
  // The solution with its VIO pose for the alignment windows, the heading-free anchor, the constant velocity.
  schedule_.remember(epoch_time_, epoch_pose_, out.solution, out.aided);
  if (epoch_pose_ && out.solution.status != core::SolutionStatus::None) {
    heading_free_.anchor(out.solution, epoch_time_, epoch_pose_->segment);
  }
  if (out.solution.status == core::SolutionStatus::Fixed || out.solution.status == core::SolutionStatus::Float) {
    last_solutions_.push_back(out.solution);
    if (last_solutions_.size() > 2) last_solutions_.erase(last_solutions_.begin());
  }
  if (options_.prediction.kind == Prediction::Vio) schedule_.schedule(epoch_time_, epoch_pose_);
}

void FusionEngine::check_integrity(const Eigen::Vector3d& p_out_E_m) {
  const std::optional<IntegrityRestart> restart =
      integrity_.check(epoch_time_, p_out_E_m, engine_.position_covariance_E_m2(), epoch_spp_p_E_m_);
  if (!restart) return;
  char text[256];
  std::snprintf(text, sizeof text,
                ": integrity: the single points are %.0f m from the output (median over %.0f s): position moved to "
                "them, ambiguities and heading restarted",
                restart->offset_m, options_.integrity.window_s);
  stats_.notes.push_back(core::format_gpst(epoch_time_) + text);
  ++stats_.integrity_restarts;
  engine_.set_position(restart->p_E_m, restart->P_E_m2);
  // The ambiguities were fitted to the old position; the heading may have been learnt from it.
  engine_.reset_ambiguities();
  if (std::optional<VioAlignment>& alignment = schedule_.alignment()) {
    alignment->heading_started = false;
    alignment->yaw_sigma_rad = std::max(alignment->yaw_sigma_rad, kRestartHeadingSigmaRad);
  }
}

// ---- Beyond the paper: the heading-free fill-in ----

std::optional<core::Solution> FusionEngine::heading_free_solution(const core::GpsTime& t,
                                                                  const std::optional<VioPoseAt>& pose) {
  if (options_.prediction.kind != Prediction::Vio || !pose) return std::nullopt;
  const std::optional<core::GpsTime> anchor_time = heading_free_.anchor_time(pose->segment);
  if (!anchor_time) return std::nullopt;
  VioIncrement increment;
  {
    const std::shared_lock lock(track_mutex_);
    const std::optional<VioPoseAt> before = track_.pose_at(*anchor_time);
    if (!before || before->segment != pose->segment) return std::nullopt;
    // R_EO = I: only the increment in O and its covariance are used, the vertical of which no heading changes.
    increment = vio_increment(before->T_OI, pose->T_OI, track_.joint_covariance(*before, *pose),
                              schedule_.lever_arm_m(), Eigen::Matrix3d::Identity());
  }
  return heading_free_.fill(t, increment);
}

FusionEpoch FusionEngine::finish_heading_free() {
  count_fix_refusals();
  FusionEpoch out;
  out.solution = *heading_free_epoch_;
  heading_free_epoch_.reset();
  out.note = "before an alignment: the heading unknown";  // the status says VIO fill-in
  ++stats_.heading_free;
  integrity_.clear();
  if (options_.prediction.kind == Prediction::Vio) schedule_.schedule(epoch_time_, epoch_pose_);
  return out;
}

}  // namespace canyon::fusion
