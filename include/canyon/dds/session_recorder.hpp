#pragma once
// An MCAP session being recorded: a channel per topic with its type's OMG IDL schema (raw_samples.hpp,
// recorded_type; each schema once), a sequence per channel, thread-safe. canyon record writes the samples it takes
// off the wire into one; canyon rover (dds.record) writes what its DdsWriters publish, each sample serialized with
// the writer's own type support (the same CDR bytes as on the wire, encapsulation header included) on the writer's
// thread, by the writer's type, so renamed topics are recorded too: no DDS reader and no second process, so what
// recording costs is the serialization and the file (measured: the thread CPU time the writers report, cpu_ns()).

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "canyon/core/result.hpp"
#include "canyon/io/mcap.hpp"

namespace canyon::dds {

class SessionRecorder {
 public:
  /// Creates the MCAP file (options: compression and chunk size); Error naming it.
  static Result<std::unique_ptr<SessionRecorder>> create(const std::string& path, const io::McapWriterOptions& options);
  SessionRecorder(const SessionRecorder&) = delete;
  SessionRecorder& operator=(const SessionRecorder&) = delete;
  ~SessionRecorder() = default;

  /// The channel of `topic`, whose samples are of DDS type `type_name` (its schema by recorded_type()); Error for a
  /// type canyon does not publish.
  Result<std::uint16_t> channel(const std::string& topic, const std::string& type_name);
  /// One sample's serialized bytes on `channel`, logged now; its publish time `publish_time_ns` (ns since the UNIX
  /// epoch; 0: now). Thread-safe. The first write error, kept (and returned again) until close().
  Status record(std::uint16_t channel, std::vector<std::uint8_t> bytes, std::uint64_t publish_time_ns = 0);
  /// Adds `ns` of thread CPU time to what recording cost (the writers time their serialization and record()).
  void add_cpu_ns(std::int64_t ns) { cpu_ns_.fetch_add(ns); }
  /// Writes the summary and closes the file; the first write error, if any.
  Status close();

  [[nodiscard]] std::uint64_t messages() const;
  [[nodiscard]] std::uint64_t bytes() const;
  [[nodiscard]] std::int64_t cpu_ns() const { return cpu_ns_.load(); }
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  SessionRecorder(io::McapWriter writer, std::string path) : writer_(std::move(writer)), path_(std::move(path)) {}

  mutable std::mutex mutex_;
  io::McapWriter writer_;
  std::string path_;
  std::vector<std::uint32_t> sequences_;          ///< per channel id
  std::map<std::string, std::uint16_t> schemas_;  ///< schema id per type name (each schema written once)
  Status status_ = Ok{};
  bool closed_ = false;
  std::atomic<std::int64_t> cpu_ns_{0};
};

/// The calling thread's CPU time (ns).
[[nodiscard]] std::int64_t thread_cpu_ns();

}  // namespace canyon::dds
