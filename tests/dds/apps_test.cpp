// The application classes of the DDS programs, constructed and run in this process on a test domain:
//  - VioApp publishes a simulated run's VIO and TopicApp records it: the recorded vio.csv and timesync.csv carry the
//    same records;
//  - BaseApp replays a base RINEX of instinct-spirent-rtk-sim and TopicApp records every RTCM frame it sent;
//  - RoverApp (fusion, VIO over DDS from a VioApp) solves a short simulated run; every epoch is solved, the live VIO
//    received every pose and pair, and the solutions TopicApp records equal the rover's own .pos;
//  - stop() ends run() promptly, from another thread and from SIGTERM through StopSignals;
//  - a bad profile file, a deployment file without its participant and an unknown topic are clear errors with exit
//    status 2.

#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "canyon/commands/simulate.hpp"
#include "canyon/config/base_config.hpp"
#include "canyon/config/rover_config.hpp"
#include "canyon/config/scenario_config.hpp"
#include "canyon/dds/base_app.hpp"
#include "canyon/dds/rover_app.hpp"
#include "canyon/dds/stop_signals.hpp"
#include "canyon/dds/topic_app.hpp"
#include "canyon/dds/vio_app.hpp"
#include "canyon/io/vio_file.hpp"

namespace canyon::dds {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

int test_domain() {
  return 120 + static_cast<int>((::getpid() + 53) % 100);
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// The lines of a .pos that are records (not % headers).
std::vector<std::string> pos_records(const fs::path& path) {
  std::vector<std::string> records;
  std::istringstream in(read_text(path));
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] != '%') records.push_back(line);
  }
  return records;
}

/// Runs `run` on a thread; the exit status once joined.
class Running {
 public:
  explicit Running(std::function<int()> run) : thread_([this, run = std::move(run)] { status_ = run(); }) {}
  ~Running() {
    if (thread_.joinable()) thread_.join();
  }
  Running(const Running&) = delete;
  Running& operator=(const Running&) = delete;
  int join() {
    thread_.join();
    return status_;
  }

 private:
  int status_ = -1;
  std::thread thread_;
};

/// A 20 s urban-severe run (rover, base, nav, vio.csv, timesync.csv), simulated once for the suite.
class DdsApps : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    sim_ = fs::temp_directory_path() / ("canyon_dds_apps_" + std::to_string(::getpid()));
    fs::remove_all(sim_);
    auto scenario =
        config::load_scenario((fs::path(CANYON_SOURCE_DIR) / "config/scenarios/urban-severe.yaml").string());
    ASSERT_TRUE(scenario.ok()) << scenario.error().to_string();
    scenario->duration_s = 20.0;
    auto summary = commands::run_simulate(*scenario, sim_.string());
    ASSERT_TRUE(summary.ok()) << summary.error().to_string();
  }
  static void TearDownTestSuite() { fs::remove_all(sim_); }

  fs::path work() {
    fs::path dir = sim_ / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::create_directories(dir);
    return dir;
  }
  TopicOptions recorder(const std::string& topic, const fs::path& out) const {
    TopicOptions o;
    o.tool = TopicTool::Record;
    o.topic = topic;
    o.out = out.string();
    o.domain = domain_;
    o.duration_s = 120.0;
    return o;
  }
  VioOptions vio_node(double pace, int wait_readers) const {
    VioOptions o;
    o.vio = (sim_ / "vio.csv").string();
    o.timesync = (sim_ / "timesync.csv").string();
    o.pace = pace;
    o.domain = domain_;
    o.wait_readers = wait_readers;
    o.wait_timeout_s = 20.0;
    o.linger_s = 10.0;
    return o;
  }
  /// rover.yaml for the simulated run: fusion with the VIO over DDS, the base from its file.
  RoverOptions rover_options(const fs::path& dir, double pace, double vio_wait_s = 5.0) const {
    std::ofstream yaml(dir / "rover.yaml");
    yaml << "estimator:\n";
    std::istringstream fusion(read_text(fs::path(CANYON_SOURCE_DIR) / "config/fusion.yaml"));
    for (std::string line; std::getline(fusion, line);) yaml << "  " << line << "\n";
    yaml << "  rover: " << (sim_ / "rover.obs").string() << "\n"
         << "  base: " << (sim_ / "base.obs").string() << "\n"
         << "  nav: [" << (sim_ / "nav.rnx").string() << "]\n"
         << "  out: " << (dir / "rover.pos").string() << "\n"
         << "rover_id: apps-test\n"
         << "input: {pace: " << pace << ", base: file, vio: dds, vio_wait_s: " << vio_wait_s << "}\n"
         << "dds: {domain: " << domain_ << "}\n";
    yaml.close();
    RoverOptions o;
    o.config_file = (dir / "rover.yaml").string();
    auto config = config::load_rover_config(o.config_file);
    EXPECT_TRUE(config.ok()) << config.error().to_string();
    if (config) o.config = std::move(*config);
    EXPECT_EQ(o.config.validate(), "");
    o.wait_subscribers = 1;
    o.wait_timeout_s = 20.0;
    return o;
  }

  static fs::path sim_;
  int domain_ = test_domain();
};

