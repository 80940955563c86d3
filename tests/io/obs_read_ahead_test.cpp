// ObsReadAhead against RinexObsReader: the same epochs, errors, warnings and progress, whatever the queue depth (0:
// no reading thread);
// stopping early (a full queue, finish() half-way, destruction) neither hangs nor changes what was returned.

#include "canyon/io/obs_read_ahead.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "canyon/io/rinex_obs.hpp"

#include "io/rinex_test_util.hpp"

namespace canyon::io {
namespace {

namespace fs = std::filesystem;

const std::string kData = CANYON_SHARED_DATA_DIR;
const std::string kKinematicRover = kData + "/cssrlib-kinematic-doy265/SEPT265G.21O";

/// What a reader gave: every epoch, the progress after each, and the warnings when it stopped.
struct Reading {
  std::vector<core::ObsEpoch> epochs;
  std::vector<double> fractions;
  std::vector<std::string> warnings;
  std::string error;
};

/// next() in a loop over an opened reader (RinexObsReader or ObsReadAhead), stopping after `max_epochs`.
template <typename Reader>
void read_epochs(Reader& reader, std::size_t max_epochs, Reading& out) {
  while (out.epochs.size() < max_epochs) {
    auto epoch = reader.next();
    if (!epoch) {
      out.error = epoch.error().message;
      break;
    }
    if (!*epoch) break;
    out.epochs.push_back(std::move(**epoch));
    out.fractions.push_back(reader.fraction_read());
  }
}

Reading read_sequentially(const std::string& path, std::size_t max_epochs = SIZE_MAX) {
  Reading out;
  auto reader = RinexObsReader::open(path);
  if (!reader) {
    out.error = reader.error().message;
    return out;
  }
  read_epochs(*reader, max_epochs, out);
  out.warnings = reader->warnings();
  return out;
}

Reading read_ahead(const std::string& path, std::size_t depth, std::size_t max_epochs = SIZE_MAX) {
  Reading out;
  auto reader = ObsReadAhead::open(path, std::nullopt, depth);
  if (!reader) {
    out.error = reader.error().message;
    return out;
  }
  read_epochs(*reader, max_epochs, out);
  out.warnings = reader->finish();
  return out;
}

void expect_same(const Reading& expected, const Reading& actual) {
  test::expect_same_epochs(expected.epochs, actual.epochs, 0.0);
  EXPECT_EQ(expected.fractions, actual.fractions);
  EXPECT_EQ(expected.warnings, actual.warnings);
  EXPECT_EQ(expected.error, actual.error);
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

#define SKIP_WITHOUT_SHARED_DATA()                                                                         \
  if (!fs::exists(kKinematicRover)) {                                                                      \
    GTEST_SKIP() << "shared datasets not found at " << kData << " (set CANYON_SHARED_DATA_DIR to enable)"; \
  }

TEST(ObsReadAhead, GivesTheReadersEpochsAndProgressAtEveryDepth) {
  SKIP_WITHOUT_SHARED_DATA();
  const Reading expected = read_sequentially(kKinematicRover);
  ASSERT_EQ(expected.epochs.size(), 360U);
  for (const std::size_t depth : {0U, 1U, 3U, 64U}) {  // 0: no reading thread
    SCOPED_TRACE("depth " + std::to_string(depth));
    expect_same(expected, read_ahead(kKinematicRover, depth));
  }
}

TEST(ObsReadAhead, CorruptEpochsGiveTheSameWarningsAndACutFileTheSameEnd) {
  SKIP_WITHOUT_SHARED_DATA();
  std::string text = read_text(kKinematicRover);
  // Corrupt the satellite record after the 100th and the 200th epoch lines, then cut the file in an epoch.
  std::size_t at = 0;
  for (int k = 0; k < 200; ++k) {
    at = text.find("\n>", at + 1);
    if (k == 99 || k == 199) text.replace(text.find('\n', at + 1) + 4, 6, "x?x?x?");
  }
  text.resize(text.size() * 3 / 4);
  const test::TempDir dir;
  const std::string path = dir.write("corrupt.21o", text);
  const Reading expected = read_sequentially(path);
  EXPECT_EQ(expected.warnings.size(), 3U);  // two corrupt epochs, the cut one
  for (const std::size_t depth : {0U, 1U, 64U}) {
    SCOPED_TRACE("depth " + std::to_string(depth));
    expect_same(expected, read_ahead(path, depth));
  }
}

TEST(ObsReadAhead, FinishingHalfWayReportsOnlyTheWarningsOfTheEpochsReturned) {
  SKIP_WITHOUT_SHARED_DATA();
  std::string text = read_text(kKinematicRover);
  std::size_t at = 0;
  for (int k = 0; k < 300; ++k) at = text.find("\n>", at + 1);
  text.replace(text.find('\n', at + 1) + 4, 6, "x?x?x?");  // a warning at epoch 300, after the stop
  const test::TempDir dir;
  const std::string path = dir.write("late-warning.21o", text);
  // The reading thread is far ahead (depth 64) when the consumer stops after 250 epochs.
  const Reading expected = read_sequentially(path, 250);
  for (const std::size_t depth : {0U, 64U}) {
    SCOPED_TRACE("depth " + std::to_string(depth));
    const Reading actual = read_ahead(path, depth, 250);
    EXPECT_TRUE(actual.warnings.empty());
    expect_same(expected, actual);
  }
}

TEST(ObsReadAhead, DestroyedWithAFullQueueDoesNotHang) {
  SKIP_WITHOUT_SHARED_DATA();
  for (int k = 0; k < 20; ++k) {
    auto reader = ObsReadAhead::open(kKinematicRover, std::nullopt, 2);
    ASSERT_TRUE(reader);
    ASSERT_TRUE(reader->next());
    ObsReadAhead moved = std::move(*reader);  // the thread keeps its state across a move
    ASSERT_TRUE(moved.next());
  }
}

TEST(ObsReadAhead, HeaderErrorsComeFromOpen) {
  const test::TempDir dir;
  const std::string path = dir.write("no-header.obs", "not a RINEX file\n");
  const auto reader = ObsReadAhead::open(path);
  ASSERT_FALSE(reader);
  EXPECT_EQ(reader.error().file, path) << reader.error().message;
  EXPECT_FALSE(ObsReadAhead::open(dir.file("missing.obs")));
}

}  // namespace
}  // namespace canyon::io
