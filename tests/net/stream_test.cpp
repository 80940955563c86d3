// TCP server and NTRIP caster with canyon's client on loopback: every byte arrives at every client, NTRIP 1 and 2
// (chunked), authentication, unknown mount points, the source table, GGA upload, reconnection with back-off after
// the server goes away, stall detection, a dead address, a slow client dropped.

#include <atomic>
#include <chrono>
#include <mutex>
#include <numeric>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <sys/socket.h>

#include "canyon/net/socket.hpp"
#include "canyon/net/stream_client.hpp"
#include "canyon/net/stream_server.hpp"

namespace canyon::net {
namespace {

using namespace std::chrono_literals;

/// Collects what a client receives.
struct Sink {
  std::mutex mutex;
  std::vector<std::uint8_t> bytes;
  std::vector<std::string> events;
  StreamClient::DataFn data() {
    return [this](std::span<const std::uint8_t> b) {
      const std::lock_guard lock(mutex);
      bytes.insert(bytes.end(), b.begin(), b.end());
    };
  }
  StreamClient::EventFn event() {
    return [this](const std::string& e) {
      const std::lock_guard lock(mutex);
      events.push_back(e);
    };
  }
  std::size_t size() {
    const std::lock_guard lock(mutex);
    return bytes.size();
  }
  bool saw(const std::string& text) {
    const std::lock_guard lock(mutex);
    for (const auto& e : events) {
      if (e.find(text) != std::string::npos) return true;
    }
    return false;
  }
};

template <typename Pred>
bool wait_for(Pred pred, std::chrono::milliseconds timeout = 5000ms) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    if (pred()) return true;
    std::this_thread::sleep_for(10ms);
  }
  return pred();
}

std::vector<std::uint8_t> pattern(std::size_t n, int seed) {
  std::vector<std::uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i)
    v[i] = static_cast<std::uint8_t>((i * 31 + static_cast<std::size_t>(seed)) & 0xFF);
  return v;
}

StreamServerOptions caster_options() {
  StreamServerOptions o;
  o.mode = StreamServerOptions::Mode::Ntrip;
  o.bind_host = "127.0.0.1";
  MountPoint m;
  m.name = "CANYON";
  o.mounts = {m};
  return o;
}

StreamClientOptions client_options(int port, int version) {
  StreamClientOptions o;
  o.host = "127.0.0.1";
  o.port = port;
  o.mount = "CANYON";
  o.ntrip_version = version;
  o.backoff_min_s = 0.1;
  o.backoff_max_s = 0.4;
  o.stall_timeout_s = 2.0;
  return o;
}

TEST(StreamServer, TcpFansOutToEveryClient) {
  StreamServerOptions o;
  o.bind_host = "127.0.0.1";
  auto server = StreamServer::start(o);
  ASSERT_TRUE(server.ok()) << server.error().to_string();
  std::vector<std::unique_ptr<Sink>> sinks;
  std::vector<std::unique_ptr<StreamClient>> clients;
  for (int k = 0; k < 3; ++k) {
    sinks.push_back(std::make_unique<Sink>());
    StreamClientOptions c;
    c.mode = StreamClientOptions::Mode::Tcp;
    c.port = (*server)->port();
    clients.push_back(std::make_unique<StreamClient>(c, sinks.back()->data(), sinks.back()->event()));
    ASSERT_TRUE(clients.back()->start().ok());
  }
  ASSERT_TRUE(wait_for([&] { return (*server)->stats().clients == 3; }));
  std::vector<std::uint8_t> all;
  for (int k = 0; k < 200; ++k) {
    const auto piece = pattern(500, k);
    (*server)->publish("", piece);
    all.insert(all.end(), piece.begin(), piece.end());
  }
  for (auto& s : sinks) {
    ASSERT_TRUE(wait_for([&] { return s->size() == all.size(); })) << s->size() << " of " << all.size();
    const std::lock_guard lock(s->mutex);
    EXPECT_EQ(s->bytes, all);
  }
}