fs::path DdsApps::sim_;

TEST_F(DdsApps, VioAppPublishesWhatTopicAppRecords) {
  const fs::path dir = work();
  TopicApp poses(recorder("canyon/vio", dir / "vio.csv"));
  TopicApp pairs(recorder("canyon/timesync", dir / "timesync.csv"));
  VioOptions node = vio_node(0.0, 1);
  node.linger_s = 1.0;
  VioApp vio(std::move(node));
  Running poses_run([&] { return poses.run(); });
  Running pairs_run([&] { return pairs.run(); });
  EXPECT_EQ(vio.run(), kExitOk);
  // The recorders stop once the node has gone (until_gone): the node lingers while they are matched.
  vio.stop();
  const auto sent = io::read_vio_csv((sim_ / "vio.csv").string());
  ASSERT_TRUE(sent.ok());
  const auto until = Clock::now() + std::chrono::seconds(10);
  while (poses.received() < static_cast<std::int64_t>(sent->records.size()) && Clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  poses.stop();
  pairs.stop();
  EXPECT_EQ(poses_run.join(), kExitOk);
  EXPECT_EQ(pairs_run.join(), kExitOk);
  const auto got = io::read_vio_csv((dir / "vio.csv").string());
  ASSERT_TRUE(got.ok()) << got.error().to_string();
  ASSERT_EQ(got->records.size(), sent->records.size());
  for (std::size_t i = 0; i < sent->records.size(); ++i) {
    EXPECT_EQ(got->records[i].t_ns, sent->records[i].t_ns) << i;
    EXPECT_EQ(got->records[i].T_OI.p, sent->records[i].T_OI.p) << i;
  }
  const auto sent_pairs = io::read_timesync_csv((sim_ / "timesync.csv").string());
  const auto got_pairs = io::read_timesync_csv((dir / "timesync.csv").string());
  ASSERT_TRUE(sent_pairs.ok() && got_pairs.ok());
  EXPECT_EQ(got_pairs->pairs.size(), sent_pairs->pairs.size());
}

TEST_F(DdsApps, BaseAppFramesReachTheRecorder) {
  const fs::path data = fs::path(CANYON_SHARED_DATA_DIR) / "instinct-spirent-rtk-sim";
  const fs::path obs = data / "iono-Klob_tropo-Saast/Base-static_MO_Spirent.obs";
  if (!fs::exists(obs)) GTEST_SKIP() << "shared datasets not found at " << CANYON_SHARED_DATA_DIR;
  const fs::path dir = work();
  std::ofstream(dir / "base.yaml") << "station: {id: 1}\n"
                                   << "input: {kind: rinex, source: file, path: " << obs.string() << ", nav: ["
                                   << (data / "RINEX_GN_Spirent.23N").string() << "], pace: 0}\n"
                                   << "outputs:\n  dds: {enabled: true, domain: " << domain_
                                   << ", topic: canyon/rtcm}\n  ntrip: {enabled: false}\n"
                                   << "log: {progress_interval_s: 0}\n";
  auto config = config::load_base_config((dir / "base.yaml").string());
  ASSERT_TRUE(config.ok()) << config.error().to_string();
  ASSERT_EQ(config->validate(), "");
  TopicApp frames(recorder("canyon/rtcm", dir / "base.rtcm3"));
  Running frames_run([&] { return frames.run(); });
  BaseOptions options;
  options.config = std::move(*config);
  options.wait_clients = 1;
  options.wait_timeout_s = 20.0;
  std::uint64_t sent = 0;
  {
    BaseApp base(std::move(options));
    EXPECT_EQ(base.run(), kExitOk);
    sent = base.stats().frames;
  }  // the base's writer goes: the recorder sees its publisher leave and stops
  EXPECT_EQ(frames_run.join(), kExitOk);
  EXPECT_GT(sent, 600U);
  EXPECT_EQ(static_cast<std::uint64_t>(frames.received()), sent);
  EXPECT_GT(fs::file_size(dir / "base.rtcm3"), 10000U);
}

TEST_F(DdsApps, RoverAppSolvesWithTheVioOverDdsAndPublishesItsSolutions) {
  const fs::path dir = work();
  TopicApp solutions(recorder("canyon/solution", dir / "recorded.pos"));
  RoverApp rover(rover_options(dir, 5.0));
  VioApp vio(vio_node(0.0, 1));
  Running solutions_run([&] { return solutions.run(); });
  Running vio_run([&] { return vio.run(); });
  EXPECT_EQ(rover.run(), kExitOk);
  vio.stop();
  EXPECT_EQ(vio_run.join(), kExitOk);
  EXPECT_EQ(rover.epochs(), 101U);  // 20 s at 5 Hz
  EXPECT_EQ(rover.solved(), 101U);
  const auto vio_counts = rover.live_vio_counts();
  ASSERT_TRUE(vio_counts.has_value());
  EXPECT_EQ(vio_counts->poses, 201U);
  EXPECT_EQ(vio_counts->pairs, 21U);
  EXPECT_GT(vio_counts->appended, 150U);
  const auto until = Clock::now() + std::chrono::seconds(10);
  while (solutions.received() < 101 && Clock::now() < until) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  solutions.stop();
  EXPECT_EQ(solutions_run.join(), kExitOk);
  const std::vector<std::string> published = pos_records(dir / "recorded.pos");
  EXPECT_EQ(published.size(), 101U);
  EXPECT_EQ(published, pos_records(dir / "rover.pos"));
}

TEST_F(DdsApps, StopEndsRunPromptly) {
  const fs::path dir = work();
  RoverOptions options = rover_options(dir, 1.0, 0.2);  // 20 s in real time; an epoch waits 0.2 s for its VIO
  options.wait_subscribers = 0;
  RoverApp rover(std::move(options));
  VioApp vio(vio_node(1.0, 0));
  TopicApp echo(recorder("canyon/solution", dir / "recorded.csv"));
  Running rover_run([&] { return rover.run(); });
  Running vio_run([&] { return vio.run(); });
  Running echo_run([&] { return echo.run(); });
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  const auto stopped = Clock::now();
  rover.stop();
  vio.stop();
  echo.stop();
  EXPECT_EQ(rover_run.join(), kExitOk);
  EXPECT_EQ(vio_run.join(), kExitOk);
  EXPECT_EQ(echo_run.join(), kExitOk);
  EXPECT_LT(Clock::now() - stopped, std::chrono::seconds(3));
  EXPECT_GT(rover.epochs(), 0U);
  EXPECT_LT(rover.epochs(), 101U);
}

/// What a program's main() does (run_app): SIGTERM blocked before any thread, the application constructed, the
/// signal forwarded to stop(). 0 if SIGTERM stopped run() within 5 s.
int stop_by_sigterm(VioOptions options) {
  const StopSignals signals;  // before any thread of this process: every thread inherits the mask
  std::atomic<int> stops{0};
  VioApp vio(std::move(options));
  const auto t0 = Clock::now();
  const StopSignals::Forwarding forwarding = signals.forward_to([&] {
    stops.fetch_add(1);
    vio.stop();
  });
  std::thread killer([] {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    ::kill(::getpid(), SIGTERM);  // to the process, as systemd and the shell send it
  });
  const int status = vio.run();
  killer.join();
  const bool prompt = Clock::now() - t0 < std::chrono::seconds(5);
  return status == kExitOk && stops.load() == 1 && prompt ? 0 : 1;
}

TEST_F(DdsApps, SigtermStopsTheApplicationThroughStopSignals) {
  // In a fresh process (re-executed, not forked): threads started before the mask was blocked, as earlier tests of
  // this process leave them (Fast DDS'), would take the signal and end the process.
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(std::exit(stop_by_sigterm(vio_node(0.5, 0))), ::testing::ExitedWithCode(0), "");  // 40 s at half speed
}

/// The AppError a construction throws.
template <typename App, typename Options>
std::optional<AppError> construction_error(Options options) {
  try {
    App app(std::move(options));
  } catch (const AppError& e) {
    return e;
  }
  return std::nullopt;
}

TEST_F(DdsApps, BadProfilesAndUnknownTopicsAreClearErrors) {
  const fs::path dir = work();
  TopicOptions missing = recorder("canyon/solution", dir / "x.pos");
  missing.profiles = (dir / "no-such-profiles.xml").string();
  auto e = construction_error<TopicApp>(missing);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->exit_status(), kExitUsage);
  EXPECT_NE(std::string(e->what()).find("cannot load the Fast DDS XML profiles"), std::string::npos) << e->what();

  std::ofstream(dir / "no-participant.xml")
      << "<?xml version=\"1.0\"?>\n<dds xmlns=\"http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles\"><profiles>"
         "<participant profile_name=\"other\"><rtps/></participant></profiles></dds>\n";
  VioOptions vio = vio_node(0.0, 0);
  vio.profiles = (dir / "no-participant.xml").string();
  e = construction_error<VioApp>(vio);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->exit_status(), kExitUsage);
  EXPECT_NE(std::string(e->what()).find("must define the participant profile 'canyon_deployment'"), std::string::npos)
      << e->what();

  TopicOptions echo = recorder("canyon/bogus", "");
  echo.tool = TopicTool::Echo;
  e = construction_error<TopicApp>(echo);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->exit_status(), kExitUsage);
  EXPECT_NE(std::string(e->what()).find("unknown topic 'canyon/bogus'"), std::string::npos) << e->what();
}

}  // namespace
}  // namespace canyon::dds
