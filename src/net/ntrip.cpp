// NTRIP protocol text (see ntrip.hpp).

#include "canyon/net/ntrip.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cstdio>

namespace canyon::net {
namespace {

constexpr std::string_view kServer = "NTRIP canyon/0.1";
constexpr std::size_t kMaxLine = 1024;
constexpr std::size_t kMaxChunkLine = 256;
constexpr char kBase64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

/// Lines of a header (without CR LF), up to the empty line. Error on a line too long or a control character.
Result<std::vector<std::string_view>> header_lines(std::string_view header) {
  std::vector<std::string_view> lines;
  std::size_t pos = 0;
  while (pos < header.size()) {
    std::size_t end = header.find('\n', pos);
    if (end == std::string_view::npos) end = header.size();
    std::string_view line = header.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = end + 1;
    if (line.empty()) break;
    if (line.size() > kMaxLine) return Error{"header line longer than " + std::to_string(kMaxLine) + " characters"};
    for (const char c : line) {
      if ((static_cast<unsigned char>(c) < 0x20 && c != '\t') || c == 0x7F) {
        return Error{"control character in the header"};
      }
    }
    lines.push_back(line);
  }
  if (lines.empty()) return Error{"empty header"};
  return lines;
}

/// Splits "Name: value".
bool split_field(std::string_view line, std::string& name, std::string_view& value) {
  const std::size_t colon = line.find(':');
  if (colon == std::string_view::npos || colon == 0) return false;
  name = lower(trim(line.substr(0, colon)));
  value = trim(line.substr(colon + 1));
  return true;
}

std::vector<std::string_view> split(std::string_view s, char sep) {
  std::vector<std::string_view> out;
  std::size_t pos = 0;
  for (;;) {
    const std::size_t end = s.find(sep, pos);
    out.push_back(s.substr(pos, end == std::string_view::npos ? std::string_view::npos : end - pos));
    if (end == std::string_view::npos) break;
    pos = end + 1;
  }
  return out;
}

std::string format_double(double v, int decimals) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*f", decimals, v);
  return text;
}

}  // namespace

