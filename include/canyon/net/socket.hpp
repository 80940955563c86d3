#pragma once
// Thin POSIX socket helpers for canyon's network module: an owning file descriptor, TCP listen/connect with
// timeouts, and sending with a deadline. Errors come back as Result naming the address and the system error.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "canyon/core/result.hpp"

namespace canyon::net {

/// An owned file descriptor (closed on destruction).
class Fd {
 public:
  Fd() = default;
  explicit Fd(int fd) : fd_(fd) {}
  Fd(Fd&& other) noexcept : fd_(other.release()) {}
  Fd& operator=(Fd&& other) noexcept;
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd();

  [[nodiscard]] int get() const { return fd_; }
  [[nodiscard]] bool valid() const { return fd_ >= 0; }
  int release();
  void reset();

 private:
  int fd_ = -1;
};

struct Endpoint {
  std::string host;
  int port = 0;
  [[nodiscard]] std::string to_string() const { return host + ":" + std::to_string(port); }
};
/// "host:port" (host may be empty: "0.0.0.0"); Error if malformed or the port is outside 1-65535 (0 with
/// `allow_zero`, for "any free port").
Result<Endpoint> parse_endpoint(std::string_view text, bool allow_zero = false);

/// A listening TCP socket (SO_REUSEADDR, non-blocking) on `host:port`; port 0 picks a free one (see local_port).
Result<Fd> tcp_listen(const std::string& host, int port, int backlog = 16);
/// The port a socket is bound to.
[[nodiscard]] int local_port(const Fd& fd);
/// "address:port" of the peer of a connected socket.
[[nodiscard]] std::string peer_name(const Fd& fd);
/// A connected TCP socket (non-blocking afterwards), or an Error within `timeout_ms`.
Result<Fd> tcp_connect(const std::string& host, int port, int timeout_ms);
/// Sends all of `data` on a (non-blocking) socket within `timeout_ms`.
Status send_all(const Fd& fd, std::span<const std::uint8_t> data, int timeout_ms);
Status send_all(const Fd& fd, std::string_view text, int timeout_ms);
/// Makes a descriptor non-blocking (and close-on-exec).
Status set_nonblocking(int fd);

/// A pipe whose read end wakes a poll() loop when written.
class WakePipe {
 public:
  WakePipe();
  [[nodiscard]] int read_fd() const { return read_.get(); }
  void wake() const;
  void drain() const;

 private:
  Fd read_;
  Fd write_;
};

}  // namespace canyon::net
