#include "canyon/config/process_config.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "canyon/config/base_config.hpp"
#include "canyon/config/rover_config.hpp"
#include "canyon/core/constants.hpp"

namespace canyon::config {
namespace {

namespace fs = std::filesystem;

Result<ProcessConfig> parse(const std::string& text) {
  return parse_process_config(YAML::Load(text), "test.yaml");
}

// Every YAML file in config/ (what a user runs; scenarios/ has its own tests) is a process, rover or base
// configuration that loads (rover and base ones also validate: their devices need not be there), and none is bound to
// the developer's datasets: those live beside their tests, in tests/data/config/.
TEST(ProcessConfigTest, EveryShippedConfigLoads) {
  const fs::path config_dir = fs::path(CANYON_SOURCE_DIR) / "config";
  int processes = 0;
  std::vector<std::string> real_time;  // rover and base files
  for (const auto& entry : fs::directory_iterator(config_dir)) {
    if (entry.path().extension() != ".yaml") continue;
    const std::string path = entry.path().string();
    SCOPED_TRACE(path);
    std::ifstream in(path);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(text.find("shared/data"), std::string::npos) << "dataset-bound: it belongs in tests/data/config/";
    const YAML::Node node = YAML::LoadFile(path);
    if (node["mode"]) {
      auto config = load_process_config(path);
      ASSERT_TRUE(config.ok()) << config.error().to_string();
      ++processes;
    } else if (node["estimator"]) {
      auto config = load_rover_config(path);
      ASSERT_TRUE(config.ok()) << config.error().to_string();
      EXPECT_EQ(config->validate(), "");
      real_time.push_back(entry.path().filename().string());
    } else {  // anything else must be a base configuration (strict YAML: an unknown key is an error)
      auto config = load_base_config(path);
      ASSERT_TRUE(config.ok()) << config.error().to_string();
      EXPECT_EQ(config->validate(), "");
      real_time.push_back(entry.path().filename().string());
    }
  }
  EXPECT_GE(processes, 4);  // spp, rtk, rtk-urban, fusion
  std::sort(real_time.begin(), real_time.end());
  EXPECT_EQ(real_time, (std::vector<std::string>{"base.yaml", "rover.yaml"}));
}

// tests/data/config/spp-cssrlib-kinematic.yaml, a job on the shared datasets: it loads and validates, and its
// relative paths, resolved against its folder, name the dataset's files and the repository's out/.
TEST(ProcessConfigTest, DatasetConfigLoadsAndNamesTheDatasetsFiles) {
  auto config = load_process_config(std::string(CANYON_TEST_DATA_DIR) + "/config/spp-cssrlib-kinematic.yaml");
  ASSERT_TRUE(config.ok()) << config.error().to_string();
  EXPECT_EQ(config->mode, ProcessMode::Spp);
  EXPECT_EQ(config->validate(), "");
  EXPECT_EQ(fs::path(config->out).lexically_normal(),
            (fs::path(CANYON_SOURCE_DIR) / "out/spp-cssrlib-kinematic.pos").lexically_normal());
  const fs::path data = fs::path(CANYON_SHARED_DATA_DIR) / "cssrlib-kinematic-doy265";
  if (!fs::exists(data)) GTEST_SKIP() << "shared dataset not present: " << data << " (the paths were not checked)";
  const auto same_file = [](const fs::path& a, const fs::path& b) { return fs::exists(a) && fs::equivalent(a, b); };
  EXPECT_TRUE(same_file(config->rover_obs, data / "SEPT265G.21O")) << config->rover_obs;
  ASSERT_EQ(config->nav.size(), 1U);
  EXPECT_TRUE(same_file(config->nav[0], data / "SEPT2650.21P")) << config->nav[0];
}

TEST(ProcessConfigTest, DefaultsMatchTheDocumentedFiles) {
  // One source of defaults: each shipped file is its mode's process_defaults(), key for key.
  for (const auto& [file, mode] : {std::pair{"spp.yaml", ProcessMode::Spp}, std::pair{"rtk.yaml", ProcessMode::Rtk},
                                   std::pair{"fusion.yaml", ProcessMode::Fusion}}) {
    auto config = load_process_config(std::string(CANYON_SOURCE_DIR) + "/config/" + file);
    ASSERT_TRUE(config.ok()) << config.error().to_string();
    EXPECT_EQ(*config, process_defaults(mode)) << file;
    EXPECT_EQ(to_yaml(*config), to_yaml(process_defaults(mode))) << file;
  }
  // The fusion defaults are the RTK engine as the fusion runs it, not the rtk mode's.
  const ProcessConfig fusion = process_defaults(ProcessMode::Fusion);
  EXPECT_EQ(fusion.rtk.ar_mode, rtk::ArMode::FixAndHold);
  EXPECT_EQ(fusion.rtk.ionosphere, rtk::IonosphereModel::Estimate);
  EXPECT_TRUE(fusion.rtk.snr_weighting);
  EXPECT_EQ(process_defaults(ProcessMode::Rtk).rtk.ar_mode, rtk::ArMode::Continuous);
}

TEST(ProcessConfigTest, AFilesModeOrTheCommandLinesSetsTheDefaults) {
  // A sparse file takes the defaults of its mode: ...
  auto sparse = parse("mode: fusion\nrtk:\n  ratio_threshold: 2.5\n");
  ASSERT_TRUE(sparse.ok()) << sparse.error().to_string();
  ProcessConfig expected = process_defaults(ProcessMode::Fusion);
  expected.rtk.ratio_threshold = 2.5;
  EXPECT_EQ(*sparse, expected);
  // ... or of the command line's --mode, which overrides the file's.
  auto overridden = parse_process_config(YAML::Load("mode: rtk\n"), "test.yaml", ProcessMode::Fusion);
  ASSERT_TRUE(overridden.ok()) << overridden.error().to_string();
  EXPECT_EQ(*overridden, process_defaults(ProcessMode::Fusion));
  auto none = parse("rtk:\n  ratio_threshold: 2.5\n");
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(none->mode, ProcessMode::Spp);
  EXPECT_EQ(none->rtk.ar_mode, rtk::ArMode::Continuous);
  EXPECT_FALSE(parse("mode: fusoin\n").ok());
  EXPECT_EQ(mode_from_name("fusion"), ProcessMode::Fusion);
  EXPECT_EQ(mode_from_name("fusoin"), std::nullopt);
}

TEST(ProcessConfigTest, FusionOptionsParseValidateAndRoundTrip) {
  auto config = parse(R"(
mode: fusion
base: base.obs
vio: vio.csv
timesync: sync/timesync.csv
fusion: {gate: chi_square, prediction: constant_velocity, lever_arm_prior_m: [0.1, 0, 0.12], alignment_max_rmse_m: 0.05,
         vio_clock: gps, cn0_screen: true, false_fix_guard: false}
)");
  ASSERT_TRUE(config.ok()) << config.error().to_string();
  EXPECT_EQ(config->mode, ProcessMode::Fusion);
  EXPECT_EQ(config->vio, "vio.csv");
  EXPECT_EQ(config->timesync, "sync/timesync.csv");
  EXPECT_EQ(config->fusion.gates.kind, fusion::GateKind::ChiSquare);
  EXPECT_EQ(config->fusion.prediction.kind, fusion::Prediction::ConstantVelocity);
  EXPECT_DOUBLE_EQ(config->fusion.alignment.lever_arm_prior_m.z(), 0.12);
  EXPECT_DOUBLE_EQ(config->fusion.alignment.fit.max_rmse_m, 0.05);
  EXPECT_TRUE(config->fusion.vio_on_gps_time);
  EXPECT_TRUE(config->fusion.cn0.enabled);
  EXPECT_FALSE(config->fusion.guard.enabled);
  auto again = parse_process_config(YAML::Load(to_yaml(*config)), "");
  ASSERT_TRUE(again.ok()) << again.error().to_string();
  EXPECT_EQ(*again, *config);
  // Unknown keys and bad values are errors naming the key.
  for (const char* bad : {"fusion: {gate: sometimes}", "fusion: {prediction: imu}", "fusion: {alignment_max_fer: 2}",
                          "fusion: {lever_arm_prior_m: [1, 2]}", "fusion: {vio_clock: utc}", "fusion: {ratio: 3}",
                          "fusion: {alignment_max_rmse_m: -1}"}) {
    const auto r = parse(bad);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_NE(r.error().to_string().find("test.yaml"), std::string::npos) << r.error().to_string();
  }
  // What fusion needs.
  ProcessConfig c;
  c.mode = ProcessMode::Fusion;
  c.rover_obs = "r.obs";
  c.nav = {"n.nav"};
  c.out = "x.pos";
  c.base_obs = "b.obs";
  EXPECT_NE(c.validate().find("VIO file"), std::string::npos) << c.validate();
  c.vio = "vio.csv";
  EXPECT_NE(c.validate().find("time-sync file"), std::string::npos) << c.validate();
  c.fusion.vio_on_gps_time = true;
  EXPECT_EQ(c.validate(), "");
}

TEST(ProcessConfigTest, RtkOptionsParseAndRoundTrip) {
  auto config = parse(R"(
mode: rtk
base: /data/base.obs
base_position: [-3959400.631, 3385704.533, 3667523.111]
rtk: {ar_mode: fix_and_hold, frequencies: 1, systems: [G, R], glonass_ar: on, ionosphere: estimate, exclude: [R07]}
)");
  ASSERT_TRUE(config.ok()) << config.error().to_string();
  EXPECT_EQ(config->mode, ProcessMode::Rtk);
  EXPECT_EQ(config->rtk.ar_mode, rtk::ArMode::FixAndHold);
  EXPECT_EQ(config->rtk.observables.num_frequencies, 1);
  EXPECT_TRUE(config->rtk.glonass_ar);
  EXPECT_EQ(config->rtk.ionosphere, rtk::IonosphereModel::Estimate);
  ASSERT_TRUE(config->base_position_E_m.has_value());
  EXPECT_NEAR(config->base_position_E_m->x(), -3959400.631, 1e-6);
  auto again = parse_process_config(YAML::Load(to_yaml(*config)), "");
  ASSERT_TRUE(again.ok()) << again.error().to_string();
  EXPECT_EQ(*again, *config);
  for (const char* bad : {"rtk: {ar_mode: sometimes}", "rtk: {frequencies: 4}", "base_position: [1, 2]",
                          "rtk: {glonass_ar: maybe}", "rtk: {ionosphere: klobuchar}", "rtk: {ratio: 3}"}) {
    EXPECT_FALSE(parse(bad).ok()) << bad;
  }
}

// The RTK engine's single-point solution is the one `spp:` configures (it was left at SppOptions' defaults before:
// the satellite-exclusion experiment's excluded satellites still fed canyon rtk's prior), and an exclusion in either
// section holds for both.
TEST(ProcessConfigTest, RtkEngineUsesTheSppSectionAndBothExclusions) {
  auto config = parse(R"(
mode: rtk
base: /data/base.obs
spp: {elevation_mask_deg: 20, systems: [G], ionosphere: off, exclude: [G05]}
rtk: {systems: [G, E], exclude: [E11]}
)");
  ASSERT_TRUE(config.ok()) << config.error().to_string();
  const rtk::RtkOptions o = config->rtk_engine_options();
  EXPECT_NEAR(o.spp.elevation_mask_rad, 20.0 * core::kDegToRad, 1e-12);
  EXPECT_TRUE(o.spp.use_gps);
  EXPECT_FALSE(o.spp.use_galileo);
  EXPECT_FALSE(o.spp.ionosphere_klobuchar);
  const auto names = [](const std::vector<core::SatelliteId>& sats) {
    std::string out;
    for (const core::SatelliteId& s : sats) out += s.to_string() + " ";
    return out;
  };
  EXPECT_EQ(names(o.spp.excluded), "G05 E11 ");
  EXPECT_EQ(names(o.observables.excluded), "E11 G05 ");
  EXPECT_TRUE(o.observables.use_galileo);                      // the RTK's own systems stay
  EXPECT_EQ(names(config->rtk.observables.excluded), "E11 ");  // the sections themselves are not changed
}

TEST(ProcessConfigTest, PrintsAndParsesBackEqual) {
  auto config = parse(R"(
mode: spp
rover: /data/rover.obs
nav: [/data/a.nav, /data/b.nav]
out: /tmp/x.pos
output: {coordinates: ecef, time_format: calendar}
spp: {elevation_mask_deg: 10, systems: [G, E], ionosphere: off, raim_fde: false, exclude: [G05, E11]}
)");
  ASSERT_TRUE(config.ok()) << config.error().to_string();
  EXPECT_NEAR(config->spp.elevation_mask_rad, 10.0 * core::kDegToRad, 1e-12);
  EXPECT_FALSE(config->spp.use_glonass);
  EXPECT_TRUE(config->spp.use_galileo);
  EXPECT_EQ(config->spp.excluded.size(), 2U);
  EXPECT_EQ(config->coordinates, io::PosCoordinates::Ecef);
  auto again = parse_process_config(YAML::Load(to_yaml(*config)), "");
  ASSERT_TRUE(again.ok()) << again.error().to_string();
  EXPECT_EQ(*again, *config);
}

TEST(ProcessConfigTest, RelativePathsAreRelativeToTheFile) {
  auto config = parse_process_config(YAML::Load("rover: obs/r.obs\nnav: n.nav\n"), "/etc/canyon/x.yaml");
  ASSERT_TRUE(config.ok());
  EXPECT_EQ(config->rover_obs, "/etc/canyon/obs/r.obs");
  EXPECT_EQ(config->nav, std::vector<std::string>{"/etc/canyon/n.nav"});
}

struct BadConfig {
  const char* yaml;
  const char* expected_in_message;
  int line;
};

TEST(ProcessConfigTest, RejectsBadConfigsNamingKeyAndLine) {
  const BadConfig cases[] = {
      {"mode: spp\nrovr: a.obs\n", "unknown key 'rovr'", 2},
      {"spp:\n  elevation_mask_deg: 15\n  elev_mask: 10\n", "unknown key 'spp.elev_mask'", 3},
      {"spp:\n  elevation_mask_deg: high\n", "'spp.elevation_mask_deg' must be a number", 2},
      {"spp:\n  systems: [G, X]\n", "'spp.systems' has 'X'", 2},
      {"mode: ppp\n", "'mode' must be spp", 1},
      {"output:\n  coordinates: utm\n", "'output.coordinates' must be llh or ecef", 2},
      {"spp:\n  raim_fde: maybe\n", "'spp.raim_fde' must be true or false", 2},
      {"spp:\n  exclude: [G99]\n", "'spp.exclude' has 'G99'", 2},
      {"spp: 5\n", "'spp' must be a map", 1},
      {"- a\n- b\n", "top level must be a map", 1},
      {"rtk:\n  ionosphere: sometimes\n", "'rtk.ionosphere' must be off, estimate or auto", 2},
      // A second section or key of one name would be ignored (yaml-cpp reads the first): an error instead.
      {"rtk:\n  code_phase_ratio: 100\nrtk:\n  code_phase_ratio: 300\n", "duplicate key 'rtk'", 3},
      {"spp:\n  elevation_mask_deg: 15\n  elevation_mask_deg: 10\n", "duplicate key 'spp.elevation_mask_deg'", 3},
  };
  for (const auto& c : cases) {
    auto config = parse(c.yaml);
    ASSERT_FALSE(config.ok()) << c.yaml;
    EXPECT_NE(config.error().message.find(c.expected_in_message), std::string::npos)
        << c.yaml << " -> " << config.error().message;
    EXPECT_EQ(config.error().file, "test.yaml");
    EXPECT_EQ(config.error().line, c.line) << c.yaml;
  }
}

TEST(ProcessConfigTest, RejectsInvalidValues) {
  auto config = parse("spp:\n  elevation_mask_deg: 95\n");
  ASSERT_FALSE(config.ok());
  EXPECT_NE(config.error().message.find("elevation_mask_rad"), std::string::npos);
  auto none = parse("spp:\n  systems: []\n");
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().message.find("at least one system"), std::string::npos);
  for (const char* bad : {"mode: fusion\nrtk:\n  partial_hold_sigma_cyc: -0.1\n",
                          "mode: fusion\nrtk:\n  partial_hold_min_satellites: 3\n"}) {
    auto hold = parse(bad);
    ASSERT_FALSE(hold.ok()) << bad;
    EXPECT_NE(hold.error().message.find("partial_hold_"), std::string::npos) << hold.error().message;
  }
  auto hold = parse("mode: fusion\nrtk:\n  partial_hold_sigma_cyc: 0.2\n");
  ASSERT_TRUE(hold.ok()) << hold.error().to_string();
  EXPECT_EQ(hold->rtk.partial_hold_sigma_cyc, 0.2);
  EXPECT_EQ(hold->rtk.partial_hold_min_satellites, 10);
}

TEST(ProcessConfigTest, IonosphereIsAutoByDefaultAndEachModeParses) {
  auto defaults = parse("mode: rtk\n");
  ASSERT_TRUE(defaults.ok()) << defaults.error().to_string();
  EXPECT_EQ(defaults->rtk.ionosphere, rtk::IonosphereModel::Auto);
  EXPECT_EQ(defaults->rtk.iono_auto_baseline_km, 10.0);
  for (const auto& [text, model] :
       {std::pair{"off", rtk::IonosphereModel::Off}, std::pair{"estimate", rtk::IonosphereModel::Estimate},
        std::pair{"auto", rtk::IonosphereModel::Auto}}) {
    auto config = parse(std::string("mode: rtk\nrtk:\n  ionosphere: ") + text + "\n  iono_auto_baseline_km: 5\n");
    ASSERT_TRUE(config.ok()) << text;
    EXPECT_EQ(config->rtk.ionosphere, model);
    EXPECT_EQ(config->rtk.iono_auto_baseline_km, 5.0);
  }
  auto negative = parse("mode: rtk\nrtk:\n  iono_auto_baseline_km: -1\n");
  ASSERT_FALSE(negative.ok());
  EXPECT_NE(negative.error().message.find("iono_auto_baseline_km"), std::string::npos);
}

TEST(ProcessConfigTest, YamlSyntaxErrorNamesTheLine) {
  const fs::path path = fs::temp_directory_path() / "canyon_bad_syntax.yaml";
  std::ofstream(path) << "mode: spp\nspp: {elevation_mask_deg: 10\n";
  auto config = load_process_config(path.string());
  ASSERT_FALSE(config.ok());
  EXPECT_NE(config.error().message.find("YAML syntax error"), std::string::npos);
  EXPECT_EQ(config.error().file, path.string());
  EXPECT_GT(config.error().line, 0);
  auto missing = load_process_config("/nonexistent/canyon.yaml");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("cannot open"), std::string::npos);
}

}  // namespace
}  // namespace canyon::config
