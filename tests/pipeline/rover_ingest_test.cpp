// canyon rover's receiver input on the real u-blox M8P log of m8p-galway-20181004 (shared data; skipped when absent):
// every RXM-RAWX epoch and the SFRBX ephemerides come out of a file and, byte for byte the same, over TCP from
// canyon's stream server; a truncated log and corrupt packets are reported with their byte offsets and cost only
// the epochs they hit.

#include "canyon/pipeline/rover_ingest.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>

#include "canyon/io/rtcm3_station_stream.hpp"
#include "canyon/net/stream_server.hpp"

namespace canyon::pipeline {
namespace {

namespace fs = std::filesystem;

constexpr int kRoverEpochs = 1180;  // the dataset README: 15:33:40.987-15:53:19.987 GPST at 1 Hz

fs::path rover_log() {
  return fs::path(CANYON_SHARED_DATA_DIR) / "m8p-galway-20181004/20181004_rover-20181004-1532.ubx.gz";
}

#define REQUIRE_ROVER_LOG() \
  if (!fs::exists(rover_log())) GTEST_SKIP() << "shared dataset not present: " << rover_log()

io::ObsFilter all_signals() {
  io::ObsFilter f;
  EXPECT_TRUE(f.systems.set_from_letters({"G", "R", "E", "C", "J"}));
  return f;
}

struct Drained {
  std::vector<core::ObsEpoch> epochs;
  std::size_t ephemerides = 0;
  std::vector<std::string> warnings;
  std::string error;
};

Drained drain(const LinkAddress& address, const LinkOptions& options = {}) {
  Drained d;
  auto link = ByteLink::open(address, options, {});
  if (!link) {
    d.error = link.error().to_string();
    return d;
  }
  ReceiverStream stream(std::move(*link), all_signals(), [&d](const std::string& w) { d.warnings.push_back(w); });
  for (;;) {
    auto epoch = stream.next([] { return false; });
    if (!epoch) {
      d.error = epoch.error().to_string();
      break;
    }
    if (!*epoch) break;
    d.epochs.push_back(std::move(**epoch));
    if (auto nav = stream.take_navigation()) d.ephemerides += nav->kepler.size() + nav->glonass.size();
  }
  return d;
}

fs::path write_temp(const std::string& name, const std::vector<std::uint8_t>& bytes) {
  fs::path path = fs::temp_directory_path() / name;
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return path;
}

bool same_epochs(const std::vector<core::ObsEpoch>& a, const std::vector<core::ObsEpoch>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!(a[i].time == b[i].time) || a[i].sats.size() != b[i].sats.size()) return false;
    for (std::size_t s = 0; s < a[i].sats.size(); ++s) {
      const auto& x = a[i].sats[s];
      const auto& y = b[i].sats[s];
      if (!(x.sat == y.sat) || x.signals.size() != y.signals.size()) return false;
      for (std::size_t k = 0; k < x.signals.size(); ++k) {
        const auto same = [](double u, double v) { return u == v || (std::isnan(u) && std::isnan(v)); };
        if (!same(x.signals[k].pseudorange_m, y.signals[k].pseudorange_m) ||
            !same(x.signals[k].carrier_phase_cyc, y.signals[k].carrier_phase_cyc))
          return false;
      }
    }
  }
  return true;
}

TEST(ReceiverStream, EveryRawxEpochAndTheEphemeridesOfARealLog) {
  REQUIRE_ROVER_LOG();
  const Drained d = drain(*LinkAddress::parse("file:" + rover_log().string()));
  EXPECT_EQ(d.error, "");
  EXPECT_TRUE(d.warnings.empty()) << d.warnings.front();
  ASSERT_EQ(static_cast<int>(d.epochs.size()), kRoverEpochs);
  EXPECT_NEAR(d.epochs.back().time - d.epochs.front().time, kRoverEpochs - 1.0, 1e-6);
  EXPECT_GE(d.ephemerides, 10u);  // GPS and GLONASS ephemerides from SFRBX
  for (const core::ObsEpoch& e : d.epochs) ASSERT_GE(e.sats.size(), 4u);
}

TEST(ReceiverStream, FilterKeepsWhatARinexReaderWould) {
  REQUIRE_ROVER_LOG();
  auto link = ByteLink::open(*LinkAddress::parse("file:" + rover_log().string()), {}, {});
  ASSERT_TRUE(link);
  io::ObsFilter gps_only;
  ASSERT_TRUE(gps_only.systems.set_from_letters({"G"}));
  ReceiverStream stream(std::move(*link), gps_only, {});
  auto epoch = stream.next([] { return false; });
  ASSERT_TRUE(epoch && *epoch);
  ASSERT_FALSE((*epoch)->sats.empty());
  for (const core::SatelliteObs& s : (*epoch)->sats) EXPECT_EQ(s.sat.system, core::Constellation::Gps);
}

