// Byte links as canyon rover reads its receiver and its base: addresses, a file, and real TCP connections to canyon's
// own stream server (net::StreamServer, what canyon base runs): data arrives, a refused connection and a link that
// dies mid-stream end in an Error naming the address, within the configured attempts, without hanging.

#include "canyon/pipeline/byte_link.hpp"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>

#include "canyon/net/stream_server.hpp"

namespace canyon::pipeline {
namespace {

namespace fs = std::filesystem;

constexpr double kMaxGiveUpS = 10.0;  // 2 attempts, 0.1 s back-off: well under this unless the link hangs

LinkOptions quick_options() {
  LinkOptions o;
  o.attempts = 2;
  o.backoff_min_s = 0.1;
  o.backoff_max_s = 0.2;
  o.stall_timeout_s = 1.0;
  return o;
}

/// Reads until the link fails or ends, or `limit_s` passes; the bytes read and the error text ("" if none).
std::pair<std::vector<std::uint8_t>, std::string> read_all(ByteLink& link, double limit_s) {
  std::vector<std::uint8_t> bytes;
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
  while (std::chrono::steady_clock::now() < until) {
    auto more = link.read(bytes, 100);
    if (!more) return {bytes, more.error().to_string()};
    if (!*more) return {bytes, ""};
  }
  return {bytes, "timed out"};
}

std::unique_ptr<net::StreamServer> tcp_server() {
  net::StreamServerOptions o;
  o.bind_host = "127.0.0.1";
  auto server = net::StreamServer::start(o);
  EXPECT_TRUE(server) << server.error().to_string();
  return server ? std::move(*server) : nullptr;
}

TEST(LinkAddress, ParsesEveryFormAndNamesTheFormsOnError) {
  auto file = LinkAddress::parse("file:log.ubx", "/data");
  ASSERT_TRUE(file) << file.error().to_string();
  EXPECT_EQ(file->kind, LinkAddress::Kind::File);
  EXPECT_EQ(file->path, "/data/log.ubx");
  auto serial = LinkAddress::parse("serial:///dev/ttyACM0?baud=921600");
  ASSERT_TRUE(serial) << serial.error().to_string();
  EXPECT_EQ(serial->kind, LinkAddress::Kind::Serial);
  EXPECT_EQ(serial->path, "/dev/ttyACM0");
  EXPECT_EQ(serial->baud, 921600);
  EXPECT_EQ(LinkAddress::parse("serial:///dev/ttyUSB1")->baud, 115200);
  auto tcp = LinkAddress::parse("tcp://127.0.0.1:2102");
  ASSERT_TRUE(tcp);
  EXPECT_EQ(tcp->kind, LinkAddress::Kind::Tcp);
  EXPECT_EQ(tcp->url.port, 2102);
  auto ntrip = LinkAddress::parse("ntrip://me:secret@caster:2101/CANYON");
  ASSERT_TRUE(ntrip);
  EXPECT_EQ(ntrip->kind, LinkAddress::Kind::Ntrip);
  EXPECT_EQ(ntrip->url.mount, "CANYON");
  EXPECT_EQ(ntrip->url.user, "me");
  EXPECT_EQ(ntrip->url.password, "secret");
  EXPECT_EQ(ntrip->text, "ntrip://me:***@caster:2101/CANYON");  // messages never show the password
  EXPECT_NE(LinkAddress::parse("log.ubx").error().message.find("file:PATH"), std::string::npos);
  EXPECT_FALSE(LinkAddress::parse("serial://ttyACM0"));
  EXPECT_FALSE(LinkAddress::parse("serial:///dev/ttyACM0?baud=fast"));
  EXPECT_FALSE(LinkAddress::parse("tcp://host"));
  EXPECT_FALSE(LinkAddress::parse("ntrip://host:2101"));
  EXPECT_FALSE(LinkAddress::parse("file:"));
}

TEST(ByteLink, FileIsReadWholeThenEnds) {
  const fs::path path = fs::temp_directory_path() / "canyon_byte_link_test.bin";
  std::vector<std::uint8_t> written(10000);
  for (std::size_t i = 0; i < written.size(); ++i) written[i] = static_cast<std::uint8_t>(i * 7);
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(written.data()), static_cast<std::streamsize>(written.size()));
  auto link = ByteLink::open(*LinkAddress::parse("file:" + path.string()), {}, {});
  ASSERT_TRUE(link) << link.error().to_string();
  auto [bytes, error] = read_all(**link, 5.0);
  EXPECT_EQ(error, "");
  EXPECT_EQ(bytes, written);
  EXPECT_EQ((*link)->stats().bytes, written.size());
  auto missing = ByteLink::open(*LinkAddress::parse("file:/nonexistent/rover.ubx"), {}, {});
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().to_string().find("/nonexistent/rover.ubx"), std::string::npos);
  fs::remove(path);
}

TEST(ByteLink, RefusedConnectionGivesUpNamingTheAddress) {
  int port = 0;
  {
    auto server = tcp_server();  // a port that was free a moment ago and is closed now
    ASSERT_NE(server, nullptr);
    port = server->port();
  }
  std::vector<std::string> events;
  const std::string text = "tcp://127.0.0.1:" + std::to_string(port);
  auto link = ByteLink::open(*LinkAddress::parse(text), quick_options(), [&events](bool problem, const std::string& e) {
    if (problem) events.push_back(e);
  });
  ASSERT_TRUE(link) << link.error().to_string();
  const auto start = std::chrono::steady_clock::now();
  auto [bytes, error] = read_all(**link, kMaxGiveUpS);
  const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(bytes.empty());
  EXPECT_NE(error.find(text), std::string::npos) << error;
  EXPECT_NE(error.find("gave up"), std::string::npos) << error;
  EXPECT_NE(error.find("refused"), std::string::npos) << error;
  EXPECT_LT(took_s, kMaxGiveUpS);
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.front().rfind(text, 0), 0u) << events.front();
  EXPECT_EQ((*link)->stats().failures, 2u);
}

TEST(ByteLink, TcpDataArrivesAndALinkThatDiesEndsInAnError) {
  auto server = tcp_server();
  ASSERT_NE(server, nullptr);
  auto link =
      ByteLink::open(*LinkAddress::parse("tcp://127.0.0.1:" + std::to_string(server->port())), quick_options(), {});
  ASSERT_TRUE(link) << link.error().to_string();
  for (int i = 0; i < 100 && server->stats().clients == 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_EQ(server->stats().clients, 1);
  const std::vector<std::uint8_t> sent = {0xd3, 0x00, 0x13, 1, 2, 3, 4, 5};
  server->publish("", sent);
  std::vector<std::uint8_t> got;
  for (int i = 0; i < 50 && got.size() < sent.size(); ++i) ASSERT_TRUE((*link)->read(got, 100));
  EXPECT_EQ(got, sent);
  server->stop();  // the peer goes away mid-stream and does not come back
  server.reset();
  auto [rest, error] = read_all(**link, kMaxGiveUpS);
  EXPECT_TRUE(rest.empty());
  EXPECT_NE(error.find("link lost"), std::string::npos) << error;
  EXPECT_EQ((*link)->stats().connections, 1u);
}

}  // namespace
}  // namespace canyon::pipeline
