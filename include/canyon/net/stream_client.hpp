#pragma once
// A client that keeps a byte stream coming: plain TCP, or NTRIP (version 2 headers by default, version 1 on
// request) from a caster's mount point. It runs on its own thread and survives the network:
//  - reconnection with exponential back-off (backoff_min_s doubling up to backoff_max_s, back to the minimum once a
//    connection delivered data);
//  - stall detection: no byte for stall_timeout_s closes the connection and reconnects;
//  - NTRIP: GGA upload every gga_interval_s (network RTK), the response checked (401, 404, source table instead of
//    data are reported), chunked transfer coding of version 2 decoded.
// Data and events go to callbacks on the client's thread.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "canyon/core/result.hpp"
#include "canyon/net/ntrip.hpp"
#include "canyon/net/socket.hpp"

namespace canyon::net {

struct StreamClientOptions {
  enum class Mode : std::uint8_t { Tcp, Ntrip };
  Mode mode = Mode::Ntrip;
  std::string host = "127.0.0.1";
  int port = 2101;
  // NTRIP.
  std::string mount;
  std::string user;
  std::string password;
  int ntrip_version = 2;
  double gga_interval_s = 0.0;  ///< 0: no GGA upload
  std::string gga;              ///< the sentence to upload (e.g. the rover's approximate position); empty: none until
                                ///< set_gga() gives one
  // Robustness.
  int connect_timeout_ms = 5000;
  double stall_timeout_s = 10.0;
  double backoff_min_s = 1.0;
  double backoff_max_s = 60.0;
  int max_attempts = 0;  ///< stop after this many failed attempts in a row (0: never)

  [[nodiscard]] std::string validate() const;
};

struct StreamClientStats {
  std::uint64_t connections = 0;  ///< successful (data flowing)
  std::uint64_t failures = 0;     ///< failed attempts (connect, refused, stall, lost)
  std::uint64_t stalls = 0;
  std::uint64_t bytes = 0;
  std::uint64_t gga_sent = 0;
  std::string last_error;
};

class StreamClient {
 public:
  using DataFn = std::function<void(std::span<const std::uint8_t>)>;
  using EventFn = std::function<void(const std::string&)>;

  StreamClient(StreamClientOptions options, DataFn on_data, EventFn on_event = {});
  ~StreamClient();
  StreamClient(const StreamClient&) = delete;
  StreamClient& operator=(const StreamClient&) = delete;

  /// Starts the thread (Error if the options are invalid).
  Status start();
  /// Stops it (within about 100 ms) and waits.
  void stop();
  /// The GGA sentence to upload from now on (the rover's latest position; thread-safe).
  void set_gga(std::string sentence);
  /// Whether the thread gave up (max_attempts) or was stopped.
  [[nodiscard]] bool finished() const { return finished_.load(); }
  [[nodiscard]] StreamClientStats stats() const;

 private:
  void run();
  /// One connection, until it fails or stop(); true if it delivered data.
  bool session();
  /// The NTRIP request and the caster's answer; the data that came with it into `data`. False (reported) on failure.
  bool start_ntrip(const Fd& fd, const std::string& where, std::vector<std::uint8_t>& data, ChunkedDecoder& chunked,
                   bool& is_chunked);
  /// The rover's GGA to the caster when the interval is due; false (reported) if the upload failed.
  bool upload_gga_if_due(const Fd& fd, const std::string& where, std::chrono::steady_clock::time_point& last_gga);
  /// `data` to the callback, counted.
  void deliver(std::vector<std::uint8_t>& data, bool& delivered);
  void fail(const std::string& why);
  void sleep_interruptible(double seconds);

  StreamClientOptions options_;
  DataFn on_data_;
  EventFn on_event_;
  std::atomic<bool> running_{false};
  std::atomic<bool> finished_{false};
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  StreamClientStats stats_;
  std::thread thread_;
};

/// Fetches a caster's source table (one request, no retry).
Result<std::vector<MountPoint>> fetch_source_table(const std::string& host, int port, int ntrip_version,
                                                   int timeout_ms = 5000);

}  // namespace canyon::net
