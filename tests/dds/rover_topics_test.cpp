// The rover's topics (idl/RoverPipeline.idl, dds/rover_msgs.hpp) over Fast DDS with the shipped profiles:
//  - the Solution adapter round-trips what a .pos file needs, bit for bit, and refuses malformed messages; so do
//    the VIO pose and time-sync adapters (the rover fed over DDS sees the files' numbers exactly);
//  - a subscriber that joins late gets every solution from its first one on, without a gap;
//  - a publisher that restarts (a rover restarted) is matched again and its solutions arrive;
//  - the monitor model's JSON line carries the schema's keys.

#include <atomic>
#include <chrono>
#include <limits>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>
#include <unistd.h>

#include "canyon/core/protection_level.hpp"
#include "canyon/dds/dds.hpp"
#include "canyon/dds/rover_msgs.hpp"
#include "canyon/pipeline/monitor_model.hpp"

#include "pipeline/fake_epochs.hpp"

namespace canyon::dds {
namespace {

int test_domain() {
  return 100 + static_cast<int>((::getpid() + 37) % 100);
}

pipeline::SolvedEpoch solved_item(std::uint64_t seq, const pipeline::LinkCounts& rover_link = {},
                                  const pipeline::LinkCounts& base_link = {}) {
  pipeline::IngestedEpoch item;
  item.seq = seq;
  item.rover_link = rover_link;
  item.base_link = base_link;
  item.rover.time = core::GpsTime{2300, 1000.0 + 0.2 * static_cast<double>(seq)};
  pipeline::EpochOutput out;
  out.solution.time = item.rover.time;
  out.solution.status = core::SolutionStatus::Fixed;
  out.solution.p_E_m = Eigen::Vector3d(-2694892.4607, -4297557.2541, 3854813.4188) +
                       Eigen::Vector3d::Constant(static_cast<double>(seq) * 1e-7);
  out.solution.P_E_m2 << 1e-4, 2e-6, 3e-6, 2e-6, 2e-4, 4e-6, 3e-6, 4e-6, 3e-4;
  out.solution.num_satellites = 17;
  out.solution.ratio = 12.345678901;
  out.solution.age_s = 0.2;
  out.ar_pruned = {core::SatelliteId{core::Constellation::Gps, 5}};
  return pipeline::testing::solved_epoch(std::move(item), out);
}

void wait_for(const std::function<bool()>& done, double timeout_s = 10.0) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!done() && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(std::chrono::milliseconds(5));
}

TEST(RoverMsgs, TimingCarriesTheDropCounts) {
  EpochContext context;
  context.rover_id = "r1";
  context.base_late = 3;
  context.malformed_samples = 5;
  context.vio_dropped = 7;
  context.vio_late = 11;
  const pipeline::SolvedEpoch item = solved_item(2, pipeline::LinkCounts{1, 2, 3, 4}, pipeline::LinkCounts{5, 6, 7, 8});
  const pipeline::TimingSample t = to_sample(to_msg_timing(item, context));
  EXPECT_EQ(t.rover_link.dropped_bytes, 1U);
  EXPECT_EQ(t.rover_link.undecodable, 4U);
  EXPECT_EQ(t.base_link.link_failures, 6U);
  EXPECT_EQ(t.base_link.bad_frames, 7U);
  EXPECT_EQ(t.seq, 2U);
  EXPECT_EQ(t.vio_dropped, 7U);
  EXPECT_EQ(t.vio_late, 11U);
  EXPECT_EQ(t.base_late, 3U);
  EXPECT_EQ(t.malformed_samples, 5U);
}

TEST(RoverMsgs, SolutionRoundTripsBitForBit) {
  const pipeline::SolvedEpoch item = solved_item(7);
  EpochContext context;
  context.rover_id = "r1";
  const msg::Solution m = to_msg_solution(item, context);
  auto s = from_msg(m);
  ASSERT_TRUE(s.ok()) << s.error().to_string();
  EXPECT_EQ(s->time.week, item.output->solution.time.week);
  EXPECT_EQ(s->time.tow_s, item.output->solution.time.tow_s);
  EXPECT_EQ(s->p_E_m, item.output->solution.p_E_m);
  EXPECT_EQ(s->P_E_m2, item.output->solution.P_E_m2);
  EXPECT_EQ(s->ratio, item.output->solution.ratio);
  EXPECT_EQ(s->status, core::SolutionStatus::Fixed);
  ASSERT_EQ(m.pruned().size(), 1U);
  EXPECT_EQ(m.pruned()[0].to_string(), "G05");
  // The protection levels go out with the solution, from its covariance (core/protection_level.hpp).
  const core::ProtectionLevels pl = core::protection_levels(item.output->solution.p_E_m, item.output->solution.P_E_m2);
  EXPECT_EQ(m.hpl_m(), pl.horizontal_m);
  EXPECT_EQ(m.vpl_m(), pl.vertical_m);
  EXPECT_GT(m.hpl_m(), 6.0 * 0.01);  // at least 6 sigma of the smallest axis (1 cm)
  EXPECT_NE(describe(m).find("HPL"), std::string::npos);

  // A partial fix (a float conditioned on fixed integer combinations) goes out as canyon's own status 8.
  pipeline::SolvedEpoch partial = solved_item(8);
  partial.output->solution.status = core::SolutionStatus::Float;
  partial.output->solution.fixed_combinations = 6;
  const msg::Solution partial_msg = to_msg_solution(partial, context);
  EXPECT_EQ(partial_msg.status(), core::kPartialFixStatus);
  auto partial_back = from_msg(partial_msg);
  ASSERT_TRUE(partial_back.ok()) << partial_back.error().to_string();
  EXPECT_EQ(partial_back->status, core::SolutionStatus::Float);
  EXPECT_EQ(core::exact_status(*partial_back), core::kPartialFixStatus);
  partial.output->solution.fixed_combinations = 0;
  EXPECT_EQ(to_msg_solution(partial, context).status(), 2);

  msg::Solution bad = m;
  bad.status(3);
  EXPECT_NE(from_msg(bad).error().message.find("status 3"), std::string::npos);
  bad = m;
  bad.pruned(std::vector<eprosima::fastrtps::fixed_string<4>>(200, "G01"));
  EXPECT_FALSE(from_msg(bad).ok());
  bad = m;
  bad.hpl_m(-1.0);
  EXPECT_NE(from_msg(bad).error().message.find("protection level"), std::string::npos);
}

TEST(RoverMsgs, VioPoseAndTimeSyncRoundTripBitForBitAndRefuseMalformed) {
  io::VioRecord r;
  r.t_ns = 1234567890123;
  r.T_OI.p = Eigen::Vector3d(1.25, -3.5, 0.125e-3);
  r.T_OI.q = Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2).normalized();
  core::Matrix6d a = core::Matrix6d::Random();
  r.covariance = a * a.transpose() + core::Matrix6d::Identity() * 1e-3;
  r.cross_previous = core::Matrix6d::Random() * 1e-4;
  const msg::VioPose m = to_msg(r, 42);
  EXPECT_EQ(m.sequence_number(), 42U);
  auto back = from_msg(m);
  ASSERT_TRUE(back.ok()) << back.error().to_string();
  EXPECT_EQ(back->t_ns, r.t_ns);
  EXPECT_EQ(back->T_OI.p, r.T_OI.p);
  EXPECT_EQ(back->T_OI.q.coeffs(), r.T_OI.q.coeffs());
  EXPECT_EQ(back->covariance, r.covariance);
  ASSERT_TRUE(back->cross_previous.has_value());
  EXPECT_EQ(*back->cross_previous, *r.cross_previous);
  r.cross_previous.reset();
  EXPECT_FALSE(from_msg(to_msg(r, 43))->cross_previous.has_value());