TEST(ReceiverStream, TcpDeliversTheSameEpochsAsTheFileThenTheLinkEndsInAnError) {
  REQUIRE_ROVER_LOG();
  auto bytes = io::read_binary_file(rover_log().string());
  ASSERT_TRUE(bytes);
  net::StreamServerOptions o;
  o.bind_host = "127.0.0.1";
  o.max_client_buffer_bytes = bytes->size() + 1;
  auto server = net::StreamServer::start(o);
  ASSERT_TRUE(server) << server.error().to_string();
  LinkOptions options;
  options.attempts = 1;
  options.backoff_min_s = 0.1;
  options.stall_timeout_s = 2.0;
  const std::string url = "tcp://127.0.0.1:" + std::to_string((*server)->port());
  std::thread peer([&] {  // serves the log once a client is there, then goes away
    for (int i = 0; i < 200 && (*server)->stats().clients == 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    (*server)->publish("", *bytes);
    for (int i = 0; i < 500 && (*server)->stats().pending_bytes > 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    (*server)->stop();
  });
  const Drained over_tcp = drain(*LinkAddress::parse(url), options);
  peer.join();
  const Drained from_file = drain(*LinkAddress::parse("file:" + rover_log().string()));
  EXPECT_TRUE(same_epochs(over_tcp.epochs, from_file.epochs))
      << over_tcp.epochs.size() << " epochs over TCP, " << from_file.epochs.size() << " from the file; "
      << over_tcp.error;
  EXPECT_EQ(over_tcp.ephemerides, from_file.ephemerides);
  EXPECT_NE(over_tcp.error.find(url), std::string::npos) << over_tcp.error;
  EXPECT_NE(over_tcp.error.find("link lost"), std::string::npos) << over_tcp.error;
}

TEST(ReceiverStream, TruncatedAndCorruptLogsCostOnlyTheEpochsTheyHit) {
  REQUIRE_ROVER_LOG();
  auto bytes = io::read_binary_file(rover_log().string());
  ASSERT_TRUE(bytes);
  // Truncated in the middle of the log, inside a packet.
  std::vector<std::uint8_t> half(bytes->begin(), bytes->begin() + static_cast<std::ptrdiff_t>(bytes->size() / 2));
  const fs::path truncated = write_temp("canyon_rover_truncated.ubx", half);
  const Drained t = drain(*LinkAddress::parse("file:" + truncated.string()));
  EXPECT_EQ(t.error, "");
  EXPECT_GT(t.epochs.size(), 400u);
  EXPECT_LT(static_cast<int>(t.epochs.size()), kRoverEpochs);

  // Corrupt: the payload of an RXM-RAWX packet a third into the log overwritten. Its checksum fails, the framer
  // resynchronises, the warning names the byte offset; that epoch is lost, no other.
  std::vector<std::uint8_t> corrupt = *bytes;
  const std::array<std::uint8_t, 4> rawx = {0xb5, 0x62, 0x02, 0x15};
  const auto hit = std::search(corrupt.begin() + static_cast<std::ptrdiff_t>(corrupt.size() / 3), corrupt.end(),
                               rawx.begin(), rawx.end());
  ASSERT_NE(hit, corrupt.end());
  for (std::size_t i = 0; i < 32; ++i) *(hit + 10 + static_cast<std::ptrdiff_t>(i)) ^= 0x5a;
  const fs::path damaged = write_temp("canyon_rover_corrupt.ubx", corrupt);
  const Drained c = drain(*LinkAddress::parse("file:" + damaged.string()));
  EXPECT_EQ(c.error, "");
  ASSERT_FALSE(c.warnings.empty()) << c.epochs.size() << " epochs";
  EXPECT_NE(c.warnings.front().find("byte "), std::string::npos) << c.warnings.front();
  EXPECT_NE(c.warnings.front().find(damaged.string()), std::string::npos) << c.warnings.front();
  EXPECT_EQ(static_cast<int>(c.epochs.size()), kRoverEpochs - 1);
  fs::remove(truncated);
  fs::remove(damaged);
}

}  // namespace
}  // namespace canyon::pipeline

