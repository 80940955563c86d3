#pragma once
// RTCM 3 streams <-> canyon's observation and navigation structures. Decoded observations land in core::ObsEpoch
// and ephemerides in core::NavigationData, exactly as the RINEX readers deliver them, so that processing cannot
// tell where they came from.
//
// Rtcm3Decoder: message payloads (from StreamFramer) in, epochs and ephemerides out.
//  - An epoch collects the MSM (and 1004/1012) messages of one epoch time, of all constellations, and is complete
//    when a message arrives with the multiple message bit (DF393, DF005) clear, or when a message of another epoch
//    time arrives, or at flush(). Satellites are sorted; signals keep their MSM order.
//  - Times: MSM and ephemeris messages carry times of week (or of day, GLONASS) and truncated weeks. They are
//    resolved against a reference GPST instant given in the options (the current time for a live stream, any time
//    within a few days of the data for a file) and then against the last epoch decoded.
//  - Carrier phase: MSM phase range / wavelength (GLONASS: the FDMA channel from MSM5/7 extended satellite
//    information, 1020 ephemerides, or the options; without it phase and Doppler are dropped with a warning).
//    Doppler = -phase range rate / wavelength.
//  - Loss of lock (core::kLliLossOfLock) at a signal's first phase, when its lock time is zero, smaller than at its
//    previous epoch, or certainly shorter than the time since its previous epoch with phase (the upper bound of its
//    indicator does not reach back to it: the lock started in between); kLliHalfCycle from DF420.
//  - Ephemerides are kept once per (satellite, toe, issue of data, data source); a repeated one is not added again.
//    Their transmission time is the epoch time of the stream when they arrived (toe before any epoch).
//
// Rtcm3Encoder: epochs in, MSM4/MSM7 (or MSM5/MSM6) payloads out, one message per constellation (several when its
// satellites x signals exceed the 64-cell mask), the multiple message bit set on all but the last of an epoch.
//  - Carrier phase is sent as phase range: per continuous arc of a (satellite, signal) the receiver's phase is
//    shifted by the integer number of cycles that brings it to the pseudorange at the arc start, and the shift is
//    kept until the next loss of lock (LLI bit 0), so a decoder sees a continuous phase that differs from the input
//    by a constant integer per arc. An arc whose code-minus-carrier drifts beyond the field's +-1171 m restarts
//    (with a loss of lock).
//  - Lock time is the time since the arc started (0 at the first epoch of a signal and at an LLI, so a decoder
//    flags loss of lock there); the half-cycle bit is LLI bit 1.
//  - Signals RTCM cannot name (e.g. QZSS L1 SAIF "1Z"), satellites without any pseudorange, and values outside
//    their fields are dropped and counted in the report.

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "canyon/core/ephemeris.hpp"
#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/core/time.hpp"
#include "canyon/io/rtcm3.hpp"
#include "canyon/io/signal_table.hpp"

namespace canyon::io {

struct Rtcm3DecoderOptions {
  /// Any GPST instant within a few days of the data (weeks and GLONASS days are resolved against it).
  core::GpsTime reference_time;
  core::LeapSecondTable leaps = core::builtin_leap_seconds();
  /// GLONASS slot -> FDMA channel known beforehand (e.g. from a navigation file), for MSM4/MSM6 streams.
  std::vector<std::pair<int, int>> glonass_channels;
};

class Rtcm3Decoder {
 public:
  enum class Content : std::uint8_t {
    Observations,     ///< MSM or 1004/1012: part of an epoch
    StationPosition,  ///< 1005/1006
    AntennaInfo,      ///< 1007/1008/1033
    GlonassBiases,    ///< 1230
    Ephemeris,        ///< 1019/1020/1042/1044/1045/1046
    Unsupported,      ///< a valid frame of a message canyon does not decode (counted)
  };
  /// What one message was.
  struct Message {
    int number = 0;
    int station_id = -1;  ///< -1 for messages without one (ephemerides)
    Content content = Content::Unsupported;
    std::optional<core::GpsTime> epoch_time;  ///< observations: their epoch (GPST)
    bool new_ephemeris = false;               ///< an ephemeris not seen before
  };

