#pragma once
// The ingest stage of `canyon rover`, without DDS: rover epochs from a RINEX file replayed at a pace or from a
// receiver's u-blox UBX stream (RXM-RAWX observations, RXM-SFRBX ephemerides) over a ByteLink (file replayed at a
// pace, serial, TCP, NTRIP); base epochs from a RINEX file (BaseCursor) or from RTCM 3 that streams in
// (LiveBaseCursor: frames from DDS, handed in by the caller, or bytes from a ByteLink, NTRIP or TCP). Ephemerides
// that arrive on the streams (SFRBX, RTCM 1019/1020/1042/1045/1046) travel with the epoch they arrived before
// (IngestedEpoch::navigation) and are added to the estimator's store by EphemerisFeed when the pipeline has drained
// the epochs before (EpochPipeline): the threaded and the sequential pipeline use the same ephemerides for the same
// epoch.
//
// Nothing is dropped silently: a corrupt frame or packet is logged with its byte offset in the stream (and the
// stream goes on); a rover epoch that waited past base_wait_s for its base is counted (base_late); a link that
// fails for good ends the rover input with an Error naming the link, or, for the base, is logged and the rover goes
// on with the base epochs it has.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "canyon/core/ephemeris.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/io/gnss_stream.hpp"
#include "canyon/io/rinex_obs.hpp"
#include "canyon/pipeline/byte_link.hpp"
#include "canyon/pipeline/epoch_pipeline.hpp"
#include "canyon/pipeline/observation_stream.hpp"

namespace canyon::pipeline {

using StopFn = std::function<bool()>;
using WarnFn = std::function<void(const std::string&)>;

/// The ephemerides of a growing NavigationData not handed out yet.
class NavigationCursor {
 public:
  /// The records appended since the last call, and the ionosphere parameters once (nullptr if nothing new).
  std::shared_ptr<const core::NavigationData> take(const core::NavigationData& all);

 private:
  std::size_t kepler_ = 0;
  std::size_t glonass_ = 0;
  bool klobuchar_ = false;
};

/// Reports a stream decoder's new problems ("LINK: byte N: what") once each.
class ProblemReporter {
 public:
  void report(const std::string& link, const io::GnssStreamDecoder& decoder, const WarnFn& warn);

 private:
  std::uint64_t count_ = 0;
  std::set<std::string> reported_;
};

/// A u-blox receiver's UBX stream as rover epochs (RXM-RAWX), with the filter of a RINEX reader applied.
class ReceiverStream {
 public:
  ReceiverStream(std::unique_ptr<ByteLink> link, io::ObsFilter filter, WarnFn warn);

  /// The next epoch; nullopt at the end of a file or once `stopped()`; Error if the link failed for good.
  Result<std::optional<core::ObsEpoch>> next(const StopFn& stopped);
  /// Ephemerides decoded since the last call (nullptr: none).
  std::shared_ptr<const core::NavigationData> take_navigation() { return navigation_.take(decoder_.navigation()); }
  [[nodiscard]] const io::GnssStreamDecoder& decoder() const { return decoder_; }
  [[nodiscard]] const ByteLink& link() const { return *link_; }

 private:
  std::unique_ptr<ByteLink> link_;
  io::ObsFilter filter_;
  WarnFn warn_;
  io::GnssStreamDecoder decoder_;
  NavigationCursor navigation_;
  ProblemReporter problems_;
  std::vector<std::uint8_t> buffer_;
  bool ended_ = false;
  std::optional<Error> failure_;
};

/// Where rover epochs come from: exactly one of the two.
struct RoverInput {
  std::optional<ObservationStream> rinex;
  std::unique_ptr<ReceiverStream> receiver;
  bool paced = true;  ///< a file: replay at the pace; a live receiver delivers at its own
};

/// Where base epochs come from: a file, or RTCM 3 streaming in through `poll` (see LiveBaseCursor::PollFn: wait at
/// most timeout_us for frames, push each into the cursor; false once the base ended).
struct BaseInput {
  using PollFn = std::function<bool(std::int64_t timeout_us, LiveBaseCursor& cursor)>;
  std::optional<BaseCursor> file;
  PollFn poll;
  std::string name = "base";             ///< names the stream in warnings ("base tcp://host:2102")
  std::shared_ptr<const ByteLink> link;  ///< the link `poll` reads, if any (for its counts in the summary)
};

/// A PollFn reading RTCM 3 from a link (NTRIP, TCP). A link that fails for good is logged once (what and where);
/// the base then counts as ended.
BaseInput::PollFn link_base_poll(std::shared_ptr<ByteLink> link, WarnFn warn);

struct RoverIngestOptions {
  double pace = 1.0;               ///< rover file replay speed (0: as fast as possible)
  double base_wait_s = 2.0;        ///< a streamed base: how long a rover epoch waits for its base epoch
  bool stream_ephemerides = true;  ///< hand the streams' ephemerides to the estimator (IngestedEpoch::navigation)
  /// A streamed base's position from its RTCM 1005/1006 (IngestedEpoch::base_position_E_m); until the first arrives,
  /// the rover epochs go on without a base (counted). False: the configured position is used, the stream's ignored.
  bool base_position_from_stream = false;
};

class RoverIngest final : public EpochSource {
 public:
  RoverIngest(RoverInput rover, BaseInput base, RoverIngestOptions options, StopFn stopped, WarnFn warn);

