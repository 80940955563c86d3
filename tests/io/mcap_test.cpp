// The MCAP writer and reader (io/mcap.hpp): a recording read back whole, its byte layout where the spec fixes it
// (magic, opcodes, little-endian lengths), a file cut short (an error naming the byte; the partial read keeps every
// message before the cut), not an MCAP file, an unwritable path. tests/ros2/mcap_check.mjs reads canyon's files with
// the independent MCAP reader of the npm registry.

#include "canyon/io/mcap.hpp"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "integration/test_support.hpp"

namespace canyon::io {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

fs::path session(int messages) {
  fs::path path = test::temp_dir("mcap") / ("session" + std::to_string(messages) + ".mcap");
  auto w = McapWriter::create(path.string());
  EXPECT_TRUE(w) << w.error().to_string();
  const auto schema = w->add_schema("canyon::msg::Solution", "omgidl", "module canyon { };");
  const auto channel = w->add_channel(*schema, "canyon/solution", "cdr");
  for (int k = 0; k < messages; ++k) {
    McapMessage m;
    m.channel_id = *channel;
    m.sequence = static_cast<std::uint32_t>(k);
    m.log_time_ns = 1000000000ULL + static_cast<std::uint64_t>(k) * 200000000ULL;
    m.publish_time_ns = m.log_time_ns - 1000;
    m.data = {0x00, 0x01, 0x00, 0x00, static_cast<std::uint8_t>(k)};
    EXPECT_TRUE(w->write(m));
  }
  EXPECT_TRUE(w->close());
  return path;
}

TEST(Mcap, ARecordingReadsBackWhole) {
  const fs::path path = session(5);
  auto content = read_mcap(path.string());
  ASSERT_TRUE(content) << content.error().to_string();
  EXPECT_TRUE(content->complete);
  ASSERT_EQ(content->schemas.size(), 1U);
  EXPECT_EQ(content->schemas.at(1).name, "canyon::msg::Solution");
  EXPECT_EQ(content->schemas.at(1).encoding, "omgidl");
  ASSERT_EQ(content->channels.size(), 1U);
  EXPECT_EQ(content->channels.at(0).topic, "canyon/solution");
  EXPECT_EQ(content->channels.at(0).message_encoding, "cdr");
  ASSERT_EQ(content->messages.size(), 5U);
  EXPECT_EQ(content->messages[3].sequence, 3U);
  EXPECT_EQ(content->messages[3].log_time_ns, 1600000000ULL);
  EXPECT_EQ(content->messages[3].publish_time_ns, 1599999000ULL);
  EXPECT_EQ(content->messages[3].data, (std::vector<std::uint8_t>{0x00, 0x01, 0x00, 0x00, 0x03}));
}

TEST(Mcap, TheLayoutIsTheSpecs) {
  const std::string bytes = slurp(session(1));
  const std::string magic("\x89MCAP0\r\n", 8);
  EXPECT_EQ(bytes.substr(0, 8), magic);
  EXPECT_EQ(bytes.substr(bytes.size() - 8), magic);
  EXPECT_EQ(bytes[8], '\x01');  // Header
  // Header content: profile "" (4-byte length 0) and library "canyon": 4 + 4 + 6 = 14 bytes.
  EXPECT_EQ(bytes.substr(9, 8), std::string("\x0e\0\0\0\0\0\0\0", 8));
  EXPECT_EQ(bytes.substr(17 + 4, 4), std::string("\x06\0\0\0", 4));
  EXPECT_EQ(bytes.substr(17 + 8, 6), "canyon");
  EXPECT_EQ(bytes[31], '\x03');  // the Schema comes next, before its Channel and the Message
  // The Footer: opcode 0x02, length 20, just before the closing magic.
  EXPECT_EQ(bytes[bytes.size() - 8 - 29], '\x02');
  EXPECT_EQ(bytes.substr(bytes.size() - 8 - 28, 8), std::string("\x14\0\0\0\0\0\0\0", 8));
}

TEST(Mcap, AFileCutShortNamesTheByteAndKeepsWhatCameBefore) {
  const fs::path path = session(10);
  const std::string bytes = slurp(path);
  const fs::path cut = path.parent_path() / "cut.mcap";
  // Cut inside the 8th message: everything after the first 7 messages' records is gone.
  // A message record: opcode 0x05, length 27 (channel 2, sequence 4, two times 8, data 5), 36 bytes in all.
  const std::size_t first = bytes.find(std::string("\x05\x1b\0\0\0\0\0\0\0", 9));
  ASSERT_NE(first, std::string::npos);
  const std::size_t at = first + std::size_t{7} * 36;
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, at + 20);
  const auto whole = read_mcap(cut.string());
  ASSERT_FALSE(whole);
  EXPECT_NE(whole.error().to_string().find("cut short at byte " + std::to_string(at)), std::string::npos)
      << whole.error().to_string();
  EXPECT_NE(whole.error().to_string().find("the 7 messages before it were read"), std::string::npos);
  std::string problem;
  const auto partial = read_mcap_partial(cut.string(), &problem);
  ASSERT_TRUE(partial);
  EXPECT_FALSE(partial->complete);
  EXPECT_EQ(partial->messages.size(), 7U);
  EXPECT_NE(problem.find("cut.mcap"), std::string::npos);
}

TEST(Mcap, NotAnMcapFileAndAnUnwritablePathAreErrors) {
  const fs::path other = test::temp_dir("mcap") / "other.mcap";
  std::ofstream(other) << "%  GPST latitude(deg)\n";
  const auto read = read_mcap(other.string());
  ASSERT_FALSE(read);
  EXPECT_NE(read.error().to_string().find("not an MCAP file"), std::string::npos);
  const auto write = McapWriter::create("/dev/null/session.mcap");
  ASSERT_FALSE(write);
  EXPECT_NE(write.error().to_string().find("/dev/null/session.mcap"), std::string::npos);
}

}  // namespace
}  // namespace canyon::io
