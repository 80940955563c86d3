#pragma once
// The base station of `canyon base` without its DDS output: reads the base receiver (RINEX replayed at a pace, UBX
// or RTCM 3 from a file, a serial port, a TCP or NTRIP source), turns every epoch into RTCM 3 (MSM, 1005/1006 and
// 1033 at the station interval, ephemerides when current and at the ephemeris interval; see
// io/rtcm3_station_stream.hpp) and sends the frames to the NTRIP caster and TCP server it runs, and to the sinks
// added (canyon-base adds the DDS writer, pipeline/rtcm_publisher.hpp).
//
// Input edge cases: a file ends the run (after the outputs have sent everything, at most flush_timeout_s); a network
// source reconnects (net::StreamClient); a serial device that fails ends the run with its error. Undecodable
// frames and packets are counted and logged, never fatal.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/config/base_config.hpp"
#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/core/time.hpp"

namespace canyon::base {

/// One RTCM 3 frame as the base sends it.
struct BaseFrame {
  std::uint64_t sequence = 0;  ///< 0, 1, 2 ... per base run
  int message_number = 0;
  int station_id = 0;
  std::optional<core::GpsTime> epoch_time;  ///< the observation epoch it was sent with
  std::vector<std::uint8_t> bytes;          ///< the whole frame
  core::PipelineNs receive_ns = 0;          ///< when the epoch's input data was read (pipeline clock)
};
using BaseFrameSink = std::function<void(const BaseFrame&)>;

struct BaseStationStats {
  std::uint64_t epochs = 0;
  std::uint64_t frames = 0;
  std::uint64_t bytes = 0;
  std::uint64_t input_problems = 0;  ///< bad frames/packets, undecodable messages
  int ntrip_clients = 0;
  int tcp_clients = 0;
  std::optional<core::GpsTime> last_epoch;
};

class BaseStation {
 public:
  using LogFn = std::function<void(const std::string&)>;

  /// Checks the configuration, opens a file input, and starts the NTRIP caster and TCP server. Error naming what
  /// failed (file and line, address and port).
  static Result<std::unique_ptr<BaseStation>> create(config::BaseConfig config, LogFn log = {});
  ~BaseStation();
  BaseStation(const BaseStation&) = delete;
  BaseStation& operator=(const BaseStation&) = delete;

  /// Adds an output (before run()).
  void add_sink(BaseFrameSink sink);
  /// Counts subscribers of outputs that are not sockets (DDS readers), for wait_for_clients.
  void set_subscriber_count(std::function<int()> count);
  /// Waits until `clients` subscribers (NTRIP + TCP clients + set_subscriber_count()) are there, at most
  /// `timeout_s`, then kSettleS more: a DDS writer counts a reader as matched before the reader has matched the
  /// writer, and on a loaded machine the first frames of a volatile stream could otherwise miss it. False on timeout
  /// or stop().
  bool wait_for_clients(int clients, double timeout_s);
  static constexpr double kSettleS = 0.5;
  /// Runs until a file input ends, stop(), or a fatal input error (returned).
  Status run();
  /// Asks run() to return (thread-safe; async-signal-safe: it only sets a flag).
  void stop() { stop_requested_.store(true); }
  [[nodiscard]] bool stop_requested() const { return stop_requested_.load(); }

  [[nodiscard]] int ntrip_port() const;
  [[nodiscard]] int tcp_port() const;
  [[nodiscard]] BaseStationStats stats() const;
  [[nodiscard]] const config::BaseConfig& config() const { return config_; }

 private:
  struct Impl;
  BaseStation(config::BaseConfig config, LogFn log);
  void log(const std::string& text) const;
  void set_station(const Eigen::Vector3d& position_E_m);
  [[nodiscard]] int subscribers() const;
  void drain_server_events();
  /// Waits until a file epoch is due at the configured pace; false if stopped.
  bool pace(const core::GpsTime& t);
  Status emit(const core::ObsEpoch& epoch, core::PipelineNs receive_ns);
  void flush_outputs();
  Status run_rinex();
  Status run_bytes();

  config::BaseConfig config_;
  LogFn log_;
  std::atomic<bool> stop_requested_{false};
  std::unique_ptr<Impl> impl_;
};

}  // namespace canyon::base
