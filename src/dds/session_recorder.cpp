// In-process MCAP recording (see session_recorder.hpp).

#include "canyon/dds/session_recorder.hpp"

#include <chrono>
#include <ctime>
#include <memory>
#include <utility>

#include "canyon/dds/raw_samples.hpp"

namespace canyon::dds {

std::int64_t thread_cpu_ns() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<std::int64_t>(t.tv_sec) * 1000000000LL + t.tv_nsec;
}

Result<std::unique_ptr<SessionRecorder>> SessionRecorder::create(const std::string& path,
                                                                 const io::McapWriterOptions& options) {
  auto writer = io::McapWriter::create(path, options);
  if (!writer) return writer.error();
  return std::unique_ptr<SessionRecorder>(new SessionRecorder(std::move(*writer), path));
}

Result<std::uint16_t> SessionRecorder::channel(const std::string& topic, const std::string& type_name) {
  const auto known = recorded_type(type_name);
  if (!known) return Error{"cannot record topic '" + topic + "': no IDL of its type " + type_name, path_, 0};
  const std::lock_guard lock(mutex_);
  auto schema = schemas_.find(type_name);
  if (schema == schemas_.end()) {
    auto added = writer_.add_schema(type_name, "omgidl", known->schema);
    if (!added) return added.error();
    schema = schemas_.emplace(type_name, *added).first;
  }
  auto id = writer_.add_channel(schema->second, topic, "cdr");
  if (!id) return id.error();
  if (sequences_.size() <= *id) sequences_.resize(*id + 1U, 0);
  return *id;
}

Status SessionRecorder::record(std::uint16_t channel, std::vector<std::uint8_t> bytes, std::uint64_t publish_time_ns) {
  const auto now = std::chrono::system_clock::now().time_since_epoch();
  const auto ns = static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(now).count());
  const std::lock_guard lock(mutex_);
  if (closed_ || !status_ || channel >= sequences_.size()) return status_;
  io::McapMessage m;
  m.channel_id = channel;
  m.sequence = sequences_[channel]++;
  m.log_time_ns = ns;
  m.publish_time_ns = publish_time_ns != 0 ? publish_time_ns : ns;
  m.data = std::move(bytes);
  status_ = writer_.write(m);
  return status_;
}

Status SessionRecorder::close() {
  const std::lock_guard lock(mutex_);
  if (closed_) return status_;
  closed_ = true;
  const Status closed = writer_.close();
  if (status_ && !closed) status_ = closed;
  return status_;
}

std::uint64_t SessionRecorder::messages() const {
  const std::lock_guard lock(mutex_);
  return writer_.messages();
}

std::uint64_t SessionRecorder::bytes() const {
  const std::lock_guard lock(mutex_);
  return writer_.bytes();
}

}  // namespace canyon::dds