std::string base64_encode(std::string_view data) {
  std::string out;
  out.reserve((data.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < data.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(data[i]) << 16) | (static_cast<unsigned char>(data[i + 1]) << 8) |
                       static_cast<unsigned char>(data[i + 2]);
    out += kBase64[(v >> 18) & 63];
    out += kBase64[(v >> 12) & 63];
    out += kBase64[(v >> 6) & 63];
    out += kBase64[v & 63];
  }
  if (i < data.size()) {
    unsigned v = static_cast<unsigned char>(data[i]) << 16;
    if (i + 1 < data.size()) v |= static_cast<unsigned char>(data[i + 1]) << 8;
    out += kBase64[(v >> 18) & 63];
    out += kBase64[(v >> 12) & 63];
    out += i + 1 < data.size() ? kBase64[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::optional<std::string> base64_decode(std::string_view text) {
  std::array<int, 256> value{};
  value.fill(-1);
  for (int k = 0; k < 64; ++k) value[static_cast<unsigned char>(kBase64[k])] = k;
  while (!text.empty() && text.back() == '=') text.remove_suffix(1);
  std::string out;
  unsigned acc = 0;
  int bits = 0;
  for (const char c : text) {
    const int v = value[static_cast<unsigned char>(c)];
    if (v < 0) return std::nullopt;
    acc = (acc << 6) | static_cast<unsigned>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((acc >> bits) & 0xFF);
    }
  }
  if (bits >= 6) return std::nullopt;  // a single trailing character cannot be
  return out;
}

std::string format_source_table(const std::vector<MountPoint>& mounts) {
  std::string out;
  for (const MountPoint& m : mounts) {
    out += "STR;" + m.name + ";" + m.identifier + ";" + m.format + ";" + m.format_details + ";" +
           std::to_string(m.carrier) + ";" + m.nav_system + ";" + m.network + ";" + m.country + ";" +
           format_double(m.latitude_deg, 2) + ";" + format_double(m.longitude_deg, 2) + ";" + (m.nmea ? "1" : "0") +
           ";" + (m.solution ? "1" : "0") + ";" + m.generator + ";" + m.compression + ";" + m.authentication + ";" +
           (m.fee ? "Y" : "N") + ";" + std::to_string(m.bitrate_bps) + ";\r\n";
  }
  out += "ENDSOURCETABLE\r\n";
  return out;
}

Result<std::vector<MountPoint>> parse_source_table(std::string_view text) {
  std::vector<MountPoint> mounts;
  int line_number = 0;
  for (std::string_view line : split(text, '\n')) {
    ++line_number;
    line = trim(line);
    if (line.rfind("STR;", 0) != 0) continue;
    const auto f = split(line, ';');
    if (f.size() < 18) {
      return Error{"source table line " + std::to_string(line_number) + ": STR record with " +
                   std::to_string(f.size()) + " fields, expected at least 18"};
    }
    MountPoint m;
    m.name = std::string(f[1]);
    m.identifier = std::string(f[2]);
    m.format = std::string(f[3]);
    m.format_details = std::string(f[4]);
    std::from_chars(f[5].data(), f[5].data() + f[5].size(), m.carrier);
    m.nav_system = std::string(f[6]);
    m.network = std::string(f[7]);
    m.country = std::string(f[8]);
    m.latitude_deg = std::strtod(std::string(f[9]).c_str(), nullptr);
    m.longitude_deg = std::strtod(std::string(f[10]).c_str(), nullptr);
    m.nmea = f[11] == "1";
    m.solution = f[12] == "1";
    m.generator = std::string(f[13]);
    m.compression = std::string(f[14]);
    m.authentication = std::string(f[15]);
    m.fee = f[16] == "Y";
    std::from_chars(f[17].data(), f[17].data() + f[17].size(), m.bitrate_bps);
    if (m.name.empty()) return Error{"source table line " + std::to_string(line_number) + ": empty mount point"};
    mounts.push_back(std::move(m));
  }
  return mounts;
}

std::optional<std::size_t> header_end(std::string_view data) {
  const std::size_t crlf = data.find("\r\n\r\n");
  const std::size_t lf = data.find("\n\n");
  if (crlf == std::string_view::npos && lf == std::string_view::npos) return std::nullopt;
  if (lf == std::string_view::npos || (crlf != std::string_view::npos && crlf + 2 <= lf)) return crlf + 4;
  return lf + 2;
}

Result<NtripRequest> parse_ntrip_request(std::string_view header) {
  if (header.size() > kMaxHeaderBytes) return Error{"request header longer than " + std::to_string(kMaxHeaderBytes)};
  auto lines = header_lines(header);
  if (!lines) return Error{"malformed request: " + lines.error().message};
  NtripRequest r;
  const auto first = split((*lines)[0], ' ');
  if (first.size() < 2) return Error{"malformed request line '" + std::string((*lines)[0]) + "'"};
  r.method = std::string(first[0]);
  std::string_view path;
  if (r.method == "SOURCE") {  // NTRIP 1 server: "SOURCE password /MOUNT"
    if (first.size() < 3) return Error{"malformed SOURCE request line"};
    r.password = std::string(first[1]);
    path = first[2];
  } else if (r.method == "GET" || r.method == "POST") {
    if (first.size() != 3 || first[2].rfind("HTTP/1.", 0) != 0) {
      return Error{"malformed request line '" + std::string((*lines)[0]) + "' (expected 'GET /MOUNT HTTP/1.x')"};
    }
    path = first[1];
  } else {
    return Error{"unsupported method '" + r.method + "'"};
  }
  if (path.empty() || path.front() != '/')
    return Error{"request path '" + std::string(path) + "' does not start with /"};
  path.remove_prefix(1);
  path = path.substr(0, path.find('?'));
  r.mount = std::string(path);
  for (std::size_t i = 1; i < lines->size(); ++i) {
    std::string name;
    std::string_view value;
    if (!split_field((*lines)[i], name, value)) {
      return Error{"malformed header field '" + std::string((*lines)[i]) + "'"};
    }
    if (name == "ntrip-version") {
      if (lower(value) == "ntrip/2.0") r.version = 2;
    } else if (name == "user-agent") {
      r.user_agent = std::string(value);
    } else if (name == "host") {
      r.host = std::string(value);
    } else if (name == "ntrip-gga") {
      r.nmea = std::string(value);
    } else if (name == "authorization") {
      const std::size_t space = value.find(' ');
      if (space == std::string_view::npos || lower(value.substr(0, space)) != "basic") {
        return Error{"unsupported authorization (only Basic)"};
      }
      const auto decoded = base64_decode(trim(value.substr(space + 1)));
      if (!decoded) return Error{"authorization is not base64"};
      const std::size_t colon = decoded->find(':');
      if (colon == std::string::npos) return Error{"authorization without 'user:password'"};
      r.user = decoded->substr(0, colon);
      r.password = decoded->substr(colon + 1);
    }
  }
  return r;
}

std::string format_ntrip_request(const ClientRequestOptions& o) {
  std::string out = "GET /" + o.mount + (o.version >= 2 ? " HTTP/1.1\r\n" : " HTTP/1.0\r\n");
  if (o.version >= 2) {
    out += "Host: " + o.host + ":" + std::to_string(o.port) + "\r\n";
    out += "Ntrip-Version: Ntrip/2.0\r\n";
  }
  out += "User-Agent: " + o.user_agent + "\r\n";
  if (!o.user.empty()) out += "Authorization: Basic " + base64_encode(o.user + ":" + o.password) + "\r\n";
  if (o.version >= 2 && !o.gga.empty()) out += "Ntrip-GGA: " + o.gga + "\r\n";
  if (o.version >= 2) out += "Connection: close\r\n";
  out += "\r\n";
  return out;
}

Result<NtripResponse> parse_ntrip_response(std::string_view header) {
  if (header.size() > kMaxHeaderBytes) return Error{"response header longer than " + std::to_string(kMaxHeaderBytes)};
  auto lines = header_lines(header);
  if (!lines) return Error{"malformed response: " + lines.error().message};
  NtripResponse r;
  r.status_line = std::string((*lines)[0]);
  const auto first = split((*lines)[0], ' ');
  bool sourcetable_type = false;
  if (first[0] == "ICY") {
    r.status = 200;
    r.kind = NtripResponse::Kind::Data;
  } else if (first[0] == "SOURCETABLE") {
    r.status = 200;
    r.kind = NtripResponse::Kind::SourceTable;
  } else if (first[0].rfind("HTTP/1.", 0) == 0 && first.size() >= 2) {
    int status = 0;
    const auto [end, ec] = std::from_chars(first[1].data(), first[1].data() + first[1].size(), status);
    if (ec != std::errc{} || end != first[1].data() + first[1].size()) {
      return Error{"malformed status line '" + r.status_line + "'"};
    }
    r.status = status;
    if (first[0] == "HTTP/1.1") r.version = 2;
    r.kind = status == 200   ? NtripResponse::Kind::Data
             : status == 401 ? NtripResponse::Kind::Unauthorized
             : status == 404 ? NtripResponse::Kind::NotFound
                             : NtripResponse::Kind::Error;
  } else {
    return Error{"not an NTRIP response: '" + r.status_line + "'"};
  }
  for (std::size_t i = 1; i < lines->size(); ++i) {
    std::string name;
    std::string_view value;
    if (!split_field((*lines)[i], name, value)) continue;  // lenient: casters send odd lines
    const std::string v = lower(value);
    if (name == "ntrip-version" && v == "ntrip/2.0") r.version = 2;
    if (name == "transfer-encoding" && v.find("chunked") != std::string::npos) r.chunked = true;
    if (name == "content-type" && v.find("sourcetable") != std::string::npos) sourcetable_type = true;
    if (name == "content-length") {
      std::size_t n = 0;
      const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), n);
      if (ec == std::errc{} && end == v.data() + v.size()) r.content_length = n;
    }
  }
  if (r.kind == NtripResponse::Kind::Data && sourcetable_type) r.kind = NtripResponse::Kind::SourceTable;
  return r;
}

