// True ionosphere and troposphere (see atmosphere.hpp).

#include "canyon/sim/atmosphere.hpp"

#include <algorithm>
#include <cmath>

#include "canyon/core/constants.hpp"
#include "canyon/gnss/atmosphere.hpp"
#include "canyon/sim/random.hpp"

namespace canyon::sim {
namespace {

constexpr double kEarthRadiusKm = 6371.0;
constexpr double kL1Hz = 1575.42e6;
constexpr double kIonoFactor = 40.3e16;  // m^3/s^2 per TECU: delay = 40.3e16 * TEC / f^2
constexpr std::uint64_t kIonoStream = 0x10, kTropoStream = 0x7209;

}  // namespace

Ionosphere::Ionosphere(const AtmosphereOptions& options, const core::Geodetic& origin, std::uint64_t seed)
    : options_(options), origin_(origin) {
  Rng rng = Rng::stream(seed, kIonoStream);
  for (int k = 0; k < options.wave_count; ++k) {
    const double azimuth = rng.uniform(0.0, 2.0 * core::kPi);
    Wave w;
    w.direction = Eigen::Vector2d(std::sin(azimuth), std::cos(azimuth));
    w.length_km = options.wave_length_km * rng.uniform(0.7, 1.3);
    w.period_s = options.wave_period_s * rng.uniform(0.7, 1.3);
    w.phase_rad = rng.uniform(0.0, 2.0 * core::kPi);
    waves_.push_back(w);
  }
}

double Ionosphere::vtec_tecu(double t_s, double lat_rad, double lon_rad) const {
  const Eigen::Vector2d x_km((lon_rad - origin_.lon_rad) * std::cos(origin_.lat_rad) * kEarthRadiusKm,
                             (lat_rad - origin_.lat_rad) * kEarthRadiusKm);
  double vtec = options_.vtec_tecu + options_.gradient_tecu_per_100km.dot(x_km) / 100.0;
  for (const Wave& w : waves_) {
    vtec += options_.wave_amplitude_tecu *
            std::sin(2.0 * core::kPi * (w.direction.dot(x_km) / w.length_km - t_s / w.period_s) + w.phase_rad);
  }
  return std::max(0.0, vtec);
}

double Ionosphere::slant_delay_l1_m(double t_s, const core::Geodetic& rcv, const core::AzEl& azel) const {
  if (azel.elevation_rad <= 0.0) return 0.0;
  const double ratio = kEarthRadiusKm / (kEarthRadiusKm + options_.shell_height_km);
  const double cos_el = std::cos(azel.elevation_rad);
  // Earth-central angle between the receiver and the pierce point, and the pierce point itself.
  const double psi = core::kPi / 2.0 - azel.elevation_rad - std::asin(ratio * cos_el);
  const double lat = std::asin(std::sin(rcv.lat_rad) * std::cos(psi) +
                               std::cos(rcv.lat_rad) * std::sin(psi) * std::cos(azel.azimuth_rad));
  const double lon = rcv.lon_rad + std::asin(std::sin(psi) * std::sin(azel.azimuth_rad) / std::cos(lat));
  const double mapping = 1.0 / std::sqrt(1.0 - ratio * ratio * cos_el * cos_el);
  return kIonoFactor * vtec_tecu(t_s, lat, lon) * mapping / (kL1Hz * kL1Hz);
}

double wet_mapping(double elevation_rad) {
  return 1.0 / (std::sin(elevation_rad) + 0.00035 / (std::tan(elevation_rad) + 0.017));
}

Troposphere::Troposphere(const AtmosphereOptions& options, std::uint64_t seed) : options_(options) {
  Rng rng = Rng::stream(seed, kTropoStream);
  period_rover_s_ = rng.uniform(3600.0, 7200.0);
  period_base_s_ = rng.uniform(3600.0, 7200.0);
  phase_rover_rad_ = rng.uniform(0.0, 2.0 * core::kPi);
  phase_base_rad_ = rng.uniform(0.0, 2.0 * core::kPi);
}

double Troposphere::residual_zwd_m(double t_s, bool base) const {
  const double period_s = base ? period_base_s_ : period_rover_s_;
  const double phase = base ? phase_base_rad_ : phase_rover_rad_;
  const double mean = options_.zwd_residual_m + (base ? options_.zwd_difference_m : 0.0);
  return mean + options_.zwd_variation_m * std::sin(2.0 * core::kPi * t_s / period_s + phase);
}

double Troposphere::slant_delay_m(double t_s, const core::Geodetic& rcv, double elevation_rad, bool base) const {
  if (elevation_rad <= 0.0) return 0.0;
  // Saastamoinen's 1 / cos(z) diverges at the horizon: below 15 deg it is continued with the ratio of the Black and
  // Eisner mapping function 1.001 / sqrt(0.002001 + sin^2 el), which stays finite (about 22 at 0 deg).
  constexpr double kBlendRad = 15.0 * core::kPi / 180.0;
  const auto black_eisner = [](double el) { return 1.001 / std::sqrt(0.002001 + std::sin(el) * std::sin(el)); };
  const double model_m = elevation_rad >= kBlendRad ? gnss::saastamoinen_delay_m(rcv, elevation_rad)
                                                    : gnss::saastamoinen_delay_m(rcv, kBlendRad) *
                                                          black_eisner(elevation_rad) / black_eisner(kBlendRad);
  return model_m + residual_zwd_m(t_s, base) * wet_mapping(elevation_rad);
}

}  // namespace canyon::sim
