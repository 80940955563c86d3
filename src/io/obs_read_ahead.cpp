// An observation file parsed ahead on its own thread (see obs_read_ahead.hpp).

#include "canyon/io/obs_read_ahead.hpp"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <iterator>
#include <mutex>
#include <utility>

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

  explicit Shared(RinexObsReader r, std::size_t d) : reader(std::move(r)), depth(d) {}

  RinexObsReader reader;  // used by the reading thread only until it has ended
  std::size_t depth;
  std::mutex mutex;
  std::condition_variable not_empty;
  std::condition_variable not_full;
  std::deque<ObsReadAheadItem> queue;  // guarded by mutex
  bool stopping = false;               // the consumer wants no more epochs
  bool ended = false;                  // the reading thread has handed over its last item
  std::deque<ObsReadAheadItem> taken;  // the consumer's side: items taken from `queue`, not yet returned

  /// The reading thread: epochs into the queue until the end of the file, an error, or stop().
  void run() {
    std::deque<ObsReadAheadItem> batch;
    bool last = false;
    while (!last) {
      auto epoch = reader.next();
      last = !epoch || !*epoch;
      batch.push_back({std::move(epoch), reader.fraction_read(), reader.warnings().size()});
      if (batch.size() < std::min(kBatch, depth) && !last) continue;
      std::unique_lock lock(mutex);
      not_full.wait(lock, [this] { return stopping || queue.size() < depth; });
      if (stopping) break;
      const bool was_empty = queue.empty();
      std::move(batch.begin(), batch.end(), std::back_inserter(queue));
      batch.clear();
      lock.unlock();
      if (was_empty) not_empty.notify_one();
    }
    const std::lock_guard lock(mutex);
    ended = true;
    not_empty.notify_one();
  }
};

Result<ObsReadAhead> ObsReadAhead::open(const std::string& path, std::optional<ObsFilter> filter, std::size_t depth) {
  auto reader = RinexObsReader::open(path, filter);
  if (!reader) return reader.error();
  RinexObsHeader header = reader->header();
  return ObsReadAhead(std::move(header), std::make_unique<Shared>(std::move(*reader), depth == 0 ? 1 : depth));
}

ObsReadAhead::ObsReadAhead(RinexObsHeader header, std::unique_ptr<Shared> shared)
    : header_(std::move(header)), shared_(std::move(shared)) {
  thread_ = std::thread([s = shared_.get()] { s->run(); });
}

ObsReadAhead::ObsReadAhead(ObsReadAhead&&) noexcept = default;

ObsReadAhead& ObsReadAhead::operator=(ObsReadAhead&& other) noexcept {
  if (this != &other) {
    stop();
    header_ = std::move(other.header_);
    shared_ = std::move(other.shared_);
    thread_ = std::move(other.thread_);
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
  {
    const std::lock_guard lock(shared_->mutex);
    shared_->stopping = true;
  }
  shared_->not_full.notify_one();
  if (thread_.joinable()) thread_.join();
}

Result<std::optional<core::ObsEpoch>> ObsReadAhead::next() {
  std::deque<ObsReadAheadItem>& taken = shared_->taken;
  if (taken.empty()) {
    std::unique_lock lock(shared_->mutex);
    shared_->not_empty.wait(lock, [this] { return !shared_->queue.empty() || shared_->ended || shared_->stopping; });
    if (shared_->stopping) return std::optional<core::ObsEpoch>{};
    taken.swap(shared_->queue);
    lock.unlock();
    shared_->not_full.notify_one();
    if (taken.empty()) return std::optional<core::ObsEpoch>{};
  }
  ObsReadAheadItem item = std::move(taken.front());
  taken.pop_front();
  fraction_read_ = item.fraction_read;
  warnings_returned_ = item.warnings;
  return std::move(item.epoch);
}

std::vector<std::string> ObsReadAhead::finish() {
  if (!shared_) return {};
  stop();
  shared_->taken.clear();
  const std::vector<std::string>& all = shared_->reader.warnings();
  return {all.begin(), all.begin() + static_cast<std::ptrdiff_t>(std::min(warnings_returned_, all.size()))};
}

}  // namespace canyon::io
