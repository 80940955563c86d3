// The estimator's options described once: spp:, rtk: and fusion: (config/spp.yaml, rtk.yaml and fusion.yaml show
// every key with its unit; tests/config/shipped_keys_test.cpp holds them to these tables). Key order: the files'.

#include "canyon/config/process_config.hpp"

namespace canyon::config {
namespace {

using F = fusion::FusionOptions;
using O = rtk::RtkOptions;

Names<bool> off_or(const char* on_name) {
  return {{{true, on_name}, {false, "off"}}};
}

/// rtk: which satellites and signals, and ambiguity resolution.
Table<O> rtk_selection_and_ar_keys() {
  using Obs = rtk::ObservableOptions;
  return {
      {"ar_mode", "", "ambiguity resolution: off | continuous | instantaneous | fix_and_hold", at(&O::ar_mode),
       names_of({rtk::ArMode::Off, rtk::ArMode::Continuous, rtk::ArMode::Instantaneous, rtk::ArMode::FixAndHold},
                rtk::ar_mode_name)},
      {"frequencies", "", "1: L1/E1/B1I/G1; 2: + L2/E5b/B2I/G2; 3: + L5/E5a/B3I",
       at(&O::observables, &Obs::num_frequencies)},
      {"systems", "", "constellations used: G GPS, R GLONASS, E Galileo, C BeiDou, J QZSS", at(&O::observables),
       Systems{}},
      {"exclude", "", "satellites never used, e.g. [G05, E11] (also those of spp.exclude)",
       at(&O::observables, &Obs::excluded), Satellites{}},
      {"elevation_mask_deg", "deg", "satellites below are not used", at(&O::elevation_mask_rad), Degrees{}},
      {"ar_elevation_mask_deg", "deg", "ambiguities of satellites below are not fixed", at(&O::ar_elevation_mask_rad),
       Degrees{}},
      {"ratio_threshold", "", "ratio test: second-best / best squared norm (the paper's 3.0)", at(&O::ratio_threshold)},
      {"min_fix_ambiguities", "", "fewer double-differenced ambiguities are not fixed", at(&O::min_fix_ambiguities)},
      {"min_lock_epochs", "", "epochs an ambiguity must be tracked before it is fixed", at(&O::min_lock_epochs)},
      {"partial_ar", "", "when the whole set fails, fix a subset (pruning, then groups)", at(&O::partial_ar)},
      {"max_pruned_satellites", "", "partial fixing drops at most this many satellites, largest ILS residual first",
       at(&O::max_pruned_satellites)},
      {"min_success_rate", "", "bootstrapped success rate (0..1) a fix needs besides the ratio test",
       at(&O::min_success_rate)},
      {"float_consistency_level", "",
       "significance of the test that the float fits some integer vector (0.001: 0.1 %); 0: no test",
       at(&O::float_consistency_level)},
      {"min_partial_fraction", "", "a partial fix keeps at least this fraction (0..1) of the fixable ambiguities",
       at(&O::min_partial_fraction)},
      {"glonass_ar", "", "fix GLONASS ambiguities: on | off (rover and base receivers of one type only)",
       at(&O::glonass_ar), Names<bool>{{{true, "on"}, {false, "off"}}, {{true, "true"}, {false, "false"}}}},
  };
}

/// rtk: the filter's models and outlier tests.
Table<O> rtk_model_keys() {
  using Slips = rtk::CycleSlipOptions;
  return {
      {"dynamics", "", "true: constant-acceleration model; false: position from single point each epoch",
       at(&O::dynamics)},
      {"accel_sigma_h_mps2", "m/s^2 per sqrt(s)", "horizontal acceleration noise with dynamics",
       at(&O::accel_sigma_h_mps2)},
      {"accel_sigma_v_mps2", "m/s^2 per sqrt(s)", "vertical acceleration noise with dynamics",
       at(&O::accel_sigma_v_mps2)},
      {"phase_sigma_m", "m", "zenith-independent carrier-phase noise a", at(&O::phase_sigma_m)},
      {"phase_sigma_el_m", "m", "elevation-dependent carrier-phase noise b: sigma^2 = a^2 + b^2 / sin^2(el)",
       at(&O::phase_sigma_el_m)},
      {"code_phase_ratio", "", "pseudorange sigma / carrier-phase sigma", at(&O::code_phase_ratio)},
      {"code_multipath_sigma_m", "m", "sigma of each signal's time-correlated code multipath state (0: none)",
       at(&O::code_multipath_sigma_m)},
      {"code_multipath_correlation_s", "s", "correlation time of the code multipath states",
       at(&O::code_multipath_correlation_s)},
      {"initial_ambiguity_sigma_cyc", "cycles", "sigma of a new single-differenced ambiguity",
       at(&O::initial_ambiguity_sigma_cyc)},
      {"ambiguity_noise_cyc", "cycles per sqrt(s)", "ambiguity random walk", at(&O::ambiguity_noise_cyc)},
      {"initial_position_sigma_m", "m", "sigma of the single-point position used as prior",
       at(&O::initial_position_sigma_m)},
      {"max_age_s", "s", "base observations older than this are not used", at(&O::max_age_s)},
      {"max_phase_innovation_m", "m", "double-differenced phase innovations beyond are rejected",
       at(&O::max_phase_innovation_m)},
      {"max_code_innovation_m", "m", "double-differenced code innovations beyond are rejected",
       at(&O::max_code_innovation_m)},
      {"max_post_fit_sigmas", "", "a DD phase with a post-fit residual beyond this many sigmas is dropped",
       at(&O::max_post_fit_sigmas)},
      {"max_post_fit_code_sigmas", "", "a DD code with a post-fit residual beyond this many sigmas is dropped",
       at(&O::max_post_fit_code_sigmas)},
      {"max_partial_fix_sigma_m", "m", "a partial fix by the success rate must leave the position this precise (3D)",
       at(&O::max_partial_fix_sigma_m)},
      {"partial_hold_sigma_cyc", "cycles",
       "fix-and-hold: a partial fix left imprecise (above) is held with this sigma all the same; 0: not held",
       at(&O::partial_hold_sigma_cyc)},
      {"partial_hold_min_satellites", "", "... only at epochs of at least this many satellites",
       at(&O::partial_hold_min_satellites)},
      {"snr_weighting", "", "true: phase sigma from C/N0, b^2 10^((snr_reference_dbhz - C/N0) / 10), not elevation",
       at(&O::snr_weighting)},
      {"snr_reference_dbhz", "dB-Hz", "C/N0 at which the SNR model's elevation-free phase sigma is b",
       at(&O::snr_reference_dbhz)},
      {"max_post_fit_rejections", "", "at most this many signals (phase or code) dropped per epoch",
       at(&O::max_post_fit_rejections)},
      {"hold_sigma_cyc", "cycles", "fix-and-hold pseudo-measurement sigma", at(&O::hold_sigma_cyc)},
      {"max_outage_s", "s", "an ambiguity not observed for longer is re-initialised", at(&O::max_outage_s)},
      {"iono_max_outage_s", "s",
       "a satellite's ionosphere state not observed for longer is re-initialised (at most max_outage_s: that)",
       at(&O::iono_max_outage_s)},
      {"slip_gf_threshold_m", "m", "jump of the geometry-free phase counted as a cycle slip (grows with the gap)",
       at(&O::slips, &Slips::gf_threshold_m)},
      {"slip_doppler", "", "also test the phase change against the Doppler", at(&O::slips, &Slips::use_doppler)},
      {"troposphere", "", "troposphere model at each receiver: saastamoinen | off", at(&O::troposphere_saastamoinen),
       off_or("saastamoinen")},
      {"ionosphere", "", "off (short baselines) | estimate (one SD delay per satellite) | auto (beyond the baseline)",
       at(&O::ionosphere),
       names_of({rtk::IonosphereModel::Off, rtk::IonosphereModel::Estimate, rtk::IonosphereModel::Auto},
                rtk::ionosphere_model_name)},
      {"iono_auto_baseline_km", "km", "with auto, the ionosphere is estimated beyond this baseline",
       at(&O::iono_auto_baseline_km)},
      {"iono_sigma_per_10km_m", "m", "prior sigma of an estimated ionosphere state per 10 km of baseline",
       at(&O::iono_sigma_per_10km_m)},
      {"iono_sigma_min_m", "m", "... and at least this, whatever the baseline", at(&O::iono_sigma_min_m)},
      {"iono_noise_m", "m per sqrt(s)", "ionosphere random walk", at(&O::iono_noise_m)},
      {"iono_residual_sigma_per_10km_m", "m",
       "a new ionosphere state from the others' (their mapped vertical delay) plus a residual of this vertical sigma "
       "per 10 km of baseline; 0: independent states with iono_sigma_per_10km_m",
       at(&O::iono_residual_sigma_per_10km_m)},
      {"ambiguity_prior_max_sigma_cyc", "cycles",
       "a new or slipped ambiguity starts from the filter's position (its DD phase against a held ambiguity) when that "
       "start's sigma is at most this; 0: from its code",
       at(&O::ambiguity_prior_max_sigma_cyc)},
  };
}

/// fusion: the time bridge (fusion/time_bridge.hpp) and the VIO track (fusion/vio_track.hpp).
Table<F> time_bridge_and_vio_keys() {
  using T = fusion::TimeBridgeOptions;
  using V = fusion::VioTrackOptions;
  return {
      {"vio_clock", "", "device: map vio.csv's t_ns with timesync.csv | gps: t_ns is GPST ns since 1980-01-06",
       at(&F::vio_on_gps_time), Names<bool>{{{false, "device"}, {true, "gps"}}}},
      {"timesync_outlier_sigmas", "", "a pair whose residual exceeds this many robust sigmas is an outlier",
       at(&F::time_sync, &T::outlier_sigmas)},
      {"timesync_min_outlier_threshold_s", "s", "residuals up to this are never outliers",
       at(&F::time_sync, &T::min_outlier_threshold_s)},
      {"timesync_max_residual_rms_s", "s", "a fit with a larger inlier residual RMS is refused",
       at(&F::time_sync, &T::max_residual_rms_s)},
      {"timesync_max_drift_ppm", "ppm", "a larger fitted device clock drift is refused",
       at(&F::time_sync, &T::max_drift_ppm)},
      {"timesync_mode", "", "whole_file: one fit to every pair | causal: the pairs received before each pose",
       at(&F::time_sync, &T::causal), Names<bool>{{{false, "whole_file"}, {true, "causal"}}}},
      {"timesync_hold_s", "s", "causal: a pose uses the pairs at least this much older",
       at(&F::time_sync, &T::causal_hold_s)},
      {"timesync_window_pairs", "", "causal: the fit takes at most this many of the latest such pairs",
       at(&F::time_sync, &T::causal_window_pairs)},
      {"vio_max_gap_s", "s", "consecutive poses further apart: a gap, the VIO frame is re-aligned",
       at(&F::vio, &V::max_gap_s)},
      {"vio_max_bridged_gap_s", "s",
       "a gap up to this after which the VIO comes back in the same frame keeps the alignment (0: none)",
       at(&F::vio, &V::max_bridged_gap_s)},
      {"vio_max_speed_mps", "m/s", "a faster jump between poses is a reset of the odometry frame",
       at(&F::vio, &V::max_speed_mps)},
      {"vio_max_rotation_rate_dps", "deg/s", "a faster turn between poses is a reset",
       at(&F::vio, &V::max_rotation_rate_dps)},
      {"vio_stitch_resets", "",
       "a jump or reset is a new odometry frame stitched to the old one (false: a new segment)",
       at(&F::vio, &V::stitch_frame_resets)},
      {"vio_reset_covariance_ratio", "", "the position covariance trace falling below this ratio is a reset",
       at(&F::vio, &V::reset_covariance_ratio)},
      {"vio_cross_covariance", "", "use the consecutive-pose cross-covariances (false: taken as zero)",
       at(&F::vio, &V::use_cross_covariance)},
      {"vio_interpolation_accel_mps2", "m/s^2",
       "acceleration the interpolation between poses misses (1 sigma): position sigma q x (1 - x) dt^2 / 2",
       at(&F::vio, &V::interpolation_accel_mps2)},
  };
}

/// fusion: alignment and lever-arm calibration (Eq. 2, fusion/alignment_schedule.hpp), and beyond the paper the
/// coarse alignment, the heading state, the integrity check and the heading-free fill-in.
Table<F> alignment_keys() {
  using A = fusion::AlignmentScheduleOptions;
  using Fit = fusion::AlignmentOptions;
  using Coarse = fusion::CoarseAlignmentOptions;
  using Heading = fusion::HeadingStateOptions;
  using Integrity = fusion::IntegrityCheckOptions;
  return {
      {"alignment_max_fer", "", "paper: first eigenvalue ratio of the window's positions below this",
       at(&F::alignment, &A::fit, &Fit::max_first_eigenvalue_ratio)},
      {"alignment_max_rmse_m", "m", "paper: the fit's RMSE below this", at(&F::alignment, &A::fit, &Fit::max_rmse_m)},
      {"alignment_min_points", "", "fewer solutions in a window: no alignment",
       at(&F::alignment, &A::fit, &Fit::min_points)},
      {"alignment_window_s", "s", "a window: the last this many seconds of solutions", at(&F::alignment, &A::window_s)},
      {"alignment_interval_s", "s", "until aligned, try at most this often", at(&F::alignment, &A::interval_s)},
      {"realign_interval_s", "s", "once aligned, refresh T_EO with t_IA held this often",
       at(&F::alignment, &A::realign_interval_s)},
      {"alignment_max_window_sigma_m", "m", "solutions with a larger 3-D position sigma do not join a window",
       at(&F::alignment, &A::max_window_sigma_m)},
      {"calibrate_lever_arm", "", "estimate t_IA in the first alignment (the paper's second pass)",
       at(&F::alignment, &A::calibrate_lever_arm)},
      {"lever_arm_prior_m", "m", "t_IA prior in the IMU frame; unexcited directions keep it",
       at(&F::alignment, &A::lever_arm_prior_m), Vector3{"must be [x, y, z] (m)"}},
      {"lever_arm_min_excitation", "", "lever-arm directions with less attitude excitation per solution are held",
       at(&F::alignment, &A::fit, &Fit::min_lever_arm_excitation)},
      {"coarse_alignment", "", "beyond the paper: gravity-aligned yaw fit while no window qualifies",
       at(&F::coarse, &Coarse::enabled)},
      {"coarse_window_s", "s", "its window", at(&F::coarse, &Coarse::window_s)},
      {"coarse_min_spread_m", "m", "RMS horizontal spread it needs", at(&F::coarse, &Coarse::min_spread_m)},
      {"coarse_max_yaw_sigma_deg", "deg", "largest yaw uncertainty it accepts",
       at(&F::coarse, &Coarse::max_yaw_sigma_deg)},
      {"heading_state", "", "beyond the paper: the alignment's heading error as a filter state",
       at(&F::heading, &Heading::enabled)},
      {"heading_random_walk_deg_per_sqrt_km", "deg per sqrt(km)", "VIO heading drift: that state's random walk",
       at(&F::heading, &Heading::random_walk_deg_per_sqrt_km)},
      {"fine_heading_sigma_deg", "deg", "heading sigma after a fine alignment",
       at(&F::heading, &Heading::fine_sigma_deg)},
      {"integrity_check", "", "beyond the paper: restart from the single point when the output leaves it",
       at(&F::integrity, &Integrity::enabled)},
      {"integrity_window_s", "s", "... the median horizontal offset of the single points over this",
       at(&F::integrity, &Integrity::window_s)},
      {"integrity_min_points", "", "... of at least this many of them", at(&F::integrity, &Integrity::min_points)},
      {"integrity_max_offset_m", "m", "... beyond this", at(&F::integrity, &Integrity::max_offset_m)},
      {"integrity_min_agreeing_share", "",
       "... but not while this share of the single points is within integrity_max_offset_m of the output",
       at(&F::integrity, &Integrity::min_agreeing_share)},
      {"heading_free_fill_in", "", "beyond the paper: before an alignment, fill in with the VIO's vertical motion",
       at(&F::heading_free, &fusion::HeadingFreeFillInOptions::enabled)},
  };
}

/// fusion: prediction (Eqs. 3-6), gates, validation (Algorithm 1) and what goes beyond the paper there.
Table<F> update_keys() {
  using P = fusion::PredictionOptions;
  using G = fusion::GateOptions;
  using Valid = fusion::FloatValidationOptions;
  using Guard = fusion::FalseFixGuardOptions;
  using R = fusion::PriorRecoveryOptions;
  return {
      {"prediction", "", "vio | constant_velocity (ablation)", at(&F::prediction, &P::kind),
       names_of({fusion::Prediction::Vio, fusion::Prediction::ConstantVelocity}, fusion::prediction_name)},
      {"vio_covariance", "", "Eqs. 4-6; false: constant_increment_sigma_m per axis (ablation)",
       at(&F::prediction, &P::vio_covariance)},
      {"constant_increment_sigma_m", "m", "the increment's sigma per axis without vio_covariance",
       at(&F::prediction, &P::constant_increment_sigma_m)},
      {"vio_sigma_factor", "", "beyond the paper: the VIO's increment covariance taken times this squared (>= 1)",
       at(&F::prediction, &P::vio_sigma_factor)},
      {"vio_scale_state", "", "beyond the paper: the VIO's scale error as a filter state, learnt from the DD phases",
       at(&F::prediction, &P::scale_state)},
      {"vio_interpolation_state", "",
       "beyond the paper: the error of the VIO interpolated between its samples as a filter state (not a random walk)",
       at(&F::prediction, &P::interpolation_state)},
      {"vio_scale_sigma", "", "... its sigma (relative) when it starts (each VIO segment)",
       at(&F::prediction, &P::vio_scale_sigma)},
      {"vio_scale_random_walk_per_sqrt_km", "per sqrt(km)", "... its random walk",
       at(&F::prediction, &P::vio_scale_random_walk_per_sqrt_km)},
      {"gate", "", "off | paper (DD phase innovation <= 5x the VIO motion) | chi_square | both",
       at(&F::gates, &G::kind),
       names_of({fusion::GateKind::Off, fusion::GateKind::Paper, fusion::GateKind::ChiSquare, fusion::GateKind::Both},
                fusion::gate_kind_name)},
      {"gate_motion_factor", "", "paper: 5 times the VIO incremental motion", at(&F::gates, &G::motion_factor)},
      {"min_gate_m", "m", "the motion gate is at least this (standing still)", at(&F::gates, &G::min_gate_m)},
      {"max_gate_m", "m", "beyond the paper: the motion gate is at most this (speed-aware); 0: no cap",
       at(&F::gates, &G::max_gate_m)},
      {"gate_sigmas", "sigmas", "chi-square gate", at(&F::gates, &G::sigmas)},
      {"gate_nlos_sigmas", "sigmas",
       "NLOS by VIO consistency: a DD code row beyond this many sigmas upward refuses its signal, phase too; 0: off",
       at(&F::gates, &G::nlos_sigmas)},
      {"max_post_fit_normalised", "", "float rejected if a DD post-fit residual exceeds this times its threshold",
       at(&F::validation, &Valid::max_post_fit_normalised)},
      {"max_prior_chi2", "", "float rejected if its chi-square(3) against the VIO prior exceeds this",
       at(&F::validation, &Valid::max_prior_chi2)},
      {"false_fix_guard", "", "beyond the paper: a fix must agree with the VIO prior", at(&F::guard, &Guard::enabled)},
      {"false_fix_chi2", "", "chi-square(3) bound of the guard", at(&F::guard, &Guard::chi2)},
      {"max_fix_sigma_m", "m", "a fix whose position sigma (largest axis) exceeds this is refused",
       at(&F::guard, &Guard::max_fix_sigma_m)},
      {"max_prior_rejections", "", "then a float failing only the prior check is taken (GNSS re-anchors)",
       at(&F::recovery, &R::max_prior_rejections)},
      {"gate_conflict_epochs", "", "then a prior whose gates rejected most rows is widened ...",
       at(&F::recovery, &R::gate_conflict_epochs)},
      {"reanchor_sigma_m", "m", "... by this sigma per axis", at(&F::recovery, &R::reanchor_sigma_m)},
      {"vio_keep_s", "s", "VIO poses older than this before the epoch are forgotten", at(&F::vio_keep_s)},
      {"output_sigma_floor_h_m", "m",
       "beyond the paper: the output covariance is the filter's plus this horizontal sigma (unmodelled multipath)",
       at(&F::output_floor, &fusion::OutputFloorOptions::horizontal_sigma_m)},
      {"output_sigma_floor_v_m", "m", "... and this vertical sigma",
       at(&F::output_floor, &fusion::OutputFloorOptions::vertical_sigma_m)},
      {"output_unfixed_sigma_factor", "",
       "a solution not fixed is output with its filter sigmas times this (code multipath the filter takes as white)",
       at(&F::output_floor, &fusion::OutputFloorOptions::unfixed_sigma_factor)},
  };
}

/// fusion: the C/N0 screen (beyond the paper, fusion/cn0_screen.hpp).
Table<F> cn0_keys() {
  using C = fusion::Cn0ScreenOptions;
  return {
      {"cn0_screen", "", "beyond the paper: drop signals far below the learnt C/N0 of line of sight",
       at(&F::cn0, &C::enabled)},
      {"cn0_margin_db", "dB", "... more than this below it", at(&F::cn0, &C::margin_db)},
      {"cn0_quantile", "", "... the learnt level: this quantile per elevation bin", at(&F::cn0, &C::quantile)},
      {"cn0_bin_deg", "deg", "... elevation bin width", at(&F::cn0, &C::bin_deg)},
      {"cn0_min_samples", "", "... bins with fewer signals screen nothing", at(&F::cn0, &C::min_samples)},
      {"cn0_monotone", "", "... a bin's level at least that of the bins below it", at(&F::cn0, &C::monotone)},
      {"cn0_cross_system", "", "... and at least the other constellations' level, less cross_system_db",
       at(&F::cn0, &C::cross_system)},
      {"cn0_cross_system_db", "dB", "the margin of that cross-system level", at(&F::cn0, &C::cross_system_db)},
  };
}

template <typename S>
Table<S> joined(std::initializer_list<Table<S>> parts) {
  Table<S> all;
  for (const Table<S>& part : parts) all.insert(all.end(), part.begin(), part.end());
  return all;
}

}  // namespace

const Table<gnss::SppOptions>& spp_table() {
  using S = gnss::SppOptions;
  static const Table<S> table{
      {"elevation_mask_deg", "deg", "satellites below are not used", at(&S::elevation_mask_rad), Degrees{}},
      {"systems", "", "constellations used: G GPS, R GLONASS, E Galileo, C BeiDou, J QZSS", whole, Systems{}},
      {"ionosphere", "", "klobuchar | off", at(&S::ionosphere_klobuchar), off_or("klobuchar")},
      {"troposphere", "", "saastamoinen | off", at(&S::troposphere_saastamoinen), off_or("saastamoinen")},
      {"code_sigma_m", "m", "zenith pseudorange noise", at(&S::code_sigma_m)},
      {"raim_fde", "", "exclude one faulty satellite when the residual chi-square test fails", at(&S::raim_fde)},
      {"max_gdop", "", "epochs with a larger GDOP get no solution", at(&S::max_gdop)},
      {"qzss_own_clock", "", "false: QZSS shares the GPS receiver clock", at(&S::qzss_own_clock)},
      {"exclude", "", "satellites never used, e.g. [G05, R12] (also those of rtk.exclude)", at(&S::excluded),
       Satellites{}},
  };
  return table;
}

const Table<rtk::RtkOptions>& rtk_table() {
  static const Table<O> table = joined({rtk_selection_and_ar_keys(), rtk_model_keys()});
  return table;
}

const Table<fusion::FusionOptions>& fusion_table() {
  static const Table<F> table = joined({time_bridge_and_vio_keys(), alignment_keys(), update_keys(), cn0_keys()});
  return table;
}

}  // namespace canyon::config
