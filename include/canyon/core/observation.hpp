#pragma once
// One receiver's observations at one epoch, as every input format (RINEX, RTCM 3, UBX) delivers them.

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/satellite.hpp"
#include "canyon/core/time.hpp"

namespace canyon::core {

inline constexpr double kNoValue = std::numeric_limits<double>::quiet_NaN();
[[nodiscard]] inline bool has_value(double v) {
  return !std::isnan(v);
}

/// Loss-of-lock indicator bits (RINEX LLI).
inline constexpr std::uint8_t kLliLossOfLock = 0x01;  ///< lost lock since the previous epoch: cycle slip possible
inline constexpr std::uint8_t kLliHalfCycle = 0x02;   ///< half-cycle ambiguity not resolved
/// Bit 2 means "BOC tracking of an MBOC signal" in RINEX 3 but "anti-spoofing on" in RINEX 2 (kept as read): RTK acts
/// on bits 0 and 1 only.
inline constexpr std::uint8_t kLliBit2 = 0x04;

/// Observables of one signal of one satellite. A missing observable is NaN (use has_value()).
struct SignalObs {
  SignalCode code;
  double pseudorange_m = kNoValue;
  double carrier_phase_cyc = kNoValue;
  double doppler_hz = kNoValue;
  double snr_dbhz = kNoValue;
  std::uint8_t lli = 0;  ///< kLli* bits of the carrier phase
};

struct SatelliteObs {
  SatelliteId sat;
  std::vector<SignalObs> signals;

  /// The signal with that code, or nullptr.
  [[nodiscard]] const SignalObs* find(SignalCode code) const {
    for (const SignalObs& s : signals) {
      if (s.code == code) return &s;
    }
    return nullptr;
  }
};

/// RINEX epoch flags.
enum class EpochFlag : std::uint8_t {
  Ok = 0,
  PowerFailure = 1,
  AntennaMoving = 2,
  NewSite = 3,
  HeaderInfo = 4,
  ExternalEvent = 5,
  CycleSlipRecords = 6,
};

struct ObsEpoch {
  GpsTime time;  ///< receiver time tag, GPST
  EpochFlag flag = EpochFlag::Ok;
  double receiver_clock_offset_s = kNoValue;  ///< as reported by the receiver, if any
  std::vector<SatelliteObs> sats;
};

/// What a receiver's observation header tells about the receiver and its signals.
struct ReceiverInfo {
  std::string marker_name;
  std::string receiver_type;
  std::string antenna_type;
  std::optional<Eigen::Vector3d> approx_position_E_m;             ///< "APPROX POSITION XYZ" if non-zero
  Eigen::Vector3d antenna_delta_hen_m = Eigen::Vector3d::Zero();  ///< height, east, north of the ARP
  /// Phase shift (cycles) applied by the receiver to align a signal with its reference, per system and signal.
  struct PhaseShift {
    Constellation system;
    SignalCode code;
    double shift_cyc = 0.0;
  };
  std::vector<PhaseShift> phase_shifts;
  /// GLONASS slot -> FDMA frequency channel from "GLONASS SLOT / FRQ #", if given.
  std::vector<std::pair<int, int>> glonass_slot_channels;
};

}  // namespace canyon::core
