// RtcmFrame over DDS: the IDL adapter round-trips and refuses what is not one RTCM 3 frame; canyon-base publishes
// every frame of a replayed base to several subscribers, in order, and a reader notices when the base goes quiet
// (deadline of the QoS profile).

#include "canyon/dds/rtcm_frame.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <thread>

#include <gtest/gtest.h>
#include <unistd.h>

#include "canyon/dds/dds.hpp"
#include "canyon/io/rtcm3.hpp"

namespace canyon::dds {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

base::BaseFrame sample_frame() {
  std::vector<std::uint8_t> payload(40, 0x5A);
  payload[0] = static_cast<std::uint8_t>(1077 >> 4);
  payload[1] = static_cast<std::uint8_t>((1077 & 0xF) << 4);
  base::BaseFrame f;
  f.sequence = 42;
  f.message_number = 1077;
  f.station_id = 3034;
  f.epoch_time = core::GpsTime{2149, 475200.0};
  f.bytes = *io::rtcm3::frame_rtcm3(payload);
  f.receive_ns = 123456789;
  return f;
}

TEST(RtcmFrameAdapter, RoundTripsThroughTheMessage) {
  const base::BaseFrame f = sample_frame();
  const msg::RtcmFrame m = to_msg(f);
  EXPECT_EQ(m.message_number(), 1077);
  auto back = from_msg(m);
  ASSERT_TRUE(back.ok()) << back.error().to_string();
  EXPECT_EQ(back->sequence, 42U);
  EXPECT_EQ(back->station_id, 3034);
  EXPECT_EQ(back->bytes, f.bytes);
  ASSERT_TRUE(back->epoch_time);
  EXPECT_EQ(*back->epoch_time, *f.epoch_time);
  EXPECT_EQ(back->receive_ns, 123456789);
}

TEST(RtcmFrameAdapter, RefusesWhatIsNotOneFrame) {
  msg::RtcmFrame m = to_msg(sample_frame());
  m.bytes()[10] ^= 1;
  auto crc = from_msg(m);
  ASSERT_FALSE(crc.ok());
  EXPECT_EQ(crc.error().message, "RtcmFrame 42: CRC-24Q mismatch");
  m.bytes().resize(2000);
  EXPECT_NE(from_msg(m).error().message.find("exceed 1029"), std::string::npos);
  m.bytes() = {0xD3, 0x00};
  EXPECT_FALSE(from_msg(m).ok());
}

/// A fresh domain and topic per test run: DDS tests of others on this machine must not see ours.
int test_domain() {
  return 100 + static_cast<int>(::getpid() % 100);
}

// A packet corrupted on the way (here its CDR encapsulation) must be refused, not thrown through Fast DDS's listener
// thread: the generated type support catches only NotEnoughMemoryException, and the rover died of
// "Unexpected CDR type received in Cdr::read_encapsulation" in the fault suite's corruption run.
TEST(RtcmFrameDds, CorruptedPayloadIsRefusedNotThrown) {
  msg::RtcmFrame message = to_msg(sample_frame());
  GuardedPubSubType<msg::RtcmFramePubSubType> guarded;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(guarded.m_typeSize);
  ASSERT_TRUE(guarded.serialize(&message, &payload));
  msg::RtcmFrame intact;
  ASSERT_TRUE(guarded.deserialize(&payload, &intact));
  EXPECT_EQ(intact.bytes(), message.bytes());

  payload.data[1] = 0x7F;  // the representation identifier: no CDR kind
  msg::RtcmFrame corrupted;
  msg::RtcmFramePubSubType generated;
  EXPECT_THROW((void)generated.deserialize(&payload, &corrupted), eprosima::fastcdr::exception::Exception);
  const std::uint64_t before = malformed_payloads();
  EXPECT_FALSE(guarded.deserialize(&payload, &corrupted));
  EXPECT_EQ(malformed_payloads(), before + 1);
}

TEST(RtcmFrameDds, EverySubscriberReceivesEveryFrameOfCanyonBase) {
  const fs::path data = fs::path(CANYON_SHARED_DATA_DIR) / "cssrlib-static-doy078";
  if (!fs::exists(data / "3034078M1.21O")) GTEST_SKIP() << "shared datasets not found at " << CANYON_SHARED_DATA_DIR;
  const std::string topic = "canyon/rtcm/test" + std::to_string(::getpid());
  const int domain = test_domain();
  const fs::path dir = fs::temp_directory_path() / ("canyon_pipeline_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path config = dir / "base.yaml";
  std::ofstream(config) << "station: {id: 3034}\n"
                        << "input: {kind: rinex, source: file, path: " << (data / "3034078M1.21O").string()
                        << ", nav: [" << (data / "SEPT078M.21P").string() << "], pace: 20}\n"
                        << "outputs:\n  dds: {enabled: true, domain: " << domain << ", topic: " << topic
                        << ", profiles: " << CANYON_SOURCE_DIR << "/config/dds/canyon_profiles.xml}\n"
                        << "  ntrip: {enabled: false}\n"
                        << "log: {progress_interval_s: 0}\n";

  auto profiles = load_profiles("");
  ASSERT_TRUE(profiles.ok()) << profiles.error().to_string();
  auto participant = DdsParticipant::create(domain, profile::kParticipant);
  ASSERT_TRUE(participant.ok()) << participant.error().to_string();
  constexpr int kReaders = 3;
  std::mutex mutex;
  std::vector<std::vector<base::BaseFrame>> received(kReaders);
  std::vector<int> bad(kReaders, 0);
  std::vector<std::unique_ptr<RtcmReader>> readers;
  for (int k = 0; k < kReaders; ++k) {
    auto reader = RtcmReader::create(**participant, topic, profile::kRtcmReader, [&, k](msg::RtcmFrame&& m) {
      auto f = from_msg(m);
      const std::lock_guard lock(mutex);
      if (f) {
        received[static_cast<std::size_t>(k)].push_back(std::move(*f));
      } else {
        ++bad[static_cast<std::size_t>(k)];
      }
    });
    ASSERT_TRUE(reader.ok()) << reader.error().to_string();
    readers.push_back(std::move(*reader));
  }
  const std::string log = (dir / "base.log").string();
  const std::string command = std::string(CANYON_BASE_BINARY) + " --config " + config.string() +
                              " --wait-for-clients " + std::to_string(kReaders) + " --wait-timeout 20 > " + log +
                              " 2>&1";
  const int rc = std::system(command.c_str());
  std::ifstream in(log);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(rc, 0) << text;
  // "stopped: 60 epochs, N frames, ..."
  const std::size_t at = text.find("stopped: ");
  ASSERT_NE(at, std::string::npos) << text;
  unsigned long long epochs = 0;
  unsigned long long frames = 0;
  ASSERT_EQ(std::sscanf(text.c_str() + at, "stopped: %llu epochs, %llu frames", &epochs, &frames), 2);
  EXPECT_EQ(epochs, 60U);
  for (int k = 0; k < kReaders; ++k) {
    const std::lock_guard lock(mutex);
    const auto& got = received[static_cast<std::size_t>(k)];
    EXPECT_EQ(bad[static_cast<std::size_t>(k)], 0);
    ASSERT_EQ(got.size(), frames) << "reader " << k << "\n" << text;
    for (std::size_t i = 0; i < got.size(); ++i) {
      ASSERT_EQ(got[i].sequence, i) << "reader " << k;  // every frame, in order
      EXPECT_EQ(got[i].station_id, 3034);
    }
  }
  // The base has stopped: within the deadline (3 s) plus a margin, the readers notice.
  bool noticed = false;
  for (int i = 0; i < 60 && !noticed; ++i) {
    std::this_thread::sleep_for(100ms);
    noticed = readers[0]->deadlines_missed() > 0;
  }
  EXPECT_TRUE(noticed);
  readers.clear();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace canyon::dds
