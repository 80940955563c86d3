#pragma once
// RTCM 3.3 (RTCM 10403.3) messages, one payload at a time: Multiple Signal Messages (MSM4-MSM7) for GPS, GLONASS,
// Galileo, QZSS and BeiDou, station messages 1005/1006 and 1033, GLONASS code-phase biases 1230, ephemerides 1019
// (GPS), 1020 (GLONASS), 1042 (BeiDou), 1044 (QZSS), 1045/1046 (Galileo F/NAV, I/NAV), and the legacy
// observations 1004 (GPS) and 1012 (GLONASS), decode only. Framing (preamble, length, CRC-24Q) is in
// stream_framer.hpp; frame_rtcm3() wraps a payload. The stateful stream codecs that turn messages into
// core::ObsEpoch and back are in rtcm3_codec.hpp.
//
// Decoders return an Error naming the message and what is wrong (too short for what its masks announce, a value
// out of its range); they never read past the payload. Encoders take physical values and round them to the field
// resolution; a value that does not fit its field is an Error (ephemerides) or written as "invalid" and counted
// (MSM cells, see MsmEncodeReport).
//
// MSM resolutions (RTCM 10403.3 table 3.5-78ff): MSM4 pseudorange 2^-24 ms (0.018 m), phase range 2^-29 ms
// (0.56 mm), CNR 1 dB-Hz, lock time indicator of 4 bits; MSM7 pseudorange 2^-29 ms (0.56 mm), phase range 2^-31 ms
// (0.14 mm), phase range rate 0.1 mm/s, CNR 2^-4 dB-Hz, lock time of 10 bits (1 ms resolution below 64 ms).
// The phase range of an MSM cell is sent relative to the satellite's rough range (within +-2^-8 ms, 1171 m): the
// carrier phase of a receiver, whose integer part is arbitrary, is therefore shifted by an integer number of cycles
// per continuous arc before encoding (see Rtcm3Encoder).

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/ephemeris.hpp"
#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/core/satellite.hpp"
#include "canyon/core/time.hpp"