std::string format_data_response(int version) {
  if (version < 2) return "ICY 200 OK\r\n\r\n";
  return "HTTP/1.1 200 OK\r\nNtrip-Version: Ntrip/2.0\r\nServer: " + std::string(kServer) +
         "\r\nContent-Type: gnss/data\r\nCache-Control: no-store, no-cache, max-age=0\r\nPragma: no-cache\r\n"
         "Connection: close\r\nTransfer-Encoding: chunked\r\n\r\n";
}

std::string format_source_table_response(int version, const std::string& table) {
  if (version < 2) {
    return "SOURCETABLE 200 OK\r\nServer: " + std::string(kServer) +
           "\r\nContent-Type: text/plain\r\nContent-Length: " + std::to_string(table.size()) + "\r\n\r\n" + table;
  }
  return "HTTP/1.1 200 OK\r\nNtrip-Version: Ntrip/2.0\r\nServer: " + std::string(kServer) +
         "\r\nContent-Type: gnss/sourcetable\r\nContent-Length: " + std::to_string(table.size()) +
         "\r\nConnection: close\r\n\r\n" + table;
}

std::string format_error_response(int version, int status, const std::string& reason) {
  std::string out = (version < 2 ? "HTTP/1.0 " : "HTTP/1.1 ") + std::to_string(status) + " " + reason + "\r\n";
  if (version >= 2) out += "Ntrip-Version: Ntrip/2.0\r\n";
  out += "Server: " + std::string(kServer) + "\r\n";
  if (status == 401) out += "WWW-Authenticate: Basic realm=\"canyon\"\r\n";
  out += "Content-Length: 0\r\nConnection: close\r\n\r\n";
  return out;
}

