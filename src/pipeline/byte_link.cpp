// Byte links: file, serial, TCP, NTRIP (see byte_link.hpp).

#include "canyon/pipeline/byte_link.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <mutex>

#include "canyon/io/gnss_stream.hpp"
#include "canyon/net/serial_port.hpp"
#include "canyon/net/stream_client.hpp"

namespace canyon::pipeline {
namespace {

constexpr std::size_t kFileChunkBytes = 4096;

const char* const kForms =
    "file:PATH, serial:///dev/DEVICE?baud=N, tcp://HOST:PORT or ntrip://[USER[:PASSWORD]@]HOST:PORT/MOUNT";

Result<LinkAddress> parse_serial(LinkAddress a) {
  std::string rest = a.text.substr(std::string("serial://").size());
  const std::size_t query = rest.find('?');
  if (query != std::string::npos) {
    const std::string option = rest.substr(query + 1);
    rest = rest.substr(0, query);
    if (option.rfind("baud=", 0) != 0) return Error{"'" + a.text + "': the only serial option is ?baud=N"};
    try {
      std::size_t used = 0;
      a.baud = std::stoi(option.substr(5), &used);
      if (used != option.size() - 5) throw std::invalid_argument(option);
    } catch (const std::exception&) {
      return Error{"'" + a.text + "': baud must be a number"};
    }
  }
  if (rest.empty() || rest.front() != '/') return Error{"'" + a.text + "' is not serial:///dev/DEVICE?baud=N"};
  a.kind = LinkAddress::Kind::Serial;
  a.path = rest;
  return a;
}

/// A file's bytes, handed out in chunks as fast as they are read.
class FileLink final : public ByteLink {
 public:
  FileLink(LinkAddress address, std::vector<std::uint8_t> bytes)
      : ByteLink(std::move(address)), bytes_(std::move(bytes)) {}
  Result<bool> read(std::vector<std::uint8_t>& out, int /*timeout_ms*/) override {
    if (next_ >= bytes_.size()) return false;
    const std::size_t n = std::min(kFileChunkBytes, bytes_.size() - next_);
    out.insert(out.end(), bytes_.begin() + static_cast<std::ptrdiff_t>(next_),
               bytes_.begin() + static_cast<std::ptrdiff_t>(next_ + n));
    next_ += n;
    stats_.bytes += n;
    return true;
  }
  [[nodiscard]] LinkStats stats() const override { return stats_; }

 private:
  std::vector<std::uint8_t> bytes_;
  std::size_t next_ = 0;
  LinkStats stats_;
};

class SerialLink final : public ByteLink {
 public:
  SerialLink(LinkAddress address, net::SerialPort port) : ByteLink(std::move(address)), port_(std::move(port)) {}
  Result<bool> read(std::vector<std::uint8_t>& out, int timeout_ms) override {
    std::uint8_t buffer[kFileChunkBytes];
    auto n = port_.read(buffer, timeout_ms);
    if (!n) return Error{"serial link failed: " + n.error().message, address().text, 0};
    out.insert(out.end(), buffer, buffer + *n);
    stats_.bytes += *n;
    return true;
  }
  [[nodiscard]] LinkStats stats() const override { return stats_; }

 private:
  net::SerialPort port_;
  LinkStats stats_;
};

/// TCP or NTRIP through net::StreamClient: its thread queues what arrives, read() takes it.
class NetworkLink final : public ByteLink {
 public:
  NetworkLink(LinkAddress address, const LinkOptions& options, LogFn log)
      : ByteLink(std::move(address)),
        max_queued_(options.max_queued_bytes),
        log_(std::move(log)),
        client_(
            client_options(this->address(), options), [this](std::span<const std::uint8_t> b) { on_data(b); },
            [this](const std::string& e) {
              if (log_) log_(e.rfind("connected to", 0) != 0, this->address().text + ": " + e);
            }) {}
  ~NetworkLink() override { client_.stop(); }
  NetworkLink(const NetworkLink&) = delete;
  NetworkLink& operator=(const NetworkLink&) = delete;

  Status start() { return client_.start(); }

  Result<bool> read(std::vector<std::uint8_t>& out, int timeout_ms) override {
    std::unique_lock lock(mutex_);
    arrived_.wait_for(lock, std::chrono::milliseconds(timeout_ms), [this] { return !queue_.empty(); });
    if (queue_.empty() && client_.finished()) {
      const std::string why = client_.stats().last_error;
      return Error{"link lost: gave up reconnecting" + (why.empty() ? std::string() : " (last: " + why + ")"),
                   address().text, 0};
    }
    for (const auto& chunk : queue_) {
      out.insert(out.end(), chunk.begin(), chunk.end());
      bytes_ += chunk.size();
    }
    queue_.clear();
    queued_ = 0;
    return true;
  }