  Result<std::optional<IngestedEpoch>> next() override;

  /// Rover epochs that went on without waiting longer for their base (streamed base).
  [[nodiscard]] std::uint64_t base_late() const { return base_late_.load(); }
  /// Rover epochs that went on without their base because no 1005/1006 had given its position yet.
  [[nodiscard]] std::uint64_t base_without_position() const { return base_without_position_.load(); }
  /// The base position in use from the stream, once one arrived (call after the run).
  [[nodiscard]] const std::optional<Eigen::Vector3d>& streamed_base_position() const { return base_position_; }
  /// The streamed base's decoder (nullptr before the first epoch or with a file base).
  [[nodiscard]] const LiveBaseCursor* live_base() const { return live_ ? &*live_ : nullptr; }
  /// What the streams delivered and lost, one line per stream (receiver, streamed base): bytes, bytes dropped,
  /// failed connection attempts, packets, bad and cut packets, undecodable messages, epochs. `problems` is set if
  /// anything was lost. Call after the run.
  struct Summary {
    std::string text;
    bool problems = false;
  };
  [[nodiscard]] std::vector<Summary> summary() const;

 private:
  Result<std::optional<core::ObsEpoch>> next_rover();
  /// Sleeps until the rover epoch at t is due at the replay pace; false if stopped meanwhile.
  bool wait_until_due(const core::GpsTime& t);
  Status attach_base(IngestedEpoch& item);
  /// The stream's base position for the epoch (base_position_from_stream), or no base while there is none.
  void attach_base_position(IngestedEpoch& item);
  void attach_navigation(IngestedEpoch& item);
  /// The streams' loss counts so far (IngestedEpoch::rover_link, base_link).
  void attach_link_counts(IngestedEpoch& item) const;

  RoverInput rover_;
  BaseInput base_;
  RoverIngestOptions options_;
  StopFn stopped_;
  WarnFn warn_;
  std::optional<LiveBaseCursor> live_;
  NavigationCursor base_navigation_;
  ProblemReporter base_problems_;
  ReplayPacer pacer_;  // when a replayed rover epoch is due, and until when it waits for its base
  std::atomic<std::uint64_t> base_late_{0};
  std::atomic<std::uint64_t> base_without_position_{0};
  std::optional<Eigen::Vector3d> base_position_;  // from the stream, the last handed to an epoch
};

/// An estimator whose add_navigation() adds the ephemerides to the store the engine reads (the pipeline calls it
/// while no stage runs); every stage is `inner`'s.
class EphemerisFeed final : public EpochEstimator {
 public:
  EphemerisFeed(EpochEstimator& inner, gnss::EphemerisStore& store) : inner_(inner), store_(store) {}
  [[nodiscard]] BridgedEpoch bridge(IngestedEpoch epoch) const override { return inner_.bridge(std::move(epoch)); }
  [[nodiscard]] AlignedEpoch align(BridgedEpoch epoch) override { return inner_.align(std::move(epoch)); }
  [[nodiscard]] PredictedEpoch predict(AlignedEpoch epoch) override { return inner_.predict(std::move(epoch)); }
  [[nodiscard]] UpdatedEpoch update(PredictedEpoch epoch) override { return inner_.update(std::move(epoch)); }
  [[nodiscard]] SolvedEpoch resolve(UpdatedEpoch epoch) override { return inner_.resolve(std::move(epoch)); }
  void finish() override { inner_.finish(); }
  void add_navigation(const core::NavigationData& fresh) override;
  /// Ephemeris records added so far.
  [[nodiscard]] std::uint64_t added() const { return added_.load(); }

 private:
  EpochEstimator& inner_;
  gnss::EphemerisStore& store_;
  std::atomic<std::uint64_t> added_{0};
};

}  // namespace canyon::pipeline
