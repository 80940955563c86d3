#pragma once
// A receiver or correction byte stream decoded end to end: StreamFramer (RTCM 3, UBX, NMEA, resynchronisation)
// feeding Rtcm3Decoder and UbxDecoder. Observations are kept per source (a u-blox base logs its own RTCM output
// beside its raw UBX measurements: both are there, and the caller chooses); ephemerides from both are merged into
// one NavigationData. Decode errors of single messages are counted and the first ones kept with their byte offset;
// nothing stops the stream.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "canyon/core/ephemeris.hpp"
#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/io/rtcm3_codec.hpp"
#include "canyon/io/stream_framer.hpp"
#include "canyon/io/ubx.hpp"

namespace canyon::io {

enum class StreamFormat : std::uint8_t { Auto, Rtcm3, Ubx };

/// "rtcm3", "ubx", "auto" <-> StreamFormat.
[[nodiscard]] std::optional<StreamFormat> parse_stream_format(const std::string& text);
[[nodiscard]] std::string stream_format_name(StreamFormat format);

struct GnssStreamOptions {
  /// Which protocols to frame: Rtcm3 frames RTCM only, Ubx frames UBX and NMEA, Auto all three.
  StreamFormat format = StreamFormat::Auto;
  Rtcm3DecoderOptions rtcm3;
  UbxDecoderOptions ubx;
};

struct GnssStreamStats {
  FramerStats framing;
  std::uint64_t rtcm3_decode_errors = 0;  ///< frames with a good CRC whose content is invalid
  std::uint64_t ubx_decode_errors = 0;
  std::uint64_t rtcm3_epochs = 0;
  std::uint64_t ubx_epochs = 0;
};

class GnssStreamDecoder {
 public:
  static constexpr std::size_t kMaxReportedErrors = 20;

  explicit GnssStreamDecoder(GnssStreamOptions options);

  /// Frames and decodes `bytes` (any split).
  void push(std::span<const std::uint8_t> bytes);
  /// End of the stream: drains the framer and completes the last RTCM epoch.
  void finish();

  /// Observation epochs decoded from RTCM 3 messages, and from UBX RXM-RAWX, oldest first.
  std::optional<core::ObsEpoch> pop_rtcm3_epoch() { return rtcm3_.pop_epoch(); }
  std::optional<core::ObsEpoch> pop_ubx_epoch() { return ubx_.pop_epoch(); }

  /// Ephemerides of both sources (each once, in arrival order).
  [[nodiscard]] const core::NavigationData& navigation() const { return nav_; }
  [[nodiscard]] const Rtcm3Decoder& rtcm3() const { return rtcm3_; }
  [[nodiscard]] const UbxDecoder& ubx() const { return ubx_; }
  [[nodiscard]] GnssStreamStats stats() const;
  /// Framing problems and message decode errors, "byte N: what", the first kMaxReportedErrors of each.
  [[nodiscard]] std::vector<std::string> problems() const;
  /// The RTCM 3 frames (whole, with offsets) seen last by push(), when keep_frames is set: for relays.
  void keep_rtcm3_frames(bool keep) { keep_frames_ = keep; }
  [[nodiscard]] std::vector<std::vector<std::uint8_t>> take_rtcm3_frames();

 private:
  void drain();
  void collect_navigation();

  GnssStreamOptions options_;
  StreamFramer framer_;
  Rtcm3Decoder rtcm3_;
  UbxDecoder ubx_;
  core::NavigationData nav_;
  std::size_t rtcm3_kepler_seen_ = 0, rtcm3_glonass_seen_ = 0, ubx_kepler_seen_ = 0, ubx_glonass_seen_ = 0;
  std::uint64_t rtcm3_errors_ = 0, ubx_errors_ = 0;
  std::uint64_t rtcm3_epochs_ = 0, ubx_epochs_ = 0;
  std::vector<std::string> errors_;
  bool keep_frames_ = false;
  std::vector<std::vector<std::uint8_t>> frames_;
};

/// A whole file's bytes, gzip-compressed or not (detected from the content). Error (path) if it cannot be opened or
/// read; a gzip stream cut short gives the bytes before the cut and says so in `warning`.
Result<std::vector<std::uint8_t>> read_binary_file(const std::string& path, std::string* warning = nullptr);

}  // namespace canyon::io
