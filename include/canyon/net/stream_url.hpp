#pragma once
// A network byte stream named by a URL: "tcp://HOST:PORT" or "ntrip://[USER[:PASSWORD]@]HOST:PORT/MOUNT" (the inputs
// of canyon convert, the rover's receiver and correction links, the base station's receiver).

#include <optional>
#include <string>

#include "canyon/core/result.hpp"

namespace canyon::net {

/// Where a network input comes from.
struct StreamUrl {
  bool ntrip = false;
  std::string host;
  int port = 0;
  std::string mount;
  std::string user;
  std::string password;
};

/// nullopt for a plain file name; Error for a malformed URL.
Result<std::optional<StreamUrl>> parse_stream_url(const std::string& text);

}  // namespace canyon::net
