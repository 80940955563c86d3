// The descriptor layer (options_table.hpp) on a small struct: one table reads, prints, compares and describes it;
// then the real tables: degrees read bit for bit as before, comparison key by key (not by printed text), and
// describe_*() defaults that read back as the defaults.

#include "canyon/config/options_table.hpp"

#include <cmath>
#include <cstdlib>
#include <functional>
#include <optional>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "canyon/config/base_config.hpp"
#include "canyon/config/process_config.hpp"
#include "canyon/config/rover_config.hpp"
#include "canyon/config/scenario_config.hpp"

namespace canyon::config {
namespace {

struct Inner {
  double gain_db = 2.0;
  int count = 3;
};

struct Toy {
  enum class Mode { Fast, Careful };
  double mask_rad = 15.0 * 0.017453292519943295;
  Mode mode = Mode::Fast;
  Inner inner;
  std::optional<Eigen::Vector3d> where_m;
  std::vector<std::string> files;
  std::size_t queue = 8;
  double scratch = 0.0;  ///< not a key: neither read, printed nor compared
};

const Table<Inner>& inner_table() {
  static const Table<Inner> table{{"count", "", "how many", at(&Inner::count)}};
  return table;
}

const Table<Toy>& toy_table() {
  static const Table<Toy> table{
      {"mask_deg", "deg", "elevation mask", at(&Toy::mask_rad), Degrees{}},
      {"mode", "", "fast | careful", at(&Toy::mode),
       Names<Toy::Mode>{{{Toy::Mode::Fast, "fast"}, {Toy::Mode::Careful, "careful"}}}},
      {"gain_db", "dB", "a nested member, flat in YAML", at(&Toy::inner, &Inner::gain_db)},
      {"where_m", "m", "optional position", at(&Toy::where_m), Optional<Vector3>{}},
      {"files", "", "paths relative to the file", at(&Toy::files), Paths{}},
      {"queue", "", "a count", at(&Toy::queue), Count{}},
      {"inner", "a section", at(&Toy::inner), inner_table()},
  };
  return table;
}

Result<Toy> read_toy(const std::string& yaml, const std::string& file = "/cfg/toy.yaml") {
  Toy toy;
  YamlMap map(YAML::Load(yaml), file);
  read_keys(toy_table(), map, toy);
  if (Status s = map.status(); !s) return s.error();
  return toy;
}

TEST(OptionsTable, ReadsMembersThroughTheirPathsAndConversions) {
  auto toy = read_toy("mask_deg: 12.3\nmode: careful\ngain_db: -1.5\nfiles: [a.nav, /abs/b.nav]\ninner: {count: 7}\n");
  ASSERT_TRUE(toy) << toy.error().to_string();
  EXPECT_EQ(toy->mask_rad, 12.3 * core::kDegToRad);  // bit for bit: deg * kDegToRad
  EXPECT_EQ(toy->mode, Toy::Mode::Careful);
  EXPECT_EQ(toy->inner.gain_db, -1.5);
  EXPECT_EQ(toy->inner.count, 7);
  EXPECT_EQ(toy->files, (std::vector<std::string>{"/cfg/a.nav", "/abs/b.nav"}));
  EXPECT_FALSE(toy->where_m.has_value());
  // Absent keys keep the member; an angle goes through degrees and back, as parse_angle_deg did.
  auto defaults = read_toy("{}");
  ASSERT_TRUE(defaults);
  EXPECT_EQ(defaults->mask_rad, Toy{}.mask_rad * core::kRadToDeg * core::kDegToRad);
  EXPECT_EQ(defaults->queue, 8U);
  auto where = read_toy("where_m: [1, 2, 3]\nqueue: -4\n");
  ASSERT_TRUE(where);
  ASSERT_TRUE(where->where_m.has_value());
  EXPECT_EQ(where->where_m->z(), 3.0);
  EXPECT_EQ(where->queue, 0U);
}

TEST(OptionsTable, UnknownKeysAndBadValuesNameTheFileTheLineAndTheKeyPath) {
  const auto error = [](const std::string& yaml) { return read_toy(yaml, "toy.yaml").error(); };
  const Error unknown = error("mode: fast\ninner:\n  count: 1\n  cuont: 2\n");
  EXPECT_EQ(unknown.message, "unknown key 'inner.cuont'");
  EXPECT_EQ(unknown.file, "toy.yaml");
  EXPECT_EQ(unknown.line, 4);
  EXPECT_EQ(error("gain_db: 1\nmode: quick\n").message, "'mode' must be fast or careful, not 'quick'");
  EXPECT_EQ(error("mode: quick\n").line, 1);
  EXPECT_EQ(error("where_m: [1, 2]\n").message, "'where_m' must be [x, y, z]");
  EXPECT_EQ(error("mask_deg: high\n").message, "'mask_deg' must be a number");
}

TEST(OptionsTable, PrintsInTableOrderAndReadsBackEqual) {
  Toy toy;
  toy.mode = Toy::Mode::Careful;
  toy.files = {"a.nav"};
  EXPECT_EQ(yaml_text(toy_table(), toy, Numbers::Digits12),
            "mask_deg: 15\nmode: careful\ngain_db: 2\nfiles: [a.nav]\nqueue: 8\ninner:\n  count: 3\n");
  toy.where_m = Eigen::Vector3d(0.1, 0.2, 1.0 / 3.0);
  const std::string twelve = yaml_text(toy_table(), toy, Numbers::Digits12);
  EXPECT_NE(twelve.find("where_m: [0.1, 0.2, 0.333333333333]\n"), std::string::npos) << twelve;
  const std::string shortest = yaml_text(toy_table(), toy, Numbers::Shortest);
  EXPECT_NE(shortest.find("where_m: [0.1, 0.2, 0.3333333333333333]\n"), std::string::npos) << shortest;
  auto again = read_toy(shortest, "");
  ASSERT_TRUE(again) << again.error().to_string();
  EXPECT_TRUE(equal_keys(toy_table(), *again, toy));
}

TEST(OptionsTable, ShortestNumbersReadBackTheSame) {
  EXPECT_EQ(shortest_number(600.0), "600");
  EXPECT_EQ(shortest_number(20000.0), "20000");
  EXPECT_EQ(shortest_number(-1234.5), "-1234.5");
  EXPECT_EQ(shortest_number(0.1), "0.1");
  EXPECT_EQ(shortest_number(5e-8), "5e-08");
  EXPECT_EQ(shortest_number(1.0 / 3.0), "0.3333333333333333");
  EXPECT_EQ(shortest_number(1e20), "1e+20");
  EXPECT_EQ(shortest_number(0.0), "0");
  // Random doubles over many magnitudes read back bit for bit.
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> mantissa(-10.0, 10.0);
  std::uniform_int_distribution<int> exponent(-30, 30);
  for (int i = 0; i < 20000; ++i) {
    const double v = mantissa(random) * std::pow(10.0, exponent(random));
    EXPECT_EQ(std::strtod(shortest_number(v).c_str(), nullptr), v) << shortest_number(v);
  }
}

TEST(OptionsTable, ComparesKeyByKey) {
  // One change per key of the table: each must make the structs differ; a member that is no key must not.
  const std::vector<std::function<void(Toy&)>> changes{
      [](Toy& t) { t.mask_rad = std::nextafter(t.mask_rad, 1.0); },
      [](Toy& t) { t.mode = Toy::Mode::Careful; },
      [](Toy& t) { t.inner.gain_db = 2.5; },
      [](Toy& t) { t.where_m = Eigen::Vector3d::Zero(); },
      [](Toy& t) { t.files.emplace_back("x"); },
      [](Toy& t) { t.queue = 9; },
      [](Toy& t) { t.inner.count = 4; },
  };
  ASSERT_EQ(changes.size(), describe_keys(toy_table(), Toy{}, Numbers::Digits12).size());
  for (std::size_t i = 0; i < changes.size(); ++i) {
    Toy changed;
    changes[i](changed);
    EXPECT_FALSE(equal_keys(toy_table(), Toy{}, changed)) << "change " << i;
  }
  Toy scratch;
  scratch.scratch = 1.0;
  EXPECT_TRUE(equal_keys(toy_table(), Toy{}, scratch));
}

TEST(OptionsTable, DescribesEveryKeyWithUnitDefaultAndDoc) {
  const auto keys = describe_keys(toy_table(), Toy{}, Numbers::Digits12);
  ASSERT_EQ(keys.size(), 7U);
  EXPECT_EQ(keys[0].path, "mask_deg");
  EXPECT_EQ(keys[0].unit, "deg");
  EXPECT_EQ(keys[0].default_value, "15");
  EXPECT_EQ(keys[0].doc, "elevation mask");
  EXPECT_EQ(keys[2].path, "gain_db");
  EXPECT_EQ(keys[3].default_value, "");  // unset optional
  EXPECT_EQ(keys[4].default_value, "[]");
  EXPECT_EQ(keys[6].path, "inner.count");
  const std::string text = format_descriptions(keys);
  EXPECT_NE(text.find("mask_deg     deg   15       elevation mask\n"), std::string::npos) << text;
  EXPECT_NE(text.find("where_m      m     (unset)  optional position\n"), std::string::npos) << text;
}

// ---------------------------------------------------------------------------------------------------------------
// The real tables.

TEST(OptionsTables, AnglesReadBitForBitAsBefore) {
  auto config =
      parse_process_config(YAML::Load("rtk: {elevation_mask_deg: 12.3}\nspp: {elevation_mask_deg: 7.7}\n"), "");
  ASSERT_TRUE(config) << config.error().to_string();
  EXPECT_EQ(config->rtk.elevation_mask_rad, 12.3 * core::kDegToRad);
  EXPECT_EQ(config->spp.elevation_mask_rad, 7.7 * core::kDegToRad);
  // An absent angle goes through degrees and back: (rad * kRadToDeg) * kDegToRad.
  EXPECT_EQ(config->rtk.ar_elevation_mask_rad,
            rtk::RtkOptions{}.ar_elevation_mask_rad * core::kRadToDeg * core::kDegToRad);
  // Printed as today: degrees at 12 digits.
  EXPECT_NE(to_yaml(*config).find("  elevation_mask_deg: 12.3\n"), std::string::npos);
  // Every tenth of a degree: another arithmetic (deg / kRadToDeg, deg * kPi / 180) differs on some of them.
  for (int tenths = 0; tenths < 900; ++tenths) {
    const std::string deg = std::to_string(tenths / 10) + "." + std::to_string(tenths % 10);
    auto c = parse_process_config(YAML::Load("rtk: {elevation_mask_deg: " + deg + "}\n"), "");
    ASSERT_TRUE(c) << c.error().to_string();
    ASSERT_EQ(c->rtk.elevation_mask_rad, std::stod(deg) * core::kDegToRad) << deg;
  }
}

TEST(OptionsTables, ComparisonIsByKeyNotByPrintedText) {
  ProcessConfig a;
  ProcessConfig b;
  b.rtk.elevation_mask_rad = std::nextafter(a.rtk.elevation_mask_rad, 1.0);
  EXPECT_EQ(to_yaml(a), to_yaml(b));  // 12 digits cannot show it
  EXPECT_FALSE(a == b);
  b = a;
  b.fusion.alignment.fit.max_rmse_m = 0.2;  // a nested fusion member, flat under fusion:
  EXPECT_FALSE(a == b);
  b = a;
  b.spp.max_iterations = 99;  // not a key: not compared
  EXPECT_TRUE(a == b);
  sim::Scenario s;
  sim::Scenario t;
  t.source_file = "elsewhere.yaml";
  EXPECT_TRUE(same_scenario(s, t));
  t.base_receiver.clock_drift_noise *= 1.0 + 1e-15;
  EXPECT_FALSE(same_scenario(s, t));
}

/// A YAML document setting every described key to its described default.
YAML::Node document_of(const std::vector<KeyDescription>& keys) {
  YAML::Node root(YAML::NodeType::Map);
  for (const KeyDescription& k : keys) {
    if (k.default_value.empty()) continue;  // unset optional
    YAML::Node node = root;
    std::string path = k.path;
    for (std::size_t dot = path.find('.'); dot != std::string::npos; dot = path.find('.')) {
      node.reset(node[path.substr(0, dot)]);
      path = path.substr(dot + 1);
    }
    node[path] = YAML::Load(k.default_value);
  }
  return root;
}

template <typename Describe>
void expect_unique_paths(const Describe& keys) {
  std::set<std::string> paths;
  for (const KeyDescription& k : keys) EXPECT_TRUE(paths.insert(k.path).second) << k.path;
  for (const KeyDescription& k : keys) EXPECT_FALSE(k.doc.empty()) << k.path;
}

TEST(OptionsTables, DescribedDefaultsReadBackAsTheDefaults) {
  const auto process = describe_process_config();
  expect_unique_paths(process);
  auto p = parse_process_config(document_of(process), "");
  ASSERT_TRUE(p) << p.error().to_string();
  EXPECT_TRUE(*p == ProcessConfig{});
  const auto rover = describe_rover_config();
  expect_unique_paths(rover);
  auto r = parse_rover_config(document_of(rover), "");
  ASSERT_TRUE(r) << r.error().to_string();
  EXPECT_TRUE(*r == RoverConfig{});
  const auto base = describe_base_config();
  expect_unique_paths(base);
  auto b = parse_base_config(document_of(base), "");
  ASSERT_TRUE(b) << b.error().to_string();
  EXPECT_TRUE(*b == BaseConfig{});
  const auto scenario = describe_scenario();
  expect_unique_paths(scenario);
  auto s = parse_scenario(document_of(scenario), "");
  ASSERT_TRUE(s) << s.error().to_string();
  EXPECT_TRUE(same_scenario(*s, sim::Scenario{}));
  // A few entries as a user sees them.
  const auto find = [](const std::vector<KeyDescription>& keys, const std::string& path) {
    for (const KeyDescription& k : keys) {
      if (k.path == path) return k;
    }
    return KeyDescription{};
  };
  EXPECT_EQ(find(process, "rtk.elevation_mask_deg").unit, "deg");
  EXPECT_EQ(find(process, "rtk.elevation_mask_deg").default_value, "15");
  EXPECT_EQ(find(process, "fusion.alignment_max_rmse_m").default_value, "0.1");
  EXPECT_EQ(find(process, "fusion.gate").default_value, "both");
  EXPECT_EQ(find(process, "rtk.glonass_ar").default_value, "off");
  EXPECT_EQ(find(process, "base_position").default_value, "");
  EXPECT_EQ(find(rover, "estimator.rtk.ar_mode").default_value, "continuous");
  EXPECT_EQ(find(base, "outputs.ntrip.port").default_value, "2101");
  EXPECT_EQ(find(scenario, "base_receiver.elevation_cutoff_deg").default_value, "5");
}

}  // namespace
}  // namespace canyon::config
