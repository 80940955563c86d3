// Mixed GNSS byte streams decoded end to end (see gnss_stream.hpp).

#include "canyon/io/gnss_stream.hpp"

#include <cerrno>
#include <cstring>

#include <zlib.h>

namespace canyon::io {

std::optional<StreamFormat> parse_stream_format(const std::string& text) {
  if (text == "auto") return StreamFormat::Auto;
  if (text == "rtcm3") return StreamFormat::Rtcm3;
  if (text == "ubx") return StreamFormat::Ubx;
  return std::nullopt;
}

std::string stream_format_name(StreamFormat format) {
  switch (format) {
    case StreamFormat::Auto: return "auto";
    case StreamFormat::Rtcm3: return "rtcm3";
    case StreamFormat::Ubx: return "ubx";
  }
  return "auto";
}

namespace {

StreamFramer::Options framer_options(StreamFormat format) {
  StreamFramer::Options o;
  o.rtcm3 = format != StreamFormat::Ubx;
  o.ubx = format != StreamFormat::Rtcm3;
  o.nmea = format != StreamFormat::Rtcm3;
  return o;
}

}  // namespace

GnssStreamDecoder::GnssStreamDecoder(GnssStreamOptions options)
    : options_(std::move(options)),
      framer_(framer_options(options_.format)),
      rtcm3_(options_.rtcm3),
      ubx_(options_.ubx) {}

void GnssStreamDecoder::push(std::span<const std::uint8_t> bytes) {
  framer_.push(bytes);
  drain();
}

void GnssStreamDecoder::finish() {
  framer_.finish();
  drain();
  rtcm3_.flush();
}

void GnssStreamDecoder::drain() {
  while (auto packet = framer_.next()) {
    if (packet->protocol == Protocol::Rtcm3) {
      if (keep_frames_) frames_.emplace_back(packet->bytes.begin(), packet->bytes.end());
      auto m = rtcm3_.decode(packet->payload());
      if (!m) {
        ++rtcm3_errors_;
        if (errors_.size() < 2 * kMaxReportedErrors) {
          errors_.push_back("byte " + std::to_string(packet->offset) + ": " + m.error().message);
        }
      } else if (m->content == Rtcm3Decoder::Content::Observations) {
        ++rtcm3_epochs_;
      }
    } else if (packet->protocol == Protocol::Ubx) {
      auto m = ubx_.decode(packet->ubx_class(), packet->ubx_id(), packet->payload());
      if (!m) {
        ++ubx_errors_;
        if (errors_.size() < 2 * kMaxReportedErrors) {
          errors_.push_back("byte " + std::to_string(packet->offset) + ": " + m.error().message);
        }
      } else if (m->content == UbxDecoder::Content::Observations) {
        ++ubx_epochs_;
      }
    }
  }
  collect_navigation();
}

void GnssStreamDecoder::collect_navigation() {
  const core::NavigationData& r = rtcm3_.navigation();
  const core::NavigationData& u = ubx_.navigation();
  for (; rtcm3_kepler_seen_ < r.kepler.size(); ++rtcm3_kepler_seen_)
    nav_.kepler.push_back(r.kepler[rtcm3_kepler_seen_]);
  for (; rtcm3_glonass_seen_ < r.glonass.size(); ++rtcm3_glonass_seen_) {
    nav_.glonass.push_back(r.glonass[rtcm3_glonass_seen_]);
  }
  for (; ubx_kepler_seen_ < u.kepler.size(); ++ubx_kepler_seen_) nav_.kepler.push_back(u.kepler[ubx_kepler_seen_]);
  for (; ubx_glonass_seen_ < u.glonass.size(); ++ubx_glonass_seen_)
    nav_.glonass.push_back(u.glonass[ubx_glonass_seen_]);
  if (u.gps_klobuchar) nav_.gps_klobuchar = u.gps_klobuchar;
}

GnssStreamStats GnssStreamDecoder::stats() const {
  GnssStreamStats s;
  s.framing = framer_.stats();
  s.rtcm3_decode_errors = rtcm3_errors_;
  s.ubx_decode_errors = ubx_errors_;
  s.rtcm3_epochs = rtcm3_epochs_;
  s.ubx_epochs = ubx_epochs_;
  return s;
}

std::vector<std::string> GnssStreamDecoder::problems() const {
  std::vector<std::string> out = framer_.problems();
  out.insert(out.end(), errors_.begin(), errors_.end());
  return out;
}

std::vector<std::vector<std::uint8_t>> GnssStreamDecoder::take_rtcm3_frames() {
  return std::exchange(frames_, {});
}

Result<std::vector<std::uint8_t>> read_binary_file(const std::string& path, std::string* warning) {
  gzFile file = gzopen(path.c_str(), "rb");
  if (file == nullptr) return Error{std::string("cannot open file: ") + std::strerror(errno), path, 0};
  gzbuffer(file, 1 << 17);
  std::vector<std::uint8_t> out;
  constexpr unsigned kChunk = 1 << 16;
  for (;;) {
    const std::size_t old = out.size();
    out.resize(old + kChunk);
    const int n = gzread(file, out.data() + old, kChunk);
    if (n < 0) {
      int code = 0;
      const std::string message = gzerror(file, &code);
      gzclose(file);
      return Error{"read error: " + message, path, 0};
    }
    out.resize(old + static_cast<std::size_t>(n));
    if (n == 0) break;
  }
  int code = Z_OK;
  const char* message = gzerror(file, &code);
  const bool cut = (code != Z_OK && code != Z_STREAM_END) || (gzdirect(file) == 0 && !gzeof(file));
  const std::string text = message != nullptr ? message : "";
  gzclose(file);
  if (cut && warning != nullptr) {
    *warning =
        path + ": compressed stream ended unexpectedly (" + text + "); " + std::to_string(out.size()) + " bytes read";
  }
  return out;
}

}  // namespace canyon::io
