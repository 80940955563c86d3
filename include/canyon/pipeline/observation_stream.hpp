#pragma once
// Observation input epoch by epoch (RINEX files, recorded RTCM 3 streams), and the choice of the base epoch for each
// rover epoch: BaseCursor for files (batch), LiveBaseCursor for a base that streams in (canyon rover). Both pick the
// same base epoch when every base epoch arrives (see LiveBaseCursor).

#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/core/time.hpp"
#include "canyon/io/gnss_stream.hpp"
#include "canyon/io/obs_read_ahead.hpp"
#include "canyon/io/rinex_obs.hpp"

namespace canyon::pipeline {

/// Base epochs within this of a rover epoch count as simultaneous (receivers whose time tags differ by ms).
inline constexpr double kBaseToleranceS = 0.05;

/// An observation file read epoch by epoch as observations: flag 6 epochs hold cycle-slip records (slip counts in
/// the observation fields), not observations, and are dropped; after a power failure (flag 1) every phase may have
/// slipped and gets the loss-of-lock bit. Streaming keeps memory flat however long the file is; a RINEX file is parsed
/// ahead on a thread of its own (io::ObsReadAhead) unless `read_ahead` is false, which changes nothing but the wall
/// time.
class ObservationStream {
 public:
  /// A RINEX file; or, if `path` ends in .rtcm3 or .rtcm, a recorded RTCM 3 stream (`canyon record canyon/rtcm`)
  /// decoded as canyon rover decodes it from DDS, with weeks resolved against `reference` (any GPST within a few
  /// days of the data, e.g. the rover file's first epoch). An RTCM file's 1005/1006 gives the header's position.
  static Result<ObservationStream> open(const std::string& path, const io::ObsFilter& filter,
                                        const std::optional<core::GpsTime>& reference = std::nullopt,
                                        bool read_ahead = true);

  /// The next epoch of observations; nullopt at the end of the file.
  Result<std::optional<core::ObsEpoch>> next() {
    for (;;) {
      auto epoch = read();
      if (!epoch) return epoch.error();
      if (!*epoch) return std::optional<core::ObsEpoch>{};
      core::ObsEpoch& e = **epoch;
      if (e.flag == core::EpochFlag::CycleSlipRecords) {
        ++slip_records_;
        continue;
      }
      if (e.flag == core::EpochFlag::PowerFailure) {
        ++power_failures_;
        for (core::SatelliteObs& sat : e.sats) {
          for (core::SignalObs& signal : sat.signals) signal.lli |= core::kLliLossOfLock;
        }
      }
      if (!first_time_) first_time_ = e.time;
      last_time_ = e.time;
      return std::move(*epoch);
    }
  }

  [[nodiscard]] const io::RinexObsHeader& header() const { return reader_ ? reader_->header() : rtcm_header_; }
  [[nodiscard]] double fraction_read() const;
  [[nodiscard]] const std::optional<core::GpsTime>& first_time() const { return first_time_; }
  [[nodiscard]] const std::optional<core::GpsTime>& last_time() const { return last_time_; }

  /// The reader's warnings and one for each kind of epoch handled above (call at the end: it stops the reading).
  void append_warnings(std::vector<std::string>& out) {
    if (reader_) {
      const std::vector<std::string> warnings = reader_->finish();
      out.insert(out.end(), warnings.begin(), warnings.end());
    }
    out.insert(out.end(), rtcm_warnings_.begin(), rtcm_warnings_.end());
    if (slip_records_ > 0) {
      out.push_back(path_ + ": " + std::to_string(slip_records_) +
                    " epochs of cycle-slip records (flag 6) are not observations, not used");
    }
    if (power_failures_ > 0) {
      out.push_back(path_ + ": " + std::to_string(power_failures_) +
                    " epochs after a power failure (flag 1): all their phases taken as lost lock");
    }
  }

 private:
  ObservationStream(std::optional<io::ObsReadAhead> reader, std::string path)
      : reader_(std::move(reader)), path_(std::move(path)) {}
  Result<std::optional<core::ObsEpoch>> read();

  std::optional<io::ObsReadAhead> reader_;
  std::deque<core::ObsEpoch> rtcm_epochs_;  // an RTCM file, decoded at open()
  std::size_t rtcm_total_ = 0;
  io::RinexObsHeader rtcm_header_;
  std::vector<std::string> rtcm_warnings_;
  std::string path_;
  int slip_records_ = 0;
  int power_failures_ = 0;
  std::optional<core::GpsTime> first_time_;
  std::optional<core::GpsTime> last_time_;
};

/// The base epochs, read one ahead of the one in use: at rover time t, the latest base epoch not later than t (plus
/// a small tolerance for receivers whose time tags differ by milliseconds), or nullptr.
class BaseCursor {
 public:
  explicit BaseCursor(ObservationStream stream) : stream_(std::move(stream)) {}

