// NTRIP protocol text: requests and responses of versions 1 and 2, Basic authentication, the source table, chunked
// transfer coding; malformed input gives an error naming the problem.

#include "canyon/net/ntrip.hpp"

#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace canyon::net {
namespace {

MountPoint named(const std::string& name) {
  MountPoint m;
  m.name = name;
  return m;
}

std::vector<std::uint8_t> bytes(const std::string& s) {
  return {s.begin(), s.end()};
}

TEST(Ntrip, Base64KnownVectors) {
  EXPECT_EQ(base64_encode(""), "");
  EXPECT_EQ(base64_encode("f"), "Zg==");
  EXPECT_EQ(base64_encode("fo"), "Zm8=");
  EXPECT_EQ(base64_encode("foo"), "Zm9v");
  EXPECT_EQ(base64_encode("user:pass word"), "dXNlcjpwYXNzIHdvcmQ=");
  EXPECT_EQ(base64_decode("dXNlcjpwYXNzIHdvcmQ="), "user:pass word");
  EXPECT_FALSE(base64_decode("!!!"));
}

TEST(Ntrip, RequestsOfBothVersionsRoundTrip) {
  for (const int version : {1, 2}) {
    ClientRequestOptions o;
    o.host = "caster.example";
    o.port = 2101;
    o.mount = "CANYON0";
    o.version = version;
    o.user = "rover";
    o.password = "secret:with:colons";
    o.gga = "$GPGGA,120000.00,5316.8280,N,00903.4706,W,1,08,1.0,60.0,M,0.0,M,,*47";
    const std::string text = format_ntrip_request(o);
    auto r = parse_ntrip_request(text);
    ASSERT_TRUE(r.ok()) << r.error().to_string();
    EXPECT_EQ(r->method, "GET");
    EXPECT_EQ(r->mount, "CANYON0");
    EXPECT_EQ(r->version, version);
    EXPECT_EQ(r->user, "rover");
    EXPECT_EQ(r->password, "secret:with:colons");
    EXPECT_EQ(r->user_agent, "NTRIP canyon/0.1");
    if (version == 2) {
      EXPECT_EQ(r->host, "caster.example:2101");
      EXPECT_EQ(r->nmea, o.gga);
    }
  }
  // RTKLIB 2.4.3's NTRIP 1 request.
  auto rtklib = parse_ntrip_request(
      "GET /BASE HTTP/1.0\r\nUser-Agent: NTRIP RTKLIB/2.4.3\r\nAccept: */*\r\n"
      "Connection: close\r\n\r\n");
  ASSERT_TRUE(rtklib.ok());
  EXPECT_EQ(rtklib->version, 1);
  EXPECT_EQ(rtklib->mount, "BASE");
  EXPECT_FALSE(rtklib->user);
}

TEST(Ntrip, MalformedRequestsAreErrors) {
  for (const std::string& bad : std::vector<std::string>{
           "", "\r\n\r\n", "GET\r\n\r\n", "GET BASE HTTP/1.0\r\n\r\n", "DELETE /X HTTP/1.1\r\n\r\n",
           "GET /X HTTP/1.1\r\nAuthorization: Digest abc\r\n\r\n",
           "GET /X HTTP/1.1\r\nAuthorization: Basic !!!\r\n\r\n", "GET /X HTTP/1.1\r\nno colon here\r\n\r\n",
           "GET /X SMTP\r\n\r\n", std::string("GET /X HTTP/1.0\r\nUser-Agent: a\x01\r\n\r\n")}) {
    auto r = parse_ntrip_request(bad);
    EXPECT_FALSE(r.ok()) << "accepted: " << bad;
  }
  auto source = parse_ntrip_request("SOURCE pass /MOUNT\r\nSource-Agent: NTRIP x\r\n\r\n");
  ASSERT_TRUE(source.ok());
  EXPECT_EQ(source->method, "SOURCE");
}

TEST(Ntrip, ResponsesOfBothVersions) {
  auto icy = parse_ntrip_response(format_data_response(1));
  ASSERT_TRUE(icy.ok());
  EXPECT_EQ(icy->kind, NtripResponse::Kind::Data);
  EXPECT_FALSE(icy->chunked);
  auto v2 = parse_ntrip_response(format_data_response(2));
  ASSERT_TRUE(v2.ok());
  EXPECT_EQ(v2->kind, NtripResponse::Kind::Data);
  EXPECT_EQ(v2->version, 2);
  EXPECT_TRUE(v2->chunked);
  for (const int version : {1, 2}) {
    const std::string table = format_source_table({named("A")});
    const std::string response = format_source_table_response(version, table);
    const auto end = header_end(response);
    ASSERT_TRUE(end);
    auto st = parse_ntrip_response(response.substr(0, *end));
    ASSERT_TRUE(st.ok());
    EXPECT_EQ(st->kind, NtripResponse::Kind::SourceTable);
    EXPECT_EQ(st->content_length, table.size());
    auto unauthorized = parse_ntrip_response(format_error_response(version, 401, "Unauthorized"));
    EXPECT_EQ(unauthorized->kind, NtripResponse::Kind::Unauthorized);
    auto missing = parse_ntrip_response(format_error_response(version, 404, "Not Found"));
    EXPECT_EQ(missing->kind, NtripResponse::Kind::NotFound);
  }
  EXPECT_FALSE(parse_ntrip_response("SSH-2.0-OpenSSH\r\n\r\n").ok());
  EXPECT_FALSE(parse_ntrip_response("HTTP/1.1 abc OK\r\n\r\n").ok());
}

TEST(Ntrip, SourceTableRoundTrips) {
  MountPoint m;
  m.name = "CANYON0";
  m.identifier = "Galway";
  m.format_details = "1005(10),1077(1),1087(1)";
  m.nav_system = "GPS+GLO";
  m.latitude_deg = 53.28;
  m.longitude_deg = -9.06;
  m.authentication = "B";
  const std::string text = format_source_table({m, named("SECOND")});
  EXPECT_NE(text.find("ENDSOURCETABLE\r\n"), std::string::npos);
  auto back = parse_source_table("CAS;x;y\r\n" + text);
  ASSERT_TRUE(back.ok());
  ASSERT_EQ(back->size(), 2U);
  EXPECT_EQ((*back)[0].name, "CANYON0");
  EXPECT_EQ((*back)[0].format_details, m.format_details);
  EXPECT_NEAR((*back)[0].latitude_deg, 53.28, 1e-9);
  EXPECT_EQ((*back)[0].authentication, "B");
  auto bad = parse_source_table("STR;X;too;few\r\n");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("line 1"), std::string::npos);
}

