// TCP / NTRIP stream client with reconnection and stall detection (see stream_client.hpp).

#include "canyon/net/stream_client.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>

#include <poll.h>
#include <sys/socket.h>

#include "canyon/net/socket.hpp"

namespace canyon::net {
namespace {

using Clock = std::chrono::steady_clock;
constexpr int kPollSliceMs = 100;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

/// Reads a response header (and what follows it) within `timeout_ms`.
Result<std::pair<std::string, std::string>> read_header(const Fd& fd, int timeout_ms,
                                                        const std::atomic<bool>* running) {
  std::string data;
  const auto start = Clock::now();
  char buffer[2048];
  for (;;) {
    if (const auto end = header_end(data)) return std::make_pair(data.substr(0, *end), data.substr(*end));
    // NTRIP 1 casters (RTKLIB's str2str among them) may send "ICY 200 OK" and a single line end before the data.
    constexpr std::string_view kIcy = "ICY 200 OK\r\n";
    if (data.size() >= kIcy.size() + 2 && data.compare(0, kIcy.size(), kIcy) == 0) {
      const std::size_t skip = data.compare(kIcy.size(), 2, "\r\n") == 0 ? kIcy.size() + 2 : kIcy.size();
      return std::make_pair(std::string(kIcy) + "\r\n", data.substr(skip));
    }
    if (data.size() > kMaxHeaderBytes) return Error{"response header longer than " + std::to_string(kMaxHeaderBytes)};
    if (running != nullptr && !running->load()) return Error{"stopped"};
    if (seconds_since(start) * 1000.0 > timeout_ms) {
      return Error{data.empty() ? "no response within " + std::to_string(timeout_ms) + " ms"
                                : "incomplete response header within " + std::to_string(timeout_ms) + " ms"};
    }
    pollfd p{fd.get(), POLLIN, 0};
    ::poll(&p, 1, kPollSliceMs);
    const ssize_t n = ::recv(fd.get(), buffer, sizeof buffer, 0);
    if (n == 0) {
      // An NTRIP 1 source table may end with the connection instead of a blank line after its header.
      if (data.rfind("SOURCETABLE", 0) == 0) return std::make_pair(data, std::string());
      return Error{data.empty() ? "connection closed without a response" : "connection closed inside the response"};
    }
    if (n < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) continue;
      return Error{std::string("recv: ") + std::strerror(errno)};
    }
    data.append(buffer, static_cast<std::size_t>(n));
  }
}

}  // namespace

std::string StreamClientOptions::validate() const {
  if (host.empty()) return "host is required";
  if (port < 1 || port > 65535) return "port must be within 1-65535";
  if (mode == Mode::Ntrip && mount.empty()) return "NTRIP needs a mount point";
  if (ntrip_version != 1 && ntrip_version != 2) return "NTRIP version must be 1 or 2";
  if (!(stall_timeout_s > 0.0)) return "stall timeout must be > 0 s";
  if (!(backoff_min_s > 0.0) || backoff_max_s < backoff_min_s) return "back-off must satisfy 0 < min <= max";
  if (gga_interval_s < 0.0) return "GGA interval must be >= 0 s";
  return {};
}

StreamClient::StreamClient(StreamClientOptions options, DataFn on_data, EventFn on_event)
    : options_(std::move(options)), on_data_(std::move(on_data)), on_event_(std::move(on_event)) {}

StreamClient::~StreamClient() {
  stop();
}

Status StreamClient::start() {
  if (const std::string e = options_.validate(); !e.empty()) return Error{"stream client: " + e};
  if (running_.exchange(true)) return Ok{};
  finished_ = false;
  thread_ = std::thread([this] { run(); });
  return Ok{};
}

void StreamClient::stop() {
  running_ = false;
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  finished_ = true;
}

void StreamClient::set_gga(std::string sentence) {
  const std::lock_guard lock(mutex_);
  options_.gga = std::move(sentence);
}

StreamClientStats StreamClient::stats() const {
  const std::lock_guard lock(mutex_);
  return stats_;
}

