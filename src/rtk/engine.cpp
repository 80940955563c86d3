// The RTK filter's stages (see engine.hpp; each piece's model is in its own header).

#include "canyon/rtk/engine.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "canyon/rtk/ambiguity_prior.hpp"
#include "canyon/rtk/ionosphere_prior.hpp"

namespace canyon::rtk {

/// The epoch between the stages (predict, update, resolve).
struct RtkEngine::PendingEpoch {
  RtkEpoch out;
  std::vector<SingleDiff> sds;
  bool aided = false;  // predicted with an external motion
  std::optional<FixSearch> search;
};

RtkEngine::RtkEngine(RtkOptions options, const gnss::EphemerisStore& ephemerides, Eigen::Vector3d p_E_base_m)
    : options_(std::move(options)),
      eph_(ephemerides),
      p_E_base_m_(std::move(p_E_base_m)),
      state_(StateLayout{options_.dynamics, options_.aiding_heading_state, options_.aiding_scale_state,
                         options_.aiding_interpolation_state}),
      resolver_(options_),
      geometry_builder_(geometry_options(), eph_, p_E_base_m_) {}

RtkEngine::~RtkEngine() = default;
RtkEngine::RtkEngine(RtkEngine&&) noexcept = default;

EpochGeometryBuilder::Options RtkEngine::geometry_options() const {
  return {options_.spp, options_.observables, options_.troposphere_saastamoinen, options_.slips, options_.max_age_s};
}

void RtkEngine::set_base_position(const Eigen::Vector3d& p_E_base_m) {
  p_E_base_m_ = p_E_base_m;
  geometry_builder_.set_base_position(p_E_base_m);
}

Result<RtkEpoch> RtkEngine::process(const core::ObsEpoch& rover, const core::ObsEpoch* base,
                                    const ExternalMotion* motion, const InnovationGate* gate) {
  auto more = predict(rover, base, motion);
  if (!more) return more.error();
  if (*more && update(gate)) resolve();
  return take_epoch();
}

// ---- Prediction ----

Result<bool> RtkEngine::predict(const core::ObsEpoch& rover, const core::ObsEpoch* base, const ExternalMotion* motion,
                                EpochGeometry* geometry) {
  prior_.reset();
  if (motion != nullptr && !initialised_) motion = nullptr;  // nothing to add the increment to yet
  // The epoch's geometry (single-point solution, observables, satellite states, cycle slips): built ahead by the
  // caller, or here.
  std::optional<EpochGeometry> own_geometry;
  if (geometry == nullptr) geometry = &own_geometry.emplace(geometry_builder_.build(rover, base, motion != nullptr));
  assert(geometry->has_base == (base != nullptr));
  if (!geometry->spp && motion == nullptr) return geometry->spp.error();

  start_epoch(rover, geometry->spp, motion);
  RtkEpoch& out = pending_->out;
  if (base == nullptr) {
    out.note = "no base observations";
    return false;
  }
  const double age_s = rover.time - base->time;
  out.solution.age_s = age_s;
  if (base_out_of_time(age_s, options_.max_age_s)) {
    out.note = "base observations too old (age " + std::to_string(age_s) + " s)";
    return false;
  }
  if (!geometry->slips) {
    // A builder of other options than geometry_options() (a longer base age), a geometry built ahead unaided for an
    // aided epoch without a single point, or a geometry not from a builder.
    return Error("rtk: the epoch's geometry has no cycle-slip scan (not built with the engine's geometry_options())");
  }
  predict_states(rover, *geometry, motion);
  if (motion != nullptr) {
    out.aided = true;
    out.prior_p_E_m = state_.position_E_m();
    out.prior_P_E_m2 = state_.position_covariance_E_m2();
    prior_ = Prior{state_.snapshot(), resolver_.last_fix()};
  }
  pending_->aided = motion != nullptr;
  return true;
}

void RtkEngine::start_epoch(const core::ObsEpoch& rover, const Result<gnss::SppSolution>& spp,
                            const ExternalMotion* motion) {
  pending_ = std::make_unique<PendingEpoch>();
  RtkEpoch& out = pending_->out;
  core::Solution& sol = out.solution;
  if (spp) {
    sol.time = spp->time;
    sol.status = core::SolutionStatus::Single;
    sol.p_E_m = spp->p_E_m;
    sol.P_E_m2 = spp->P_E_m2;
    sol.v_E_mps = spp->v_E_mps;
    sol.num_satellites = spp->num_satellites;
    out.hdop = spp->dop.hdop;
  } else if (motion != nullptr) {
    // The prior stands in for the single-point solution.
    sol.time = rover.time;
    sol.status = core::SolutionStatus::None;
    sol.p_E_m = state_.position_E_m() + motion->delta_p_E_m;
    sol.P_E_m2 = state_.position_covariance_E_m2() + motion->Q_E_m2;
    out.note = "no single-point solution: " + spp.error().message;
  }
}

void RtkEngine::predict_states(const core::ObsEpoch& rover, EpochGeometry& geometry, const ExternalMotion* motion) {
  const core::Solution& sol = pending_->out.solution;
  if (options_.ar_mode == ArMode::Instantaneous) reset_ambiguities();
  choose_ionosphere_model((sol.p_E_m - p_E_base_m_).norm());  // single-point position, or the prior
  const double dt_s = last_time_ ? std::abs(rover.time - *last_time_) : 0.0;
  if (motion != nullptr) {
    external_motion_update(state_, *motion, live_);
  } else {
    own_motion_update(state_, options_, dt_s, !initialised_, *geometry.spp);
    initialised_ = true;
    live_ = {};  // an epoch without external motion: the next one with it restarts the aiding error states
  }
  keyed_random_walk(state_, options_, dt_s);
  last_time_ = rover.time;
  pending_->sds = form_single_differences(geometry, state_.position_E_m(), options_, eph_, iono_estimated_);
  track_states(pending_->sds, rover.time, *geometry.slips);
}

void RtkEngine::track_states(std::vector<SingleDiff>& sds, const core::GpsTime& t, const SlipScan& slips) {
  for (const SlipEvent& e : slips.events) remove_state({e.sat, e.frequency});
  const double iono_max_outage_s = std::max(options_.max_outage_s, options_.iono_max_outage_s);
  for (const StateKey& key : states_.stale(t, options_.max_outage_s, iono_max_outage_s)) remove_state(key);
  const std::vector<FilterState::NewState> added = states_.admit(sds, state_, t, slips, options_, iono_estimated_);
  state_.add(added);
  if (iono_estimated_) {
    const double baseline_10km = (state_.position_E_m() - p_E_base_m_).norm() / 1e4;
    const IonospherePrior prior{std::max(options_.iono_sigma_per_10km_m * baseline_10km, options_.iono_sigma_min_m),
                                options_.iono_residual_sigma_per_10km_m * baseline_10km, options_.iono_sigma_min_m};
    add_ionosphere_states(state_, sds, prior, eph_);
  }
  if (options_.ambiguity_prior_max_sigma_cyc > 0.0 && !added.empty()) {
    std::vector<StateKey> keys;
    keys.reserve(added.size());
    for (const FilterState::NewState& s : added) keys.push_back(s.key);
    pending_->out.ambiguities_from_position =
        start_ambiguities_from_position(state_, sds, keys, options_.ambiguity_prior_max_sigma_cyc);
  }
  assign_state_indices(sds, state_);
}

void RtkEngine::choose_ionosphere_model(double baseline_m) {
  bool estimate = options_.ionosphere == IonosphereModel::Estimate;
  if (options_.ionosphere == IonosphereModel::Auto) {
    // Hysteresis: on beyond the threshold, off again only below 80 % of it (no toggling around it).
    const double on_m = options_.iono_auto_baseline_km * 1e3;
    estimate = iono_estimated_ ? baseline_m >= 0.8 * on_m : baseline_m > on_m;
  }
  if (iono_estimated_ && !estimate) {
    std::vector<StateKey> iono;
    for (const StateKey& key : state_.keys()) {
      if (key.ionosphere()) iono.push_back(key);
    }
    for (const StateKey& key : iono) remove_state(key);
  }
  iono_estimated_ = estimate;
}

void RtkEngine::remove_state(const StateKey& key) {
  if (!state_.has(key)) return;
  state_.remove(key);
  states_.forget(key);
  resolver_.forget(key);
}

void RtkEngine::reset_ambiguities() {
  state_.clear_keyed();
  states_.clear();
  resolver_.clear();
}

// ---- Update ----

bool RtkEngine::update(const InnovationGate* gate) {
  assert(pending_ && "update() after a predict() that returned true");
  RtkEpoch& out = pending_->out;
  std::vector<SingleDiff>& sds = pending_->sds;
  core::Solution& sol = out.solution;
  const DdUpdateResult result =
      dd_measurement_update(state_, sds, options_, pending_->aided ? gate : nullptr, out.rejected);
  out.num_dd_measurements = result.phase_rows;
  out.max_post_fit_normalised = result.worst_post_fit_normalised;
  out.num_dd_code_measurements = result.code_rows;
  if (out.num_dd_measurements == 0) {
    out.note = "no double-differenced phase";
    return false;
  }
  sol.status = core::SolutionStatus::Float;
  sol.p_E_m = state_.position_E_m();
  sol.P_E_m2 = state_.position_covariance_E_m2();
  out.float_p_E_m = sol.p_E_m;
  out.float_P_E_m2 = sol.P_E_m2;
  int satellites = 0;
  for (std::size_t i = 0; i < sds.size(); ++i) {
    if (sds[i].frequency == 0 || (i > 0 && sds[i - 1].sat != sds[i].sat)) ++satellites;
  }
  sol.num_satellites = satellites;
  if (!result.consistent) {
    // Float validation: residuals still beyond their thresholds after the rejections allowed (more outliers than
    // the epoch can shed, e.g. reflections in a street canyon): the float solution and its covariance cannot be
    // trusted, and neither can integers fixed from them.
    out.note = "float solution failed validation (post-fit residuals beyond their thresholds after " +
               std::to_string(options_.max_post_fit_rejections) + " rejections)";
    return false;
  }
  return options_.ar_mode != ArMode::Off;
}

// ---- Ambiguity resolution ----

void RtkEngine::resolve() {
  FixSearch& search = propose_fixes();
  while (search.next() != nullptr) search.decide(true);
  conclude_fixes();
}

FixSearch& RtkEngine::propose_fixes() {
  assert(pending_ && "propose_fixes() after an update() that returned true");
  return pending_->search.emplace(resolver_.search(state_, pending_->sds));
}

void RtkEngine::conclude_fixes() {
  assert(pending_ && pending_->search && "conclude_fixes() after propose_fixes()");
  const FixSearch& search = *pending_->search;
  RtkEpoch& out = pending_->out;
  core::Solution& sol = out.solution;
  if (search.ratio()) sol.ratio = std::min(*search.ratio(), 999.9);
  if (search.float_variance_factor()) out.float_variance_factor = *search.float_variance_factor();
  out.too_few_to_fix = search.too_few_satellites();
  if (!search.fix()) {
    out.note = search.why_not();
    if (const auto& imprecise = search.imprecise()) {
      // The most precise combinations are fixed, but not enough of them to call the position fixed: the float
      // position conditioned on them is still the better one.
      sol.p_E_m = imprecise->p_E_m;
      sol.P_E_m2 = imprecise->P_E_m2;
      sol.fixed_combinations = static_cast<int>(imprecise->a_fix.size());
      out.note +=
          "; float position conditioned on " + std::to_string(imprecise->a_fix.size()) + " fixed integer combinations";
      hold_imprecise(*imprecise);
    }
  } else if (!search.fix()->position_ok) {
    out.note = "float ambiguity covariance not positive definite";
  } else {
    // Conditional update on the fixed DD ambiguities: x_fix = x - P D^T Q_a^-1 (a_float - a_fix), the position rows.
    const FixCandidate& fix = *search.fix();
    sol.p_E_m = fix.p_E_m;
    sol.P_E_m2 = fix.P_E_m2;
    sol.status = core::SolutionStatus::Fixed;
    out.num_fixed_ambiguities = static_cast<int>(fix.a_fix.size());
    if (!fix.combinations) {
      for (std::size_t i = 0; i < fix.dd.size(); ++i) {
        FixedAmbiguity fixed{state_.key_at(fix.dd[i].first), state_.key_at(fix.dd[i].second),
                             fix.a_fix[static_cast<Eigen::Index>(i)]};
        for (const SingleDiff& sd : pending_->sds) {
          if (sd.sat == fixed.sat.sat && sd.frequency == fixed.sat.frequency) fixed.wavelength_m = sd.wavelength_m;
        }
        out.fixed_ambiguities.push_back(fixed);
      }
    }
    out.ar_pruned = fix.pruned;
    resolver_.commit(fix, state_);
  }
  pending_->search.reset();
}

void RtkEngine::hold_imprecise(const FixCandidate& imprecise) {
  if (options_.partial_hold_sigma_cyc <= 0.0 || !imprecise.position_ok) return;
  if (pending_->out.solution.num_satellites < options_.partial_hold_min_satellites) return;
  resolver_.hold(imprecise, state_, options_.partial_hold_sigma_cyc);
  pending_->out.note += " (held)";
}

RtkEpoch RtkEngine::take_epoch() {
  assert(pending_ && "take_epoch() after a predict() that succeeded");
  RtkEpoch out = std::move(pending_->out);
  pending_.reset();
  return out;
}

// ---- Between epochs ----

void RtkEngine::revert_to_prior() {
  if (!prior_) return;
  state_.revert(prior_->state);
  resolver_.restore_last_fix(std::move(prior_->last_fix));
  prior_.reset();
}

std::optional<RtkEngine::HeadingError> RtkEngine::heading_error() const {
  if (state_.heading_index() < 0 || !live_.heading) return std::nullopt;
  const int h = state_.heading_index();
  return HeadingError{state_.x()[h], state_.P()(h, h)};
}

std::optional<RtkEngine::ScaleError> RtkEngine::scale_error() const {
  if (state_.scale_index() < 0 || !live_.scale) return std::nullopt;
  const int i = state_.scale_index();
  return ScaleError{state_.x()[i], state_.P()(i, i)};
}

std::optional<RtkEngine::HeadingError> RtkEngine::take_heading_error() {
  std::optional<HeadingError> heading = heading_error();
  if (heading) state_.set_aiding_value(state_.heading_index(), 0.0);
  return heading;
}

}  // namespace canyon::rtk