TEST(Ntrip, ChunkedDecodingInAnySplit) {
  std::mt19937 rng(5);
  std::string wire;
  std::vector<std::uint8_t> expected;
  for (int k = 0; k < 50; ++k) {
    std::vector<std::uint8_t> piece(1 + rng() % 700);
    for (auto& b : piece) b = static_cast<std::uint8_t>(rng());
    wire += chunk(piece);
    expected.insert(expected.end(), piece.begin(), piece.end());
  }
  wire += "0\r\n\r\n";
  ChunkedDecoder d;
  std::vector<std::uint8_t> out;
  std::size_t pos = 0;
  while (pos < wire.size()) {
    const std::size_t n = std::min<std::size_t>(1 + rng() % 37, wire.size() - pos);
    ASSERT_TRUE(d.feed({reinterpret_cast<const std::uint8_t*>(wire.data() + pos), n}, out).ok());
    pos += n;
  }
  EXPECT_TRUE(d.finished());
  EXPECT_EQ(out, expected);
  // Extensions and trailers are accepted.
  ChunkedDecoder e;
  out.clear();
  ASSERT_TRUE(e.feed(bytes("3;ext=1\r\nabc\r\n0\r\nTrailer: x\r\n\r\n"), out).ok());
  EXPECT_EQ(std::string(out.begin(), out.end()), "abc");
  EXPECT_TRUE(e.finished());
}

TEST(Ntrip, MalformedChunksAreErrors) {
  for (const std::string& bad :
       std::vector<std::string>{"zz\r\nabc\r\n", "3\r\nabcX", std::string(300, '1') + "\r\n", "FFFFFFFFF\r\n"}) {
    ChunkedDecoder d;
    std::vector<std::uint8_t> out;
    EXPECT_FALSE(d.feed(bytes(bad), out).ok()) << bad.substr(0, 20);
    EXPECT_FALSE(d.feed(bytes("1\r\na\r\n"), out).ok());  // stays failed
  }
}

}  // namespace
}  // namespace canyon::net