void StreamClient::fail(const std::string& why) {
  {
    const std::lock_guard lock(mutex_);
    ++stats_.failures;
    stats_.last_error = why;
  }
  if (on_event_) on_event_(why);
}

void StreamClient::sleep_interruptible(double seconds) {
  std::unique_lock lock(mutex_);
  wake_.wait_for(lock, std::chrono::duration<double>(seconds), [this] { return !running_.load(); });
}

void StreamClient::run() {
  double backoff_s = options_.backoff_min_s;
  int failed_in_a_row = 0;
  while (running_.load()) {
    if (session()) {
      backoff_s = options_.backoff_min_s;
      failed_in_a_row = 0;
    } else {
      ++failed_in_a_row;
    }
    if (!running_.load()) break;
    if (options_.max_attempts > 0 && failed_in_a_row >= options_.max_attempts) {
      if (on_event_) on_event_("giving up after " + std::to_string(failed_in_a_row) + " failed attempts");
      break;
    }
    if (on_event_) {
      char text[64];
      std::snprintf(text, sizeof text, "reconnecting in %.1f s", backoff_s);
      on_event_(text);
    }
    sleep_interruptible(backoff_s);
    backoff_s = std::min(2.0 * backoff_s, options_.backoff_max_s);
  }
  finished_ = true;
}

bool StreamClient::start_ntrip(const Fd& fd, const std::string& where, std::vector<std::uint8_t>& data,
                               ChunkedDecoder& chunked, bool& is_chunked) {
  ClientRequestOptions r;
  r.host = options_.host;
  r.port = options_.port;
  r.mount = options_.mount;
  r.version = options_.ntrip_version;
  r.user = options_.user;
  r.password = options_.password;
  if (Status s = send_all(fd, format_ntrip_request(r), options_.connect_timeout_ms); !s.ok()) {
    fail(where + ": " + s.error().message);
    return false;
  }
  auto header = read_header(fd, options_.connect_timeout_ms, &running_);
  if (!header) {
    fail(where + ": " + header.error().message);
    return false;
  }
  auto response = parse_ntrip_response(header->first);
  if (!response) {
    fail(where + ": " + response.error().message);
    return false;
  }
  switch (response->kind) {
    case NtripResponse::Kind::Data: break;
    case NtripResponse::Kind::SourceTable:
      fail(where + ": the caster answered with its source table (mount point unknown)");
      return false;
    case NtripResponse::Kind::Unauthorized: fail(where + ": 401 unauthorized (user/password)"); return false;
    case NtripResponse::Kind::NotFound: fail(where + ": 404 mount point not found"); return false;
    case NtripResponse::Kind::Error: fail(where + ": caster answered '" + response->status_line + "'"); return false;
  }
  is_chunked = response->chunked;
  const std::string& rest = header->second;
  const std::span<const std::uint8_t> first(reinterpret_cast<const std::uint8_t*>(rest.data()), rest.size());
  if (!is_chunked) {
    data.assign(first.begin(), first.end());
    return true;
  }
  if (Status s = chunked.feed(first, data); !s.ok()) {
    fail(where + ": " + s.error().message);
    return false;
  }
  return true;
}

bool StreamClient::upload_gga_if_due(const Fd& fd, const std::string& where, Clock::time_point& last_gga) {
  std::string line;
  if (options_.mode == StreamClientOptions::Mode::Ntrip && options_.gga_interval_s > 0.0 &&
      seconds_since(last_gga) >= options_.gga_interval_s) {
    const std::lock_guard lock(mutex_);
    line = options_.gga;
  }
  if (line.empty()) return true;
  if (line.size() < 2 || line.substr(line.size() - 2) != "\r\n") line += "\r\n";
  if (Status s = send_all(fd, line, options_.connect_timeout_ms); !s.ok()) {
    fail(where + ": GGA upload: " + s.error().message);
    return false;
  }
  const std::lock_guard lock(mutex_);
  ++stats_.gga_sent;
  last_gga = Clock::now();
  return true;
}

