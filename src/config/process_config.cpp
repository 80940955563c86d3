// `canyon process` configuration: strict YAML parsing, printing and validation.

#include "canyon/config/process_config.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "canyon/config/yaml_reader.hpp"
#include "canyon/core/constants.hpp"

namespace canyon::config {
namespace {

std::string resolve(const std::string& path, const std::string& file) {
  if (path.empty() || file.empty() || std::filesystem::path(path).is_absolute()) return path;
  return (std::filesystem::path(file).parent_path() / path).lexically_normal().string();
}

/// Reads `systems` (a list of constellation letters) into the flags; records an error for anything else.
void parse_systems(YamlMap& map, core::ConstellationFlags& flags) {
  std::vector<std::string> systems = flags.letters();
  map.get("systems", systems);
  std::string bad;
  if (!flags.set_from_letters(systems, &bad)) map.fail("systems", "has '" + bad + "'; allowed: G, R, E, C, J");
}

void parse_satellites(YamlMap& map, const std::string& key, std::vector<core::SatelliteId>& out) {
  std::vector<std::string> texts;
  texts.reserve(out.size());
  for (const auto& sat : out) texts.push_back(sat.to_string());
  map.get(key, texts);
  out.clear();
  for (const std::string& text : texts) {
    const auto sat = core::parse_satellite(text);
    if (!sat) {
      map.fail(key, "has '" + text + "', not a satellite (e.g. G05, R12, E30, C20, J02)");
    } else {
      out.push_back(*sat);
    }
  }
}

void parse_angle_deg(YamlMap& map, const std::string& key, double& value_rad) {
  double deg = value_rad * core::kRadToDeg;
  map.get(key, deg);
  value_rad = deg * core::kDegToRad;
}

void parse_rtk(YamlMap map, rtk::RtkOptions& o) {
  std::string ar = rtk::ar_mode_name(o.ar_mode);
  map.get("ar_mode", ar);
  if (ar == "off") {
    o.ar_mode = rtk::ArMode::Off;
  } else if (ar == "continuous") {
    o.ar_mode = rtk::ArMode::Continuous;
  } else if (ar == "instantaneous") {
    o.ar_mode = rtk::ArMode::Instantaneous;
  } else if (ar == "fix_and_hold") {
    o.ar_mode = rtk::ArMode::FixAndHold;
  } else {
    map.fail("ar_mode", "must be off, continuous, instantaneous or fix_and_hold, not '" + ar + "'");
  }
  map.get("frequencies", o.observables.num_frequencies);
  rtk::ObservableOptions& obs = o.observables;
  parse_systems(map, obs);
  parse_satellites(map, "exclude", obs.excluded);
  parse_angle_deg(map, "elevation_mask_deg", o.elevation_mask_rad);
  parse_angle_deg(map, "ar_elevation_mask_deg", o.ar_elevation_mask_rad);
  map.get("ratio_threshold", o.ratio_threshold);
  map.get("min_fix_ambiguities", o.min_fix_ambiguities);
  map.get("min_lock_epochs", o.min_lock_epochs);
  map.get("partial_ar", o.partial_ar);
  map.get("max_pruned_satellites", o.max_pruned_satellites);
  map.get("min_success_rate", o.min_success_rate);
  map.get("float_consistency_level", o.float_consistency_level);
  map.get("min_partial_fraction", o.min_partial_fraction);
  std::string glonass_ar = o.glonass_ar ? "on" : "off";
  map.get("glonass_ar", glonass_ar);
  if (glonass_ar != "on" && glonass_ar != "off" && glonass_ar != "true" && glonass_ar != "false") {
    map.fail("glonass_ar", "must be on or off, not '" + glonass_ar + "'");
  }
  o.glonass_ar = glonass_ar == "on" || glonass_ar == "true";
  map.get("dynamics", o.dynamics);
  map.get("accel_sigma_h_mps2", o.accel_sigma_h_mps2);
  map.get("accel_sigma_v_mps2", o.accel_sigma_v_mps2);
  map.get("phase_sigma_m", o.phase_sigma_m);
  map.get("phase_sigma_el_m", o.phase_sigma_el_m);
  map.get("code_phase_ratio", o.code_phase_ratio);
  map.get("initial_ambiguity_sigma_cyc", o.initial_ambiguity_sigma_cyc);
  map.get("ambiguity_noise_cyc", o.ambiguity_noise_cyc);
  map.get("initial_position_sigma_m", o.initial_position_sigma_m);
  map.get("max_age_s", o.max_age_s);
  map.get("max_phase_innovation_m", o.max_phase_innovation_m);
  map.get("max_code_innovation_m", o.max_code_innovation_m);
  map.get("max_post_fit_sigmas", o.max_post_fit_sigmas);
  map.get("max_post_fit_code_sigmas", o.max_post_fit_code_sigmas);
  map.get("max_partial_fix_sigma_m", o.max_partial_fix_sigma_m);
  map.get("snr_weighting", o.snr_weighting);
  map.get("snr_reference_dbhz", o.snr_reference_dbhz);
  map.get("max_post_fit_rejections", o.max_post_fit_rejections);
  map.get("hold_sigma_cyc", o.hold_sigma_cyc);
  map.get("max_outage_s", o.max_outage_s);
  map.get("slip_gf_threshold_m", o.slips.gf_threshold_m);
  map.get("slip_doppler", o.slips.use_doppler);
  std::string tropo = o.troposphere_saastamoinen ? "saastamoinen" : "off";
  map.get("troposphere", tropo);
  if (tropo != "saastamoinen" && tropo != "off") {
    map.fail("troposphere", "must be saastamoinen or off, not '" + tropo + "'");
  }
  o.troposphere_saastamoinen = tropo == "saastamoinen";
  std::string iono = rtk::ionosphere_model_name(o.ionosphere);
  map.get("ionosphere", iono);
  if (iono == "estimate") {
    o.ionosphere = rtk::IonosphereModel::Estimate;
  } else if (iono == "off") {
    o.ionosphere = rtk::IonosphereModel::Off;
  } else if (iono == "auto") {
    o.ionosphere = rtk::IonosphereModel::Auto;
  } else {
    map.fail("ionosphere", "must be off, estimate or auto, not '" + iono + "'");
  }
  map.get("iono_auto_baseline_km", o.iono_auto_baseline_km);
  map.get("iono_sigma_per_10km_m", o.iono_sigma_per_10km_m);
  map.get("iono_sigma_min_m", o.iono_sigma_min_m);
  map.get("iono_noise_m", o.iono_noise_m);
  map.reject_unknown_keys();
}

void parse_vector3(YamlMap& map, const std::string& key, Eigen::Vector3d& v) {
  if (!map.has(key)) return;
  std::vector<double> values;
  map.get(key, values);
  if (values.size() != 3) {
    map.fail(key, "must be [x, y, z] (m)");
    return;
  }
  v = Eigen::Vector3d(values[0], values[1], values[2]);
}

void parse_fusion(YamlMap map, fusion::FusionOptions& o) {
  std::string clock = o.vio_on_gps_time ? "gps" : "device";
  map.get("vio_clock", clock);
  if (clock != "device" && clock != "gps") map.fail("vio_clock", "must be device or gps, not '" + clock + "'");
  o.vio_on_gps_time = clock == "gps";
  map.get("timesync_outlier_sigmas", o.time_sync.outlier_sigmas);
  map.get("timesync_min_outlier_threshold_s", o.time_sync.min_outlier_threshold_s);
  map.get("timesync_max_residual_rms_s", o.time_sync.max_residual_rms_s);
  map.get("timesync_max_drift_ppm", o.time_sync.max_drift_ppm);
  std::string mode = o.time_sync.causal ? "causal" : "whole_file";
  map.get("timesync_mode", mode);
  if (mode != "whole_file" && mode != "causal") {
    map.fail("timesync_mode", "must be whole_file or causal, not '" + mode + "'");
  }
  o.time_sync.causal = mode == "causal";
  map.get("timesync_hold_s", o.time_sync.causal_hold_s);
  map.get("timesync_window_pairs", o.time_sync.causal_window_pairs);
  map.get("vio_max_gap_s", o.vio.max_gap_s);
  map.get("vio_max_speed_mps", o.vio.max_speed_mps);
  map.get("vio_max_rotation_rate_dps", o.vio.max_rotation_rate_dps);
  map.get("vio_reset_covariance_ratio", o.vio.reset_covariance_ratio);
  map.get("vio_cross_covariance", o.vio.use_cross_covariance);
  map.get("alignment_max_fer", o.alignment.fit.max_first_eigenvalue_ratio);
  map.get("alignment_max_rmse_m", o.alignment.fit.max_rmse_m);
  map.get("alignment_min_points", o.alignment.fit.min_points);
  map.get("alignment_window_s", o.alignment.window_s);
  map.get("alignment_interval_s", o.alignment.interval_s);
  map.get("realign_interval_s", o.alignment.realign_interval_s);
  map.get("alignment_max_window_sigma_m", o.alignment.max_window_sigma_m);
  map.get("calibrate_lever_arm", o.alignment.calibrate_lever_arm);
  parse_vector3(map, "lever_arm_prior_m", o.alignment.lever_arm_prior_m);
  map.get("lever_arm_min_excitation", o.alignment.fit.min_lever_arm_excitation);
  map.get("coarse_alignment", o.coarse.enabled);
  map.get("coarse_window_s", o.coarse.window_s);
  map.get("coarse_min_spread_m", o.coarse.min_spread_m);
  map.get("coarse_max_yaw_sigma_deg", o.coarse.max_yaw_sigma_deg);
  map.get("heading_state", o.heading.enabled);
  map.get("heading_random_walk_deg_per_sqrt_km", o.heading.random_walk_deg_per_sqrt_km);
  map.get("fine_heading_sigma_deg", o.heading.fine_sigma_deg);
  map.get("integrity_check", o.integrity.enabled);
  map.get("integrity_window_s", o.integrity.window_s);
  map.get("integrity_min_points", o.integrity.min_points);
  map.get("integrity_max_offset_m", o.integrity.max_offset_m);
  map.get("heading_free_fill_in", o.heading_free.enabled);
  std::string prediction = fusion::prediction_name(o.prediction.kind);
  map.get("prediction", prediction);
  if (prediction == "vio") {
    o.prediction.kind = fusion::Prediction::Vio;
  } else if (prediction == "constant_velocity") {
    o.prediction.kind = fusion::Prediction::ConstantVelocity;
  } else {
    map.fail("prediction", "must be vio or constant_velocity, not '" + prediction + "'");
  }
  map.get("vio_covariance", o.prediction.vio_covariance);
  map.get("constant_increment_sigma_m", o.prediction.constant_increment_sigma_m);
  std::string gate = fusion::gate_kind_name(o.gates.kind);
  map.get("gate", gate);
  if (gate == "off") {
    o.gates.kind = fusion::GateKind::Off;
  } else if (gate == "paper") {
    o.gates.kind = fusion::GateKind::Paper;
  } else if (gate == "chi_square") {
    o.gates.kind = fusion::GateKind::ChiSquare;
  } else if (gate == "both") {
    o.gates.kind = fusion::GateKind::Both;
  } else {
    map.fail("gate", "must be off, paper, chi_square or both, not '" + gate + "'");
  }
  map.get("gate_motion_factor", o.gates.motion_factor);
  map.get("min_gate_m", o.gates.min_gate_m);
  map.get("gate_sigmas", o.gates.sigmas);
  map.get("max_post_fit_normalised", o.validation.max_post_fit_normalised);
  map.get("max_prior_chi2", o.validation.max_prior_chi2);
  map.get("false_fix_guard", o.guard.enabled);
  map.get("false_fix_chi2", o.guard.chi2);
  map.get("max_fix_sigma_m", o.guard.max_fix_sigma_m);
  map.get("max_prior_rejections", o.recovery.max_prior_rejections);
  map.get("gate_conflict_epochs", o.recovery.gate_conflict_epochs);
  map.get("reanchor_sigma_m", o.recovery.reanchor_sigma_m);
  map.get("vio_keep_s", o.vio_keep_s);
  map.get("cn0_screen", o.cn0.enabled);
  map.get("cn0_margin_db", o.cn0.margin_db);
  map.get("cn0_quantile", o.cn0.quantile);
  map.get("cn0_bin_deg", o.cn0.bin_deg);
  map.get("cn0_min_samples", o.cn0.min_samples);
  map.get("cn0_monotone", o.cn0.monotone);
  map.get("cn0_cross_system", o.cn0.cross_system);
  map.get("cn0_cross_system_db", o.cn0.cross_system_db);
  map.reject_unknown_keys();
}

void parse_spp(YamlMap map, gnss::SppOptions& o) {
  parse_angle_deg(map, "elevation_mask_deg", o.elevation_mask_rad);
  parse_systems(map, o);
  std::string iono = o.ionosphere_klobuchar ? "klobuchar" : "off";
  map.get("ionosphere", iono);
  if (iono != "klobuchar" && iono != "off") map.fail("ionosphere", "must be klobuchar or off, not '" + iono + "'");
  o.ionosphere_klobuchar = iono == "klobuchar";
  std::string tropo = o.troposphere_saastamoinen ? "saastamoinen" : "off";
  map.get("troposphere", tropo);
  if (tropo != "saastamoinen" && tropo != "off") {
    map.fail("troposphere", "must be saastamoinen or off, not '" + tropo + "'");
  }
  o.troposphere_saastamoinen = tropo == "saastamoinen";
  map.get("code_sigma_m", o.code_sigma_m);
  map.get("raim_fde", o.raim_fde);
  map.get("max_gdop", o.max_gdop);
  map.get("qzss_own_clock", o.qzss_own_clock);
  parse_satellites(map, "exclude", o.excluded);
  map.reject_unknown_keys();
}

}  // namespace

std::string mode_name(ProcessMode mode) {
  switch (mode) {
    case ProcessMode::Spp: return "spp";
    case ProcessMode::Rtk: return "rtk";
    case ProcessMode::Fusion: return "fusion";
  }
  return "?";
}

std::string ProcessConfig::validate() const {
  if (rover_obs.empty()) return "a rover observation file is required (--rover or 'rover:')";
  if (nav.empty()) return "at least one navigation file is required (--nav or 'nav:')";
  if (out.empty()) return "a solution file is required (--out or 'out:')";
  if (exclude_most_observed < 0) return "exclude_most_observed must be >= 0";
  if (const std::string e = spp.validate(); !e.empty()) return "spp: " + e;
  if (mode == ProcessMode::Rtk || mode == ProcessMode::Fusion) {
    if (base_obs.empty()) return mode_name(mode) + " needs a base observation file (--base or 'base:')";
    if (const std::string e = rtk.validate(); !e.empty()) return "rtk: " + e;
  }
  if (mode == ProcessMode::Fusion) {
    if (vio.empty()) return "fusion needs a VIO file (--vio or 'vio:')";
    if (timesync.empty() && !fusion.vio_on_gps_time) {
      return "fusion needs a time-sync file (--timesync or 'timesync:'), or fusion.vio_clock: gps for VIO stamped "
             "with GPST";
    }
    if (const std::string e = fusion.validate(); !e.empty()) return "fusion: " + e;
  }
  return {};
}

rtk::RtkOptions ProcessConfig::rtk_engine_options() const {
  rtk::RtkOptions o = rtk;
  o.spp = spp;
  for (const core::SatelliteId& sat : rtk.observables.excluded) {
    if (std::find(o.spp.excluded.begin(), o.spp.excluded.end(), sat) == o.spp.excluded.end()) {
      o.spp.excluded.push_back(sat);
    }
  }
  for (const core::SatelliteId& sat : spp.excluded) {
    std::vector<core::SatelliteId>& excluded = o.observables.excluded;
    if (std::find(excluded.begin(), excluded.end(), sat) == excluded.end()) excluded.push_back(sat);
  }
  return o;
}

bool operator==(const ProcessConfig& a, const ProcessConfig& b) {
  return to_yaml(a) == to_yaml(b);
}

Result<ProcessConfig> parse_process_config(const YAML::Node& node, const std::string& file, ProcessConfig defaults) {
  ProcessConfig c = std::move(defaults);
  YamlMap top(node, file);
  std::string mode = mode_name(c.mode);
  top.get("mode", mode);
  if (mode == "spp") {
    c.mode = ProcessMode::Spp;
  } else if (mode == "rtk") {
    c.mode = ProcessMode::Rtk;
  } else if (mode == "fusion") {
    c.mode = ProcessMode::Fusion;
  } else {
    top.fail("mode", "must be spp, rtk or fusion, not '" + mode + "'");
  }
  top.get("rover", c.rover_obs);
  c.rover_obs = resolve(c.rover_obs, file);
  top.get("base", c.base_obs);
  c.base_obs = resolve(c.base_obs, file);
  top.get("vio", c.vio);
  c.vio = resolve(c.vio, file);
  top.get("timesync", c.timesync);
  c.timesync = resolve(c.timesync, file);
  if (top.has("base_position")) {
    std::vector<std::string> xyz;
    top.get("base_position", xyz);
    std::vector<double> values;
    for (const std::string& v : xyz) {
      try {
        values.push_back(std::stod(v));
      } catch (const std::exception&) {
        values.clear();
        break;
      }
    }
    if (values.size() != 3) {
      top.fail("base_position", "must be [X, Y, Z], ECEF metres");
    } else {
      c.base_position_E_m = Eigen::Vector3d(values[0], values[1], values[2]);
    }
  }
  top.get("nav", c.nav);
  for (std::string& n : c.nav) n = resolve(n, file);
  top.get("out", c.out);
  c.out = resolve(c.out, file);
  top.get("nmea", c.nmea_out);
  c.nmea_out = resolve(c.nmea_out, file);
  top.get("exclude_most_observed", c.exclude_most_observed);
  if (c.exclude_most_observed < 0) top.fail("exclude_most_observed", "must be >= 0");
  {
    YamlMap output = top.sub("output");
    std::string coordinates = c.coordinates == io::PosCoordinates::Llh ? "llh" : "ecef";
    output.get("coordinates", coordinates);
    if (coordinates != "llh" && coordinates != "ecef") {
      output.fail("coordinates", "must be llh or ecef, not '" + coordinates + "'");
    }
    c.coordinates = coordinates == "ecef" ? io::PosCoordinates::Ecef : io::PosCoordinates::Llh;
    std::string time_format = c.time_format == io::PosTimeFormat::WeekTow ? "tow" : "calendar";
    output.get("time_format", time_format);
    if (time_format != "tow" && time_format != "calendar") {
      output.fail("time_format", "must be tow or calendar, not '" + time_format + "'");
    }
    c.time_format = time_format == "calendar" ? io::PosTimeFormat::Calendar : io::PosTimeFormat::WeekTow;
    output.reject_unknown_keys();
  }
  parse_spp(top.sub("spp"), c.spp);
  parse_rtk(top.sub("rtk"), c.rtk);
  parse_fusion(top.sub("fusion"), c.fusion);
  top.reject_unknown_keys();
  if (Status s = top.status(); !s) return s.error();
  if (const std::string e = c.spp.validate(); !e.empty()) return Error{"spp: " + e, file, 0};
  if (const std::string e = c.rtk.validate(); !e.empty()) return Error{"rtk: " + e, file, 0};
  if (const std::string e = c.fusion.validate(); !e.empty()) return Error{"fusion: " + e, file, 0};
  return c;
}

Result<ProcessConfig> load_process_config(const std::string& path, ProcessConfig defaults) {
  auto node = load_yaml_file(path);
  if (!node) return node.error();
  return parse_process_config(*node, path, std::move(defaults));
}

static void emit_rtk(YAML::Emitter& out, const rtk::RtkOptions& o) {
  out << YAML::Key << "rtk" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "ar_mode" << YAML::Value << rtk::ar_mode_name(o.ar_mode);
  out << YAML::Key << "frequencies" << YAML::Value << o.observables.num_frequencies;
  out << YAML::Key << "systems" << YAML::Value << YAML::Flow << o.observables.letters();
  std::vector<std::string> excluded;
  for (const auto& sat : o.observables.excluded) excluded.push_back(sat.to_string());
  out << YAML::Key << "exclude" << YAML::Value << YAML::Flow << excluded;
  out << YAML::Key << "elevation_mask_deg" << YAML::Value << o.elevation_mask_rad * core::kRadToDeg;
  out << YAML::Key << "ar_elevation_mask_deg" << YAML::Value << o.ar_elevation_mask_rad * core::kRadToDeg;
  out << YAML::Key << "ratio_threshold" << YAML::Value << o.ratio_threshold;
  out << YAML::Key << "min_fix_ambiguities" << YAML::Value << o.min_fix_ambiguities;
  out << YAML::Key << "min_lock_epochs" << YAML::Value << o.min_lock_epochs;
  out << YAML::Key << "partial_ar" << YAML::Value << o.partial_ar;
  out << YAML::Key << "max_pruned_satellites" << YAML::Value << o.max_pruned_satellites;
  out << YAML::Key << "min_success_rate" << YAML::Value << o.min_success_rate;
  out << YAML::Key << "float_consistency_level" << YAML::Value << o.float_consistency_level;
  out << YAML::Key << "min_partial_fraction" << YAML::Value << o.min_partial_fraction;
  out << YAML::Key << "glonass_ar" << YAML::Value << (o.glonass_ar ? "on" : "off");
  out << YAML::Key << "dynamics" << YAML::Value << o.dynamics;
  out << YAML::Key << "accel_sigma_h_mps2" << YAML::Value << o.accel_sigma_h_mps2;
  out << YAML::Key << "accel_sigma_v_mps2" << YAML::Value << o.accel_sigma_v_mps2;
  out << YAML::Key << "phase_sigma_m" << YAML::Value << o.phase_sigma_m;
  out << YAML::Key << "phase_sigma_el_m" << YAML::Value << o.phase_sigma_el_m;
  out << YAML::Key << "code_phase_ratio" << YAML::Value << o.code_phase_ratio;
  out << YAML::Key << "initial_ambiguity_sigma_cyc" << YAML::Value << o.initial_ambiguity_sigma_cyc;
  out << YAML::Key << "ambiguity_noise_cyc" << YAML::Value << o.ambiguity_noise_cyc;
  out << YAML::Key << "initial_position_sigma_m" << YAML::Value << o.initial_position_sigma_m;
  out << YAML::Key << "max_age_s" << YAML::Value << o.max_age_s;
  out << YAML::Key << "max_phase_innovation_m" << YAML::Value << o.max_phase_innovation_m;
  out << YAML::Key << "max_code_innovation_m" << YAML::Value << o.max_code_innovation_m;
  out << YAML::Key << "max_post_fit_sigmas" << YAML::Value << o.max_post_fit_sigmas;
  out << YAML::Key << "max_post_fit_code_sigmas" << YAML::Value << o.max_post_fit_code_sigmas;
  out << YAML::Key << "max_partial_fix_sigma_m" << YAML::Value << o.max_partial_fix_sigma_m;
  out << YAML::Key << "snr_weighting" << YAML::Value << o.snr_weighting;
  out << YAML::Key << "snr_reference_dbhz" << YAML::Value << o.snr_reference_dbhz;
  out << YAML::Key << "max_post_fit_rejections" << YAML::Value << o.max_post_fit_rejections;
  out << YAML::Key << "hold_sigma_cyc" << YAML::Value << o.hold_sigma_cyc;
  out << YAML::Key << "max_outage_s" << YAML::Value << o.max_outage_s;
  out << YAML::Key << "slip_gf_threshold_m" << YAML::Value << o.slips.gf_threshold_m;
  out << YAML::Key << "slip_doppler" << YAML::Value << o.slips.use_doppler;
  out << YAML::Key << "troposphere" << YAML::Value << (o.troposphere_saastamoinen ? "saastamoinen" : "off");
  out << YAML::Key << "ionosphere" << YAML::Value << rtk::ionosphere_model_name(o.ionosphere);
  out << YAML::Key << "iono_auto_baseline_km" << YAML::Value << o.iono_auto_baseline_km;
  out << YAML::Key << "iono_sigma_per_10km_m" << YAML::Value << o.iono_sigma_per_10km_m;
  out << YAML::Key << "iono_sigma_min_m" << YAML::Value << o.iono_sigma_min_m;
  out << YAML::Key << "iono_noise_m" << YAML::Value << o.iono_noise_m;
  out << YAML::EndMap;
}

static void emit_fusion(YAML::Emitter& out, const fusion::FusionOptions& o) {
  const auto key = [&out](const char* k) -> YAML::Emitter& { return out << YAML::Key << k << YAML::Value; };
  out << YAML::Key << "fusion" << YAML::Value << YAML::BeginMap;
  key("vio_clock") << (o.vio_on_gps_time ? "gps" : "device");
  key("timesync_outlier_sigmas") << o.time_sync.outlier_sigmas;
  key("timesync_min_outlier_threshold_s") << o.time_sync.min_outlier_threshold_s;
  key("timesync_max_residual_rms_s") << o.time_sync.max_residual_rms_s;
  key("timesync_max_drift_ppm") << o.time_sync.max_drift_ppm;
  key("timesync_mode") << (o.time_sync.causal ? "causal" : "whole_file");
  key("timesync_hold_s") << o.time_sync.causal_hold_s;
  key("timesync_window_pairs") << o.time_sync.causal_window_pairs;
  key("vio_max_gap_s") << o.vio.max_gap_s;
  key("vio_max_speed_mps") << o.vio.max_speed_mps;
  key("vio_max_rotation_rate_dps") << o.vio.max_rotation_rate_dps;
  key("vio_reset_covariance_ratio") << o.vio.reset_covariance_ratio;
  key("vio_cross_covariance") << o.vio.use_cross_covariance;
  key("alignment_max_fer") << o.alignment.fit.max_first_eigenvalue_ratio;
  key("alignment_max_rmse_m") << o.alignment.fit.max_rmse_m;
  key("alignment_min_points") << o.alignment.fit.min_points;
  key("alignment_window_s") << o.alignment.window_s;
  key("alignment_interval_s") << o.alignment.interval_s;
  key("realign_interval_s") << o.alignment.realign_interval_s;
  key("alignment_max_window_sigma_m") << o.alignment.max_window_sigma_m;
  key("calibrate_lever_arm") << o.alignment.calibrate_lever_arm;
  key("lever_arm_prior_m") << YAML::Flow << YAML::BeginSeq << o.alignment.lever_arm_prior_m.x()
                           << o.alignment.lever_arm_prior_m.y() << o.alignment.lever_arm_prior_m.z() << YAML::EndSeq;
  key("lever_arm_min_excitation") << o.alignment.fit.min_lever_arm_excitation;
  key("coarse_alignment") << o.coarse.enabled;
  key("coarse_window_s") << o.coarse.window_s;
  key("coarse_min_spread_m") << o.coarse.min_spread_m;
  key("coarse_max_yaw_sigma_deg") << o.coarse.max_yaw_sigma_deg;
  key("heading_state") << o.heading.enabled;
  key("heading_random_walk_deg_per_sqrt_km") << o.heading.random_walk_deg_per_sqrt_km;
  key("fine_heading_sigma_deg") << o.heading.fine_sigma_deg;
  key("integrity_check") << o.integrity.enabled;
  key("integrity_window_s") << o.integrity.window_s;
  key("integrity_min_points") << o.integrity.min_points;
  key("integrity_max_offset_m") << o.integrity.max_offset_m;
  key("heading_free_fill_in") << o.heading_free.enabled;
  key("prediction") << fusion::prediction_name(o.prediction.kind);
  key("vio_covariance") << o.prediction.vio_covariance;
  key("constant_increment_sigma_m") << o.prediction.constant_increment_sigma_m;
  key("gate") << fusion::gate_kind_name(o.gates.kind);
  key("gate_motion_factor") << o.gates.motion_factor;
  key("min_gate_m") << o.gates.min_gate_m;
  key("gate_sigmas") << o.gates.sigmas;
  key("max_post_fit_normalised") << o.validation.max_post_fit_normalised;
  key("max_prior_chi2") << o.validation.max_prior_chi2;
  key("false_fix_guard") << o.guard.enabled;
  key("false_fix_chi2") << o.guard.chi2;
  key("max_fix_sigma_m") << o.guard.max_fix_sigma_m;
  key("max_prior_rejections") << o.recovery.max_prior_rejections;
  key("gate_conflict_epochs") << o.recovery.gate_conflict_epochs;
  key("reanchor_sigma_m") << o.recovery.reanchor_sigma_m;
  key("vio_keep_s") << o.vio_keep_s;
  key("cn0_screen") << o.cn0.enabled;
  key("cn0_margin_db") << o.cn0.margin_db;
  key("cn0_quantile") << o.cn0.quantile;
  key("cn0_bin_deg") << o.cn0.bin_deg;
  key("cn0_min_samples") << o.cn0.min_samples;
  key("cn0_monotone") << o.cn0.monotone;
  key("cn0_cross_system") << o.cn0.cross_system;
  key("cn0_cross_system_db") << o.cn0.cross_system_db;
  out << YAML::EndMap;
}

std::string to_yaml(const ProcessConfig& c) {
  YAML::Emitter out;
  out.SetDoublePrecision(12);  // shortest form of the configured values (0.99, not 0.98999999999999999)
  out << YAML::BeginMap;
  out << YAML::Key << "mode" << YAML::Value << mode_name(c.mode);
  out << YAML::Key << "rover" << YAML::Value << c.rover_obs;
  out << YAML::Key << "base" << YAML::Value << c.base_obs;
  out << YAML::Key << "vio" << YAML::Value << c.vio;
  out << YAML::Key << "timesync" << YAML::Value << c.timesync;
  if (c.base_position_E_m) {
    out << YAML::Key << "base_position" << YAML::Value << YAML::Flow << YAML::BeginSeq << c.base_position_E_m->x()
        << c.base_position_E_m->y() << c.base_position_E_m->z() << YAML::EndSeq;
  }
  out << YAML::Key << "nav" << YAML::Value << YAML::Flow << c.nav;
  out << YAML::Key << "out" << YAML::Value << c.out;
  if (!c.nmea_out.empty()) out << YAML::Key << "nmea" << YAML::Value << c.nmea_out;
  out << YAML::Key << "exclude_most_observed" << YAML::Value << c.exclude_most_observed;
  out << YAML::Key << "output" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "coordinates" << YAML::Value << (c.coordinates == io::PosCoordinates::Llh ? "llh" : "ecef");
  out << YAML::Key << "time_format" << YAML::Value
      << (c.time_format == io::PosTimeFormat::WeekTow ? "tow" : "calendar");
  out << YAML::EndMap;
  const gnss::SppOptions& s = c.spp;
  out << YAML::Key << "spp" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "elevation_mask_deg" << YAML::Value << s.elevation_mask_rad * core::kRadToDeg;
  out << YAML::Key << "systems" << YAML::Value << YAML::Flow << s.letters();
  out << YAML::Key << "ionosphere" << YAML::Value << (s.ionosphere_klobuchar ? "klobuchar" : "off");
  out << YAML::Key << "troposphere" << YAML::Value << (s.troposphere_saastamoinen ? "saastamoinen" : "off");
  out << YAML::Key << "code_sigma_m" << YAML::Value << s.code_sigma_m;
  out << YAML::Key << "raim_fde" << YAML::Value << s.raim_fde;
  out << YAML::Key << "max_gdop" << YAML::Value << s.max_gdop;
  out << YAML::Key << "qzss_own_clock" << YAML::Value << s.qzss_own_clock;
  std::vector<std::string> excluded;
  for (const auto& sat : s.excluded) excluded.push_back(sat.to_string());
  out << YAML::Key << "exclude" << YAML::Value << YAML::Flow << excluded;
  out << YAML::EndMap;
  emit_rtk(out, c.rtk);
  emit_fusion(out, c.fusion);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace canyon::config