namespace canyon::io::rtcm3 {

inline constexpr std::size_t kMaxPayloadBytes = 1023;
/// Speed of light times one millisecond: the unit of MSM ranges.
inline constexpr double kRangeMsM = 299792.458;
/// Pi as the GPS ICD defines it, for semicircle <-> radian conversions (as the satellites' own software uses).
inline constexpr double kGpsPi = 3.1415926535898;

/// The frame around a payload: 0xD3, length, payload, CRC-24Q. Error if the payload exceeds 1023 bytes.
Result<std::vector<std::uint8_t>> frame_rtcm3(std::span<const std::uint8_t> payload);
/// Appends the frame of `payload` to `out`.
Status append_frame(std::span<const std::uint8_t> payload, std::vector<std::uint8_t>& out);
/// Message number of a payload (its first 12 bits), 0 if shorter than 2 bytes.
[[nodiscard]] int message_number(std::span<const std::uint8_t> payload);

// ---------------------------------------------------------------------------------------------------------------
// Multiple Signal Messages.

/// MSM message number of a system: 1070 + type (GPS), 1080 (GLONASS), 1090 (Galileo), 1110 (QZSS), 1120 (BeiDou).
[[nodiscard]] int msm_message_number(core::Constellation system, int msm_type);
/// System and MSM type (1-7) of a message number, nullopt if it is not an MSM of a supported system.
struct MsmKind {
  core::Constellation system;
  int type = 0;
};
[[nodiscard]] std::optional<MsmKind> msm_kind(int message_number);
/// RINEX signal code of MSM signal id 1-32 (DF395 bit position) of a system (RTCM 10403.3 tables 3.5-91 ff.);
/// nullopt if the id is reserved.
[[nodiscard]] std::optional<core::SignalCode> msm_signal_code(core::Constellation system, int signal_id);
/// Inverse: the MSM signal id of a RINEX code, nullopt if RTCM has none (e.g. QZSS L1 SAIF "1Z").
[[nodiscard]] std::optional<int> msm_signal_id(core::Constellation system, core::SignalCode code);

/// One cell (satellite x signal). Missing values are NaN.
struct MsmCell {
  int signal_id = 0;                             ///< DF395 bit position 1-32
  double pseudorange_m = core::kNoValue;         ///< full pseudorange (m)
  double phase_range_m = core::kNoValue;         ///< full phase range (m): carrier phase times wavelength
  double phase_range_rate_mps = core::kNoValue;  ///< MSM5/7 only (m/s); Doppler = -rate / wavelength
  double cnr_dbhz = core::kNoValue;              ///< carrier-to-noise ratio (dB-Hz)
  double lock_time_ms = 0.0;                     ///< minimum lock time the indicator guarantees (ms)
  int lock_indicator = 0;                        ///< decoding: DF402 / DF407 as sent (encoding uses lock_time_ms)
  bool half_cycle = false;                       ///< DF420: half-cycle ambiguity not resolved
};

struct MsmSatellite {
  int satellite_id = 0;        ///< DF394 bit position 1-64 (GPS PRN, GLONASS slot, QZSS PRN - 192, ...)
  int extended_info = 15;      ///< MSM5/7: GLONASS frequency channel + 7 (0-13); 15 = not given
  std::vector<MsmCell> cells;  ///< in signal id order
};

struct MsmHeader {
  core::Constellation system = core::Constellation::Gps;
  int type = 7;        ///< MSM type: 4, 5, 6 or 7 (1-3 are decoded without observables)
  int station_id = 0;  ///< DF003, 0-4095
  /// Epoch time field (30 bits) as sent: GPS/QZSS/Galileo/BeiDou time of week in ms (system time: BDT for BeiDou);
  /// GLONASS: day of week (3 bits, 0 Sunday, 7 unknown) << 27 | Moscow time of day in ms (27 bits).
  std::uint32_t epoch_time = 0;
  bool multiple_message = false;           ///< DF393: more MSMs of this epoch follow
  int iods = 0;                            ///< DF409 issue of data station
  int clock_steering = 0;                  ///< DF411
  int external_clock = 0;                  ///< DF412
  bool divergence_free_smoothing = false;  ///< DF417
  int smoothing_interval = 0;              ///< DF418
};

struct MsmMessage {
  MsmHeader header;
  std::vector<MsmSatellite> satellites;  ///< in satellite id order
};

/// What encoding could not represent: values written as "invalid" because they do not fit their field.
struct MsmEncodeReport {
  int cells = 0;               ///< cells written
  int invalid_values = 0;      ///< pseudoranges, phase ranges or rates outside their field (written as invalid)
  int dropped_satellites = 0;  ///< satellites with no pseudorange at all (no rough range to send them with)
};

/// Appends the payload of one MSM (header.type 4-7) to `out`. At most 64 cells: the caller splits larger sets (see
/// Rtcm3Encoder). Error if the message would exceed 64 cells or 1023 bytes.
Result<MsmEncodeReport> append_msm(const MsmMessage& message, std::vector<std::uint8_t>& out);
/// Decodes an MSM payload (types 4-7; 1-3 carry no complete observables and are refused).
Result<MsmMessage> decode_msm(std::span<const std::uint8_t> payload);
/// The same into `out`, reusing its storage (no allocation once it has held a message as large).
Status decode_msm(std::span<const std::uint8_t> payload, MsmMessage& out);

/// Lock time indicators: MSM4/5 DF402 (4 bits) and MSM6/7 DF407 (10 bits), as minimum lock times in ms.
[[nodiscard]] double msm_lock_time_ms(int indicator, bool extended);
[[nodiscard]] int msm_lock_indicator(double lock_time_ms, bool extended);

/// Converts an MSM epoch time field to GPST, the week taken nearest `reference`. GLONASS needs the leap seconds.
[[nodiscard]] core::GpsTime msm_epoch_time(core::Constellation system, std::uint32_t epoch_time,
                                           const core::GpsTime& reference, const core::LeapSecondTable& leaps);
/// The epoch time field of a GPST instant for a system (rounded to the millisecond).
[[nodiscard]] std::uint32_t msm_epoch_field(core::Constellation system, const core::GpsTime& time,
                                            const core::LeapSecondTable& leaps);

// ---------------------------------------------------------------------------------------------------------------
// Station messages.

/// 1005 (stationary antenna reference point) and 1006 (with antenna height).
struct StationPosition {
  int station_id = 0;
  int itrf_year = 0;  ///< DF021 (0 = not given)
  bool gps = true;    ///< DF022-024: systems the station serves
  bool glonass = true;
  bool galileo = true;
  bool reference_station = false;                     ///< DF141: physical (false) or non-physical/computed (true)
  Eigen::Vector3d arp_E_m = Eigen::Vector3d::Zero();  ///< antenna reference point, ECEF (m, 0.1 mm resolution)
  bool single_oscillator = false;                     ///< DF142
  int quarter_cycle = 0;                              ///< DF364
  std::optional<double> antenna_height_m;             ///< 1006 only: height of the ARP above the marker (m)
};
Status append_station_position(const StationPosition& station, std::vector<std::uint8_t>& out);
Result<StationPosition> decode_station_position(std::span<const std::uint8_t> payload);

/// 1033 (receiver and antenna descriptors); also reads 1007 and 1008 (the antenna part only).
struct AntennaInfo {
  int station_id = 0;
  std::string antenna_descriptor;  ///< IGS antenna type, at most 31 characters
  int antenna_setup_id = 0;
  std::string antenna_serial;
  std::string receiver_type;
  std::string receiver_firmware;
  std::string receiver_serial;
};
Status append_antenna_info(const AntennaInfo& info, std::vector<std::uint8_t>& out);
Result<AntennaInfo> decode_antenna_info(std::span<const std::uint8_t> payload);

/// 1230: GLONASS L1/L2 code-phase biases (m) of the station's receiver.
struct GlonassBiases {
  int station_id = 0;
  bool aligned = false;  ///< DF421: observations already aligned (biases applied)
  /// L1 C/A, L1 P, L2 C/A, L2 P; absent when the mask bit is not set. Resolution 0.02 m.
  std::array<std::optional<double>, 4> bias_m;
};
Status append_glonass_biases(const GlonassBiases& biases, std::vector<std::uint8_t>& out);
Result<GlonassBiases> decode_glonass_biases(std::span<const std::uint8_t> payload);

// ---------------------------------------------------------------------------------------------------------------
// Ephemerides. Times in core::KeplerEphemeris / GlonassEphemeris are GPST; the messages carry truncated weeks and
// system times, resolved here against `reference` (a GPST instant within a few days: the stream's epoch time).

/// 1019 (GPS), 1044 (QZSS), 1042 (BeiDou), 1045 (Galileo F/NAV) or 1046 (Galileo I/NAV): the message is chosen from
/// the satellite's system and, for Galileo, from `data_source` (bit 1 F/NAV E5a -> 1045, else 1046). Error if a
/// field is out of its range. A message carries no transmission time: decoding sets it to toe.
Status append_kepler_ephemeris(const core::KeplerEphemeris& eph, std::vector<std::uint8_t>& out);
Result<core::KeplerEphemeris> decode_kepler_ephemeris(std::span<const std::uint8_t> payload,
                                                      const core::GpsTime& reference);
/// 1020. tk and tb are Moscow times of day; `leaps` converts them.
Status append_glonass_ephemeris(const core::GlonassEphemeris& eph, const core::LeapSecondTable& leaps,
                                std::vector<std::uint8_t>& out);
Result<core::GlonassEphemeris> decode_glonass_ephemeris(std::span<const std::uint8_t> payload,
                                                        const core::GpsTime& reference,
                                                        const core::LeapSecondTable& leaps);
/// The ephemeris message number for a satellite's record (0 if none).
[[nodiscard]] int ephemeris_message_number(const core::KeplerEphemeris& eph);

/// URA index (GPS/QZSS/BeiDou, 0-15) -> the ICD's nominal accuracy (2.0, 2.8, 4.0, 5.7, 8.0, 11.3, 16, 32 ... 8192
/// m), and metres -> the index of the first range (upper bounds 2.4, 3.4, 4.85 ... 6144 m) that holds them; SISA
/// index (Galileo, 0-255) <-> metres (255: no accuracy, -1).
[[nodiscard]] double ura_m(int index);
[[nodiscard]] int ura_index(double accuracy_m);
[[nodiscard]] double sisa_m(int index);
[[nodiscard]] int sisa_index(double accuracy_m);

// ---------------------------------------------------------------------------------------------------------------
// Legacy observations (decode only): 1004 (GPS L1/L2) and 1012 (GLONASS L1/L2).

struct LegacySignal {
  core::SignalCode code;
  double pseudorange_m = core::kNoValue;
  double phase_range_m = core::kNoValue;  ///< L1 pseudorange + the phase-range field (m); see phase_reference_m
  /// The L1 pseudorange the phase-range field is relative to: an encoder keeps that difference within its field by
  /// steps of 1500 cycles, so a decoder keeps (phase range - reference) / wavelength continuous over epochs.
  double phase_reference_m = core::kNoValue;
  double cnr_dbhz = core::kNoValue;
  double lock_time_s = 0.0;   ///< minimum lock time the indicator guarantees
  double lock_upper_s = 0.0;  ///< the lock time is below this (the next indicator's minimum)
};
struct LegacySatellite {
  core::SatelliteId sat;
  int glonass_channel = core::kNoGlonassChannel;
  std::vector<LegacySignal> signals;
};
struct LegacyObsMessage {
  core::Constellation system = core::Constellation::Gps;
  int station_id = 0;
  std::uint32_t epoch_time = 0;  ///< GPS: time of week (ms); GLONASS: Moscow time of day (ms)
  bool synchronous = false;      ///< DF005: more messages of this epoch follow
  std::vector<LegacySatellite> satellites;
};
Result<LegacyObsMessage> decode_legacy_obs(std::span<const std::uint8_t> payload);

}  // namespace canyon::io::rtcm3
