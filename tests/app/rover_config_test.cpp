// config/rover.yaml loads, prints and reads back equal; typos and broken rules are errors naming the key.

#include "canyon/app/rover_config.hpp"

#include <gtest/gtest.h>

namespace canyon::app {
namespace {

TEST(RoverConfig, ShippedFileLoadsAndRoundTrips) {
  auto config = load_rover_config(std::string(CANYON_SOURCE_DIR) + "/config/rover.yaml");
  ASSERT_TRUE(config) << config.error().to_string();
  EXPECT_EQ(config->validate(), "");
  EXPECT_EQ(config->estimator.mode, ProcessMode::Rtk);
  EXPECT_TRUE(config->pipeline.threaded);
  auto again = parse_rover_config(YAML::Load(to_yaml(*config)), "printed");
  ASSERT_TRUE(again) << again.error().to_string();
  EXPECT_TRUE(*again == *config);
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
  EXPECT_NE(error(estimator + "input: {base: ntrip}\n").find("file or dds"), std::string::npos);
  EXPECT_NE(error(estimator + "pipeline: {queue_capacity: 0}\n").find("queue_capacity"), std::string::npos);
  EXPECT_NE(error(estimator + "dds: {domain: 300}\n").find("dds.domain"), std::string::npos);
  EXPECT_NE(error(estimator + "input: {pace: -1}\n").find("input.pace"), std::string::npos);
  EXPECT_NE(error("estimator: {mode: spp, rover: r.obs, nav: [n.rnx]}\n").find("rtk or fusion"), std::string::npos);
  EXPECT_NE(
      error("estimator: {mode: rtk, rover: r.obs, nav: [n.rnx], rtk: {ratio_treshold: 3}}\n").find("ratio_treshold"),
      std::string::npos);
  EXPECT_EQ(error("estimator: {mode: rtk, rover: r.obs, nav: [n.rnx]}\ninput: {base: dds}\n"), "");
}

}  // namespace
}  // namespace canyon::app
