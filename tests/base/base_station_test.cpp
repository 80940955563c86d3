// `canyon base` without DDS: the shipped configuration loads, strict YAML errors name file, line and key, bad
// settings are refused with the rule, and the engine replays RINEX into RTCM 3 that decodes back to the base's
// observations, over its NTRIP caster and TCP server to canyon's clients.

#include "canyon/base/base_station.hpp"

#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>

#include "canyon/config/base_config.hpp"
#include "canyon/io/gnss_stream.hpp"
#include "canyon/io/rinex_obs.hpp"
#include "canyon/net/stream_client.hpp"

namespace canyon::base {
namespace {

namespace fs = std::filesystem;

Result<config::BaseConfig> parse(const std::string& text) {
  return config::parse_base_config(YAML::Load(text), "base.yaml");
}

// config/base.yaml, what a user runs: a u-blox receiver on a serial port, DDS and NTRIP out. It loads and validates
// without the receiver being there.
TEST(BaseConfigTest, ShippedFileLoadsAndRoundTrips) {
  const std::string path = std::string(CANYON_SOURCE_DIR) + "/config/base.yaml";
  auto config = config::load_base_config(path);
  ASSERT_TRUE(config.ok()) << config.error().to_string();
  EXPECT_EQ(config->validate(), "");
  EXPECT_EQ(config->input.kind, config::BaseInputKind::Ubx);
  EXPECT_EQ(config->input.source, config::BaseInputSource::Serial);
  EXPECT_EQ(config->input.path, "/dev/ttyACM0");  // a device: not resolved against the file's folder
  EXPECT_EQ(config->input.baud, 115200);
  EXPECT_FALSE(config->station.position_E_m.has_value());  // the user's surveyed position, documented in the file
  EXPECT_EQ(config->rtcm.msm, 7);
  EXPECT_TRUE(config->dds.enabled);
  EXPECT_TRUE(config->ntrip.enabled);
  EXPECT_EQ(config->ntrip.mountpoint, "CANYON");
  EXPECT_EQ(config->ntrip.port, 2101);
  auto again = config::parse_base_config(YAML::Load(config::to_yaml(*config)), "");
  ASSERT_TRUE(again.ok()) << again.error().to_string();
  EXPECT_EQ(*again, *config);
}

// tests/data/config/base.yaml, the replay of a recorded base from the shared datasets: its relative paths, resolved
// against its folder, name the dataset's files.
TEST(BaseConfigTest, DatasetFileLoadsAndRoundTrips) {
  const std::string path = std::string(CANYON_TEST_DATA_DIR) + "/config/base.yaml";
  auto config = config::load_base_config(path);
  ASSERT_TRUE(config.ok()) << config.error().to_string();
  EXPECT_EQ(config->validate(), "");
  EXPECT_EQ(config->station.id, 3034);
  EXPECT_EQ(config->input.kind, config::BaseInputKind::Rinex);
  EXPECT_EQ(config->input.source, config::BaseInputSource::File);
  EXPECT_EQ(config->rtcm.msm, 7);
  EXPECT_TRUE(config->dds.enabled);
  EXPECT_TRUE(config->ntrip.enabled);
  auto again = config::parse_base_config(YAML::Load(config::to_yaml(*config)), "");
  ASSERT_TRUE(again.ok()) << again.error().to_string();
  EXPECT_EQ(*again, *config);
  const fs::path data = fs::path(CANYON_SHARED_DATA_DIR) / "cssrlib-static-doy078";
  if (!fs::exists(data)) GTEST_SKIP() << "shared dataset not present: " << data << " (the paths were not checked)";
  const auto same_file = [](const fs::path& a, const fs::path& b) { return fs::exists(a) && fs::equivalent(a, b); };
  EXPECT_TRUE(same_file(config->input.path, data / "3034078M1.21O")) << config->input.path;
  ASSERT_EQ(config->input.nav.size(), 1U);
  EXPECT_TRUE(same_file(config->input.nav[0], data / "SEPT078M.21P")) << config->input.nav[0];
}

TEST(BaseConfigTest, UnknownKeysAndBadValuesNameFileLineAndKey) {
  auto typo = parse("station:\n  id: 5\n  posiiton: [1, 2, 3]\n");
  ASSERT_FALSE(typo.ok());
  EXPECT_EQ(typo.error().to_string(), "base.yaml:3: unknown key 'station.posiiton'");
  auto kind = parse("input:\n  kind: sbf\n");
  ASSERT_FALSE(kind.ok());
  EXPECT_NE(kind.error().to_string().find("base.yaml:2: 'input.kind' must be rinex, ubx or rtcm3"), std::string::npos);
  auto nested = parse("outputs:\n  ntrip:\n    prot: 2101\n");
  ASSERT_FALSE(nested.ok());
  EXPECT_EQ(nested.error().to_string(), "base.yaml:3: unknown key 'outputs.ntrip.prot'");
  auto type = parse("rtcm:\n  msm: seven\n");
  ASSERT_FALSE(type.ok());
  EXPECT_NE(type.error().to_string().find("'rtcm.msm' must be an integer"), std::string::npos);
  auto position = parse("station:\n  position: [1, 2]\n");
  ASSERT_FALSE(position.ok());
  EXPECT_NE(position.error().to_string().find("'station.position' must be [X, Y, Z]"), std::string::npos);
  auto time = parse("input:\n  approx_time: yesterday\n");
  ASSERT_FALSE(time.ok());
}

TEST(BaseConfigTest, ValidationNamesTheRule) {
  config::BaseConfig c;
  c.input.path = "x.obs";
  EXPECT_EQ(c.validate(), "");
  config::BaseConfig bad = c;
  bad.station.id = 5000;
  EXPECT_EQ(bad.validate(), "station.id must be within 0-4095");
  bad = c;
  bad.rtcm.msm = 3;
  EXPECT_NE(bad.validate().find("rtcm.msm"), std::string::npos);
  bad = c;
  bad.input.source = config::BaseInputSource::Ntrip;
  EXPECT_NE(bad.validate().find("input.kind rinex needs input.source file"), std::string::npos);
  bad.input.kind = config::BaseInputKind::Rtcm3;
  EXPECT_NE(bad.validate().find("input.host and input.port"), std::string::npos);
  bad = c;
  bad.dds.enabled = bad.ntrip.enabled = bad.tcp.enabled = false;
  EXPECT_EQ(bad.validate(), "at least one output (dds, ntrip, tcp, ros2) must be enabled");
  bad = c;
  bad.ntrip.user = "u";
  EXPECT_NE(bad.validate().find("go together"), std::string::npos);
  bad = c;
  bad.ntrip.mountpoint = "A/B";
  EXPECT_NE(bad.validate().find("mountpoint"), std::string::npos);
}

TEST(BaseStationTest, MissingInputFileIsAnErrorBeforeAnyOutputStarts) {
  config::BaseConfig c;
  c.input.path = "/nonexistent/base.obs";
  c.dds.enabled = false;
  c.ntrip.port = 0;
  auto base = BaseStation::create(c);
  ASSERT_FALSE(base.ok());
  EXPECT_NE(base.error().to_string().find("/nonexistent/base.obs"), std::string::npos);
}

/// Collects a client's bytes.
struct Collected {
  std::mutex mutex;
  std::vector<std::uint8_t> bytes;
};

TEST(BaseStationTest, ReplaysRinexToNtripAndTcpClientsAndSinks) {
  const fs::path obs = fs::path(CANYON_SHARED_DATA_DIR) / "cssrlib-static-doy078/3034078M1.21O";
  if (!fs::exists(obs)) GTEST_SKIP() << "shared datasets not found at " << CANYON_SHARED_DATA_DIR;
  config::BaseConfig c;
  c.station.id = 3034;
  c.input.path = obs.string();
  c.input.nav = {(fs::path(CANYON_SHARED_DATA_DIR) / "cssrlib-static-doy078/SEPT078M.21P").string()};
  c.input.pace = 0.0;
  c.dds.enabled = false;
  c.ntrip.bind = "127.0.0.1";
  c.ntrip.port = 0;
  c.tcp.enabled = true;
  c.tcp.bind = "127.0.0.1";
  c.tcp.port = 0;
  c.progress_interval_s = 0.0;
  std::vector<std::string> log;
  auto base = BaseStation::create(c, [&log](const std::string& line) { log.push_back(line); });
  ASSERT_TRUE(base.ok()) << base.error().to_string();
  std::vector<BaseFrame> sunk;
  (*base)->add_sink([&sunk](const BaseFrame& f) { sunk.push_back(f); });

  Collected ntrip;
  Collected tcp;
  net::StreamClientOptions no;
  no.port = (*base)->ntrip_port();
  no.mount = "CANYON";
  net::StreamClient ntrip_client(no, [&](std::span<const std::uint8_t> b) {
    const std::lock_guard lock(ntrip.mutex);
    ntrip.bytes.insert(ntrip.bytes.end(), b.begin(), b.end());
  });
  net::StreamClientOptions to;
  to.mode = net::StreamClientOptions::Mode::Tcp;
  to.port = (*base)->tcp_port();
  net::StreamClient tcp_client(to, [&](std::span<const std::uint8_t> b) {
    const std::lock_guard lock(tcp.mutex);
    tcp.bytes.insert(tcp.bytes.end(), b.begin(), b.end());
  });
  ASSERT_TRUE(ntrip_client.start().ok());
  ASSERT_TRUE(tcp_client.start().ok());
  ASSERT_TRUE((*base)->wait_for_clients(2, 10.0));
  ASSERT_TRUE((*base)->run().ok());

  const BaseStationStats s = (*base)->stats();
  EXPECT_EQ(s.epochs, 60U);
  ASSERT_EQ(sunk.size(), s.frames);
  std::vector<std::uint8_t> all;
  for (std::size_t k = 0; k < sunk.size(); ++k) {
    EXPECT_EQ(sunk[k].sequence, k);
    EXPECT_EQ(sunk[k].station_id, 3034);
    all.insert(all.end(), sunk[k].bytes.begin(), sunk[k].bytes.end());
  }
  EXPECT_EQ(all.size(), s.bytes);
  // Every byte reached both clients (run() flushes the servers before returning).
  auto wait = [](Collected& c, std::size_t n) {
    for (int k = 0; k < 200; ++k) {
      {
        const std::lock_guard lock(c.mutex);
        if (c.bytes.size() >= n) return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  };
  ASSERT_TRUE(wait(ntrip, all.size()));
  ASSERT_TRUE(wait(tcp, all.size()));
  ntrip_client.stop();
  tcp_client.stop();
  EXPECT_EQ(ntrip.bytes, all);
  EXPECT_EQ(tcp.bytes, all);

  // The stream decodes back to the base's epochs (RTCM cannot carry QZSS 1Z).
  io::GnssStreamOptions o;
  o.format = io::StreamFormat::Rtcm3;
  o.rtcm3.reference_time = core::GpsTime{2149, 475200.0};
  io::GnssStreamDecoder decoder(o);
  decoder.push(all);
  decoder.finish();
  auto original = io::read_rinex_obs(obs.string());
  ASSERT_TRUE(original.ok());
  int epochs = 0;
  while (auto e = decoder.pop_rtcm3_epoch()) {
    const core::ObsEpoch& ref = original->epochs.at(static_cast<std::size_t>(epochs++));
    EXPECT_NEAR(e->time - ref.time, 0.0, 1e-9);
    EXPECT_EQ(e->sats.size(), ref.sats.size());
  }
  EXPECT_EQ(epochs, 60);
  ASSERT_TRUE(decoder.rtcm3().station());
  EXPECT_EQ(decoder.rtcm3().station()->station_id, 3034);
  EXPECT_EQ(decoder.navigation().kepler.size(), 33U);
}

}  // namespace
}  // namespace canyon::base
