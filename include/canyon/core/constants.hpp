#pragma once
// Physical and system constants (SI units unless the name says otherwise).

namespace canyon::core {

inline constexpr double kSpeedOfLightMps = 299792458.0;
inline constexpr double kPi = 3.1415926535897932;
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kRadToDeg = 180.0 / kPi;

// WGS84 ellipsoid.
inline constexpr double kWgs84SemiMajorM = 6378137.0;
inline constexpr double kWgs84Flattening = 1.0 / 298.257223563;
inline constexpr double kWgs84EccentricitySq = kWgs84Flattening * (2.0 - kWgs84Flattening);

// Earth rotation rate and gravitational constants as each system's ICD defines them.
inline constexpr double kEarthRotationRateRadps = 7.2921151467e-5;  // GPS, Galileo, QZSS (WGS84 / GTRF)
inline constexpr double kBdsEarthRotationRateRadps = 7.292115e-5;   // BeiDou (CGCS2000)
inline constexpr double kGloEarthRotationRateRadps = 7.292115e-5;   // GLONASS (PZ-90)
inline constexpr double kGpsMuM3ps2 = 3.9860050e14;                 // GPS, QZSS
inline constexpr double kGalMuM3ps2 = 3.986004418e14;               // Galileo
inline constexpr double kBdsMuM3ps2 = 3.986004418e14;               // BeiDou
inline constexpr double kGloMuM3ps2 = 3.9860044e14;                 // GLONASS (PZ-90)
inline constexpr double kGloSemiMajorM = 6378136.0;                 // PZ-90 semi-major axis
inline constexpr double kGloJ2 = 1.0826257e-3;                      // PZ-90 second zonal harmonic

}  // namespace canyon::core
