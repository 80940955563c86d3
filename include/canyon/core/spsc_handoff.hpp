#pragma once
// A bounded single-producer/single-consumer hand-off between two pipeline stages. The items travel through
// moodycamel's lock-free circular buffer (Debian libreaderwriterqueue-dev), used only through its non-blocking calls;
// a side that has to wait sleeps on a futex (Linux) and is woken only when it has reason to be:
//  - the consumer, by the next item (at once: a real-time epoch must not wait for a batch);
//  - a producer that found the queue full, once the consumer has taken it down to half.
// The buffer's own blocking calls wake a full producer at every freed slot: at full speed that is a wake-up, and across
// CPUs an inter-processor interrupt, per item. Here a full queue costs one per half a queue of items.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <utility>

#include <linux/futex.h>
#include <readerwriterqueue/readerwritercircularbuffer.h>
#include <sys/syscall.h>
#include <unistd.h>

namespace canyon::core {

template <typename T>
class SpscHandoff {
 public:
  /// Holds at most `capacity` items (at least 1); a full producer wakes again at capacity / 2.
  explicit SpscHandoff(std::size_t capacity)
      : ring_(std::max<std::size_t>(capacity, 1)), low_water_(std::max<std::size_t>(capacity, 1) / 2) {}

  /// Producer: queues `item`, sleeping while the queue is full. True if it found the queue full and waited.
  bool push(T item) {
    if (try_push(item)) return false;
    do {
      wait_for_space();
    } while (!try_push(item));
    return true;
  }

  /// Consumer: the next item, sleeping until there is one.
  T pop() {
    T item{};
    while (!ring_.try_dequeue(item)) wait_for_item();
    wake_producer_if_low();
    return item;
  }

  /// Items queued now (a snapshot; thread-safe).
  [[nodiscard]] std::size_t size_approx() const { return ring_.size_approx(); }
  [[nodiscard]] std::size_t capacity() const { return ring_.max_capacity(); }

 private:
  // Straight futex calls rather than std::atomic wait/notify: libstdc++'s wait spins and calls sched_yield() before it
  // sleeps, which with six stage threads on two CPUs hands the CPU around instead of to the stage that has work.
  /// Sleeps while `word` holds `seen` (returns at once if it does not; spurious returns are allowed).
  static void futex_wait(std::atomic<std::uint32_t>& word, std::uint32_t seen) {
    // NOLINTNEXTLINE(cppcoreguidelines-pro-type-vararg): the futex system call has no wrapper
    syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&word), FUTEX_WAIT_PRIVATE, seen, nullptr, nullptr, 0);
  }
  static void futex_wake(std::atomic<std::uint32_t>& word) {
    // NOLINTNEXTLINE(cppcoreguidelines-pro-type-vararg)
    syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&word), FUTEX_WAKE_PRIVATE, 1, nullptr, nullptr, 0);
  }
  static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t) &&
                std::atomic<std::uint32_t>::is_always_lock_free);

  /// Moves `item` in if there is room (it is left untouched if not), and wakes a sleeping consumer.
  bool try_push(T& item) {
    if (!ring_.try_enqueue(std::move(item))) return false;
    // Dekker with wait_for_item(): the item is in before consumer_sleeping_ is read, consumer_sleeping_ is set before
    // the queue is looked at; so either the consumer sees the item or this side sees it asleep.
    std::atomic_thread_fence(std::memory_order_seq_cst);
    if (consumer_sleeping_.load(std::memory_order_seq_cst)) {
      items_posted_.fetch_add(1, std::memory_order_seq_cst);
      futex_wake(items_posted_);
    }
    return true;
  }

  void wait_for_item() {
    const std::uint32_t seen = items_posted_.load(std::memory_order_seq_cst);
    consumer_sleeping_.store(true, std::memory_order_seq_cst);
    std::atomic_thread_fence(std::memory_order_seq_cst);
    if (ring_.size_approx() == 0) futex_wait(items_posted_, seen);
    consumer_sleeping_.store(false, std::memory_order_seq_cst);
  }

  void wait_for_space() {
    const std::uint32_t seen = space_posted_.load(std::memory_order_seq_cst);
    producer_sleeping_.store(true, std::memory_order_seq_cst);
    std::atomic_thread_fence(std::memory_order_seq_cst);
    if (ring_.size_approx() > low_water_) futex_wait(space_posted_, seen);
    producer_sleeping_.store(false, std::memory_order_seq_cst);
  }

  void wake_producer_if_low() {
    std::atomic_thread_fence(std::memory_order_seq_cst);
    if (producer_sleeping_.load(std::memory_order_seq_cst) && ring_.size_approx() <= low_water_) {
      space_posted_.fetch_add(1, std::memory_order_seq_cst);
      futex_wake(space_posted_);
    }
  }

  moodycamel::BlockingReaderWriterCircularBuffer<T> ring_;
  std::size_t low_water_;
  std::atomic<bool> consumer_sleeping_{false};
  std::atomic<bool> producer_sleeping_{false};
  std::atomic<std::uint32_t> items_posted_{0};  // bumped to wake the consumer
  std::atomic<std::uint32_t> space_posted_{0};  // bumped to wake the producer
};

}  // namespace canyon::core