  explicit Rtcm3Decoder(Rtcm3DecoderOptions options);

  /// Decodes one payload. Error naming the message and what is wrong; the decoder is then unchanged.
  Result<Message> decode(std::span<const std::uint8_t> payload);
  /// Epochs completed so far, oldest first (call after each decode()).
  std::optional<core::ObsEpoch> pop_epoch();
  /// End of the stream: completes the epoch being assembled.
  void flush();

  [[nodiscard]] const std::optional<rtcm3::StationPosition>& station() const { return station_; }
  [[nodiscard]] const std::optional<rtcm3::AntennaInfo>& antenna() const { return antenna_; }
  [[nodiscard]] const std::optional<rtcm3::GlonassBiases>& glonass_biases() const { return biases_; }
  /// Every distinct ephemeris decoded so far, in arrival order.
  [[nodiscard]] const core::NavigationData& navigation() const { return nav_; }
  /// GLONASS slot -> channel as known now.
  [[nodiscard]] std::vector<std::pair<int, int>> glonass_channels() const;
  /// Count of valid frames per message number.
  [[nodiscard]] const std::map<int, std::uint64_t>& message_counts() const { return counts_; }
  /// Recovered problems ("GLONASS R05: channel unknown, phase dropped"), each once.
  [[nodiscard]] const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  struct LockState {
    double lock_ms = 0.0;
    core::GpsTime time;
    double last_phase_cyc = core::kNoValue;  // legacy messages: (phase range - L1 pseudorange) / wavelength
    bool seen = false;
  };
  Status add_msm(const rtcm3::MsmMessage& msm, Message& out);
  Status add_legacy(const rtcm3::LegacyObsMessage& legacy, Message& out);
  /// Starts a new epoch at `time` if it differs from the one being assembled.
  void begin_epoch(const core::GpsTime& time);
  void complete_epoch();
  /// LLI bits from the lock time of a signal at `time`.
  std::uint8_t lock_lli(const core::SatelliteId& sat, core::SignalCode code, double lock_ms, double upper_ms,
                        const core::GpsTime& time);
  core::SatelliteObs& satellite(const core::SatelliteId& sat);
  void warn_once(const std::string& text);
  bool add_ephemeris_key(const core::SatelliteId& sat, const core::GpsTime& toe, int iod, int source);

  Rtcm3DecoderOptions options_;
  core::GpsTime reference_;
  std::optional<core::GpsTime> last_epoch_time_;
  std::optional<core::ObsEpoch> assembling_;
  std::array<int, core::kMaxSatellites> slot_of_{};  // satellite index -> position in assembling_->sats, or -1
  std::vector<core::ObsEpoch> ready_;
  std::size_t ready_head_ = 0;
  SignalTable<LockState> locks_;
  rtcm3::MsmMessage msm_;               // decoded into, reused
  std::map<int, int> glonass_channel_;  // slot -> channel
  std::optional<rtcm3::StationPosition> station_;
  std::optional<rtcm3::AntennaInfo> antenna_;
  std::optional<rtcm3::GlonassBiases> biases_;
  core::NavigationData nav_;
  std::set<std::tuple<int, int, long long, int, int>> ephemeris_keys_;
  std::map<int, std::uint64_t> counts_;
  std::vector<std::string> warnings_;
  std::set<std::string> warned_;
};

/// One encoded message: its frame (preamble to CRC) and what it holds.
struct Rtcm3Frame {
  int message_number = 0;
  std::optional<core::GpsTime> epoch_time;  ///< observation messages: their epoch
  std::vector<std::uint8_t> bytes;          ///< the whole frame
};

struct Rtcm3EncoderOptions {
  int station_id = 0;  ///< DF003, 0-4095
  int msm_type = 7;    ///< 4 (MSM4), 5, 6 or 7 (MSM7)
  core::LeapSecondTable leaps = core::builtin_leap_seconds();
  /// GLONASS slot -> FDMA channel (wavelengths, and MSM5/7 extended satellite information). Ephemerides given to
  /// the encoder add to it.
  std::vector<std::pair<int, int>> glonass_channels;

