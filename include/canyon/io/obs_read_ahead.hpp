#pragma once
// An observation file parsed on a thread of its own, a bounded number of epochs ahead of its consumer: batch
// processing overlaps reading with solving (the rover and base files each get a thread; on a 2-core machine this takes
// the parsing, about an eighth of canyon process's time, off the solving thread). The epochs, their order, the errors
// and the warnings are exactly those of RinexObsReader::next() called in a loop: only the thread differs.

#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/io/rinex_obs.hpp"

namespace canyon::io {

class ObsReadAhead {
 public:
  /// Epochs parsed ahead of next() at most. Memory: about 6 kB per epoch on cssrlib-kinematic (35 satellites, four
  /// signals each), every page of it first touched by the reading thread; 32 instead of 64 took a run there from about
  /// 510 to 400 page faults (11 us each on the development VM) and 0-1.3 ms off its ~40 ms, 16 no further.
  static constexpr std::size_t kDefaultDepth = 32;

  /// Opens the file and reads its header on the calling thread (its errors are returned here), then starts the
  /// reading thread. Depth 0: no reading thread, next() parses on the caller's thread (for a caller that already runs
  /// on a thread of its own: on a 2-core machine a third busy thread only takes turns with the other two).
  static Result<ObsReadAhead> open(const std::string& path, std::optional<ObsFilter> filter = std::nullopt,
                                   std::size_t depth = kDefaultDepth);

  ObsReadAhead(ObsReadAhead&&) noexcept;
  ObsReadAhead& operator=(ObsReadAhead&&) noexcept;
  ObsReadAhead(const ObsReadAhead&) = delete;
  ObsReadAhead& operator=(const ObsReadAhead&) = delete;
  /// Stops the reading thread (it may be blocked on a full queue) and joins it.
  ~ObsReadAhead();

  /// As RinexObsReader::next(): the next epoch, nullopt at the end, or the reader's error (after which the reader has
  /// stopped and next() keeps returning nullopt).
  Result<std::optional<core::ObsEpoch>> next();

  [[nodiscard]] const RinexObsHeader& header() const { return header_; }
  /// Fraction of the file read up to the epoch next() returned last (0..1), as the reader would tell.
  [[nodiscard]] double fraction_read() const { return fraction_read_; }
  /// Stops the reading thread and returns the reader's warnings about the epochs next() has returned (the same as a
  /// reader that had stopped there); next() returns nullopt afterwards.
  std::vector<std::string> finish();

 private:
  struct Shared;
  ObsReadAhead(RinexObsHeader header, std::unique_ptr<Shared> shared, bool threaded);
  void stop();

  RinexObsHeader header_;
  std::unique_ptr<Shared> shared_;
  double fraction_read_ = 0.0;
  std::size_t warnings_returned_ = 0;  // reader warnings up to the epoch next() returned last
  bool threaded_ = true;               // false: depth 0, no reading thread
  std::thread thread_;
};

}  // namespace canyon::io
