#pragma once
// A server that fans one byte stream out to every connected client: a plain TCP server (clients get the bytes as
// soon as they connect), or an NTRIP caster (versions 1 and 2) serving streams by mount point, with the source
// table and optional Basic authentication. One thread runs a poll() loop; publish() may be called from any thread.
//
// Every client has its own send buffer: a client that cannot keep up (buffer beyond max_client_buffer_bytes) is
// disconnected rather than slowing the others down. NTRIP clients may send NMEA GGA sentences upstream (network
// RTK); the last one of each client is kept and logged.

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "canyon/core/result.hpp"
#include "canyon/net/ntrip.hpp"
#include "canyon/net/socket.hpp"

namespace canyon::net {

struct StreamServerOptions {
  enum class Mode : std::uint8_t { Tcp, Ntrip };
  Mode mode = Mode::Tcp;
  std::string bind_host = "0.0.0.0";
  int port = 0;                    ///< 0: any free port (see StreamServer::port())
  std::vector<MountPoint> mounts;  ///< NTRIP: the mount points served
  std::string user;                ///< NTRIP: empty, no authentication; else Basic user:password
  std::string password;
  std::size_t max_client_buffer_bytes = 1 << 20;  ///< a slower client is disconnected
  int max_clients = 64;
  int handshake_timeout_ms = 5000;  ///< NTRIP: the request header must arrive within this time

  /// Empty if valid, else the violated rule.
  [[nodiscard]] std::string validate() const;
};

struct StreamServerStats {
  int clients = 0;                 ///< connected (streaming) now
  std::uint64_t connections = 0;   ///< accepted in total
  std::uint64_t refused = 0;       ///< NTRIP: bad request, unknown mount point, wrong credentials, too many
  std::uint64_t dropped_slow = 0;  ///< disconnected because their buffer overflowed
  std::uint64_t bytes_sent = 0;
  std::uint64_t gga_received = 0;
  std::size_t pending_bytes = 0;  ///< queued for clients, not sent yet
};

class StreamServer {
 public:
  /// Binds and starts serving. Error naming the address if the port cannot be bound or the options are invalid.
  static Result<std::unique_ptr<StreamServer>> start(StreamServerOptions options);
  ~StreamServer();
  StreamServer(const StreamServer&) = delete;
  StreamServer& operator=(const StreamServer&) = delete;

  /// The bound port.
  [[nodiscard]] int port() const { return port_; }
  /// Sends `bytes` to every client of `mount` (TCP mode: to every client; the mount is ignored).
  void publish(const std::string& mount, std::span<const std::uint8_t> bytes);
  [[nodiscard]] StreamServerStats stats() const;
  /// Events since the last call ("127.0.0.1:40412 connected to /CANYON (NTRIP 1)", "... refused: 401"), oldest
  /// first.
  std::vector<std::string> take_events();
  /// Stops the loop and closes every connection (also done by the destructor).
  void stop();

 private:
  struct Client;
  explicit StreamServer(StreamServerOptions options, Fd listener);
  void run();
  void accept_clients();
  void handle_input(Client& c);
  void handshake(Client& c);
  void event(std::string text);

  StreamServerOptions options_;
  Fd listener_;
  int port_ = 0;
  WakePipe wake_;
  mutable std::mutex mutex_;  // guards clients_ output buffers, stats_, events_
  std::vector<std::unique_ptr<Client>> clients_;
  StreamServerStats stats_;
  std::vector<std::string> events_;
  std::atomic<bool> running_{true};
  std::thread thread_;
};

}  // namespace canyon::net
