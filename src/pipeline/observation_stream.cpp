// Observation input and base matching (see observation_stream.hpp).

#include "canyon/pipeline/observation_stream.hpp"

#include <chrono>
#include <fstream>
#include <iterator>

namespace canyon::pipeline {
namespace {

bool is_rtcm_path(const std::string& path) {
  const auto ends_with = [&path](const std::string& tail) {
    return path.size() >= tail.size() && path.compare(path.size() - tail.size(), tail.size(), tail) == 0;
  };
  return ends_with(".rtcm3") || ends_with(".rtcm");
}

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

io::GnssStreamOptions rtcm_options(const core::GpsTime& reference) {
  io::GnssStreamOptions o;
  o.format = io::StreamFormat::Rtcm3;
  o.rtcm3.reference_time = reference;
  return o;
}

}  // namespace

Result<ObservationStream> ObservationStream::open(const std::string& path, const io::ObsFilter& filter,
                                                  const std::optional<core::GpsTime>& reference, bool read_ahead) {
  if (!is_rtcm_path(path)) {
    auto reader = io::ObsReadAhead::open(path, filter, read_ahead ? io::ObsReadAhead::kDefaultDepth : 0);
    if (!reader) return reader.error();
    return ObservationStream(std::move(*reader), path);
  }
  if (!reference) {
    return Error{"an RTCM 3 observation file needs a reference time (the rover file's TIME OF FIRST OBS)", path, 0};
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error{"cannot open the RTCM 3 file", path, 0};
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  io::GnssStreamDecoder decoder(rtcm_options(*reference));
  decoder.push(bytes);
  decoder.finish();
  ObservationStream stream(std::nullopt, path);
  while (auto epoch = decoder.pop_rtcm3_epoch()) stream.rtcm_epochs_.push_back(std::move(*epoch));
  if (stream.rtcm_epochs_.empty()) return Error{"no RTCM 3 observation epochs in the file", path, 0};
  stream.rtcm_total_ = stream.rtcm_epochs_.size();
  if (const auto& station = decoder.rtcm3().station())
    stream.rtcm_header_.receiver.approx_position_E_m = station->arp_E_m;
  for (const std::string& p : decoder.problems()) {
    std::string warning = path;
    warning += ": ";
    warning += p;
    stream.rtcm_warnings_.push_back(std::move(warning));
  }
  return stream;
}

Result<std::optional<core::ObsEpoch>> ObservationStream::read() {
  if (reader_) return reader_->next();
  if (rtcm_epochs_.empty()) return std::optional<core::ObsEpoch>{};
  std::optional<core::ObsEpoch> epoch(std::move(rtcm_epochs_.front()));
  rtcm_epochs_.pop_front();
  return epoch;
}

double ObservationStream::fraction_read() const {
  if (reader_) return reader_->fraction_read();
  return rtcm_total_ == 0 ? 1.0 : 1.0 - static_cast<double>(rtcm_epochs_.size()) / static_cast<double>(rtcm_total_);
}

LiveBaseCursor::LiveBaseCursor(const core::GpsTime& reference, PollFn poll)
    : decoder_(rtcm_options(reference)), poll_(std::move(poll)) {}

void LiveBaseCursor::push(const std::vector<std::uint8_t>& frame, std::int64_t send_ns) {
  last_send_ns_ = send_ns;
  decoder_.push(frame);
  drain();
}

void LiveBaseCursor::drain() {
  while (auto epoch = decoder_.pop_rtcm3_epoch()) epochs_.push_back(Timed{std::move(*epoch), last_send_ns_});
}

std::optional<Eigen::Vector3d> LiveBaseCursor::station_position() const {
  if (const auto& station = decoder_.rtcm3().station()) return station->arp_E_m;
  return std::nullopt;
}

LiveBaseCursor::Match LiveBaseCursor::at(const core::GpsTime& t, std::int64_t deadline_ns) {
  const auto reached = [this, &t] {
    const core::GpsTime* latest =
        !epochs_.empty() ? &epochs_.back().epoch.time : (current_ ? &current_->epoch.time : nullptr);
    return latest != nullptr && *latest - t >= -kBaseToleranceS;
  };
  Match match;
  while (!reached() && !ended_) {
    const std::int64_t left_ns = deadline_ns - now_ns();
    if (left_ns <= 0) {
      match.late = true;
      break;
    }
    if (!poll_(std::min<std::int64_t>(left_ns / 1000 + 1, 100000))) ended_ = true;
  }
  while (!epochs_.empty() && epochs_.front().epoch.time - t <= kBaseToleranceS) {
    current_ = std::move(epochs_.front());
    epochs_.pop_front();
  }
  if (current_ && current_->epoch.time - t <= kBaseToleranceS) {
    match.epoch = &current_->epoch;
    match.send_ns = current_->send_ns;
  }
  return match;
}

}  // namespace canyon::pipeline
