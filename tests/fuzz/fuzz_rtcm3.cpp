// libFuzzer target: RTCM 3 streams and payloads. Built by tests/fuzz/run.sh with clang++-14
// -fsanitize=fuzzer,address,undefined (not part of the normal build). Any crash, leak, sanitizer report or hang is a
// bug: bad input must come back as an Error or a count.
//
// The input is used twice: as a byte stream (framing, resynchronisation, every message decoder, epoch assembly),
// split into reads at sizes taken from its first byte; and as one message payload given to every decoder with
// each supported message number written over its first 12 bits.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "canyon/io/gnss_stream.hpp"
#include "canyon/io/rtcm3.hpp"
#include "canyon/io/rtcm3_codec.hpp"

namespace {

void decode_payload(std::vector<std::uint8_t>& p, int number) {
  if (p.size() < 2) return;
  p[0] = static_cast<std::uint8_t>(number >> 4);
  p[1] = static_cast<std::uint8_t>((p[1] & 0x0F) | ((number & 0xF) << 4));
  const canyon::core::GpsTime reference{2176, 282600.0};
  const auto leaps = canyon::core::builtin_leap_seconds();
  namespace r = canyon::io::rtcm3;
  (void)r::decode_msm(p);
  (void)r::decode_station_position(p);
  (void)r::decode_antenna_info(p);
  (void)r::decode_glonass_biases(p);
  (void)r::decode_kepler_ephemeris(p, reference);
  (void)r::decode_glonass_ephemeris(p, reference, leaps);
  (void)r::decode_legacy_obs(p);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  // As a stream, in reads of 1 + data[0] % 64 bytes.
  canyon::io::GnssStreamOptions o;
  o.format = canyon::io::StreamFormat::Rtcm3;
  o.rtcm3.reference_time = canyon::core::GpsTime{2176, 282600.0};
  canyon::io::GnssStreamDecoder decoder(o);
  const std::size_t step = 1 + data[0] % 64;
  for (std::size_t pos = 1; pos < size; pos += step) decoder.push({data + pos, std::min(step, size - pos)});
  decoder.finish();
  while (decoder.pop_rtcm3_epoch()) {
  }
  (void)decoder.problems();
  // As one payload of a message type chosen by the second byte, through every decoder and the stateful one twice.
  static const int kNumbers[] = {1004, 1005, 1006, 1012, 1019, 1020, 1033, 1042, 1044, 1045, 1046, 1074,
                                 1075, 1076, 1077, 1084, 1087, 1094, 1097, 1114, 1117, 1124, 1127, 1230};
  if (size < 4) return 0;
  std::vector<std::uint8_t> payload(data + 2, data + std::min<std::size_t>(size, 1025));
  const int number = kNumbers[data[1] % (sizeof kNumbers / sizeof kNumbers[0])];
  decode_payload(payload, number);
  canyon::io::Rtcm3DecoderOptions d;
  d.reference_time = canyon::core::GpsTime{2176, 282600.0};
  canyon::io::Rtcm3Decoder stateful(d);
  (void)stateful.decode(payload);
  (void)stateful.decode(payload);
  stateful.flush();
  while (stateful.pop_epoch()) {
  }
  return 0;
}
