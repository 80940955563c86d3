// Stream URLs (see stream_url.hpp).

#include "canyon/net/stream_url.hpp"

#include "canyon/net/socket.hpp"

namespace canyon::net {

Result<std::optional<StreamUrl>> parse_stream_url(const std::string& text) {
  StreamUrl u;
  std::string rest;
  if (text.rfind("ntrip://", 0) == 0) {
    u.ntrip = true;
    rest = text.substr(8);
  } else if (text.rfind("tcp://", 0) == 0) {
    rest = text.substr(6);
  } else {
    return std::optional<StreamUrl>{};
  }
  const std::string usage = "'" + text + "' is not tcp://HOST:PORT or ntrip://[USER[:PASSWORD]@]HOST:PORT/MOUNT";
  if (u.ntrip) {
    const std::size_t slash = rest.find('/');
    if (slash == std::string::npos || slash + 1 >= rest.size()) return Error{usage};
    u.mount = rest.substr(slash + 1);
    rest = rest.substr(0, slash);
    const std::size_t at = rest.rfind('@');
    if (at != std::string::npos) {
      const std::string credentials = rest.substr(0, at);
      rest = rest.substr(at + 1);
      const std::size_t colon = credentials.find(':');
      u.user = credentials.substr(0, colon);
      if (colon != std::string::npos) u.password = credentials.substr(colon + 1);
    }
  }
  auto endpoint = parse_endpoint(rest);
  if (!endpoint || rest.front() == ':') return Error{usage};
  u.host = endpoint->host;
  u.port = endpoint->port;
  return std::optional<StreamUrl>{u};
}

}  // namespace canyon::net
