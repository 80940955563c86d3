#pragma once
// A bounded single-producer/single-consumer hand-off in batches, for throughput (batch processing) rather than
// latency. The producer's items cross over `batch` at a time and the consumer takes everything queued at once, so
// each side takes the lock and wakes the other once per batch, not once per item; and neither side spins while it
// waits (on two cores a spinning waiter burns the CPU the other side needs). An item waits on the producer's side
// until its batch is full or the producer closes the queue.

#include <algorithm>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <iterator>
#include <mutex>
#include <optional>
#include <utility>

namespace canyon::core {

template <typename T>
class BatchQueue {
 public:
  /// At most `depth` items wait between the two sides (at least 1); batches of min(batch, depth) items.
  explicit BatchQueue(std::size_t depth, std::size_t batch = 16)
      : depth_(std::max<std::size_t>(depth, 1)), batch_(std::clamp<std::size_t>(batch, 1, depth_)) {}

  /// Producer: queues `item`, handing the batch over when it is full (blocking while `depth` items wait). False if
  /// the consumer has stopped (the item is dropped).
  bool push(T item) {
    pending_.push_back(std::move(item));
    return pending_.size() < batch_ || hand_over();
  }
  /// Producer: hands over what is batched now, full batch or not (blocking while `depth` items wait). False if the
  /// consumer has stopped.
  bool flush() { return pending_.empty() || hand_over(); }
  /// Producer: hands over what is batched and marks the end of the items.
  void close() {
    hand_over();
    {
      const std::lock_guard lock(mutex_);
      closed_ = true;
    }
    not_empty_.notify_one();
  }
  /// Consumer: the next item; nullopt after the last item of a closed queue, or after stop().
  std::optional<T> pop() {
    if (taken_.empty()) {
      std::unique_lock lock(mutex_);
      not_empty_.wait(lock, [this] { return !queue_.empty() || closed_ || stopped_; });
      if (stopped_) return std::nullopt;
      taken_.swap(queue_);
      lock.unlock();
      not_full_.notify_one();
      if (taken_.empty()) return std::nullopt;
    }
    std::optional<T> item(std::move(taken_.front()));
    taken_.pop_front();
    return item;
  }
  /// Consumer: wants no more items; a producer blocked on a full queue returns false.
  void stop() {
    {
      const std::lock_guard lock(mutex_);
      stopped_ = true;
    }
    not_full_.notify_one();
  }
  /// Times the producer found the queue full and waited.
  [[nodiscard]] std::size_t full_waits() const {
    const std::lock_guard lock(mutex_);
    return full_waits_;
  }

 private:
  bool hand_over() {
    std::unique_lock lock(mutex_);
    if (queue_.size() >= depth_ && !stopped_) {
      ++full_waits_;
      not_full_.wait(lock, [this] { return stopped_ || queue_.size() < depth_; });
    }
    if (stopped_) {
      pending_.clear();
      return false;
    }
    const bool was_empty = queue_.empty();
    std::move(pending_.begin(), pending_.end(), std::back_inserter(queue_));
    pending_.clear();
    lock.unlock();
    if (was_empty) not_empty_.notify_one();
    return true;
  }

  const std::size_t depth_;
  const std::size_t batch_;
  mutable std::mutex mutex_;
  std::condition_variable not_empty_;
  std::condition_variable not_full_;
  std::deque<T> queue_;         // guarded by mutex_
  bool closed_ = false;         // guarded by mutex_
  bool stopped_ = false;        // guarded by mutex_
  std::size_t full_waits_ = 0;  // guarded by mutex_
  std::deque<T> pending_;       // the producer's side
  std::deque<T> taken_;         // the consumer's side
};

}  // namespace canyon::core