  msg::VioPose bad = m;
  bad.q_OI_xyzw({0.0, 0.0, 0.0, 0.1});
  EXPECT_NE(from_msg(bad).error().message.find("not a rotation"), std::string::npos);
  bad = m;
  bad.p_O_m({0.0, std::numeric_limits<double>::quiet_NaN(), 0.0});
  EXPECT_NE(from_msg(bad).error().message.find("not finite"), std::string::npos);
  bad = m;
  auto cov = bad.covariance_upper();
  cov[0] = -1.0;
  bad.covariance_upper(cov);
  EXPECT_NE(from_msg(bad).error().message.find("positive definite"), std::string::npos);

  const io::TimeSyncPair pair{987654321, core::GpsTime{2266, 316800.123456789}, 0};
  auto p = from_msg(to_msg(pair));
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(p->t_ns, pair.t_ns);
  EXPECT_EQ(p->time.week, 2266);
  EXPECT_EQ(p->time.tow_s, pair.time.tow_s);
  msg::TimeSyncSample out_of_range = to_msg(pair);
  out_of_range.gps_tow_s(700000.0);
  EXPECT_FALSE(from_msg(out_of_range).ok());
}

class RoverTopics : public ::testing::Test {
 protected:
  void SetUp() override {
    auto profiles = load_profiles("");
    ASSERT_TRUE(profiles.ok()) << profiles.error().to_string();
    auto p = DdsParticipant::create(test_domain(), profile::kParticipant);
    ASSERT_TRUE(p.ok()) << p.error().to_string();
    participant_ = std::move(*p);
    topic_ = "canyon/solution/test" + std::to_string(::getpid()) + "/" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name();
  }
  std::unique_ptr<DdsParticipant> participant_;
  std::string topic_;
};

