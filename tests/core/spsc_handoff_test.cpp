// core::SpscHandoff across two real threads: order and no lost wake-up (either side faster), the bound, and a full
// producer that sleeps until the consumer has taken the queue down to half.

#include "canyon/core/spsc_handoff.hpp"

#include <atomic>
#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace canyon::core {
namespace {

/// Sends 0..n-1 through a queue of `capacity`, pausing the producer every `producer_pause` items and the consumer
/// every `consumer_pause` items (0: never), and checks that all arrive in order.
void expect_all_in_order(std::size_t capacity, int n, int producer_pause, int consumer_pause) {
  SpscHandoff<std::unique_ptr<int>> queue(capacity);
  std::thread producer([&] {
    for (int i = 0; i < n; ++i) {
      (void)queue.push(std::make_unique<int>(i));
      if (producer_pause > 0 && i % producer_pause == 0) std::this_thread::sleep_for(std::chrono::microseconds(20));
    }
  });
  int wrong = 0;
  for (int i = 0; i < n; ++i) {
    const std::unique_ptr<int> item = queue.pop();
    if (!item || *item != i) ++wrong;
    if (consumer_pause > 0 && i % consumer_pause == 0) std::this_thread::sleep_for(std::chrono::microseconds(20));
  }
  producer.join();
  EXPECT_EQ(wrong, 0) << "capacity " << capacity;
  EXPECT_EQ(queue.size_approx(), 0U);
}

TEST(SpscHandoff, DeliversEveryItemInOrderWhicheverSideIsFaster) {
  for (const std::size_t capacity : {1U, 2U, 7U, 64U}) {
    expect_all_in_order(capacity, 50000, 0, 0);  // both flat out: the wake-ups race the sleeps
    expect_all_in_order(capacity, 2000, 7, 0);   // the consumer waits for items
    expect_all_in_order(capacity, 2000, 0, 7);   // the producer waits for space
  }
}

TEST(SpscHandoff, AFullProducerSleepsUntilTheQueueIsDownToHalf) {
  SpscHandoff<int> queue(8);
  EXPECT_EQ(queue.capacity(), 8U);
  std::atomic<int> pushed{0};
  std::atomic<int> waited{0};
  std::thread producer([&] {
    for (int i = 0; i < 20; ++i) {
      if (queue.push(i)) waited.fetch_add(1);
      pushed.store(i + 1);
    }
  });
  const auto settle = [] { std::this_thread::sleep_for(std::chrono::milliseconds(50)); };
  settle();
  EXPECT_EQ(pushed.load(), 8) << "the queue holds 8 items, no more";
  for (int i = 0; i < 3; ++i) EXPECT_EQ(queue.pop(), i);
  settle();
  EXPECT_EQ(pushed.load(), 8) << "5 of 8 left: the producer must sleep on";
  EXPECT_EQ(queue.pop(), 3);  // 4 left: half
  settle();
  EXPECT_EQ(pushed.load(), 12) << "woken at half, it fills the queue again";
  for (int i = 4; i < 20; ++i) EXPECT_EQ(queue.pop(), i);
  producer.join();
  EXPECT_EQ(pushed.load(), 20);
  // Each wake-up lets the producer queue at least 4 more (half the queue): 12 items after the first 8 take at most 3
  // waits (a producer woken at every freed slot would wait up to 12 times).
  EXPECT_GE(waited.load(), 2);
  EXPECT_LE(waited.load(), 3);
}

}  // namespace
}  // namespace canyon::core
