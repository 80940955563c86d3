#pragma once
// Broadcast navigation messages as decoded from RINEX, RTCM 3 or UBX. All times are converted to GPST by the
// decoder; each system's own week numbering and time scale (GST, BDT, GLONASS UTC(SU)+3h) never leaks past it.

#include <array>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/satellite.hpp"
#include "canyon/core/time.hpp"

namespace canyon::core {

/// Keplerian broadcast ephemeris: GPS LNAV, Galileo I/NAV and F/NAV, BeiDou D1/D2, QZSS LNAV.
struct KeplerEphemeris {
  SatelliteId sat;
  GpsTime toc;                ///< clock reference time (GPST)
  GpsTime toe;                ///< ephemeris reference time (GPST)
  GpsTime transmission_time;  ///< time of transmission of the message (GPST), if known, else == toe

  // Clock: dt = af0 + af1 (t - toc) + af2 (t - toc)^2, seconds.
  double af0_s = 0.0;
  double af1_sps = 0.0;
  double af2_sps2 = 0.0;

  // Orbit (ICD names).
  double sqrt_a_sqrtm = 0.0;
  double e = 0.0;
  double i0_rad = 0.0;
  double omega0_rad = 0.0;  ///< longitude of the ascending node at weekly epoch
  double omega_rad = 0.0;   ///< argument of perigee
  double m0_rad = 0.0;
  double delta_n_radps = 0.0;
  double omega_dot_radps = 0.0;
  double idot_radps = 0.0;
  double cuc_rad = 0.0, cus_rad = 0.0;
  double crc_m = 0.0, crs_m = 0.0;
  double cic_rad = 0.0, cis_rad = 0.0;
  double toe_sow_s = 0.0;  ///< toe in the system's own seconds of week (BDT for BeiDou)

  /// Group delays (s): GPS/QZSS TGD in [0]; Galileo BGD E5a/E1 in [0], BGD E5b/E1 in [1];
  /// BeiDou TGD1 (B1I) in [0], TGD2 (B2I) in [1].
  std::array<double, 2> tgd_s = {0.0, 0.0};

  int iode = 0;                 ///< IODE (GPS/QZSS), IODnav (Galileo), AODE (BeiDou)
  int iodc = 0;                 ///< IODC (GPS/QZSS), AODC (BeiDou)
  int health = 0;               ///< SV health word as broadcast (0 = healthy)
  double accuracy_m = 0.0;      ///< URA (GPS/QZSS/BeiDou) or SISA (Galileo), metres
  int data_source = 0;          ///< Galileo data sources bits (I/NAV 0x201/0x205, F/NAV 0x102); GPS L2 codes flag
  double fit_interval_h = 0.0;  ///< 0 = default (4 h)
};

/// GLONASS broadcast ephemeris: PZ-90 state at tb, integrated numerically.
struct GlonassEphemeris {
  SatelliteId sat;
  GpsTime toe;                                         ///< tb converted to GPST
  GpsTime frame_time;                                  ///< message frame time tk (GPST)
  int frequency_channel = 0;                           ///< FDMA channel k in [-7, 6]
  int health = 0;                                      ///< Bn / health flags as broadcast (0 = healthy)
  int age_days = 0;                                    ///< E_n
  Eigen::Vector3d p_E_m = Eigen::Vector3d::Zero();     ///< position, PZ-90 (m)
  Eigen::Vector3d v_E_mps = Eigen::Vector3d::Zero();   ///< velocity (m/s)
  Eigen::Vector3d a_E_mps2 = Eigen::Vector3d::Zero();  ///< lunisolar acceleration (m/s^2)
  /// MINUS tau_n (s), i.e. RINEX's "SV clock bias" as written: satellite clock = tau_n_s + gamma_n (t - tb)
  /// (= -tau_n + gamma_n (t - tb) in ICD terms). Decoders of the raw message (RTCM 1020, UBX) store -tau_n here.
  double tau_n_s = 0.0;
  double gamma_n = 0.0;  ///< relative frequency bias
  double delta_tau_n_s = 0.0;
};

/// Klobuchar parameters from the GPS navigation message (RINEX "ION ALPHA/BETA" or "IONOSPHERIC CORR GPSA/GPSB").
struct KlobucharParams {
  std::array<double, 4> alpha = {0, 0, 0, 0};
  std::array<double, 4> beta = {0, 0, 0, 0};
};

/// Everything a navigation source delivers.
struct NavigationData {
  std::vector<KeplerEphemeris> kepler;
  std::vector<GlonassEphemeris> glonass;
  std::optional<KlobucharParams> gps_klobuchar;
  std::optional<KlobucharParams> bds_klobuchar;
  std::optional<int> leap_seconds;  ///< GPST - UTC from the header, if given

  /// Appends another source's records (e.g. several --nav files).
  void merge(const NavigationData& other);
  /// FDMA channel of a GLONASS slot from the broadcast ephemerides (kNoGlonassChannel if unknown).
  [[nodiscard]] int glonass_channel(int slot) const;
};

}  // namespace canyon::core
