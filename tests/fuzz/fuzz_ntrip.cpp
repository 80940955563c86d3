// libFuzzer target: NTRIP requests and responses, chunked transfer coding, the source table, base64. Built by
// tests/fuzz/run.sh (clang++-14 -fsanitize=fuzzer,address,undefined).

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "canyon/net/ntrip.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  (void)canyon::net::header_end(text);
  (void)canyon::net::parse_ntrip_request(text);
  (void)canyon::net::parse_ntrip_response(text);
  (void)canyon::net::parse_source_table(text);
  (void)canyon::net::base64_decode(text);
  if (size > 0) {
    canyon::net::ChunkedDecoder chunked;
    std::vector<std::uint8_t> out;
    const std::size_t step = 1 + data[0] % 17;
    for (std::size_t pos = 1; pos < size; pos += step) {
      if (!chunked.feed({data + pos, std::min(step, size - pos)}, out).ok()) break;
    }
  }
  return 0;
}
