// Options of the RTK filter (see rtk_options.hpp).

#include "canyon/rtk/rtk_options.hpp"

#include <cmath>

#include "canyon/core/constants.hpp"

namespace canyon::rtk {

const char* ar_mode_name(ArMode mode) {
  switch (mode) {
    case ArMode::Off: return "off";
    case ArMode::Continuous: return "continuous";
    case ArMode::Instantaneous: return "instantaneous";
    case ArMode::FixAndHold: return "fix_and_hold";
  }
  return "?";
}

const char* ionosphere_model_name(IonosphereModel model) {
  switch (model) {
    case IonosphereModel::Off: return "off";
    case IonosphereModel::Estimate: return "estimate";
    case IonosphereModel::Auto: return "auto";
  }
  return "?";
}

std::string RtkOptions::validate() const {
  if (observables.num_frequencies < 1 || observables.num_frequencies > kMaxFrequencies) {
    return "frequencies must be 1, 2 or 3";
  }
  if (!(elevation_mask_rad >= 0.0 && elevation_mask_rad < core::kPi / 2.0)) {
    return "elevation_mask_rad must be in [0, pi/2)";
  }
  if (!(ratio_threshold >= 1.0)) return "ratio_threshold must be >= 1";
  if (min_fix_ambiguities < 1) return "min_fix_ambiguities must be >= 1";
  if (!(min_success_rate >= 0.0 && min_success_rate <= 1.0)) return "min_success_rate must be in [0, 1]";
  if (!(float_consistency_level >= 0.0 && float_consistency_level < 0.5)) {
    return "float_consistency_level must be in [0, 0.5) (0: no test)";
  }
  if (!(min_partial_fraction >= 0.0 && min_partial_fraction <= 1.0)) return "min_partial_fraction must be in [0, 1]";
  if (!(max_partial_fix_sigma_m > 0.0)) return "max_partial_fix_sigma_m must be > 0";
  if (!(partial_hold_sigma_cyc >= 0.0 && std::isfinite(partial_hold_sigma_cyc))) {
    return "partial_hold_sigma_cyc must be finite and >= 0 (0: not held)";
  }
  if (partial_hold_min_satellites < 4) return "partial_hold_min_satellites must be >= 4";
  if (!(snr_reference_dbhz > 0.0)) return "snr_reference_dbhz must be > 0";
  if (!(iono_auto_baseline_km >= 0.0)) return "iono_auto_baseline_km must be >= 0";
  if (!(iono_residual_sigma_per_10km_m >= 0.0 && std::isfinite(iono_residual_sigma_per_10km_m))) {
    return "iono_residual_sigma_per_10km_m must be finite and >= 0 (0: independent ionosphere states)";
  }
  if (max_pruned_satellites < 0) return "max_pruned_satellites must be >= 0";
  if (!(phase_sigma_m > 0.0) || !(code_phase_ratio > 0.0)) return "phase_sigma_m and code_phase_ratio must be > 0";
  if (!(code_multipath_sigma_m >= 0.0 && std::isfinite(code_multipath_sigma_m))) {
    return "code_multipath_sigma_m must be finite and >= 0";
  }
  if (!(code_multipath_correlation_s > 0.0 && std::isfinite(code_multipath_correlation_s))) {
    return "code_multipath_correlation_s must be finite and > 0";
  }
  if (!(max_age_s > 0.0)) return "max_age_s must be > 0";
  if (!(iono_max_outage_s >= 0.0 && std::isfinite(iono_max_outage_s)))
    return "iono_max_outage_s must be finite and >= 0";
  if (!(initial_ambiguity_sigma_cyc > 0.0)) return "initial_ambiguity_sigma_cyc must be > 0";
  if (!(hold_sigma_cyc > 0.0)) return "hold_sigma_cyc must be > 0";
  if (!(ambiguity_prior_max_sigma_cyc >= 0.0 && ambiguity_prior_max_sigma_cyc < 0.5)) {
    return "ambiguity_prior_max_sigma_cyc must be >= 0 and < 0.5";
  }
  if (!(max_post_fit_sigmas > 0.0) || !(max_post_fit_code_sigmas > 0.0) || max_post_fit_rejections < 0) {
    return "max_post_fit_sigmas and max_post_fit_code_sigmas must be > 0 and max_post_fit_rejections >= 0";
  }
  if (const std::string e = slips.validate(); !e.empty()) return "slips: " + e;
  if (const std::string e = spp.validate(); !e.empty()) return "spp: " + e;
  return {};
}

}  // namespace canyon::rtk
