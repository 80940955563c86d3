#pragma once
// Options of the RTK filter (engine.hpp; the model each option belongs to is described in the header of the piece
// that uses it: single_difference.hpp, dd_update.hpp, ambiguity_resolution.hpp, time_update.hpp).

#include <string>

#include "canyon/gnss/spp.hpp"
#include "canyon/rtk/cycle_slip.hpp"
#include "canyon/rtk/observables.hpp"

namespace canyon::rtk {

enum class ArMode { Off, Continuous, Instantaneous, FixAndHold };

/// Differential ionosphere: neglected (short baselines), estimated as one single-differenced slant delay per
/// satellite (L1-band metres, scaled by (f_1 / f)^2 on other frequencies; it delays code and advances phase), or
/// Auto: estimated while the baseline is longer than iono_auto_baseline_km (off again below 80 % of it).
enum class IonosphereModel { Off, Estimate, Auto };

struct RtkOptions {
  ObservableOptions observables;  ///< systems, number of frequencies (1..3), excluded satellites
  ArMode ar_mode = ArMode::Continuous;
  double elevation_mask_rad = 15.0 * 0.017453292519943295;     ///< satellites below are not used
  double ar_elevation_mask_rad = 15.0 * 0.017453292519943295;  ///< ambiguities below are not fixed
  bool dynamics = false;            ///< constant-acceleration model; false: position from SPP each epoch
  double accel_sigma_h_mps2 = 3.0;  ///< horizontal acceleration noise (m/s^2 per sqrt(s)) with dynamics
  double accel_sigma_v_mps2 = 1.0;  ///< vertical acceleration noise with dynamics
  double phase_sigma_m = 0.003;     ///< a: zenith-independent phase noise (m)
  double phase_sigma_el_m = 0.003;  ///< b: elevation-dependent phase noise (m), divided by sin(el)
  double code_phase_ratio = 100.0;  ///< code sigma / phase sigma

  /// Time-correlated code multipath (single_difference.hpp): sigma of each signal's SD code error state (m); 0: none.
  double code_multipath_sigma_m = 0.0;
  double code_multipath_correlation_s = 30.0;  ///< its correlation time (s)

  bool snr_weighting = false;                 ///< b^2 10^((snr_reference - C/N0) / 10) instead of b^2 / sin^2(el)
  double snr_reference_dbhz = 45.0;           ///< C/N0 at which the SNR model's phase sigma is b (dB-Hz)
  double initial_ambiguity_sigma_cyc = 30.0;  ///< sigma of a new ambiguity (cycles)
  double ambiguity_noise_cyc = 1e-4;          ///< ambiguity random walk (cycles per sqrt(s))
  double initial_position_sigma_m = 30.0;     ///< sigma of the SPP position used as prior (m)
  double ratio_threshold = 3.0;               ///< ratio test threshold (the paper's 3.0)
  int min_fix_ambiguities = 4;                ///< fewer DD ambiguities are not fixed
  bool partial_ar = true;                     ///< when the full set fails, fix a subset (pruning, groups)
  int max_pruned_satellites = 6;              ///< partial fixing drops at most this many satellites one by one
  double min_success_rate = 0.99;             ///< bootstrapped success rate a fix needs besides the ratio test
  double float_consistency_level = 0.0;       ///< significance of the float consistency test (above); 0: no test
  double min_partial_fraction = 0.2;          ///< a partial fix keeps at least this fraction of the ambiguities
  double max_partial_fix_sigma_m = 0.05;      ///< a partial fix by the success rate must leave the position this
                                              ///< precise (3D sigma, m) to count as fixed
  int min_lock_epochs = 0;                    ///< epochs an ambiguity must be tracked before it is fixed
  bool glonass_ar = false;                    ///< fix GLONASS ambiguities (needs equal inter-frequency biases)
  double max_age_s = 30.0;                    ///< base observations older than this are not used
  double max_phase_innovation_m = 30.0;       ///< DD phase innovations beyond are rejected as outliers
  double max_code_innovation_m = 100.0;       ///< DD code innovations beyond are rejected as outliers
  double max_post_fit_sigmas = 4.0;           ///< DD phase post-fit residuals beyond (in sigmas) are rejected
  double max_post_fit_code_sigmas = 6.0;      ///< DD code post-fit residuals beyond (in sigmas) are rejected
  int max_post_fit_rejections = 3;            ///< at most this many signals (phase or code) rejected per epoch
  double hold_sigma_cyc = 0.001;              ///< fix-and-hold pseudo-measurement sigma (cycles)
  double max_outage_s = 5.0;                  ///< an ambiguity not observed for longer is re-initialised
  /// A satellite's ionosphere state not observed for longer is re-initialised (s; at most max_outage_s counts as it):
  /// the ionosphere walks slowly (iono_noise_m), so a state kept through a blockage starts the re-acquired signal's
  /// ambiguity from the position (ambiguity_prior.hpp) where a fresh one's 20 km prior would not allow it.
  double iono_max_outage_s = 0.0;
  CycleSlipOptions slips;                ///< cycle-slip detection at each receiver
  bool troposphere_saastamoinen = true;  ///< model the troposphere at each receiver (off: data without one)
  IonosphereModel ionosphere = IonosphereModel::Auto;  ///< differential ionosphere model
  double iono_auto_baseline_km = 10.0;  ///< with Auto, the ionosphere is estimated on baselines longer than this
  double iono_sigma_per_10km_m = 0.03;  ///< prior sigma of a SD ionosphere state per 10 km of baseline (m)
  double iono_sigma_min_m = 0.001;      ///< the prior sigma is at least this (m), whatever the baseline
  double iono_noise_m = 0.001;          ///< SD ionosphere random walk (m per sqrt(s))
  /// A new ionosphere state from the others' (ionosphere_prior.hpp): its own vertical residual sigma per 10 km of
  /// baseline (m); 0: every state independent, with the sigma above.
  double iono_residual_sigma_per_10km_m = 0.0;
  /// A new or slipped ambiguity from the filter's position (ambiguity_prior.hpp): started as the DD phase's ambiguity
  /// against a held one when that start's sigma is at most this (cycles); 0: every new ambiguity from its code, with
  /// initial_ambiguity_sigma_cyc.
  double ambiguity_prior_max_sigma_cyc = 0.0;
  /// Fix-and-hold of a partial fix by the success rate that leaves the position less precise than
  /// max_partial_fix_sigma_m (cascaded fixing: the most precise, wide-lane-like combinations held while the rest
  /// converge): its integers are held with this sigma (cycles) at epochs of at least partial_hold_min_satellites
  /// satellites; 0: not held (they condition only the epoch's output).
  double partial_hold_sigma_cyc = 0.0;
  int partial_hold_min_satellites = 10;  ///< fewest satellites of an epoch whose imprecise partial fix is held
  gnss::SppOptions spp;                  ///< single-point solution (prior and fallback)
  /// A heading-error state of the external aiding (see above); set by the aiding's owner (the fusion), not in YAML.
  bool aiding_heading_state = false;
  /// A scale-error state of the external aiding (time_update.hpp); set by the aiding's owner, not in YAML.
  bool aiding_scale_state = false;
  /// An interpolation-error state of the external aiding (time_update.hpp); set by the aiding's owner, not in YAML.
  bool aiding_interpolation_state = false;

  /// Empty if valid, else the violated rule.
  [[nodiscard]] std::string validate() const;
};

[[nodiscard]] const char* ar_mode_name(ArMode mode);
/// "off", "estimate" or "auto", as in the configuration.
[[nodiscard]] const char* ionosphere_model_name(IonosphereModel model);

}  // namespace canyon::rtk
