// C/N0, noise and multipath of one signal (see signal_model.hpp).

#include "canyon/sim/signal_model.hpp"

#include <algorithm>
#include <cmath>
#include <complex>

#include "canyon/core/constants.hpp"

namespace canyon::sim {
namespace {

constexpr double kMinDenominator = 0.1;  // keeps the code-loop error finite when reflections cancel the direct path

}  // namespace

double line_of_sight_cn0_dbhz(const ReceiverOptions& rx, double elevation_rad, int band_index) {
  const double x = 1.0 - std::sin(std::max(0.0, elevation_rad));
  const double cn0 = rx.cn0_zenith_dbhz - (rx.cn0_zenith_dbhz - rx.cn0_horizon_dbhz) * x * x;
  return band_index > 0 ? cn0 + rx.band2_cn0_offset_db : cn0;
}

double scaled_sigma(const ReceiverOptions& rx, double sigma_ref, double cn0_dbhz) {
  return sigma_ref * std::pow(10.0, (rx.cn0_reference_dbhz - cn0_dbhz) / 20.0);
}

double chip_length_m(core::Constellation system, core::SignalCode code) {
  constexpr double kChip1023 = core::kSpeedOfLightMps / 1.023e6;
  switch (system) {
    case core::Constellation::Glonass:
      return code.attribute == 'P' ? core::kSpeedOfLightMps / 5.11e6 : core::kSpeedOfLightMps / 0.511e6;
    case core::Constellation::BeiDou: return core::kSpeedOfLightMps / 2.046e6;
    case core::Constellation::Galileo: return code.band == '1' ? kChip1023 : kChip1023 / 10.0;
    default:
      // GPS/QZSS: C/A, L2C and L1C at 1.023 Mcps; P(Y) (W, P, Y) and L5 at 10.23 Mcps.
      if (code.band == '5' || code.attribute == 'W' || code.attribute == 'P' || code.attribute == 'Y') {
        return kChip1023 / 10.0;
      }
      return kChip1023;
  }
}

double dll_envelope_m(double delay_m, double chip_m, double spacing_chips) {
  const double half_m = 0.5 * spacing_chips * chip_m;
  if (delay_m <= 0.0) return 0.0;
  if (delay_m <= half_m) return delay_m;
  if (delay_m <= chip_m - half_m) return half_m;
  if (delay_m < chip_m + half_m) return half_m * (chip_m + half_m - delay_m) / (2.0 * half_m);
  return 0.0;
}

MultipathError line_of_sight_multipath(const std::vector<Reflection>& reflections, double wavelength_m, double chip_m,
                                       double spacing_chips) {
  std::complex<double> composite(1.0, 0.0);
  double code_numerator = 0.0, code_denominator = 1.0;
  for (const Reflection& r : reflections) {
    const double phi = 2.0 * core::kPi * r.excess_m / wavelength_m + core::kPi;
    composite += std::polar(r.amplitude, phi);
    code_numerator += r.amplitude * dll_envelope_m(r.excess_m, chip_m, spacing_chips) * std::cos(phi);
    code_denominator += r.amplitude * std::cos(phi);
  }
  MultipathError e;
  e.code_m = code_numerator / std::max(kMinDenominator, code_denominator);
  e.phase_m = wavelength_m / (2.0 * core::kPi) * std::arg(composite);
  e.cn0_change_db = 20.0 * std::log10(std::max(1e-3, std::abs(composite)));
  return e;
}

}  // namespace canyon::sim
