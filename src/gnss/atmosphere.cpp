// Tropospheric (Saastamoinen) and ionospheric (Klobuchar) delay models for single-frequency positioning.
//
// Saastamoinen (1972, "Atmospheric correction for the troposphere and stratosphere in radio ranging of satellites"):
// zenith hydrostatic delay 0.0022768 P / (1 - 0.00266 cos 2 lat - 0.00028 h_km) and zenith wet delay
// 0.002277 (1255 / T + 0.05) e, with P, T, e from the standard atmosphere (P0 = 1013.25 hPa, T0 = 15 C, lapse
// rate 6.5 K/km, water vapour pressure from the relative humidity by the Magnus-type formula), both mapped with
// 1 / cos(z) (z = zenith angle), the mapping Saastamoinen's closed form uses; adequate above ~15 deg elevation.
// Klobuchar: IS-GPS-200 20.3.3.5.2.5 (figure 20-4), angles in semicircles, result on L1.

#include "canyon/gnss/atmosphere.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "canyon/core/constants.hpp"

namespace canyon::gnss {
namespace {

constexpr double kStdPressureHpa = 1013.25;
constexpr double kStdTemperatureK = 288.15;
constexpr double kLapseRateKpm = 6.5e-3;
constexpr double kKlobucharNightDelayS = 5e-9;
constexpr double kMinPeriodS = 72000.0;

}  // namespace

double saastamoinen_delay_m(const core::Geodetic& rcv, double elevation_rad, double humidity) {
  if (rcv.height_m < -100.0 || rcv.height_m > 1e4 || elevation_rad <= 0.0) return 0.0;
  const double h_m = std::max(rcv.height_m, 0.0);
  const double pressure_hpa = kStdPressureHpa * std::pow(1.0 - 2.2557e-5 * h_m, 5.2568);
  const double temperature_k = kStdTemperatureK - kLapseRateKpm * h_m;
  const double vapour_hpa = 6.108 * humidity * std::exp((17.15 * temperature_k - 4684.0) / (temperature_k - 38.45));
  const double cos_z = std::cos(core::kPi / 2.0 - elevation_rad);
  const double zhd_m = 0.0022768 * pressure_hpa / (1.0 - 0.00266 * std::cos(2.0 * rcv.lat_rad) - 0.00028 * h_m / 1e3);
  const double zwd_m = 0.002277 * (1255.0 / temperature_k + 0.05) * vapour_hpa;
  return (zhd_m + zwd_m) / cos_z;
}

double klobuchar_delay_m(const core::GpsTime& t, const core::Geodetic& rcv, const core::AzEl& azel,
                         const core::KlobucharParams& params) {
  const bool none =
      params.alpha == std::array<double, 4>{0, 0, 0, 0} && params.beta == std::array<double, 4>{0, 0, 0, 0};
  const core::KlobucharParams& p = none ? default_klobuchar() : params;
  if (rcv.height_m < -1e3 || azel.elevation_rad <= 0.0) return 0.0;
  const double el_sc = azel.elevation_rad / core::kPi;  // semicircles
  const double psi_sc = 0.0137 / (el_sc + 0.11) - 0.022;
  double lat_i_sc = rcv.lat_rad / core::kPi + psi_sc * std::cos(azel.azimuth_rad);
  lat_i_sc = std::clamp(lat_i_sc, -0.416, 0.416);
  const double lon_i_sc =
      rcv.lon_rad / core::kPi + psi_sc * std::sin(azel.azimuth_rad) / std::cos(lat_i_sc * core::kPi);
  const double lat_m_sc = lat_i_sc + 0.064 * std::cos((lon_i_sc - 1.617) * core::kPi);
  double local_s = std::fmod(4.32e4 * lon_i_sc + t.tow_s, 86400.0);
  if (local_s < 0.0) local_s += 86400.0;
  const double obliquity = 1.0 + 16.0 * std::pow(0.53 - el_sc, 3.0);
  double amp_s = 0.0, per_s = 0.0;
  for (int n = 3; n >= 0; --n) {
    amp_s = amp_s * lat_m_sc + p.alpha[n];
    per_s = per_s * lat_m_sc + p.beta[n];
  }
  amp_s = std::max(amp_s, 0.0);
  per_s = std::max(per_s, kMinPeriodS);
  const double x_rad = 2.0 * core::kPi * (local_s - 50400.0) / per_s;
  const double delay_s =
      std::abs(x_rad) < 1.57
          ? obliquity * (kKlobucharNightDelayS + amp_s * (1.0 - x_rad * x_rad / 2.0 + std::pow(x_rad, 4.0) / 24.0))
          : obliquity * kKlobucharNightDelayS;
  return core::kSpeedOfLightMps * delay_s;
}

core::KlobucharParams default_klobuchar() {
  return core::KlobucharParams{{0.1118e-07, -0.7451e-08, -0.5961e-07, 0.1192e-06},
                               {0.1167e+06, -0.2294e+06, -0.1311e+06, 0.1049e+07}};
}

}  // namespace canyon::gnss
