// Scenario files: the shipped ones load and document their defaults truthfully; bad files give clear errors naming
// the file, the line and the key; a scenario prints and parses back unchanged.

#include "canyon/config/scenario_config.hpp"

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>

#include "canyon/sim/simulator.hpp"

#include "io/rinex_test_util.hpp"

namespace canyon::config {
namespace {

namespace fs = std::filesystem;

const fs::path kScenarioDir = fs::path(CANYON_SOURCE_DIR) / "config" / "scenarios";

Result<sim::Scenario> parse(const std::string& text) {
  return parse_scenario(YAML::Load(text), "bad.yaml");
}

TEST(ScenarioConfigTest, ShippedScenariosLoadByName) {
  for (const char* name : {"open-sky", "light-blocked", "urban-moderate", "urban-severe"}) {
    auto file = find_scenario_file(name);
    ASSERT_TRUE(file.ok()) << file.error().to_string();
    auto scenario = load_scenario(*file);
    ASSERT_TRUE(scenario.ok()) << scenario.error().to_string();
    EXPECT_EQ(scenario->name, name);
  }
  auto severe = load_scenario((kScenarioDir / "urban-severe.yaml").string());
  ASSERT_TRUE(severe.ok());
  EXPECT_EQ(severe->city.height_mean_m, 55.0);
  EXPECT_EQ(severe->city.height_max_m, 81.0);
  EXPECT_EQ(severe->rover_rate_hz, 5.0);
  EXPECT_EQ(severe->base.distance_m, 20000.0);
  const auto missing = find_scenario_file("downtown-tokyo");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("urban-severe"), std::string::npos) << missing.error().to_string();
}

/// "key: value  # ... default D" lines of a shipped file: (dotted key path, D).
std::vector<std::pair<std::string, std::string>> documented_defaults(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::pair<std::string, std::string>> out;
  std::string line, section;
  const std::regex entry(R"(^( *)([a-z0-9_]+):[^#]*#.*default (.*)$)");
  const std::regex header(R"(^([a-z0-9_]+):)");
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_search(line, m, header)) section = m[1];
    if (!std::regex_match(line, m, entry)) continue;
    const std::string key = m[1].length() > 0 ? section + "." + m[2].str() : m[2].str();
    out.emplace_back(key, m[3]);
  }
  return out;
}

