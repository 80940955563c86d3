// libFuzzer target: u-blox UBX streams (with NMEA and RTCM 3 interleaved) and UBX payloads, navigation words
// included. Built by tests/fuzz/run.sh (clang++-14 -fsanitize=fuzzer,address,undefined).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "canyon/io/gnss_stream.hpp"
#include "canyon/io/nav_message.hpp"
#include "canyon/io/ubx.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  // A mixed stream in reads of 1 + data[0] % 128 bytes.
  canyon::io::GnssStreamOptions o;
  o.format = canyon::io::StreamFormat::Auto;
  o.ubx.reference_time = canyon::core::GpsTime{2021, 399000.0};
  canyon::io::GnssStreamDecoder decoder(o);
  const std::size_t step = 1 + data[0] % 128;
  for (std::size_t pos = 1; pos < size; pos += step) decoder.push({data + pos, std::min(step, size - pos)});
  decoder.finish();
  while (decoder.pop_ubx_epoch()) {
  }
  while (decoder.pop_rtcm3_epoch()) {
  }
  // Payloads of the decoded message kinds: RAWX, SFRBX (each constellation), NAV-PVT, NAV-TIMEGPS.
  canyon::io::UbxDecoderOptions u;
  u.reference_time = canyon::core::GpsTime{2021, 399000.0};
  canyon::io::UbxDecoder ubx(u);
  const std::span<const std::uint8_t> payload(data + 1, size - 1);
  (void)ubx.decode(0x02, 0x15, payload);
  (void)ubx.decode(0x01, 0x07, payload);
  (void)ubx.decode(0x01, 0x20, payload);
  std::vector<std::uint8_t> sfrbx(data + 1, data + size);
  if (sfrbx.size() >= 8) {
    for (const std::uint8_t gnss : {0, 2, 3, 5, 6}) {
      sfrbx[0] = gnss;
      for (int repeat = 0; repeat < 3; ++repeat) (void)ubx.decode(0x02, 0x13, sfrbx);
    }
  }
  while (ubx.pop_epoch()) {
  }
  return 0;
}
