// The ingest stage of canyon rover (see rover_ingest.hpp).

#include "canyon/pipeline/rover_ingest.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>

namespace canyon::pipeline {
namespace {

constexpr int kReadSliceMs = 100;  // a blocked read looks at the stop flag this often
constexpr std::int64_t kPaceSliceNs = 50'000'000;
constexpr double kSameBasePositionM = 1e-4;  // RTCM 1005's resolution: a smaller change is the same position

io::GnssStreamOptions ubx_options() {
  io::GnssStreamOptions o;
  o.format = io::StreamFormat::Ubx;
  return o;
}

LinkCounts link_counts(const ByteLink* link, const io::GnssStreamDecoder& d) {
  LinkCounts c;
  const io::GnssStreamStats s = d.stats();
  c.bad_frames = s.framing.bad_packets();
  c.undecodable = s.rtcm3_decode_errors + s.ubx_decode_errors;
  if (link != nullptr) {
    const LinkStats l = link->stats();
    c.dropped_bytes = l.dropped_bytes;
    c.link_failures = l.failures;
  }
  return c;
}

RoverIngest::Summary stream_summary(const std::string& name, const ByteLink* link, const io::GnssStreamDecoder& d,
                                    std::uint64_t epochs) {
  const io::GnssStreamStats s = d.stats();
  const LinkCounts lost = link_counts(link, d);
  std::string text = name + ": ";
  if (link != nullptr) {
    text += std::to_string(link->stats().bytes) + " bytes, " + std::to_string(lost.dropped_bytes) +
            " dropped (queue full), " + std::to_string(lost.link_failures) + " failed connection attempts; ";
  }
  text += std::to_string(s.framing.rtcm3_frames) + " RTCM 3 frames, " + std::to_string(s.framing.ubx_packets) +
          " UBX packets, " + std::to_string(lost.bad_frames) + " bad or cut, " +
          std::to_string(s.framing.garbage_bytes) + " garbage bytes, " + std::to_string(lost.undecodable) +
          " undecodable; " + std::to_string(epochs) + " epochs";
  const bool problems = lost.bad_frames > 0 || lost.undecodable > 0 || lost.dropped_bytes > 0 || lost.link_failures > 0;
  return {std::move(text), problems};
}

}  // namespace

void RoverIngest::attach_link_counts(IngestedEpoch& item) const {
  if (rover_.receiver) item.rover_link = link_counts(&rover_.receiver->link(), rover_.receiver->decoder());
  if (live_) item.base_link = link_counts(base_.link.get(), live_->decoder());
}

std::vector<RoverIngest::Summary> RoverIngest::summary() const {
  std::vector<Summary> out;
  if (rover_.receiver) {
    const io::GnssStreamDecoder& d = rover_.receiver->decoder();
    out.push_back(stream_summary("rover " + rover_.receiver->link().address().text, &rover_.receiver->link(), d,
                                 d.stats().ubx_epochs));
  }
  if (live_) {
    out.push_back(
        stream_summary(base_.name, base_.link.get(), live_->decoder(), live_->decoder().stats().rtcm3_epochs));
  }
  return out;
}

std::shared_ptr<const core::NavigationData> NavigationCursor::take(const core::NavigationData& all) {
  const bool new_klobuchar = !klobuchar_ && (all.gps_klobuchar || all.bds_klobuchar);
  if (all.kepler.size() == kepler_ && all.glonass.size() == glonass_ && !new_klobuchar) return nullptr;
  auto fresh = std::make_shared<core::NavigationData>();
  fresh->kepler.assign(all.kepler.begin() + static_cast<std::ptrdiff_t>(kepler_), all.kepler.end());
  fresh->glonass.assign(all.glonass.begin() + static_cast<std::ptrdiff_t>(glonass_), all.glonass.end());
  if (new_klobuchar) {
    fresh->gps_klobuchar = all.gps_klobuchar;
    fresh->bds_klobuchar = all.bds_klobuchar;
    klobuchar_ = all.gps_klobuchar.has_value();
  }
  kepler_ = all.kepler.size();
  glonass_ = all.glonass.size();
  return fresh;
}

void ProblemReporter::report(const std::string& link, const io::GnssStreamDecoder& decoder, const WarnFn& warn) {
  const io::GnssStreamStats s = decoder.stats();
  const std::uint64_t count = s.framing.bad_packets() + s.rtcm3_decode_errors + s.ubx_decode_errors;
  if (count == count_) return;
  count_ = count;
  for (const std::string& p : decoder.problems()) {
    if (!reported_.insert(p).second || !warn) continue;
    std::string text = link;
    text.append(": ").append(p);
    warn(text);
  }
}

ReceiverStream::ReceiverStream(std::unique_ptr<ByteLink> link, io::ObsFilter filter, WarnFn warn)
    : link_(std::move(link)), filter_(filter), warn_(std::move(warn)), decoder_(ubx_options()) {}

Result<std::optional<core::ObsEpoch>> ReceiverStream::next(const StopFn& stopped) {
  for (;;) {
    if (auto epoch = decoder_.pop_ubx_epoch()) {
      io::apply_obs_filter(filter_, *epoch);
      return epoch;
    }
    if (failure_) return *failure_;  // after the epochs decoded before the link failed
    if (ended_ || stopped()) return std::optional<core::ObsEpoch>{};
    buffer_.clear();
    auto more = link_->read(buffer_, kReadSliceMs);
    if (!more) failure_ = more.error();
    if (more && *more) {
      decoder_.push(buffer_);
    } else {
      ended_ = true;  // the end of a file or a failed link: the last packet may have been cut short
      decoder_.finish();
    }
    problems_.report("rover " + link_->address().text, decoder_, warn_);
  }
}

BaseInput::PollFn link_base_poll(std::shared_ptr<ByteLink> link, WarnFn warn) {
  auto buffer = std::make_shared<std::vector<std::uint8_t>>();
  return [link = std::move(link), warn = std::move(warn), buffer](std::int64_t timeout_us, LiveBaseCursor& cursor) {
    buffer->clear();
    const int timeout_ms = static_cast<int>(std::clamp<std::int64_t>(timeout_us / 1000, 1, kReadSliceMs));
    auto more = link->read(*buffer, timeout_ms);
    if (!more) {
      if (warn) warn("base: " + more.error().to_string() + "; going on with the base epochs received");
      return false;
    }
    if (!buffer->empty()) cursor.push(*buffer, 0);
    return *more;
  };
}

RoverIngest::RoverIngest(RoverInput rover, BaseInput base, RoverIngestOptions options, StopFn stopped, WarnFn warn)
    : rover_(std::move(rover)),
      base_(std::move(base)),
      options_(options),
      stopped_(std::move(stopped)),
      warn_(std::move(warn)),
      pacer_(options.pace, options.base_wait_s) {}

Result<std::optional<core::ObsEpoch>> RoverIngest::next_rover() {
  if (rover_.receiver) return rover_.receiver->next(stopped_);
  if (rover_.rinex) return rover_.rinex->next();
  return Error{"rover ingest: no rover input"};
}

Result<std::optional<IngestedEpoch>> RoverIngest::next() {
  auto next = next_rover();
  if (!next) return next.error();
  if (!*next) return std::optional<IngestedEpoch>{};
  std::optional<IngestedEpoch> item(std::in_place);
  item->rover = std::move(**next);
  if (!wait_until_due(item->rover.time)) return std::optional<IngestedEpoch>{};  // stopped
  if (Status s = attach_base(*item); !s) return s.error();
  attach_navigation(*item);
  attach_link_counts(*item);
  item->arrival_ns = core::pipeline_now_ns();  // the epoch is complete (rover and base) and enters the stages
  return item;
}

bool RoverIngest::wait_until_due(const core::GpsTime& t) {
  if (!rover_.paced || !(options_.pace > 0.0)) return !stopped_();
  const std::int64_t due = pacer_.due_ns(t, core::pipeline_now_ns());
  while (!stopped_()) {
    const std::int64_t left = due - core::pipeline_now_ns();
    if (left <= 0) return true;
    std::this_thread::sleep_for(std::chrono::nanoseconds(std::min(left, kPaceSliceNs)));
  }
  return false;
}

Status RoverIngest::attach_base(IngestedEpoch& item) {
  const core::GpsTime t = item.rover.time;
  if (base_.file) {
    auto base = base_.file->at(t);
    if (!base) return base.error();
    if (*base != nullptr) item.base = **base;
    return Ok{};
  }
  if (!base_.poll) return Ok{};
  if (!live_) {
    // Stopping ends the wait for the base at once (false: the base counts as ended).
    live_.emplace(t, [this](std::int64_t timeout_us) { return !stopped_() && base_.poll(timeout_us, *live_); });
  }
  // The wait counts from when the epoch is due (a replay), or from now (a live receiver delivers it when due): an
  // epoch that ingest reaches late, after an outage, does not wait a whole base_wait_s more.
  const std::int64_t now = core::pipeline_now_ns();
  const std::int64_t deadline =
      rover_.paced ? pacer_.base_deadline_ns(t, now) : now + static_cast<std::int64_t>(options_.base_wait_s * 1e9);
  const LiveBaseCursor::Match match = live_->at(t, deadline);
  base_problems_.report(base_.name, live_->decoder(), warn_);
  if (match.late) base_late_.fetch_add(1);
  if (match.epoch != nullptr) item.base = *match.epoch;
  item.base_send_ns = match.send_ns;
  if (options_.base_position_from_stream && item.base) attach_base_position(item);
  return Ok{};
}

void RoverIngest::attach_base_position(IngestedEpoch& item) {
  const std::optional<Eigen::Vector3d> p = live_->station_position();
  if (!p) {
    // Without the base position the base epoch cannot be differenced: the rover epoch goes on alone.
    if (base_without_position_.fetch_add(1) == 0) {
      warn_(base_.name +
            ": no base position yet (RTCM 1005/1006): rover epochs go on without the base until one "
            "arrives (or give estimator.base_position)");
    }
    item.base.reset();
    return;
  }
  if (base_position_ && (*p - *base_position_).norm() <= kSameBasePositionM) return;
  if (base_position_) {
    char moved[96];
    std::snprintf(moved, sizeof moved, " (moved %.3f m)", (*p - *base_position_).norm());
    warn_(base_.name + ": the base position changed" + moved + ": the new one is used from GPST " +
          std::to_string(item.rover.time.week) + " " + std::to_string(item.rover.time.tow_s));
  }
  base_position_ = *p;
  item.base_position_E_m = *p;
}

void RoverIngest::attach_navigation(IngestedEpoch& item) {
  if (!options_.stream_ephemerides) return;
  std::shared_ptr<const core::NavigationData> rover = rover_.receiver ? rover_.receiver->take_navigation() : nullptr;
  std::shared_ptr<const core::NavigationData> base =
      live_ ? base_navigation_.take(live_->decoder().navigation()) : nullptr;
  if (rover && base) {
    auto both = std::make_shared<core::NavigationData>(*rover);
    both->merge(*base);
    item.navigation = std::move(both);
  } else {
    item.navigation = rover ? std::move(rover) : std::move(base);
  }
}

void EphemerisFeed::add_navigation(const core::NavigationData& fresh) {
  added_.fetch_add(static_cast<std::uint64_t>(store_.add(fresh)));
}

}  // namespace canyon::pipeline