namespace canyon::pipeline {
namespace {

/// A streamed base (instinct-spirent-rtk-sim's base RINEX as RTCM 3 MSM7, one base epoch per poll) whose 1005 starts
/// only at its 5th epoch and moves by 1 m at its 20th: the rover epochs before the first 1005 go on without the base
/// (counted), the first with it carries the position, the next ones do not (unchanged), the move is handed on.
TEST(RoverIngest, StreamedBasePositionComesFromThe1005AndEpochsBeforeItGoOnWithoutTheBase) {
  const fs::path data = fs::path(CANYON_SHARED_DATA_DIR) / "instinct-spirent-rtk-sim/iono-Klob_tropo-Saast";
  if (!fs::exists(data)) GTEST_SKIP() << "shared dataset not present: " << data;
  io::ObsFilter filter = all_signals();
  auto base_file = io::read_rinex_obs((data / "Base-static_MO_Spirent.obs").string(), filter);
  ASSERT_TRUE(base_file) << base_file.error().to_string();
  io::Rtcm3StationStreamOptions options;
  options.station_interval_s = 1.0;
  options.send_ephemerides = false;
  io::Rtcm3StationStream encoder(options);
  io::rtcm3::StationPosition station;
  station.arp_E_m = Eigen::Vector3d(4157177.0658, 671230.4766, 4774767.0311);
  std::vector<std::vector<std::uint8_t>> per_epoch;  // the frames of each base epoch, concatenated
  for (std::size_t k = 0; k < 30 && k < base_file->epochs.size(); ++k) {
    if (k == 4) encoder.set_station(station);
    if (k == 19) {
      station.arp_E_m.x() += 1.0;
      encoder.set_station(station);
    }
    auto frames = encoder.epoch(base_file->epochs[k]);
    ASSERT_TRUE(frames) << frames.error().to_string();
    std::vector<std::uint8_t> bytes;
    for (const io::Rtcm3Frame& f : *frames) bytes.insert(bytes.end(), f.bytes.begin(), f.bytes.end());
    per_epoch.push_back(std::move(bytes));
  }
  auto rover = ObservationStream::open((data / "Rover-dynamic_MO_Spirent.obs").string(), filter);
  ASSERT_TRUE(rover) << rover.error().to_string();
  RoverInput rover_input;
  rover_input.rinex.emplace(std::move(*rover));
  BaseInput base;
  std::size_t next = 0;
  base.poll = [&](std::int64_t /*timeout_us*/, LiveBaseCursor& cursor) {
    if (next == per_epoch.size()) return false;
    cursor.push(per_epoch[next++], 0);
    return true;
  };
  RoverIngestOptions ingest_options;
  ingest_options.pace = 0.0;
  ingest_options.base_position_from_stream = true;
  std::vector<std::string> warnings;
  RoverIngest ingest(
      std::move(rover_input), std::move(base), ingest_options, [] { return false; },
      [&](const std::string& w) { warnings.push_back(w); });
  std::vector<IngestedEpoch> items;
  for (int k = 0; k < 25; ++k) {
    auto item = ingest.next();
    ASSERT_TRUE(item) << item.error().to_string();
    ASSERT_TRUE(item->has_value());
    items.push_back(std::move(**item));
  }
  for (int k = 0; k < 4; ++k) {
    EXPECT_FALSE(items[static_cast<std::size_t>(k)].base.has_value()) << k;
    EXPECT_FALSE(items[static_cast<std::size_t>(k)].base_position_E_m.has_value()) << k;
  }
  ASSERT_TRUE(items[4].base.has_value());
  ASSERT_TRUE(items[4].base_position_E_m.has_value());
  EXPECT_LT((*items[4].base_position_E_m - Eigen::Vector3d(4157177.0658, 671230.4766, 4774767.0311)).norm(), 1e-4);
  for (int k = 5; k < 19; ++k) {
    EXPECT_TRUE(items[static_cast<std::size_t>(k)].base.has_value()) << k;
    EXPECT_FALSE(items[static_cast<std::size_t>(k)].base_position_E_m.has_value()) << k;
  }
  ASSERT_TRUE(items[19].base_position_E_m.has_value());
  EXPECT_NEAR(items[19].base_position_E_m->x() - items[4].base_position_E_m->x(), 1.0, 1e-4);
  EXPECT_EQ(ingest.base_without_position(), 4U);
  ASSERT_TRUE(ingest.streamed_base_position().has_value());
  ASSERT_EQ(warnings.size(), 2U);
  EXPECT_NE(warnings[0].find("no base position yet"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[1].find("moved 1.000 m"), std::string::npos) << warnings[1];
}

}  // namespace
}  // namespace canyon::pipeline
