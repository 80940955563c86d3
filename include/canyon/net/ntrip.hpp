#pragma once
// NTRIP (Networked Transport of RTCM via Internet Protocol), the protocol text without sockets: requests and
// responses of versions 1 and 2, HTTP chunked transfer coding, Basic authentication, the source table.
//
// Version 1 (RTCM 10410.0 appendix): "GET /MOUNT HTTP/1.0", User-Agent "NTRIP ...", optional Authorization; the
// caster answers "ICY 200 OK" and streams raw bytes, or "SOURCETABLE 200 OK" with the table for "GET /" or an
// unknown mount point, or "HTTP/1.0 401 Unauthorized".
// Version 2 (RTCM 10410.1): HTTP/1.1 with "Ntrip-Version: Ntrip/2.0" and "Host"; the caster answers "HTTP/1.1 200 OK"
// with "Content-Type: gnss/data" and the data in chunked transfer coding (source table: "gnss/sourcetable"),
// "404 Not Found" for an unknown mount point, "401 Unauthorized".
// A client may send NMEA GGA sentences upstream after the header (network RTK: the caster learns its position).

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "canyon/core/result.hpp"

namespace canyon::net {

[[nodiscard]] std::string base64_encode(std::string_view data);
/// nullopt if `text` is not base64.
[[nodiscard]] std::optional<std::string> base64_decode(std::string_view text);

/// One source table record ("STR;...") describing a mount point.
struct MountPoint {
  std::string name;        ///< mount point, e.g. "CANYON0"
  std::string identifier;  ///< source identifier (place)
  std::string format = "RTCM 3.3";
  std::string format_details;  ///< e.g. "1005(10),1077(1),1087(1)"
  int carrier = 2;             ///< 0 none, 1 L1, 2 L1+L2
  std::string nav_system;      ///< e.g. "GPS+GLO+GAL+BDS+QZS"
  std::string network = "canyon";
  std::string country = "XXX";
  double latitude_deg = 0.0;
  double longitude_deg = 0.0;
  bool nmea = false;      ///< the client must send GGA
  bool solution = false;  ///< network solution (false: single base)
  std::string generator = "canyon";
  std::string compression = "none";
  std::string authentication = "N";  ///< N none, B basic
  bool fee = false;
  int bitrate_bps = 0;
};

/// The source table text (STR lines, then "ENDSOURCETABLE"), CR LF line ends.
[[nodiscard]] std::string format_source_table(const std::vector<MountPoint>& mounts);
/// Mount points of a source table (other record kinds are skipped). Error naming the line of a malformed STR.
Result<std::vector<MountPoint>> parse_source_table(std::string_view text);

/// A client's request as a caster sees it.
struct NtripRequest {
  std::string method;  ///< "GET" (also "SOURCE"/"POST" from NTRIP servers: parsed, refused by canyon)
  std::string mount;   ///< without the leading '/'; empty: the source table
  int version = 1;     ///< 2 with "Ntrip-Version: Ntrip/2.0"
  std::string user_agent;
  std::optional<std::string> user;  ///< from "Authorization: Basic"
  std::optional<std::string> password;
  std::string host;
  std::string nmea;  ///< a GGA sentence in the "Ntrip-GGA" header (v2), if any
};
/// Largest header canyon reads before refusing a request or response.
inline constexpr std::size_t kMaxHeaderBytes = 8192;

/// Parses a request header (up to and including the empty line). Error saying what is malformed.
Result<NtripRequest> parse_ntrip_request(std::string_view header);
/// Where a header ends: the index after "\r\n\r\n" (or "\n\n"), or nullopt if not complete yet.
[[nodiscard]] std::optional<std::size_t> header_end(std::string_view data);

/// A client's request for a mount point (empty mount: the source table).
struct ClientRequestOptions {
  std::string host;  ///< caster host name, for "Host:" (v2)
  int port = 2101;
  std::string mount;
  int version = 2;   ///< 1 or 2
  std::string user;  ///< empty: no authentication
  std::string password;
  std::string user_agent = "NTRIP canyon/0.1";
  std::string gga;  ///< v2: sent in the "Ntrip-GGA" header when not empty
};
[[nodiscard]] std::string format_ntrip_request(const ClientRequestOptions& o);

/// What a caster answered.
struct NtripResponse {
  enum class Kind : std::uint8_t { Data, SourceTable, Unauthorized, NotFound, Error };
  Kind kind = Kind::Error;
  int status = 0;        ///< HTTP status (200, 401, 404, ...); 200 for "ICY 200 OK"
  int version = 1;       ///< 2 if "Ntrip-Version: Ntrip/2.0" or HTTP/1.1 with gnss/data
  bool chunked = false;  ///< "Transfer-Encoding: chunked"
  std::optional<std::size_t> content_length;
  std::string status_line;
};
/// Parses a response header (up to and including the empty line).
Result<NtripResponse> parse_ntrip_response(std::string_view header);

/// The response a caster sends.
[[nodiscard]] std::string format_data_response(int version);
[[nodiscard]] std::string format_source_table_response(int version, const std::string& table);
[[nodiscard]] std::string format_error_response(int version, int status, const std::string& reason);

/// HTTP chunked transfer coding, decoded as bytes arrive. Chunk extensions are ignored; trailers are skipped.
class ChunkedDecoder {
 public:
  /// Appends the payload bytes contained in `input` to `out`. Error (and the decoder stays failed) on a malformed
  /// chunk size line or a chunk size beyond kMaxChunk.
  Status feed(std::span<const std::uint8_t> input, std::vector<std::uint8_t>& out);
  /// The zero-size last chunk has arrived.
  [[nodiscard]] bool finished() const { return state_ == State::Done; }
  static constexpr std::size_t kMaxChunk = 1 << 24;

 private:
  enum class State : std::uint8_t { Size, Data, DataEnd, Trailer, Done, Failed };
  State state_ = State::Size;
  std::string line_;
  std::size_t remaining_ = 0;
};

/// The chunk framing of `data` (size line, data, CR LF).
[[nodiscard]] std::string chunk(std::span<const std::uint8_t> data);

}  // namespace canyon::net