TEST(ScenarioConfigTest, DocumentedDefaultsAreTheDefaults) {
  // The default scenario, printed, gives the value of every key; each shipped file's "default X" must say the same.
  const YAML::Node defaults = YAML::Load(scenario_to_yaml(sim::Scenario{}));
  int checked = 0;
  for (const auto& entry : fs::directory_iterator(kScenarioDir)) {
    for (const auto& [key, documented] : documented_defaults(entry.path())) {
      if (key == "origin.lat_deg" || key == "origin.lon_deg" || key == "origin.height_m" || key == "origin") continue;
      const std::size_t dot = key.find('.');
      const YAML::Node value =
          dot == std::string::npos ? defaults[key] : defaults[key.substr(0, dot)][key.substr(dot + 1)];
      ASSERT_TRUE(value.IsDefined()) << entry.path() << ": " << key;
      const YAML::Node doc = YAML::Load(documented);
      if (value.IsSequence()) {
        ASSERT_TRUE(doc.IsSequence()) << key;
        ASSERT_EQ(doc.size(), value.size()) << key;
        for (std::size_t i = 0; i < doc.size(); ++i)
          EXPECT_EQ(doc[i].as<std::string>(), value[i].as<std::string>()) << key;
      } else {
        // Compare numerically where both are numbers, else as text.
        try {
          EXPECT_DOUBLE_EQ(doc.as<double>(), value.as<double>()) << entry.path() << ": " << key;
        } catch (const YAML::Exception&) {
          EXPECT_EQ(doc.as<std::string>(), value.as<std::string>()) << entry.path() << ": " << key;
        }
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 300);
}

TEST(ScenarioConfigTest, PrintsAndParsesBackEqual) {
  auto severe = load_scenario((kScenarioDir / "urban-severe.yaml").string());
  ASSERT_TRUE(severe.ok());
  severe->route.waypoints_N_m = {{0.0, 5.0}, {60.0, 5.0}};
  severe->seed = 123456789012ULL;
  const std::string text = scenario_to_yaml(*severe);
  auto again = parse_scenario(YAML::Load(text), "again.yaml");
  ASSERT_TRUE(again.ok()) << again.error().to_string();
  EXPECT_EQ(scenario_to_yaml(*again), text);
  // A truth section (as canyon simulate writes it) is accepted and ignored.
  auto with_truth = parse_scenario(YAML::Load(scenario_to_yaml(*severe, "  baseline_m: 20000.0\n")), "t.yaml");
  ASSERT_TRUE(with_truth.ok()) << with_truth.error().to_string();
  EXPECT_EQ(scenario_to_yaml(*with_truth), text);
}

TEST(ScenarioConfigTest, UnknownKeyNamesFileAndLine) {
  const auto r = parse("name: x\ncity:\n  street_width_m: 20\n  buliding_height_m: 40\n");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().file, "bad.yaml");
  EXPECT_EQ(r.error().line, 4);
  EXPECT_NE(r.error().message.find("unknown key 'city.buliding_height_m'"), std::string::npos) << r.error().message;
}

TEST(ScenarioConfigTest, NegativeHeightIsAnErrorAtItsLine) {
  const auto r = parse("name: x\ncity:\n  street_width_m: 20\n  height_min_m: -5\n");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().line, 4) << r.error().to_string();
  EXPECT_NE(r.error().message.find("city.height_min_m must be >= 0, not -5"), std::string::npos) << r.error().message;
  const auto mean = parse("city: {height_mean_m: 90, height_max_m: 81}\n");
  ASSERT_FALSE(mean.ok());
  EXPECT_NE(mean.error().message.find("city.height_mean_m must be in [10, 81]"), std::string::npos)
      << mean.error().message;
}

TEST(ScenarioConfigTest, RouteOutsideTheCityIsAnError) {
  const auto r = parse(
      "name: x\ncity:\n  blocks: [4, 4]\nroute:\n  speed_mps: 1.4\n  waypoints_m: [[0, 10], [120, 10], [900, 10]]\n");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().line, 6) << r.error().to_string();
  EXPECT_NE(r.error().message.find("route.waypoints_m[2] (east 900 m, north 10 m) is outside the city"),
            std::string::npos)
      << r.error().message;
  // A route through a building: found when the city is built.
  auto inside = parse("name: x\ncity: {blocks: [4, 4]}\nroute: {waypoints_m: [[0, 45], [60, 45]]}\n");
  ASSERT_TRUE(inside.ok()) << inside.error().to_string();
  io::test::TempDir tmp;
  const auto sim = sim::simulate(*inside, tmp.file("nav.rnx"));
  ASSERT_FALSE(sim.ok());
  EXPECT_NE(sim.error().message.find("the route enters a building"), std::string::npos) << sim.error().message;
  EXPECT_EQ(sim.error().file, "bad.yaml");
}

TEST(ScenarioConfigTest, BadValuesAndTypes) {
  for (const char* bad :
       {"duration_s: ten", "seed: -1", "start: \"2023-13-01 00:00:00\"", "constellation: {systems: [G, X]}",
        "constellation: {gps_signals: [1C, 1W]}", "constellation: {galileo_signals: [1C, 9Q]}",
        "city: {street_width_m: 0}", "route: {sidewalk_offset_m: 15}", "rover_receiver: {cn0_horizon_dbhz: 60}",
        "trees: {crown_top_m: 2}", "route: {waypoints_m: [[0, 0, 0], [1, 1, 1]]}", "vio: {t_IA_m: [0, 0]}",
        "atmosphere: {gradient_tecu_per_100km: [1]}", "origin: {lat_deg: 95}", "base: {rate_hz: 0}"}) {
    const auto r = parse(bad);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_EQ(r.error().file, "bad.yaml") << bad;
    EXPECT_GE(r.error().line, 1) << bad << ": " << r.error().to_string();
  }
}

}  // namespace
}  // namespace canyon::config