  Result<const core::ObsEpoch*> at(const core::GpsTime& t) {
    constexpr double kToleranceS = kBaseToleranceS;
    if (!primed_) {
      if (Status s = read_next(); !s) return s.error();
      primed_ = true;
    }
    while (next_ && next_->time - t <= kToleranceS) {
      current_ = std::move(next_);
      if (Status s = read_next(); !s) return s.error();
    }
    if (current_ && current_->time - t <= kToleranceS) return &*current_;
    return nullptr;
  }

  [[nodiscard]] ObservationStream& stream() { return stream_; }

 private:
  Status read_next() {
    auto epoch = stream_.next();
    if (!epoch) return epoch.error();
    next_ = std::move(*epoch);
    return Ok{};
  }

  ObservationStream stream_;
  std::optional<core::ObsEpoch> current_;
  std::optional<core::ObsEpoch> next_;
  bool primed_ = false;
};

/// The pacing of a rover file replayed as a live receiver (canyon rover): epoch t is due at the instant the first
/// epoch was read plus (t - first) / pace. A live base's epoch for t is waited for until due + base_wait: counted from
/// when the epoch is due, not from when ingest gets to it, so a base outage delays every epoch by at most base_wait
/// instead of adding one whole wait per epoch (the rover would fall further behind real time with every epoch of the
/// outage). Pace 0 (as fast as possible, the rover follows the base): every epoch is due at once and waits from then.
class ReplayPacer {
 public:
  ReplayPacer(double pace, double base_wait_s)
      : pace_(pace), base_wait_ns_(static_cast<std::int64_t>(base_wait_s * 1e9)) {}

  /// When epoch t is due (monotonic ns); the first call anchors the replay at (t, now_ns).
  [[nodiscard]] std::int64_t due_ns(const core::GpsTime& t, std::int64_t now_ns) {
    if (!(pace_ > 0.0)) return now_ns;
    if (!anchored_) {
      anchor_ = Anchor{t, now_ns};
      anchored_ = true;
    }
    return anchor_.ns + static_cast<std::int64_t>((t - anchor_.t) / pace_ * 1e9);
  }
  /// Until when epoch t waits for its base epoch (monotonic ns); may already have passed when ingest is behind.
  [[nodiscard]] std::int64_t base_deadline_ns(const core::GpsTime& t, std::int64_t now_ns) {
    return due_ns(t, now_ns) + base_wait_ns_;
  }

 private:
  struct Anchor {
    core::GpsTime t;
    std::int64_t ns = 0;
  };
  double pace_;
  std::int64_t base_wait_ns_;
  // A plain flag, not std::optional: GCC 12 takes the optional's payload for uninitialised where due_ns is inlined.
  bool anchored_ = false;
  Anchor anchor_{};
};

/// A base whose RTCM 3 frames stream in (DDS, NTRIP, TCP). Frames are decoded as they come; at(t) waits until the base
/// reached rover time t (a base epoch at or after t - kBaseToleranceS), or until the deadline, and then returns the
/// latest base epoch not later than t + kBaseToleranceS, as BaseCursor does. The two agree whenever every base epoch
/// not later than t + tolerance arrived before its rover epoch's deadline, and the base rate is at most 10 Hz.
class LiveBaseCursor {
 public:
  /// `poll(timeout_us)` waits at most that long for frames and hands each to push(); false when the base ended.
  using PollFn = std::function<bool(std::int64_t timeout_us)>;
  LiveBaseCursor(const core::GpsTime& reference, PollFn poll);

  /// One whole RTCM 3 frame, with the base's send time of it (monotonic ns, 0 unknown).
  void push(const std::vector<std::uint8_t>& frame, std::int64_t send_ns);
  struct Match {
    const core::ObsEpoch* epoch = nullptr;  ///< nullptr: none
    std::int64_t send_ns = 0;               ///< when the base sent the epoch's last frame
    bool late = false;                      ///< the deadline passed before the base reached t
  };
  /// The base epoch for rover time t; waits for the base at most until `deadline_ns` (monotonic).
  Match at(const core::GpsTime& t, std::int64_t deadline_ns);
  [[nodiscard]] const io::GnssStreamDecoder& decoder() const { return decoder_; }
  /// The base position from 1005/1006, once seen.
  [[nodiscard]] std::optional<Eigen::Vector3d> station_position() const;

 private:
  struct Timed {
    core::ObsEpoch epoch;
    std::int64_t send_ns = 0;
  };
  void drain();

  io::GnssStreamDecoder decoder_;
  PollFn poll_;
  std::deque<Timed> epochs_;  // decoded, not yet superseded
  std::optional<Timed> current_;
  bool ended_ = false;
  std::int64_t last_send_ns_ = 0;
};

}  // namespace canyon::pipeline