  /// Empty if valid, else the violated rule.
  [[nodiscard]] std::string validate() const;
};

/// What encoding an epoch left out.
struct Rtcm3EncodeReport {
  int messages = 0;
  int cells = 0;
  int unsupported_signals = 0;    ///< signals without an RTCM signal id (e.g. QZSS "1Z")
  int invalid_values = 0;         ///< values outside their field, sent as invalid
  int dropped_satellites = 0;     ///< satellites without a pseudorange
  int phase_without_channel = 0;  ///< GLONASS phases dropped: FDMA channel unknown
  int arc_restarts = 0;           ///< arcs restarted because code-minus-carrier left the field
};

class Rtcm3Encoder {
 public:
  explicit Rtcm3Encoder(Rtcm3EncoderOptions options);

  /// Encodes one epoch; frames appended to `out`. Error only if the options are invalid.
  Result<Rtcm3EncodeReport> encode_epoch(const core::ObsEpoch& epoch, std::vector<Rtcm3Frame>& out);
  /// 1005 (or 1006 with an antenna height) with this encoder's station id.
  Result<Rtcm3Frame> encode_station(rtcm3::StationPosition station) const;
  /// 1033 with this encoder's station id.
  Result<Rtcm3Frame> encode_antenna(rtcm3::AntennaInfo info) const;
  /// 1230 with this encoder's station id.
  Result<Rtcm3Frame> encode_glonass_biases(rtcm3::GlonassBiases biases) const;
  /// Ephemeris messages (1019, 1020, 1042, 1044, 1045/1046). A GLONASS ephemeris also teaches the channel.
  Result<Rtcm3Frame> encode_ephemeris(const core::KeplerEphemeris& eph) const;
  Result<Rtcm3Frame> encode_ephemeris(const core::GlonassEphemeris& eph);
  void set_glonass_channel(int slot, int channel);

  [[nodiscard]] const Rtcm3EncoderOptions& options() const { return options_; }

 private:
  struct Arc {
    double offset_cyc = 0.0;  // integer cycles subtracted from the phase
    core::GpsTime start;      // lock start
    bool valid = false;
  };
  /// Wavelength of a signal (cached per system and code; GLONASS: per channel, not cached).
  std::optional<double> wavelength(core::Constellation system, core::SignalCode code, int channel);
  /// The epoch's satellites into per_system_, their cells made; the number of satellites used per constellation.
  std::array<std::size_t, core::kNumConstellations> collect_satellites(const core::ObsEpoch& epoch,
                                                                       Rtcm3EncodeReport& report);
  /// One signal's MSM cell: its phase shifted by its arc's integer offset (a new arc at a slip or when the phase
  /// strays), its lock time.
  rtcm3::MsmCell make_cell(const core::GpsTime& t, const core::SatelliteId& sat, const core::SignalObs& s,
                           int signal_id, int channel, double reference_m, Rtcm3EncodeReport& report);
  /// A message's worth of a constellation's satellites: at most 64 cells.
  struct PendingMessage {
    core::Constellation system;
    std::size_t first;
    std::size_t count;
  };
  std::vector<PendingMessage> split_into_messages(const std::array<std::size_t, core::kNumConstellations>& used);
  Status emit_message(const core::GpsTime& t, const PendingMessage& p, bool more_follow, std::vector<Rtcm3Frame>& out,
                      Rtcm3EncodeReport& report);

  Rtcm3EncoderOptions options_;
  std::map<int, int> glonass_channel_;
  SignalTable<Arc> arcs_;
  std::array<std::array<double, 260>, core::kNumConstellations> wavelength_m_{};       // 0: not looked up, < 0: none
  rtcm3::MsmMessage msm_;                                                              // scratch
  std::array<std::vector<rtcm3::MsmSatellite>, core::kNumConstellations> per_system_;  // scratch
  std::vector<std::uint8_t> payload_;                                                  // scratch
};

}  // namespace canyon::io
