// POSIX socket helpers (see socket.hpp).

#include "canyon/net/socket.hpp"

#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstring>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

namespace canyon::net {
namespace {

std::string system_error(const char* what) {
  return std::string(what) + ": " + std::strerror(errno);
}

}  // namespace

Fd& Fd::operator=(Fd&& other) noexcept {
  if (this != &other) {
    reset();
    fd_ = other.release();
  }
  return *this;
}

Fd::~Fd() {
  reset();
}

int Fd::release() {
  const int fd = fd_;
  fd_ = -1;
  return fd;
}

void Fd::reset() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

Result<Endpoint> parse_endpoint(std::string_view text, bool allow_zero) {
  // Messages appended piecewise: GCC 12 warns falsely (-Wrestrict) on "'" + std::string.
  std::string quoted = "'";
  quoted.append(text).append("'");
  const std::size_t colon = text.rfind(':');
  if (colon == std::string_view::npos) return Error{quoted + " is not host:port"};
  Endpoint e;
  e.host = std::string(text.substr(0, colon));
  if (e.host.empty()) e.host = "0.0.0.0";
  const std::string_view port = text.substr(colon + 1);
  const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), e.port);
  if (ec != std::errc{} || end != port.data() + port.size() || e.port < (allow_zero ? 0 : 1) || e.port > 65535) {
    return Error{quoted + ": bad port"};
  }
  return e;
}

Status set_nonblocking(int fd) {
  const int flags = ::fcntl(fd, F_GETFL, 0);
  if (flags < 0 || ::fcntl(fd, F_SETFL, flags | O_NONBLOCK) < 0) return Error{system_error("fcntl")};
  ::fcntl(fd, F_SETFD, FD_CLOEXEC);
  return Ok{};
}

Result<Fd> tcp_listen(const std::string& host, int port, int backlog) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (const int rc = ::getaddrinfo(host.empty() ? nullptr : host.c_str(), service.c_str(), &hints, &found); rc != 0) {
    return Error{"cannot resolve " + host + ": " + ::gai_strerror(rc)};
  }
  Fd fd(::socket(found->ai_family, found->ai_socktype, found->ai_protocol));
  if (!fd.valid()) {
    ::freeaddrinfo(found);
    return Error{system_error("socket")};
  }
  const int one = 1;
  ::setsockopt(fd.get(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  const int bound = ::bind(fd.get(), found->ai_addr, found->ai_addrlen);
  ::freeaddrinfo(found);
  if (bound != 0) return Error{system_error(("cannot listen on " + host + ":" + service).c_str())};
  if (::listen(fd.get(), backlog) != 0) return Error{system_error("listen")};
  if (Status s = set_nonblocking(fd.get()); !s.ok()) return s.error();
  return fd;
}

int local_port(const Fd& fd) {
  sockaddr_in addr{};
  socklen_t len = sizeof addr;
  if (::getsockname(fd.get(), reinterpret_cast<sockaddr*>(&addr), &len) != 0) return 0;
  return ntohs(addr.sin_port);
}

std::string peer_name(const Fd& fd) {
  sockaddr_in addr{};
  socklen_t len = sizeof addr;
  if (::getpeername(fd.get(), reinterpret_cast<sockaddr*>(&addr), &len) != 0) return "?";
  char text[INET_ADDRSTRLEN] = "?";
  ::inet_ntop(AF_INET, &addr.sin_addr, text, sizeof text);
  return std::string(text) + ":" + std::to_string(ntohs(addr.sin_port));
}

Result<Fd> tcp_connect(const std::string& host, int port, int timeout_ms) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const std::string where = host + ":" + std::to_string(port);
  if (const int rc = ::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found); rc != 0) {
    return Error{"cannot resolve " + host + ": " + ::gai_strerror(rc)};
  }
  Fd fd(::socket(found->ai_family, found->ai_socktype, found->ai_protocol));
  if (!fd.valid()) {
    ::freeaddrinfo(found);
    return Error{system_error("socket")};
  }
  if (Status s = set_nonblocking(fd.get()); !s.ok()) {
    ::freeaddrinfo(found);
    return s.error();
  }
  const int rc = ::connect(fd.get(), found->ai_addr, found->ai_addrlen);
  ::freeaddrinfo(found);
  if (rc != 0 && errno != EINPROGRESS) return Error{system_error(("cannot connect to " + where).c_str())};
  if (rc != 0) {
    pollfd p{fd.get(), POLLOUT, 0};
    const int ready = ::poll(&p, 1, timeout_ms);
    if (ready == 0)
      return Error{"cannot connect to " + where + ": timed out after " + std::to_string(timeout_ms) + " ms"};
    int error = 0;
    socklen_t len = sizeof error;
    ::getsockopt(fd.get(), SOL_SOCKET, SO_ERROR, &error, &len);
    if (ready < 0 || error != 0) {
      errno = error != 0 ? error : errno;
      return Error{system_error(("cannot connect to " + where).c_str())};
    }
  }
  const int one = 1;
  ::setsockopt(fd.get(), IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  return fd;
}

Status send_all(const Fd& fd, std::span<const std::uint8_t> data, int timeout_ms) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  std::size_t sent = 0;
  while (sent < data.size()) {
    const ssize_t n = ::send(fd.get(), data.data() + sent, data.size() - sent, MSG_NOSIGNAL);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) return Error{system_error("send")};
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return Error{"send: timed out"};
    pollfd p{fd.get(), POLLOUT, 0};
    ::poll(&p, 1, static_cast<int>(left.count()));
  }
  return Ok{};
}

Status send_all(const Fd& fd, std::string_view text, int timeout_ms) {
  return send_all(fd, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()}, timeout_ms);
}

WakePipe::WakePipe() {
  int fds[2] = {-1, -1};
  if (::pipe(fds) == 0) {
    read_ = Fd(fds[0]);
    write_ = Fd(fds[1]);
    (void)set_nonblocking(fds[0]);
    (void)set_nonblocking(fds[1]);
  }
}

void WakePipe::wake() const {
  const char c = 1;
  [[maybe_unused]] const ssize_t n = ::write(write_.get(), &c, 1);
}

void WakePipe::drain() const {
  char buffer[64];
  while (::read(read_.get(), buffer, sizeof buffer) > 0) {
  }
}

}  // namespace canyon::net