void StreamClient::deliver(std::vector<std::uint8_t>& data, bool& delivered) {
  if (!delivered) {
    const std::lock_guard lock(mutex_);
    ++stats_.connections;
  }
  delivered = true;
  {
    const std::lock_guard lock(mutex_);
    stats_.bytes += data.size();
  }
  on_data_(data);
  data.clear();
}

bool StreamClient::session() {
  const std::string where = options_.host + ":" + std::to_string(options_.port) +
                            (options_.mode == StreamClientOptions::Mode::Ntrip ? "/" + options_.mount : "");
  auto fd = tcp_connect(options_.host, options_.port, options_.connect_timeout_ms);
  if (!fd) {
    fail(fd.error().message);
    return false;
  }
  std::vector<std::uint8_t> data;
  ChunkedDecoder chunked;
  bool is_chunked = false;
  if (options_.mode == StreamClientOptions::Mode::Ntrip && !start_ntrip(*fd, where, data, chunked, is_chunked)) {
    return false;
  }
  if (on_event_) on_event_("connected to " + where);
  bool delivered = false;
  auto last_data = Clock::now();
  auto last_gga = Clock::now() - std::chrono::hours(1);
  char buffer[16384];
  while (running_.load()) {
    if (!data.empty()) {
      deliver(data, delivered);
      last_data = Clock::now();
    }
    if (!upload_gga_if_due(*fd, where, last_gga)) return delivered;
    if (seconds_since(last_data) > options_.stall_timeout_s) {
      {
        const std::lock_guard lock(mutex_);
        ++stats_.stalls;
      }
      char text[96];
      std::snprintf(text, sizeof text, ": no data for %.1f s (stall)", options_.stall_timeout_s);
      fail(where + text);
      return delivered;
    }
    pollfd p{fd->get(), POLLIN, 0};
    ::poll(&p, 1, kPollSliceMs);
    const ssize_t n = ::recv(fd->get(), buffer, sizeof buffer, 0);
    if (n == 0) {
      fail(where + ": connection closed by the peer");
      return delivered;
    }
    if (n < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) continue;
      fail(where + ": recv: " + std::strerror(errno));
      return delivered;
    }
    const std::span<const std::uint8_t> got(reinterpret_cast<const std::uint8_t*>(buffer), static_cast<std::size_t>(n));
    if (!is_chunked) {
      data.insert(data.end(), got.begin(), got.end());
      continue;
    }
    if (Status s = chunked.feed(got, data); !s.ok()) {
      fail(where + ": " + s.error().message);
      return delivered;
    }
    if (chunked.finished()) {
      if (!data.empty()) on_data_(data);
      fail(where + ": the caster ended the stream");
      return delivered;
    }
  }
  return delivered;
}

Result<std::vector<MountPoint>> fetch_source_table(const std::string& host, int port, int ntrip_version,
                                                   int timeout_ms) {
  auto fd = tcp_connect(host, port, timeout_ms);
  if (!fd) return fd.error();
  ClientRequestOptions r;
  r.host = host;
  r.port = port;
  r.version = ntrip_version;
  if (Status s = send_all(*fd, format_ntrip_request(r), timeout_ms); !s.ok()) return s.error();
  auto header = read_header(*fd, timeout_ms, nullptr);
  if (!header) return header.error();
  auto response = parse_ntrip_response(header->first);
  if (!response) return response.error();
  if (response->kind != NtripResponse::Kind::SourceTable) {
    return Error{host + ":" + std::to_string(port) + ": no source table ('" + response->status_line + "')"};
  }
  std::string body = header->second;
  const auto start = Clock::now();
  char buffer[4096];
  while (body.find("ENDSOURCETABLE") == std::string::npos && seconds_since(start) * 1000.0 < timeout_ms) {
    pollfd p{fd->get(), POLLIN, 0};
    ::poll(&p, 1, kPollSliceMs);
    const ssize_t n = ::recv(fd->get(), buffer, sizeof buffer, 0);
    if (n == 0) break;
    if (n > 0) body.append(buffer, static_cast<std::size_t>(n));
  }
  return parse_source_table(body);
}

}  // namespace canyon::net
