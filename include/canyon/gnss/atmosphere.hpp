#pragma once
// Atmosphere models for single-frequency positioning.

#include "canyon/core/ephemeris.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/core/time.hpp"

namespace canyon::gnss {

/// Saastamoinen zenith delays (m) with a standard atmosphere (pressure and temperature from height, relative
/// humidity `humidity` in [0, 1]) mapped to elevation: total slant tropospheric delay. 0 for heights outside
/// [-100 m, 10 km] or elevations <= 0 (as RTKLIB does).
[[nodiscard]] double saastamoinen_delay_m(const core::Geodetic& rcv, double elevation_rad, double humidity = 0.7);

/// Klobuchar ionospheric delay (m) on GPS L1 at GPST `t` for a receiver at `rcv` looking at `azel`. Scale by
/// (f_L1 / f)^2 for other frequencies.
[[nodiscard]] double klobuchar_delay_m(const core::GpsTime& t, const core::Geodetic& rcv, const core::AzEl& azel,
                                       const core::KlobucharParams& params);

/// Default Klobuchar parameters (RTKLIB's 2004/1/1 values) for when a navigation file carries none.
[[nodiscard]] core::KlobucharParams default_klobuchar();

}  // namespace canyon::gnss
