// The WAN link model: configured delay, jitter, loss, bandwidth, outage, duplication, reordering and corruption
// give the expected fates and rates; options parse strictly.

#include "canyon/netemu/link_model.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace canyon::netemu {
namespace {

constexpr std::int64_t kMs = 1'000'000;

TEST(LinkModel, DelayAndJitterStayInTheirBoundsAndKeepTheOrder) {
  LinkOptions o;
  o.delay_ms = 20.0;
  o.jitter_ms = 5.0;
  LinkModel link(o);
  std::int64_t previous = 0;
  double sum_ms = 0.0;
  constexpr int kPackets = 20000;
  for (int i = 0; i < kPackets; ++i) {
    const std::int64_t t = std::int64_t{i} * 10 * kMs;  // 100 Hz: far apart, so the order rule never binds
    const Verdict v = link.admit(t, 200);
    ASSERT_FALSE(v.drop);
    const double d_ms = static_cast<double>(v.release_ns - t) / kMs;
    EXPECT_GE(d_ms, 15.0 - 1e-9);
    EXPECT_LE(d_ms, 25.0 + 1e-9);
    EXPECT_GE(v.release_ns, previous);
    previous = v.release_ns;
    sum_ms += d_ms;
  }
  EXPECT_NEAR(sum_ms / kPackets, 20.0, 0.1);
}

TEST(LinkModel, LossRateMatches) {
  LinkOptions o;
  o.loss = 0.2;
  o.seed = 7;
  LinkModel link(o);
  int lost = 0;
  constexpr int kPackets = 50000;
  for (int i = 0; i < kPackets; ++i) lost += link.admit(std::int64_t{i} * kMs, 100).drop ? 1 : 0;
  EXPECT_NEAR(static_cast<double>(lost) / kPackets, 0.2, 0.01);
  EXPECT_EQ(link.counters().lost, static_cast<std::uint64_t>(lost));
}

TEST(LinkModel, BandwidthSerialisesAndTailDrops) {
  LinkOptions o;
  o.rate_kbps = 1000.0;  // 1 Mbit/s: a 1250-byte packet takes 10 ms
  o.queue_limit_ms = 100.0;
  LinkModel link(o);
  // A burst of 20 packets at once: releases 10 ms apart; from the 12th on the wait exceeds 100 ms.
  int dropped = 0;
  std::vector<std::int64_t> releases;
  for (int i = 0; i < 20; ++i) {
    const Verdict v = link.admit(0, 1250);
    if (v.drop) {
      EXPECT_TRUE(v.queue_full);
      ++dropped;
    } else {
      releases.push_back(v.release_ns);
    }
  }
  EXPECT_EQ(dropped, 9);
  for (std::size_t i = 0; i < releases.size(); ++i) {
    EXPECT_EQ(releases[i], static_cast<std::int64_t>(i + 1) * 10 * kMs);
  }
}

TEST(LinkModel, OutageDropsEverythingAndEnds) {
  LinkOptions o;
  o.delay_ms = 5.0;
  o.outage = true;
  LinkModel link(o);
  for (int i = 0; i < 100; ++i) EXPECT_TRUE(link.admit(std::int64_t{i} * kMs, 100).outage);
  o.outage = false;
  link.set_options(o);
  EXPECT_FALSE(link.admit(200 * kMs, 100).drop);
  EXPECT_EQ(link.counters().outage_drops, 100U);
}

TEST(LinkModel, DuplicationReorderingAndCorruptionRates) {
  LinkOptions o;
  o.delay_ms = 20.0;
  o.duplicate = 0.05;
  o.reorder = 0.1;
  o.reorder_ms = 15.0;
  o.corrupt = 0.02;
  LinkModel link(o);
  int dup = 0;
  int reordered = 0;
  int corrupt = 0;
  constexpr int kPackets = 40000;
  for (int i = 0; i < kPackets; ++i) {
    const Verdict v = link.admit(std::int64_t{i} * kMs, 100);
    dup += v.duplicate ? 1 : 0;
    corrupt += v.corrupt ? 1 : 0;
    if (v.reordered) {
      ++reordered;
      EXPECT_EQ(v.release_ns - std::int64_t{i} * kMs, 35 * kMs);  // later than the next packets: really out of order
    }
  }
  EXPECT_NEAR(dup / static_cast<double>(kPackets), 0.05, 0.005);
  EXPECT_NEAR(reordered / static_cast<double>(kPackets), 0.1, 0.01);
  EXPECT_NEAR(corrupt / static_cast<double>(kPackets), 0.02, 0.004);
}

TEST(LinkModel, SameSeedSameFates) {
  LinkOptions o;
  o.loss = 0.3;
  o.jitter_ms = 3.0;
  o.delay_ms = 10.0;
  LinkModel a(o);
  LinkModel b(o);
  for (int i = 0; i < 1000; ++i) {
    const Verdict va = a.admit(std::int64_t{i} * kMs, 64);
    const Verdict vb = b.admit(std::int64_t{i} * kMs, 64);
    ASSERT_EQ(va.drop, vb.drop);
    ASSERT_EQ(va.release_ns, vb.release_ns);
  }
}

TEST(LinkOptionsParse, ReadsKeysAndRefusesBadInput) {
  auto ok = parse_link_options("# the 20 km link\ndelay_ms = 20\njitter_ms=5\nloss=0.01 # one percent\n", "link.conf");
  ASSERT_TRUE(ok.ok()) << ok.error().to_string();
  EXPECT_EQ(ok->delay_ms, 20.0);
  EXPECT_EQ(ok->jitter_ms, 5.0);
  EXPECT_EQ(ok->loss, 0.01);
  auto round = parse_link_options(ok->to_text(), "text");
  ASSERT_TRUE(round.ok());
  EXPECT_EQ(*round, *ok);

  auto unknown = parse_link_options("delay_ms=1\ndelay=3\n", "link.conf");
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().line, 2);
  EXPECT_NE(unknown.error().message.find("unknown key 'delay'"), std::string::npos);
  EXPECT_FALSE(parse_link_options("loss=abc\n", "x").ok());
  EXPECT_FALSE(parse_link_options("loss\n", "x").ok());
  auto range = parse_link_options("loss=1.5\n", "x");
  ASSERT_FALSE(range.ok());
  EXPECT_EQ(range.error().message, "loss must be in [0, 1] (is 1.5)");
  EXPECT_FALSE(parse_link_options("delay_ms=2\njitter_ms=5\n", "x").ok());
  EXPECT_FALSE(parse_link_options("outage=2\n", "x").ok());
  EXPECT_FALSE(parse_link_options("delay_ms=-1\n", "x").ok());
}

}  // namespace
}  // namespace canyon::netemu
