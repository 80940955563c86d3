// The rover's replay pacing (pipeline/observation_stream.hpp, ReplayPacer): epochs due at the pace from the first one,
// and the wait for a live base counted from when the epoch is due, so that a base outage never makes the rover fall
// further and further behind real time.

#include <algorithm>
#include <cstdint>

#include <gtest/gtest.h>

#include "canyon/pipeline/observation_stream.hpp"

namespace canyon::pipeline {
namespace {

constexpr std::int64_t kSecondNs = 1'000'000'000;

core::GpsTime at_s(double tow_s) {
  return core::GpsTime{2250, tow_s};
}

TEST(ReplayPacer, EpochsAreDueAtThePaceFromTheFirst) {
  ReplayPacer real_time(1.0, 2.0);
  const std::int64_t start_ns = 7 * kSecondNs;
  EXPECT_EQ(real_time.due_ns(at_s(100.0), start_ns), start_ns);
  // Asked later (or earlier) than due: the anchor decides, not the clock.
  EXPECT_EQ(real_time.due_ns(at_s(105.0), start_ns + 60 * kSecondNs), start_ns + 5 * kSecondNs);
  EXPECT_EQ(real_time.due_ns(at_s(101.0), start_ns), start_ns + kSecondNs);

  ReplayPacer twice(2.0, 2.0);
  EXPECT_EQ(twice.due_ns(at_s(100.0), start_ns), start_ns);
  EXPECT_EQ(twice.due_ns(at_s(110.0), start_ns), start_ns + 5 * kSecondNs);
}

TEST(ReplayPacer, AsFastAsPossibleWaitsFromNow) {
  ReplayPacer fast(0.0, 5.0);
  EXPECT_EQ(fast.due_ns(at_s(100.0), 3 * kSecondNs), 3 * kSecondNs);
  EXPECT_EQ(fast.base_deadline_ns(at_s(200.0), 4 * kSecondNs), 9 * kSecondNs);
}

// A base outage of 60 epochs at 1 Hz: every epoch waits for its base until the deadline and then goes on without it.
// The rover stays at most base_wait behind its epochs' due times; waiting base_wait from the moment ingest gets to an
// epoch instead would add (base_wait - 1 s) of delay per epoch: 60 s behind after this outage.
TEST(ReplayPacer, BaseOutageDelaysEpochsByAtMostTheBaseWait) {
  constexpr double kBaseWaitS = 2.0;
  ReplayPacer pacer(1.0, kBaseWaitS);
  std::int64_t now_ns = 0;
  std::int64_t max_lag_ns = 0;
  for (int k = 0; k < 60; ++k) {
    const core::GpsTime t = at_s(1000.0 + k);
    const std::int64_t due = pacer.due_ns(t, now_ns);
    now_ns = std::max(now_ns, due);  // ingest sleeps until the epoch is due
    const std::int64_t deadline = pacer.base_deadline_ns(t, now_ns);
    EXPECT_EQ(deadline - due, static_cast<std::int64_t>(kBaseWaitS * 1e9)) << "epoch " << k;
    now_ns = std::max(now_ns, deadline);  // no base: the wait runs out
    max_lag_ns = std::max(max_lag_ns, now_ns - due);
  }
  EXPECT_LE(max_lag_ns, static_cast<std::int64_t>(kBaseWaitS * 1e9));
}

}  // namespace
}  // namespace canyon::pipeline
