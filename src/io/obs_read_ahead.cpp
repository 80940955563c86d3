// An observation file parsed ahead on its own thread (see obs_read_ahead.hpp).

#include "canyon/io/obs_read_ahead.hpp"

#include <algorithm>
#include <utility>

#include "canyon/core/batch_queue.hpp"

namespace canyon::io {

/// What the reading thread hands over: one result of RinexObsReader::next() and where the reader stood after it.
struct ObsReadAheadItem {
  Result<std::optional<core::ObsEpoch>> epoch;
  double fraction_read;
  std::size_t warnings;  // size of the reader's warnings after this epoch
};

struct ObsReadAhead::Shared {
  /// Epochs handed over at a time: one lock and at most one wake-up per batch, not per epoch.
  static constexpr std::size_t kBatch = 16;

  explicit Shared(RinexObsReader r, std::size_t depth) : reader(std::move(r)), queue(depth, kBatch) {}

  RinexObsReader reader;  // used by the reading thread only until it has ended
  core::BatchQueue<ObsReadAheadItem> queue;
  bool ended = false;  // the consumer has seen the last item (or stopped)

  /// The reading thread: epochs into the queue until the end of the file, an error, or stop().
  void run() {
    for (bool last = false; !last;) {
      auto epoch = reader.next();
      last = !epoch || !*epoch;
      if (!queue.push({std::move(epoch), reader.fraction_read(), reader.warnings().size()})) return;
    }
    queue.close();
  }
};

Result<ObsReadAhead> ObsReadAhead::open(const std::string& path, std::optional<ObsFilter> filter, std::size_t depth) {
  auto reader = RinexObsReader::open(path, filter);
  if (!reader) return reader.error();
  RinexObsHeader header = reader->header();
  const bool threaded = depth > 0;
  return ObsReadAhead(std::move(header), std::make_unique<Shared>(std::move(*reader), std::max<std::size_t>(depth, 1)),
                      threaded);
}

ObsReadAhead::ObsReadAhead(RinexObsHeader header, std::unique_ptr<Shared> shared, bool threaded)
    : header_(std::move(header)), shared_(std::move(shared)), threaded_(threaded) {
  if (threaded_) thread_ = std::thread([s = shared_.get()] { s->run(); });
}

ObsReadAhead::ObsReadAhead(ObsReadAhead&&) noexcept = default;

ObsReadAhead& ObsReadAhead::operator=(ObsReadAhead&& other) noexcept {
  if (this != &other) {
    stop();
    header_ = std::move(other.header_);
    shared_ = std::move(other.shared_);
    thread_ = std::move(other.thread_);
    threaded_ = other.threaded_;
    fraction_read_ = other.fraction_read_;
    warnings_returned_ = other.warnings_returned_;
  }
  return *this;
}

ObsReadAhead::~ObsReadAhead() {
  stop();
}

void ObsReadAhead::stop() {
  if (!shared_) return;
  shared_->queue.stop();
  shared_->ended = true;
  if (thread_.joinable()) thread_.join();
}

Result<std::optional<core::ObsEpoch>> ObsReadAhead::next() {
  if (shared_->ended) return std::optional<core::ObsEpoch>{};
  if (!threaded_) {  // depth 0: parsed here, on the caller's thread
    auto epoch = shared_->reader.next();
    if (!epoch || !*epoch) shared_->ended = true;
    fraction_read_ = shared_->reader.fraction_read();
    warnings_returned_ = shared_->reader.warnings().size();
    return epoch;
  }
  std::optional<ObsReadAheadItem> item = shared_->queue.pop();
  if (!item) {
    shared_->ended = true;
    return std::optional<core::ObsEpoch>{};
  }
  fraction_read_ = item->fraction_read;
  warnings_returned_ = item->warnings;
  return std::move(item->epoch);
}

std::vector<std::string> ObsReadAhead::finish() {
  if (!shared_) return {};
  stop();
  const std::vector<std::string>& all = shared_->reader.warnings();
  return {all.begin(), all.begin() + static_cast<std::ptrdiff_t>(std::min(warnings_returned_, all.size()))};
}

}  // namespace canyon::io