TEST(StreamServer, NtripVersionsOneAndTwoWithAuthentication) {
  StreamServerOptions o = caster_options();
  o.user = "rover";
  o.password = "pw";
  auto server = StreamServer::start(o);
  ASSERT_TRUE(server.ok());
  const int port = (*server)->port();
  Sink v1;
  Sink v2;
  StreamClientOptions c1 = client_options(port, 1);
  c1.user = "rover";
  c1.password = "pw";
  StreamClientOptions c2 = client_options(port, 2);
  c2.user = "rover";
  c2.password = "pw";
  c2.gga_interval_s = 0.2;
  c2.gga = "$GPGGA,120000.00,5316.8280,N,00903.4706,W,1,08,1.0,60.0,M,0.0,M,,*47";
  StreamClient a(c1, v1.data(), v1.event());
  StreamClient b(c2, v2.data(), v2.event());
  ASSERT_TRUE(a.start().ok());
  ASSERT_TRUE(b.start().ok());
  ASSERT_TRUE(wait_for([&] { return (*server)->stats().clients == 2; }));
  std::vector<std::uint8_t> all;
  for (int k = 0; k < 100; ++k) {
    const auto piece = pattern(777, k);
    (*server)->publish("CANYON", piece);
    (*server)->publish("OTHER", pattern(10, k));  // nobody listens there
    all.insert(all.end(), piece.begin(), piece.end());
  }
  ASSERT_TRUE(wait_for([&] { return v1.size() == all.size() && v2.size() == all.size(); }));
  EXPECT_EQ(v1.bytes, all);
  EXPECT_EQ(v2.bytes, all);  // chunked on the wire, decoded by the client
  EXPECT_TRUE(wait_for([&] { return (*server)->stats().gga_received >= 2; }));
  bool logged_v2 = false;
  for (const auto& e : (*server)->take_events()) logged_v2 = logged_v2 || e.find("(NTRIP 2") != std::string::npos;
  EXPECT_TRUE(logged_v2);
}

