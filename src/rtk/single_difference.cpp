// Single differences of one epoch (see single_difference.hpp).

#include "canyon/rtk/single_difference.hpp"

#include <algorithm>
#include <cmath>

namespace canyon::rtk {

using core::Constellation;
using core::SatelliteId;

double first_wavelength_m(const gnss::EphemerisStore& eph, SatelliteId sat) {
  const char band = sat.system == Constellation::BeiDou ? '2' : '1';
  const int channel = sat.system == Constellation::Glonass ? eph.glonass_channel(sat.prn) : core::kNoGlonassChannel;
  return core::wavelength_m(sat.system, core::SignalCode{band, 'C'}, channel).value_or(0.19029367279836487);
}

double zero_diff_phase_variance(const RtkOptions& o, double elevation_rad, double snr_dbhz) {
  const double b2 = o.phase_sigma_el_m * o.phase_sigma_el_m;
  if (o.snr_weighting && core::has_value(snr_dbhz) && snr_dbhz > 0.0) {
    return o.phase_sigma_m * o.phase_sigma_m + b2 * std::pow(10.0, (o.snr_reference_dbhz - snr_dbhz) / 10.0);
  }
  const double sin_el = std::max(std::sin(elevation_rad), 0.05);
  return o.phase_sigma_m * o.phase_sigma_m + b2 / (sin_el * sin_el);
}

std::vector<SingleDiff> form_single_differences(EpochGeometry& geometry, const Eigen::Vector3d& p_E_rover_m,
                                                const RtkOptions& options, const gnss::EphemerisStore& eph,
                                                bool iono_estimated) {
  const ReceiverObservables& rover_obs = geometry.rover_obs;
  const ReceiverObservables& base_obs = geometry.base_obs;
  const ReceiverGeometry rover(p_E_rover_m);
  const bool tropo = options.troposphere_saastamoinen;
  std::vector<SingleDiff> sds;
  sds.reserve(rover_obs.signals.size());
  SatelliteId current{};
  ZeroDiff zr;
  ZeroDiff zb;
  for (const SignalObservable& r : rover_obs.signals) {
    const SignalObservable* b = base_obs.find(r.sat, r.frequency);
    if (b == nullptr) continue;
    if (r.sat != current || sds.empty()) {
      // Each receiver's geometry at its own transmission time (its own time tag and pseudorange).
      current = r.sat;
      const double pr_r = any_pseudorange(rover_obs, r.sat);
      zr = core::has_value(pr_r) ? zero_difference(geometry.rover_states, r.sat, pr_r, rover, tropo) : ZeroDiff{};
      zb = geometry.base_model(r.sat);
    }
    if (!zr.valid || !zb.valid || zr.elevation_rad < options.elevation_mask_rad) continue;
    SingleDiff sd;
    sd.sat = r.sat;
    sd.frequency = r.frequency;
    sd.group = static_cast<int>(r.sat.system) * kMaxFrequencies + r.frequency;
    sd.wavelength_m = r.wavelength_m;
    if (iono_estimated) sd.iono_scale = std::pow(r.wavelength_m / first_wavelength_m(eph, r.sat), 2);
    sd.lli = static_cast<std::uint8_t>(r.lli | b->lli);
    const double model_m = zr.model_m - zb.model_m;
    if (core::has_value(r.carrier_phase_cyc) && core::has_value(b->carrier_phase_cyc) &&
        std::abs(r.wavelength_m - b->wavelength_m) < 1e-9) {
      sd.phase_m = r.wavelength_m * (r.carrier_phase_cyc - b->carrier_phase_cyc) - model_m;
    }
    if (core::has_value(r.pseudorange_m) && core::has_value(b->pseudorange_m)) {
      sd.code_m = (r.pseudorange_m - b->pseudorange_m) - model_m;
    }
    const double var_sd = zero_diff_phase_variance(options, zr.elevation_rad, r.snr_dbhz) +
                          zero_diff_phase_variance(options, zb.elevation_rad, b->snr_dbhz);
    sd.phase_variance_m2 = var_sd;
    sd.code_variance_m2 = var_sd * options.code_phase_ratio * options.code_phase_ratio;
    sd.test_variance_m2 = zero_diff_phase_variance(options, zr.elevation_rad, core::kNoValue) +
                          zero_diff_phase_variance(options, zb.elevation_rad, core::kNoValue);
    sd.los_E = zr.los_E;
    sd.elevation_rad = zr.elevation_rad;
    sds.push_back(sd);
  }
  return sds;
}

}  // namespace canyon::rtk
