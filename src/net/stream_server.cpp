// TCP stream server and NTRIP caster (see stream_server.hpp).

#include "canyon/net/stream_server.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>

#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

namespace canyon::net {
namespace {

using Clock = std::chrono::steady_clock;
constexpr int kPollTimeoutMs = 200;
constexpr std::size_t kMaxUpstreamLine = 256;
constexpr std::size_t kMaxEvents = 1000;

}  // namespace

struct StreamServer::Client {
  enum class State : std::uint8_t { Handshake, Streaming };
  Fd fd;
  std::string peer;
  State state = State::Handshake;
  std::string in;  // handshake header, then upstream line
  std::string mount;
  int version = 1;
  std::string out;  // pending output
  std::size_t out_pos = 0;
  bool close_after_flush = false;
  bool closed = false;
  Clock::time_point connected = Clock::now();
  std::string last_gga;
};

std::string StreamServerOptions::validate() const {
  if (port < 0 || port > 65535) return "port must be within 0-65535";
  if (mode == Mode::Ntrip && mounts.empty()) return "an NTRIP caster needs at least one mount point";
  for (const MountPoint& m : mounts) {
    if (m.name.empty() || m.name.find_first_of(" /;\r\n") != std::string::npos) {
      return "mount point '" + m.name + "' is empty or has ' ', '/', ';'";
    }
  }
  if (max_clients < 1) return "max_clients must be >= 1";
  if (max_client_buffer_bytes < 1024) return "max_client_buffer_bytes must be >= 1024";
  return {};
}

Result<std::unique_ptr<StreamServer>> StreamServer::start(StreamServerOptions options) {
  if (const std::string e = options.validate(); !e.empty()) return Error{"stream server: " + e};
  auto listener = tcp_listen(options.bind_host, options.port);
  if (!listener) return listener.error();
  std::unique_ptr<StreamServer> server(new StreamServer(std::move(options), std::move(*listener)));
  server->thread_ = std::thread([s = server.get()] { s->run(); });
  return server;
}

StreamServer::StreamServer(StreamServerOptions options, Fd listener)
    : options_(std::move(options)), listener_(std::move(listener)), port_(local_port(listener_)) {}

StreamServer::~StreamServer() {
  stop();
}

void StreamServer::stop() {
  if (running_.exchange(false)) {
    wake_.wake();
  }
  if (thread_.joinable()) thread_.join();
  const std::lock_guard lock(mutex_);
  clients_.clear();
  listener_.reset();
}

void StreamServer::event(std::string text) {
  if (events_.size() < kMaxEvents) events_.push_back(std::move(text));
}

std::vector<std::string> StreamServer::take_events() {
  const std::lock_guard lock(mutex_);
  return std::exchange(events_, {});
}

StreamServerStats StreamServer::stats() const {
  const std::lock_guard lock(mutex_);
  StreamServerStats s = stats_;
  s.clients = static_cast<int>(std::count_if(clients_.begin(), clients_.end(), [](const auto& c) {
    return c->state == Client::State::Streaming && !c->closed;
  }));
  for (const auto& c : clients_) {
    if (!c->closed) s.pending_bytes += c->out.size() - c->out_pos;
  }
  return s;
}

void StreamServer::publish(const std::string& mount, std::span<const std::uint8_t> bytes) {
  if (bytes.empty()) return;
  {
    const std::lock_guard lock(mutex_);
    for (auto& c : clients_) {
      if (c->closed || c->close_after_flush || c->state != Client::State::Streaming) continue;
      if (options_.mode == StreamServerOptions::Mode::Ntrip && c->mount != mount) continue;
      if (c->out.size() - c->out_pos + bytes.size() > options_.max_client_buffer_bytes) {
        ++stats_.dropped_slow;
        event(c->peer + " disconnected: too slow (" + std::to_string(c->out.size() - c->out_pos) + " bytes not sent)");
        c->closed = true;
        continue;
      }
      if (c->version >= 2) {
        c->out += chunk(bytes);
      } else {
        c->out.append(reinterpret_cast<const char*>(bytes.data()), bytes.size());
      }
    }
  }
  wake_.wake();
}

void StreamServer::accept_clients() {
  for (;;) {
    Fd fd(::accept(listener_.get(), nullptr, nullptr));
    if (!fd.valid()) return;
    (void)set_nonblocking(fd.get());
    auto c = std::make_unique<Client>();
    c->peer = peer_name(fd);
    c->fd = std::move(fd);
    ++stats_.connections;
    const auto streaming = std::count_if(clients_.begin(), clients_.end(), [](const auto& x) { return !x->closed; });
    if (streaming >= options_.max_clients) {
      ++stats_.refused;
      event(c->peer + " refused: too many clients");
      if (options_.mode == StreamServerOptions::Mode::Ntrip) {
        c->out = format_error_response(1, 503, "Service Unavailable");
        c->close_after_flush = true;
      } else {
        c->closed = true;
      }
    } else if (options_.mode == StreamServerOptions::Mode::Tcp) {
      c->state = Client::State::Streaming;
      event(c->peer + " connected (TCP)");
    }
    clients_.push_back(std::move(c));
  }
}

void StreamServer::handshake(Client& c) {
  const auto end = header_end(c.in);
  if (!end) {
    if (c.in.size() > kMaxHeaderBytes) {
      ++stats_.refused;
      event(c.peer + " refused: request header too long");
      c.out = format_error_response(1, 400, "Bad Request");
      c.close_after_flush = true;
    }
    return;
  }
  const std::string header = c.in.substr(0, *end);
  std::string rest = c.in.substr(*end);
  c.in.clear();
  auto request = parse_ntrip_request(header);
  auto refuse = [&](int version, int status, const std::string& reason, const std::string& why) {
    ++stats_.refused;
    event(c.peer + " refused: " + std::to_string(status) + " " + why);
    c.out = format_error_response(version, status, reason);
    c.close_after_flush = true;
  };
  if (!request) {
    refuse(1, 400, "Bad Request", request.error().message);
    return;
  }
  const int version = request->version;
  if (request->method != "GET") {
    refuse(version, 501, "Not Implemented", request->method + ": canyon's caster takes no uploads");
    return;
  }
  const auto mount = std::find_if(options_.mounts.begin(), options_.mounts.end(),
                                  [&](const MountPoint& m) { return m.name == request->mount; });
  if (request->mount.empty() || (mount == options_.mounts.end() && version < 2)) {
    // The source table: asked for, or (NTRIP 1) the answer to an unknown mount point.
    c.out = format_source_table_response(version, format_source_table(options_.mounts));
    c.close_after_flush = true;
    event(c.peer + " got the source table" +
          (request->mount.empty() ? std::string() : " (unknown mount point /" + request->mount + ")"));
    if (!request->mount.empty()) ++stats_.refused;
    return;
  }
  if (mount == options_.mounts.end()) {
    refuse(version, 404, "Not Found", "unknown mount point /" + request->mount);
    return;
  }
  if (!options_.user.empty() &&
      (request->user.value_or("") != options_.user || request->password.value_or("") != options_.password)) {
    refuse(version, 401, "Unauthorized", "wrong or missing credentials for /" + request->mount);
    return;
  }
  c.mount = request->mount;
  c.version = version;
  c.state = Client::State::Streaming;
  c.out = format_data_response(version);
  event(c.peer + " connected to /" + c.mount + " (NTRIP " + std::to_string(version) + ", " +
        (request->user_agent.empty() ? "no user agent" : request->user_agent) + ")");
  if (!request->nmea.empty()) {
    ++stats_.gga_received;
    c.last_gga = request->nmea;
  }
  c.in = std::move(rest);
}

void StreamServer::handle_input(Client& c) {
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::recv(c.fd.get(), buffer, sizeof buffer, 0);
    if (n == 0) {
      if (c.state == Client::State::Streaming) event(c.peer + " disconnected");
      c.closed = true;
      return;
    }
    if (n < 0) {
      if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) c.closed = true;
      return;
    }
    if (c.close_after_flush) continue;  // the answer is on its way; ignore what follows
    if (c.state == Client::State::Handshake) {
      c.in.append(buffer, static_cast<std::size_t>(n));
      handshake(c);
      if (c.state != Client::State::Streaming) continue;
    } else {
      c.in.append(buffer, static_cast<std::size_t>(n));
    }
    // Upstream lines (GGA for network RTK); anything else is ignored.
    for (std::size_t nl = c.in.find('\n'); nl != std::string::npos; nl = c.in.find('\n')) {
      std::string line = c.in.substr(0, nl);
      c.in.erase(0, nl + 1);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (line.rfind("$G", 0) == 0 && line.find("GGA,") != std::string::npos) {
        if (c.last_gga.empty()) event(c.peer + " sends GGA: " + line.substr(0, 80));
        c.last_gga = line;
        ++stats_.gga_received;
      }
    }
    if (c.in.size() > kMaxUpstreamLine) c.in.clear();
  }
}

