// config/rover.yaml (a u-blox receiver, the base over DDS) and tests/data/config/rover.yaml (a replay of the shared
// datasets) load, print and read back equal; typos and broken rules are errors naming the key.

#include "canyon/config/rover_config.hpp"

#include <algorithm>
#include <filesystem>

#include <gtest/gtest.h>

#include "canyon/pipeline/cpu_affinity.hpp"

namespace canyon::config {
namespace {

// What a user runs: it loads and validates without the receiver being there.
TEST(RoverConfig, ShippedFileLoadsAndRoundTrips) {
  auto config = load_rover_config(std::string(CANYON_SOURCE_DIR) + "/config/rover.yaml");
  ASSERT_TRUE(config) << config.error().to_string();
  EXPECT_EQ(config->validate(), "");
  EXPECT_EQ(config->estimator.mode, ProcessMode::Rtk);
  EXPECT_EQ(config->rover, RoverInputKind::Ubx);
  EXPECT_EQ(config->rover_source, "serial:///dev/ttyACM0?baud=115200");
  EXPECT_EQ(config->base, RoverBaseSource::Dds);
  EXPECT_TRUE(config->stream_ephemerides);
  EXPECT_TRUE(config->estimator.nav.empty());  // the ephemerides come from the streams
  EXPECT_TRUE(config->estimator.rover_obs.empty());
  EXPECT_TRUE(config->estimator.base_obs.empty());
  EXPECT_TRUE(config->pipeline.threaded);
  auto again = parse_rover_config(YAML::Load(to_yaml(*config)), "printed");
  ASSERT_TRUE(again) << again.error().to_string();
  EXPECT_TRUE(*again == *config);
}

// The replay of the shared datasets: its relative paths, resolved against its folder, name the dataset's files.
TEST(RoverConfig, DatasetFileLoadsAndRoundTrips) {
  auto config = load_rover_config(std::string(CANYON_TEST_DATA_DIR) + "/config/rover.yaml");
  ASSERT_TRUE(config) << config.error().to_string();
  EXPECT_EQ(config->validate(), "");
  EXPECT_EQ(config->estimator.mode, ProcessMode::Rtk);
  EXPECT_EQ(config->rover, RoverInputKind::Rinex);
  EXPECT_EQ(config->base, RoverBaseSource::File);
  auto again = parse_rover_config(YAML::Load(to_yaml(*config)), "printed");
  ASSERT_TRUE(again) << again.error().to_string();
  EXPECT_TRUE(*again == *config);
  namespace fs = std::filesystem;
  const fs::path data = fs::path(CANYON_SHARED_DATA_DIR) / "instinct-spirent-rtk-sim";
  if (!fs::exists(data)) GTEST_SKIP() << "shared dataset not present: " << data << " (the paths were not checked)";
  const auto same_file = [](const fs::path& a, const fs::path& b) { return fs::exists(a) && fs::equivalent(a, b); };
  EXPECT_TRUE(same_file(config->estimator.rover_obs, data / "iono-Klob_tropo-Saast/Rover-dynamic_MO_Spirent.obs"))
      << config->estimator.rover_obs;
  EXPECT_TRUE(same_file(config->estimator.base_obs, data / "iono-Klob_tropo-Saast/Base-static_MO_Spirent.obs"))
      << config->estimator.base_obs;
  ASSERT_EQ(config->estimator.nav.size(), 1U);
  EXPECT_TRUE(same_file(config->estimator.nav[0], data / "RINEX_GN_Spirent.23N")) << config->estimator.nav[0];
}

TEST(RoverConfig, TyposAndBrokenRulesAreErrors) {
  const std::string estimator = "estimator: {mode: rtk, rover: r.obs, base: b.obs, nav: [n.rnx]}\n";
  const auto error = [](const std::string& yaml) {
    auto c = parse_rover_config(YAML::Load(yaml), "rover.yaml");
    if (!c) return c.error().to_string();
    return c->validate();
  };
  EXPECT_NE(error("rover_id: x\n").find("'estimator:'"), std::string::npos);
  EXPECT_NE(error(estimator + "input: {pase: 1}\n").find("pase"), std::string::npos);
  EXPECT_NE(error(estimator + "input: {base: udp}\n").find("file, dds, ntrip or tcp"), std::string::npos);
  EXPECT_NE(error(estimator + "pipeline: {queue_capacity: 0}\n").find("queue_capacity"), std::string::npos);
  EXPECT_NE(error(estimator + "dds: {domain: 300}\n").find("dds.domain"), std::string::npos);
  EXPECT_NE(error(estimator + "input: {pace: -1}\n").find("input.pace"), std::string::npos);
  EXPECT_NE(error("estimator: {mode: spp, rover: r.obs, nav: [n.rnx]}\n").find("rtk or fusion"), std::string::npos);
  EXPECT_NE(
      error("estimator: {mode: rtk, rover: r.obs, nav: [n.rnx], rtk: {ratio_treshold: 3}}\n").find("ratio_treshold"),
      std::string::npos);
  EXPECT_EQ(error("estimator: {mode: rtk, rover: r.obs, nav: [n.rnx]}\ninput: {base: dds}\n"), "");
}

TEST(RoverConfig, ReceiverAndNetworkInputs) {
  const auto parse = [](const std::string& yaml) { return parse_rover_config(YAML::Load(yaml), "/cfg/rover.yaml"); };
  const auto error = [&parse](const std::string& yaml) {
    auto c = parse(yaml);
    if (!c) return c.error().to_string();
    return c->validate();
  };
  // A u-blox rover from a file relative to the configuration, the base from NTRIP, ephemerides from the streams.
  auto c = parse(
      "estimator: {mode: rtk, nav: [], base_position: [1, 2, 3]}\n"
      "input: {rover: ubx, rover_source: 'file:logs/rover.ubx', base: ntrip, base_source: 'ntrip://u:p@h:2101/M',\n"
      "        link_attempts: 0, link_stall_timeout_s: 3}\n");
  ASSERT_TRUE(c) << c.error().to_string();
  EXPECT_EQ(c->validate(), "");
  EXPECT_EQ(c->rover, RoverInputKind::Ubx);
  EXPECT_EQ(c->rover_source, "file:/cfg/logs/rover.ubx");
  EXPECT_EQ(c->base, RoverBaseSource::Ntrip);
  EXPECT_EQ(c->link.attempts, 0);
  EXPECT_EQ(c->link.stall_timeout_s, 3.0);
  auto again = parse_rover_config(YAML::Load(to_yaml(*c)), "printed");
  ASSERT_TRUE(again) << again.error().to_string();
  EXPECT_TRUE(*again == *c);

  const std::string est = "estimator: {mode: rtk, rover: r.obs, nav: [n.rnx], base_position: [1, 2, 3]}\n";
  EXPECT_EQ(error(est + "input: {base: tcp, base_source: 'tcp://127.0.0.1:2102'}\n"), "");
  EXPECT_NE(error(est + "input: {base: tcp}\n").find("input.base_source is required"), std::string::npos);
  EXPECT_NE(error(est + "input: {base: ntrip, base_source: 'tcp://h:1'}\n").find("must be ntrip://"),
            std::string::npos);
  EXPECT_NE(error(est + "input: {rover: ubx, base: dds}\n").find("input.rover_source is required"), std::string::npos);
  EXPECT_NE(error(est + "input: {rover: sbf}\n").find("rinex or ubx"), std::string::npos);
  EXPECT_EQ(error(est + "input: {base: ntrip, base_source: 'ntrip://h:1/M', ntrip_gga_interval_s: 5}\n"), "");
  EXPECT_NE(
      error(est + "input: {base: tcp, base_source: 'tcp://h:1', ntrip_gga_interval_s: 5}\n").find("needs base ntrip"),
      std::string::npos);
  EXPECT_NE(error(est + "input: {base: ntrip, base_source: 'ntrip://h:1/M', ntrip_gga_interval_s: -1}\n")
                .find("input.ntrip_gga_interval_s"),
            std::string::npos);
  EXPECT_NE(error(est + "input: {base: dds, link_attempts: -1}\n").find("input.link_attempts"), std::string::npos);
  // A malformed address is an error naming the file, the line and the key.
  const std::string bad = error(est + "input:\n  rover: ubx\n  rover_source: 'usb:/dev/x'\n");
  EXPECT_NE(bad.find("/cfg/rover.yaml:4"), std::string::npos) << bad;
  EXPECT_NE(bad.find("input.rover_source"), std::string::npos) << bad;
  // No ephemerides anywhere.
  EXPECT_NE(error("estimator: {mode: rtk, rover: r.obs, base: b.obs, nav: []}\n").find("navigation file"),
            std::string::npos);
  EXPECT_NE(error("estimator: {mode: rtk, nav: [], base_position: [1, 2, 3]}\n"
                  "input: {rover: ubx, rover_source: 'file:r.ubx', base: dds, stream_ephemerides: false}\n")
                .find("navigation file"),
            std::string::npos);
}

TEST(RoverConfig, VioFromDds) {
  const auto error = [](const std::string& yaml) {
    auto c = parse_rover_config(YAML::Load(yaml), "rover.yaml");
    if (!c) return c.error().to_string();
    return c->validate();
  };
  const std::string fusion = "estimator: {mode: fusion, rover: r.obs, base: b.obs, nav: [n.rnx]}\n";
  auto c = parse_rover_config(YAML::Load(fusion + "input: {vio: dds, vio_wait_s: 0.5, vio_queue_poses: 100}\n"
                                                  "dds: {vio_topic: a/vio, timesync_topic: a/sync}\n"),
                              "rover.yaml");
  ASSERT_TRUE(c) << c.error().to_string();
  EXPECT_EQ(c->validate(), "");  // no vio.csv or timesync.csv needed
  EXPECT_EQ(c->vio, RoverVioSource::Dds);
  EXPECT_EQ(c->vio_wait_s, 0.5);
  EXPECT_EQ(c->vio_queue_poses, 100U);
  EXPECT_EQ(c->vio_topic, "a/vio");
  auto again = parse_rover_config(YAML::Load(to_yaml(*c)), "printed");
  ASSERT_TRUE(again) << again.error().to_string();
  EXPECT_TRUE(*again == *c);
  EXPECT_NE(error(fusion + "input: {vio: udp}\n").find("file, dds or ros2"), std::string::npos);
  // ROS 2 Odometry: no files needed either; the frames it expects are keys of ros2.
  auto ros2 = parse_rover_config(
      YAML::Load(fusion + "input: {vio: ros2}\nros2: {vio_topic: ov/odom, vio_frame_id: global, vio_child_frame_id: "
                          "imu0}\n"),
      "rover.yaml");
  ASSERT_TRUE(ros2) << ros2.error().to_string();
  EXPECT_EQ(ros2->validate(), "");
  EXPECT_EQ(ros2->vio, RoverVioSource::Ros2);
  EXPECT_EQ(ros2->ros2.vio_frame_id, "global");
  EXPECT_NE(error("estimator: {mode: rtk, rover: r.obs, base: b.obs, nav: [n.rnx]}\ninput: {vio: ros2}\n")
                .find("input.vio ros2 needs estimator.mode fusion"),
            std::string::npos);
  EXPECT_NE(error(fusion + "input: {vio: dds, vio_wait_s: -1}\n").find("input.vio_wait_s"), std::string::npos);
  EXPECT_NE(error(fusion + "input: {vio: dds, vio_queue_poses: 3}\n").find("input.vio_queue_poses"), std::string::npos);
  EXPECT_NE(error("estimator: {mode: rtk, rover: r.obs, base: b.obs, nav: [n.rnx]}\ninput: {vio: dds}\n")
                .find("needs estimator.mode fusion"),
            std::string::npos);
  EXPECT_NE(error(fusion).find("vio"), std::string::npos);  // from files, the files are required
}

TEST(RoverConfig, StageThreadCpuAffinity) {
  const std::string rtk = "estimator: {mode: rtk, rover: r.obs, base: b.obs, nav: [n.rnx]}\n";
  const auto parse = [](const std::string& yaml) { return parse_rover_config(YAML::Load(yaml), "rover.yaml"); };
  const auto error = [&parse](const std::string& yaml) {
    auto c = parse(yaml);
    if (!c) return c.error().to_string();
    return c->validate();
  };
  auto c = parse(rtk + "pipeline: {cpu_affinity: {ingest: [0], alignment: [1, 0, 1], ambiguity: [1]}}\n");
  ASSERT_TRUE(c) << c.error().to_string();
  EXPECT_EQ(c->validate(), "");
  EXPECT_TRUE(c->pipeline.pinned());
  EXPECT_EQ(c->pipeline.cpu_affinity[static_cast<std::size_t>(pipeline::Stage::Ingest)], std::vector<int>{0});
  EXPECT_EQ(c->pipeline.cpu_affinity[static_cast<std::size_t>(pipeline::Stage::Alignment)], (std::vector<int>{0, 1}));
  EXPECT_TRUE(c->pipeline.cpu_affinity[static_cast<std::size_t>(pipeline::Stage::TimeBridge)].empty());
  auto again = parse_rover_config(YAML::Load(to_yaml(*c)), "printed");
  ASSERT_TRUE(again) << again.error().to_string();
  EXPECT_TRUE(*again == *c);
  EXPECT_FALSE(parse(rtk)->pipeline.pinned());  // the default: the OS places every thread

  EXPECT_NE(error(rtk + "pipeline: {cpu_affinity: {alignmnet: [1]}}\n").find("pipeline.cpu_affinity.alignmnet"),
            std::string::npos);
  EXPECT_NE(error(rtk + "pipeline: {cpu_affinity: {update: [1.5]}}\n").find("integers in 0..1023"), std::string::npos);
  EXPECT_NE(error(rtk + "pipeline: {cpu_affinity: {update: [-1]}}\n").find("integers in 0..1023"), std::string::npos);
  EXPECT_NE(error(rtk + "pipeline: {cpu_affinity: {update: 1}}\n").find("pipeline.cpu_affinity.update"),
            std::string::npos);
  EXPECT_NE(error(rtk + "pipeline: {threaded: false, cpu_affinity: {update: [0]}}\n").find("threaded: true"),
            std::string::npos);
  // A CPU this process may not run on is found before the rover starts.
  auto far = parse(rtk + "pipeline: {cpu_affinity: {prediction: [1023]}}\n");
  ASSERT_TRUE(far) << far.error().to_string();
  EXPECT_EQ(far->validate(), "");
  EXPECT_NE(
      far->pipeline.unavailable_cpu().find("cpu_affinity.prediction: CPU 1023 is not one this process may run on"),
      std::string::npos);
  const std::vector<int> allowed = pipeline::allowed_cpus();
  const bool has_0_and_1 =
      std::binary_search(allowed.begin(), allowed.end(), 0) && std::binary_search(allowed.begin(), allowed.end(), 1);
  EXPECT_EQ(c->pipeline.unavailable_cpu().empty(), has_0_and_1);
}

}  // namespace
}  // namespace canyon::config