TEST_F(RoverTopics, LateSubscriberGetsEverySolutionFromItsFirstOn) {
  auto writer = SolutionWriter::create(*participant_, topic_, profile::kSolutionWriter);
  ASSERT_TRUE(writer.ok()) << writer.error().to_string();
  EpochContext context;
  std::uint64_t seq = 0;
  const auto publish = [&](int n) {
    for (int i = 0; i < n; ++i) {
      msg::Solution m = to_msg_solution(solved_item(seq++), context);
      ASSERT_TRUE((*writer)->write(m));
    }
  };
  publish(20);  // nobody listens yet
  std::mutex mutex;
  std::vector<std::uint64_t> got;
  auto reader = SolutionReader::create(*participant_, topic_, profile::kSolutionReader, [&](msg::Solution&& m) {
    const std::lock_guard lock(mutex);
    got.push_back(m.sequence_number());
  });
  ASSERT_TRUE(reader.ok()) << reader.error().to_string();
  wait_for([&] { return (*writer)->matched() == 1 && (*reader)->matched() == 1; });
  ASSERT_EQ((*writer)->matched(), 1);
  publish(100);
  ASSERT_TRUE((*writer)->wait_for_acknowledgments(5.0));
  wait_for([&] {
    const std::lock_guard lock(mutex);
    return !got.empty() && got.back() == seq - 1;
  });
  const std::lock_guard lock(mutex);
  ASSERT_FALSE(got.empty());
  EXPECT_EQ(got.back(), seq - 1);
  for (std::size_t i = 1; i < got.size(); ++i) EXPECT_EQ(got[i], got[i - 1] + 1) << "gap at " << i;
  EXPECT_GE(got.size(), 100U);  // at least everything published after it matched
}

TEST_F(RoverTopics, RestartedPublisherIsMatchedAgain) {
  std::mutex mutex;
  std::vector<std::uint64_t> got;
  auto reader = SolutionReader::create(*participant_, topic_, profile::kSolutionReader, [&](msg::Solution&& m) {
    const std::lock_guard lock(mutex);
    got.push_back(m.sequence_number());
  });
  ASSERT_TRUE(reader.ok());
  EpochContext context;
  for (int run = 0; run < 2; ++run) {
    // A separate participant per run, as a rover process that exits and starts again.
    auto p = DdsParticipant::create(test_domain(), profile::kParticipant);
    ASSERT_TRUE(p.ok());
    auto writer = SolutionWriter::create(**p, topic_, profile::kSolutionWriter);
    ASSERT_TRUE(writer.ok());
    wait_for([&] { return (*writer)->matched() == 1; });
    ASSERT_EQ((*writer)->matched(), 1) << "run " << run;
    for (std::uint64_t seq = 0; seq < 50; ++seq) {
      msg::Solution m = to_msg_solution(solved_item(seq), context);
      ASSERT_TRUE((*writer)->write(m));
    }
    ASSERT_TRUE((*writer)->wait_for_acknowledgments(5.0));
    writer->reset();
    p->reset();
    wait_for([&] { return (*reader)->matched() == 0; });
    EXPECT_EQ((*reader)->matched(), 0) << "the reader still sees the stopped publisher";
  }
  const std::lock_guard lock(mutex);
  ASSERT_EQ(got.size(), 100U);
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], i % 50);
}

TEST(MonitorModel, JsonLineCarriesTheSchema) {
  pipeline::MonitorModel model(0);
  pipeline::TimingSample t;
  t.seq = 0;
  t.arrival_ns = 1000;
  for (std::size_t i = 0; i < 6; ++i) {
    t.enter_ns[i] = 2000 + static_cast<std::int64_t>(i) * 1000;
    t.exit_ns[i] = t.enter_ns[i] + 500;
  }
  t.correction_age_s = 0.2;
  t.alignment_rmse_m = 0.02;
  t.alignment_eigen_ratio = 0.5;
  t.malformed_samples = 4;
  model.add_timing(t);
  pipeline::SolutionSample s;
  s.seq = 0;
  s.status = 1;
  s.pruned = {"G05"};
  s.arrival_ns = 1000;
  s.received_ns = 9000;
  model.add_solution(s);
  s.seq = 3;  // two lost
  model.add_solution(s);
  const std::string j = model.json_line(2'000'000'000);
  for (
      const char* key :
      {"\"t_s\":2.000", "\"stages\":{\"ingest\":{\"p50_us\":0.5", "\"end_to_end\":{\"p50_us\":6.5",
       "\"correction_age_s\":0.200", "\"queues\":{",
       R"("drops":{"vio":0,"vio_late":0,"base_late":0,"malformed":4,"solutions":2},"links":{"rover":{"dropped_bytes":0,"failures":0,"bad_frames":0,"undecodable":0},"base":{"dropped_bytes":0)",
       "\"pruned\":[\"G05\"]", "\"alignment\":{\"rmse_m\":0.0200", "\"lever_arm_m\":[0.0000,0.0000,0.0000]"}) {
    EXPECT_NE(j.find(key), std::string::npos) << key << " not in " << j;
  }
  EXPECT_EQ(model.lost_solutions(), 2U);
}

}  // namespace
}  // namespace canyon::dds
