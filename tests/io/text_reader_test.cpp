// TextReader: line numbers through unread_line(), the end of the input, and the line a truncated gzip stream cuts.

#include "canyon/io/text_reader.hpp"

#include <string>

#include <gtest/gtest.h>
#include <zlib.h>

#include "io/rinex_test_util.hpp"

namespace canyon::io {
namespace {

/// `text` gzip-compressed.
std::string gzip(const std::string& text) {
  uLongf size = compressBound(static_cast<uLong>(text.size())) + 32;
  std::string out(size, '\0');
  z_stream z{};
  EXPECT_EQ(deflateInit2(&z, Z_BEST_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY), Z_OK);
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(text.data()));
  z.avail_in = static_cast<uInt>(text.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(size);
  EXPECT_EQ(deflate(&z, Z_FINISH), Z_STREAM_END);
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

TEST(TextReader, PlainLastLineWithoutNewlineIsNotCut) {
  test::TempDir tmp;
  auto reader = TextReader::open(tmp.write("plain.txt", "one\r\ntwo\nthree"));
  ASSERT_TRUE(reader.ok());
  EXPECT_EQ(reader->next_line(), "one");
  EXPECT_EQ(reader->next_line(), "two");
  reader->unread_line();
  EXPECT_EQ(reader->line_number(), 1);
  EXPECT_EQ(reader->next_line(), "two");
  EXPECT_EQ(reader->next_line(), "three");
  EXPECT_EQ(reader->line_number(), 3);
  EXPECT_FALSE(reader->line_cut());
  EXPECT_FALSE(reader->ended());
  EXPECT_FALSE(reader->next_line().has_value());
  EXPECT_TRUE(reader->ended());
  EXPECT_FALSE(reader->read_error().has_value());
}

TEST(TextReader, TruncatedGzipCutsTheLastLine) {
  test::TempDir tmp;
  std::string text;
  for (int i = 0; i < 2000; ++i) text += "line " + std::to_string(i) + " of a text that compresses well enough\n";
  const std::string gz = gzip(text);
  auto reader = TextReader::open(tmp.write("cut.txt.gz", gz.substr(0, gz.size() / 2)));
  ASSERT_TRUE(reader.ok());
  std::string last;
  int lines = 0;
  while (const auto line = reader->next_line()) {
    const std::string expected = "line " + std::to_string(lines) + " of a text that compresses well enough";
    if (!reader->line_cut()) {
      EXPECT_EQ(*line, expected);
    }
    last = *line;
    ++lines;
    if (reader->line_cut()) {
      reader->unread_line();
      EXPECT_FALSE(reader->line_cut());  // pushed back: not consumed
      ASSERT_EQ(reader->next_line(), last);
      EXPECT_TRUE(reader->line_cut());
    }
  }
  EXPECT_TRUE(reader->ended());
  ASSERT_TRUE(reader->read_error().has_value());
  EXPECT_GT(lines, 10);
  EXPECT_LT(lines, 2000);
  EXPECT_TRUE(reader->line_cut());  // the last line consumed stays the cut one
  EXPECT_NE(last, "line " + std::to_string(lines - 1) + " of a text that compresses well enough");
}

}  // namespace
}  // namespace canyon::io