Status ChunkedDecoder::feed(std::span<const std::uint8_t> input, std::vector<std::uint8_t>& out) {
  std::size_t i = 0;
  while (i < input.size()) {
    switch (state_) {
      case State::Failed: return Error{"chunked transfer coding broken earlier"};
      case State::Done: return Ok{};
      case State::Size:
      case State::Trailer: {
        const char c = static_cast<char>(input[i++]);
        if (c != '\n') {
          if (c != '\r') line_ += c;
          if (line_.size() > kMaxChunkLine) {
            state_ = State::Failed;
            return Error{"chunk line longer than " + std::to_string(kMaxChunkLine) + " characters"};
          }
          break;
        }
        if (state_ == State::Trailer) {
          if (line_.empty()) state_ = State::Done;
          line_.clear();
          break;
        }
        const std::string_view size_text = trim(std::string_view(line_).substr(0, line_.find(';')));
        std::size_t size = 0;
        const auto [end, ec] = std::from_chars(size_text.data(), size_text.data() + size_text.size(), size, 16);
        if (size_text.empty() || ec != std::errc{} || end != size_text.data() + size_text.size() || size > kMaxChunk) {
          state_ = State::Failed;
          return Error{"malformed chunk size line '" + line_.substr(0, 40) + "'"};
        }
        line_.clear();
        remaining_ = size;
        state_ = size == 0 ? State::Trailer : State::Data;
        break;
      }
      case State::Data: {
        const std::size_t n = std::min(remaining_, input.size() - i);
        out.insert(out.end(), input.begin() + static_cast<std::ptrdiff_t>(i),
                   input.begin() + static_cast<std::ptrdiff_t>(i + n));
        i += n;
        remaining_ -= n;
        if (remaining_ == 0) state_ = State::DataEnd;
        break;
      }
      case State::DataEnd: {
        const char c = static_cast<char>(input[i++]);
        if (c == '\r') break;
        if (c != '\n') {
          state_ = State::Failed;
          return Error{"chunk data not followed by CR LF"};
        }
        state_ = State::Size;
        break;
      }
    }
  }
  return Ok{};
}

std::string chunk(std::span<const std::uint8_t> data) {
  char size[24];
  std::snprintf(size, sizeof size, "%zx\r\n", data.size());
  std::string out = size;
  out.append(reinterpret_cast<const char*>(data.data()), data.size());
  out += "\r\n";
  return out;
}

}  // namespace canyon::net
