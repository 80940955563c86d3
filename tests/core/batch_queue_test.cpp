// core::BatchQueue: order, the end, back-pressure and stopping, across two real threads.

#include "canyon/core/batch_queue.hpp"

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace canyon::core {
namespace {

TEST(BatchQueue, DeliversEveryItemInOrderAndThenTheEnd) {
  for (const std::size_t depth : {1U, 3U, 16U, 64U}) {
    BatchQueue<int> queue(depth, 16);
    std::thread producer([&queue] {
      for (int i = 0; i < 1000; ++i) EXPECT_TRUE(queue.push(i));
      queue.close();  // 1000 is no multiple of the batch: the last, partial batch crosses on close()
    });
    std::vector<int> seen;
    while (std::optional<int> item = queue.pop()) seen.push_back(*item);
    producer.join();
    ASSERT_EQ(seen.size(), 1000U) << "depth " << depth;
    for (int i = 0; i < 1000; ++i) EXPECT_EQ(seen[static_cast<std::size_t>(i)], i);
    EXPECT_FALSE(queue.pop().has_value()) << "an ended queue stays ended";
  }
}

TEST(BatchQueue, AFullQueueBlocksTheProducerUntilTheConsumerTakes) {
  BatchQueue<int> queue(4, 2);
  std::atomic<int> pushed{0};
  std::thread producer([&] {
    for (int i = 0; i < 20; ++i) {
      ASSERT_TRUE(queue.push(i));
      pushed.store(i + 1);
    }
    queue.close();
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  // 4 queued and one batch of 2 in hand (the push that fills it blocks): never all 20.
  EXPECT_LE(pushed.load(), 6);
  int n = 0;
  while (queue.pop()) ++n;
  producer.join();
  EXPECT_EQ(n, 20);
  EXPECT_GT(queue.full_waits(), 0U);
}

TEST(BatchQueue, StopReleasesABlockedProducer) {
  BatchQueue<int> queue(2, 1);
  std::atomic<bool> refused{false};
  std::thread producer([&] {
    for (int i = 0; i < 100; ++i) {
      if (!queue.push(i)) {
        refused.store(true);
        break;
      }
    }
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  queue.stop();
  producer.join();  // would hang if stop() did not wake the producer
  EXPECT_TRUE(refused.load());
  EXPECT_FALSE(queue.pop().has_value());
}

}  // namespace
}  // namespace canyon::core
