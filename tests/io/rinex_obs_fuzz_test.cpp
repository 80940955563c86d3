// Seeded mutation test of the RINEX observation reader: corrupted, truncated and spliced variants of valid files
// must give either a result or an Error naming the file, never a crash or a hang.

#include <random>
#include <string>

#include <gtest/gtest.h>

#include "canyon/io/rinex_obs.hpp"

#include "io/rinex_test_util.hpp"

namespace canyon::io {
namespace {

using test::epoch_v2;
using test::epoch_v3;
using test::header_line;
using test::obs_field;

std::string valid_v3() {
  std::string text = header_line("     3.04           OBSERVATION DATA    M", "RINEX VERSION / TYPE") +
                     header_line("G    4 C1C L1C D1C S1C", "SYS / # / OBS TYPES") +
                     header_line("R    2 C1C L1C", "SYS / # / OBS TYPES") +
                     header_line("  2 R01  1 R02 -4", "GLONASS SLOT / FRQ #") +
                     header_line("  2021     9    22     6    30    0.0000000     GPS", "TIME OF FIRST OBS") +
                     header_line("", "END OF HEADER");
  for (int i = 0; i < 4; ++i) {
    text += epoch_v3(2021, 9, 22, 6, 30, i, 0, 3);
    text += "G05" + obs_field(2.1e7 + i) + obs_field(1.1e8 + i, 1, 6) + obs_field(-100.0) + obs_field(45.0) + "\n";
    text += "G07" + obs_field(2.2e7 + i) + obs_field(1.2e8 + i) + "\n";
    text += "R01" + obs_field(2.3e7 + i) + obs_field(1.3e8 + i) + "\n";
  }
  return text;
}

std::string valid_v2() {
  std::string text = header_line("     2.11           OBSERVATION DATA    M", "RINEX VERSION / TYPE") +
                     header_line("     7    C1    P1    L1    D1    S1    C2    L2", "# / TYPES OF OBSERV") +
                     header_line("", "END OF HEADER");
  for (int i = 0; i < 3; ++i) {
    text += epoch_v2(2021, 9, 22, 6, 30, i, 0, 2) + "G05R07\n";
    for (int k = 0; k < 2; ++k) {
      text += obs_field(2.1e7) + obs_field(2.1e7) + obs_field(1.1e8, 0, 5) + obs_field(-50.0) + obs_field(40.0) + "\n";
      text += obs_field(2.1e7) + obs_field(8.5e7) + "\n";
    }
  }
  return text;
}

TEST(RinexObservationFuzz, MutatedFilesNeverCrash) {
  test::TempDir tmp;
  std::mt19937 rng(20240624);
  const std::string printable = " 0123456789.-+>GREJCSDX\n\t";
  const std::string bases[] = {valid_v3(), valid_v2()};
  for (const std::string& base : bases) {
    ASSERT_TRUE(read_rinex_obs(tmp.write("base.rnx", base)).ok());
    for (int trial = 0; trial < 600; ++trial) {
      std::string text = base;
      std::uniform_int_distribution<std::size_t> pos(0, text.size() - 1);
      switch (trial % 4) {
        case 0:  // overwrite a few characters
          for (int k = 0; k < 3; ++k) text[pos(rng)] = printable[rng() % printable.size()];
          break;
        case 1:  // truncate
          text.resize(pos(rng));
          break;
        case 2:  // delete a span
          text.erase(pos(rng), rng() % 40);
          break;
        default:  // random bytes
          for (int k = 0; k < 5; ++k) text[pos(rng)] = static_cast<char>(rng() % 256);
          break;
      }
      const std::string path = tmp.write("mutated.rnx", text);
      const auto file = read_rinex_obs(path);
      if (!file.ok()) {
        EXPECT_EQ(file.error().file, path);
        EXPECT_FALSE(file.error().message.empty());
      }
    }
  }
}

}  // namespace
}  // namespace canyon::io