TEST(StreamServer, GgaGoesUpOnlyOnceTheRoverHasAPositionAndFollowsIt) {
  auto server = StreamServer::start(caster_options());
  ASSERT_TRUE(server.ok());
  Sink sink;
  StreamClientOptions c = client_options((*server)->port(), 2);
  c.gga_interval_s = 0.1;  // no sentence yet: nothing is sent until set_gga()
  StreamClient client(c, sink.data(), sink.event());
  ASSERT_TRUE(client.start().ok());
  ASSERT_TRUE(wait_for([&] { return (*server)->stats().clients == 1; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  EXPECT_EQ((*server)->stats().gga_received, 0U);
  EXPECT_EQ(client.stats().gga_sent, 0U);
  const std::string first = "$GPGGA,120000.00,5316.8280,N,00903.4706,W,1,08,1.0,60.0,M,0.0,M,,*47";
  client.set_gga(first);
  ASSERT_TRUE(wait_for([&] { return (*server)->stats().gga_received >= 1; }));
  const std::string second = "$GPGGA,120001.00,5316.8281,N,00903.4706,W,4,09,0.9,60.1,M,0.0,M,1.0,0001*7B";
  client.set_gga(second);
  const auto received = (*server)->stats().gga_received;
  ASSERT_TRUE(wait_for([&] { return (*server)->stats().gga_received >= received + 2; }));
  bool logged = false;
  for (const auto& e : (*server)->take_events()) logged = logged || e.find("sends GGA") != std::string::npos;
  EXPECT_TRUE(logged);  // the caster logs the first sentence of a client
  EXPECT_GE(client.stats().gga_sent, 3U);
}

TEST(StreamServer, RefusesWrongCredentialsAndUnknownMountPoints) {
  StreamServerOptions o = caster_options();
  o.user = "rover";
  o.password = "pw";
  auto server = StreamServer::start(o);
  ASSERT_TRUE(server.ok());
  for (const int version : {1, 2}) {
    Sink bad_auth;
    StreamClientOptions c = client_options((*server)->port(), version);
    c.user = "rover";
    c.password = "wrong";
    c.max_attempts = 1;
    StreamClient a(c, bad_auth.data(), bad_auth.event());
    ASSERT_TRUE(a.start().ok());
    ASSERT_TRUE(wait_for([&] { return a.finished(); }));
    EXPECT_TRUE(bad_auth.saw("401")) << version;

    Sink unknown;
    c.mount = "NOPE";
    c.password = "pw";
    StreamClient b(c, unknown.data(), unknown.event());
    ASSERT_TRUE(b.start().ok());
    ASSERT_TRUE(wait_for([&] { return b.finished(); }));
    // NTRIP 1 casters answer an unknown mount point with the source table, NTRIP 2 with 404.
    EXPECT_TRUE(unknown.saw(version == 1 ? "source table" : "404")) << version;
  }
  EXPECT_GE((*server)->stats().refused, 4U);
}

TEST(StreamServer, SourceTable) {
  StreamServerOptions o = caster_options();
  MountPoint second;
  second.name = "SECOND";
  o.mounts.push_back(second);
  auto server = StreamServer::start(o);
  ASSERT_TRUE(server.ok());
  for (const int version : {1, 2}) {
    auto table = fetch_source_table("127.0.0.1", (*server)->port(), version);
    ASSERT_TRUE(table.ok()) << table.error().to_string();
    ASSERT_EQ(table->size(), 2U);
    EXPECT_EQ((*table)[0].name, "CANYON");
    EXPECT_EQ((*table)[1].name, "SECOND");
  }
}

TEST(StreamClient, ReconnectsWithBackOffWhenTheServerComesBack) {
  auto first = StreamServer::start(caster_options());
  ASSERT_TRUE(first.ok());
  const int port = (*first)->port();
  Sink sink;
  StreamClient client(client_options(port, 2), sink.data(), sink.event());
  ASSERT_TRUE(client.start().ok());
  ASSERT_TRUE(wait_for([&] { return (*first)->stats().clients == 1; }));
  (*first)->publish("CANYON", pattern(100, 1));
  ASSERT_TRUE(wait_for([&] { return sink.size() == 100; }));
  // The server goes away: the client notices, backs off and retries.
  (*first)->stop();
  first->reset();
  ASSERT_TRUE(wait_for([&] { return client.stats().failures >= 2; }));
  EXPECT_TRUE(sink.saw("reconnecting in"));
  // And comes back on the same port.
  StreamServerOptions o = caster_options();
  o.port = port;
  auto second = StreamServer::start(o);
  ASSERT_TRUE(second.ok()) << second.error().to_string();
  ASSERT_TRUE(wait_for([&] { return (*second)->stats().clients == 1; }));
  (*second)->publish("CANYON", pattern(100, 2));
  ASSERT_TRUE(wait_for([&] { return sink.size() == 200; }));
  EXPECT_EQ(client.stats().connections, 2U);
}

TEST(StreamClient, DetectsAStalledStream) {
  auto server = StreamServer::start(caster_options());
  ASSERT_TRUE(server.ok());
  Sink sink;
  StreamClientOptions c = client_options((*server)->port(), 1);
  c.stall_timeout_s = 0.5;
  StreamClient client(c, sink.data(), sink.event());
  ASSERT_TRUE(client.start().ok());
  ASSERT_TRUE(wait_for([&] { return (*server)->stats().clients == 1; }));
  (*server)->publish("CANYON", pattern(10, 1));
  // Nothing more is published: the client declares a stall and reconnects.
  ASSERT_TRUE(wait_for([&] { return client.stats().stalls >= 1; }));
  EXPECT_TRUE(sink.saw("stall"));
  EXPECT_TRUE(wait_for([&] { return (*server)->stats().connections >= 2; }));
}

TEST(StreamClient, DeadAddressGivesUpWithTheError) {
  // A port that was free a moment ago: connection refused.
  auto probe = tcp_listen("127.0.0.1", 0);
  ASSERT_TRUE(probe.ok());
  const int port = local_port(*probe);
  probe->reset();
  Sink sink;
  StreamClientOptions c = client_options(port, 2);
  c.max_attempts = 3;
  StreamClient client(c, sink.data(), sink.event());
  ASSERT_TRUE(client.start().ok());
  ASSERT_TRUE(wait_for([&] { return client.finished(); }));
  EXPECT_EQ(client.stats().failures, 3U);
  EXPECT_NE(client.stats().last_error.find("cannot connect to 127.0.0.1:" + std::to_string(port)), std::string::npos)
      << client.stats().last_error;
  EXPECT_TRUE(sink.saw("giving up after 3"));
}

TEST(StreamServer, DropsAClientThatDoesNotRead) {
  StreamServerOptions o;
  o.bind_host = "127.0.0.1";
  o.max_client_buffer_bytes = std::size_t{64} * 1024;
  auto server = StreamServer::start(o);
  ASSERT_TRUE(server.ok());
  auto slow = tcp_connect("127.0.0.1", (*server)->port(), 1000);
  ASSERT_TRUE(slow.ok());
  const int small = 4096;
  ::setsockopt(slow->get(), SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
  ASSERT_TRUE(wait_for([&] { return (*server)->stats().clients == 1; }));
  for (int k = 0; k < 2000 && (*server)->stats().dropped_slow == 0; ++k) {
    (*server)->publish("", pattern(4096, k));
    std::this_thread::sleep_for(1ms);
  }
  EXPECT_EQ((*server)->stats().dropped_slow, 1U);
  EXPECT_TRUE(wait_for([&] { return (*server)->stats().clients == 0; }));
}

TEST(StreamServer, BadOptionsAndBusyPortAreErrors) {
  StreamServerOptions o = caster_options();
  o.mounts.clear();
  EXPECT_FALSE(StreamServer::start(o).ok());
  auto first = StreamServer::start(caster_options());
  ASSERT_TRUE(first.ok());
  StreamServerOptions same = caster_options();
  same.port = (*first)->port();
  // SO_REUSEADDR lets a second socket bind only when the first is not listening.
  auto second = StreamServer::start(same);
  ASSERT_FALSE(second.ok());
  EXPECT_NE(second.error().message.find("cannot listen on 127.0.0.1:" + std::to_string(same.port)), std::string::npos);
  EXPECT_FALSE(parse_endpoint("localhost").ok());
  EXPECT_FALSE(parse_endpoint("localhost:99999").ok());
  EXPECT_EQ(parse_endpoint(":2101")->host, "0.0.0.0");
}

}  // namespace
}  // namespace canyon::net
