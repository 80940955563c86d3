#pragma once
// The true ionosphere and troposphere of a scenario: what the signals are delayed by. Processing software models
// neither exactly; between the rover and a base 20 km away they leave the double-differenced residuals that grow
// with the baseline.
//
// Ionosphere: a thin shell at `shell_height_km`. The vertical TEC at the pierce point (east, north in km from the
// city origin, at time t) is
//   VTEC = vtec + g . (east, north) / 100 + sum_k A_k sin(2 pi (k_k . x / L_k - t / T_k) + phi_k)
// (clipped at 0): a large-scale gradient g (TECU per 100 km) and travelling disturbances with random directions,
// wavelengths L ~ wave_length_km and periods T ~ wave_period_s (each x [0.7, 1.3]). The slant delay on frequency f
// is 40.3e16 VTEC F / f^2 metres with the thin-shell mapping F = 1 / sqrt(1 - (R cos(el) / (R + h))^2): a group
// delay on the code, an advance of the carrier phase.
//
// Troposphere: Saastamoinen with the standard atmosphere (the model RTKLIB and canyon apply; below 15 deg, where its
// 1 / cos(z) diverges, continued with the Black and Eisner mapping function) plus a residual zenith wet delay mapped
// with Chao's wet mapping function 1 / (sin el + 0.00035 / (tan el + 0.017)). The residual is
// zwd_residual_m at the rover, zwd_residual_m + zwd_difference_m at the base, each varying by zwd_variation_m with
// periods of 1 to 2 hours.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/geodesy.hpp"
#include "canyon/sim/scenario.hpp"

namespace canyon::sim {

class Ionosphere {
 public:
  Ionosphere(const AtmosphereOptions& options, const core::Geodetic& origin, std::uint64_t seed);
  /// Slant ionospheric delay (m) on the GPS L1 frequency at t_s (seconds since the scenario start), for a receiver
  /// at `rcv` looking at `azel`. Scale by (f_L1 / f)^2 for other frequencies.
  [[nodiscard]] double slant_delay_l1_m(double t_s, const core::Geodetic& rcv, const core::AzEl& azel) const;
  /// Vertical TEC (TECU) at a pierce point.
  [[nodiscard]] double vtec_tecu(double t_s, double lat_rad, double lon_rad) const;

 private:
  struct Wave {
    Eigen::Vector2d direction;  // unit (east, north)
    double length_km;
    double period_s;
    double phase_rad;
  };
  AtmosphereOptions options_;
  core::Geodetic origin_;
  std::vector<Wave> waves_;
};

class Troposphere {
 public:
  Troposphere(const AtmosphereOptions& options, std::uint64_t seed);
  /// Slant tropospheric delay (m) at t_s for a receiver at `rcv` (the base when `base` is true).
  [[nodiscard]] double slant_delay_m(double t_s, const core::Geodetic& rcv, double elevation_rad, bool base) const;
  /// Residual zenith wet delay (m) of the rover or the base at t_s.
  [[nodiscard]] double residual_zwd_m(double t_s, bool base) const;

 private:
  AtmosphereOptions options_;
  double period_rover_s_ = 3600.0, period_base_s_ = 5400.0;
  double phase_rover_rad_ = 0.0, phase_base_rad_ = 0.0;
};

/// Chao's wet mapping function.
[[nodiscard]] double wet_mapping(double elevation_rad);

}  // namespace canyon::sim