  void set_gga(const std::string& sentence) override { client_.set_gga(sentence); }

  [[nodiscard]] LinkStats stats() const override {
    const net::StreamClientStats c = client_.stats();
    const std::lock_guard lock(mutex_);
    return LinkStats{bytes_, dropped_, c.connections, c.failures};
  }

 private:
  static net::StreamClientOptions client_options(const LinkAddress& a, const LinkOptions& options) {
    net::StreamClientOptions o;
    o.mode = a.kind == LinkAddress::Kind::Ntrip ? net::StreamClientOptions::Mode::Ntrip
                                                : net::StreamClientOptions::Mode::Tcp;
    o.host = a.url.host;
    o.port = a.url.port;
    o.mount = a.url.mount;
    o.user = a.url.user;
    o.password = a.url.password;
    o.max_attempts = options.attempts;
    o.stall_timeout_s = options.stall_timeout_s;
    o.backoff_min_s = options.backoff_min_s;
    o.backoff_max_s = options.backoff_max_s;
    o.gga_interval_s = options.gga_interval_s;
    return o;
  }

  void on_data(std::span<const std::uint8_t> bytes) {
    {
      const std::lock_guard lock(mutex_);
      if (queued_ + bytes.size() > max_queued_) {
        dropped_ += bytes.size();
        return;
      }
      queue_.emplace_back(bytes.begin(), bytes.end());
      queued_ += bytes.size();
    }
    arrived_.notify_one();
  }

  std::size_t max_queued_;
  LogFn log_;
  mutable std::mutex mutex_;
  std::condition_variable arrived_;
  std::deque<std::vector<std::uint8_t>> queue_;
  std::size_t queued_ = 0;
  std::uint64_t bytes_ = 0;
  std::uint64_t dropped_ = 0;
  net::StreamClient client_;  // last: its thread calls on_data, which uses the members above
};

}  // namespace

Result<LinkAddress> LinkAddress::parse(const std::string& text, const std::string& folder) {
  LinkAddress a;
  a.text = text;
  if (text.rfind("file:", 0) == 0) {
    a.path = text.substr(5);
    if (a.path.empty()) return Error{"'" + text + "': file: needs a path"};
    if (!folder.empty() && std::filesystem::path(a.path).is_relative()) {
      a.path = (std::filesystem::path(folder) / a.path).lexically_normal().string();
    }
    return a;
  }
  if (text.rfind("serial://", 0) == 0) return parse_serial(std::move(a));
  auto url = net::parse_stream_url(text);
  if (!url) return url.error();
  if (!*url) return Error{"'" + text + "' is not a link address: " + kForms};
  a.kind = (*url)->ntrip ? Kind::Ntrip : Kind::Tcp;
  a.url = **url;
  if (!a.url.password.empty()) {  // logs and messages do not show it
    const std::string secret = ":" + a.url.password + "@";
    if (const std::size_t at = a.text.find(secret); at != std::string::npos) a.text.replace(at, secret.size(), ":***@");
  }
  return a;
}

std::string LinkOptions::validate() const {
  if (attempts < 0) return "attempts must be >= 0";
  if (!(stall_timeout_s > 0.0)) return "stall_timeout_s must be > 0";
  if (!(backoff_min_s > 0.0 && backoff_max_s >= backoff_min_s)) return "backoff_min_s must be > 0 and <= backoff_max_s";
  if (max_queued_bytes < 4096) return "max_queued_bytes must be >= 4096";
  if (!(gga_interval_s >= 0.0)) return "gga_interval_s must be >= 0";
  return {};
}

Result<std::unique_ptr<ByteLink>> ByteLink::open(const LinkAddress& address, const LinkOptions& options, LogFn log) {
  if (const std::string e = options.validate(); !e.empty()) return Error{"link options: " + e, address.text, 0};
  switch (address.kind) {
    case LinkAddress::Kind::File: {
      std::string warning;
      auto bytes = io::read_binary_file(address.path, &warning);
      if (!bytes) return bytes.error();
      if (!warning.empty() && log) log(true, warning);
      return std::unique_ptr<ByteLink>(std::make_unique<FileLink>(address, std::move(*bytes)));
    }
    case LinkAddress::Kind::Serial: {
      auto port = net::SerialPort::open(address.path, address.baud);
      if (!port) return port.error();
      return std::unique_ptr<ByteLink>(std::make_unique<SerialLink>(address, std::move(*port)));
    }
    case LinkAddress::Kind::Tcp:
    case LinkAddress::Kind::Ntrip: {
      auto link = std::make_unique<NetworkLink>(address, options, std::move(log));
      if (Status s = link->start(); !s) return Error{s.error().message, address.text, 0};
      return std::unique_ptr<ByteLink>(std::move(link));
    }
  }
  return Error{"unknown link kind", address.text, 0};
}

}  // namespace canyon::pipeline