void StreamServer::run() {
  std::vector<pollfd> fds;
  while (running_.load()) {
    {
      const std::lock_guard lock(mutex_);
      fds.clear();
      fds.push_back({listener_.get(), POLLIN, 0});
      fds.push_back({wake_.read_fd(), POLLIN, 0});
      for (const auto& c : clients_) {
        const bool pending = c->out.size() > c->out_pos;
        fds.push_back({c->fd.get(), static_cast<short>(POLLIN | (pending ? POLLOUT : 0)), 0});
      }
    }
    ::poll(fds.data(), fds.size(), kPollTimeoutMs);
    if (!running_.load()) break;
    const std::lock_guard lock(mutex_);
    if ((fds[1].revents & POLLIN) != 0) wake_.drain();
    const std::size_t polled = fds.size() - 2;
    for (std::size_t i = 0; i < polled && i < clients_.size(); ++i) {
      Client& c = *clients_[i];
      const short revents = fds[i + 2].revents;
      if ((revents & (POLLIN | POLLHUP | POLLERR)) != 0) handle_input(c);
      // Write what is pending (also when POLLOUT was not asked for: publish() may have added output).
      while (!c.closed && c.out.size() > c.out_pos) {
        const ssize_t n = ::send(c.fd.get(), c.out.data() + c.out_pos, c.out.size() - c.out_pos, MSG_NOSIGNAL);
        if (n <= 0) {
          if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
            event(c.peer + " disconnected (send failed)");
            c.closed = true;
          }
          break;
        }
        c.out_pos += static_cast<std::size_t>(n);
        stats_.bytes_sent += static_cast<std::uint64_t>(n);
      }
      if (c.out_pos > 0 && c.out_pos == c.out.size()) {
        c.out.clear();
        c.out_pos = 0;
        if (c.close_after_flush) c.closed = true;
      }
      if (c.state == Client::State::Handshake && !c.close_after_flush &&
          Clock::now() - c.connected > std::chrono::milliseconds(options_.handshake_timeout_ms)) {
        ++stats_.refused;
        event(c.peer + " refused: no request within " + std::to_string(options_.handshake_timeout_ms) + " ms");
        c.closed = true;
      }
    }
    if ((fds[0].revents & POLLIN) != 0) accept_clients();
    std::erase_if(clients_, [](const auto& c) { return c->closed; });
  }
}

}  // namespace canyon::net
