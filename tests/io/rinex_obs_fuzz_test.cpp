// Seeded mutation tests of the RINEX observation reader. Corrupted, truncated and spliced variants of valid files
// must give either a result or an Error naming the file, never a crash or a hang; and a file with one corrupted
// epoch must give every other epoch unchanged, whatever the corruption.

#include <algorithm>
#include <cctype>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "canyon/io/rinex_obs.hpp"

#include "io/rinex_test_util.hpp"

namespace canyon::io {
namespace {

using test::epoch_v2;
using test::epoch_v3;
using test::header_line;
using test::obs_field;

/// A valid file and the byte range [begin, end) of each of its epochs (end just after the epoch's last newline).
struct Base {
  std::string text;
  std::vector<std::pair<std::size_t, std::size_t>> epochs;
};

Base valid_v3(int epochs) {
  Base b;
  b.text = header_line("     3.04           OBSERVATION DATA    M", "RINEX VERSION / TYPE") +
           header_line("G    4 C1C L1C D1C S1C", "SYS / # / OBS TYPES") +
           header_line("R    2 C1C L1C", "SYS / # / OBS TYPES") +
           header_line("  2 R01  1 R02 -4", "GLONASS SLOT / FRQ #") +
           header_line("  2021     9    22     6    30    0.0000000     GPS", "TIME OF FIRST OBS") +
           header_line("", "END OF HEADER");
  for (int i = 0; i < epochs; ++i) {
    const std::size_t begin = b.text.size();
    b.text += epoch_v3(2021, 9, 22, 6, 30, i, 0, 3);
    b.text += "G05" + obs_field(2.1e7 + i) + obs_field(1.1e8 + i, 1, 6) + obs_field(-100.0) + obs_field(45.0) + "\n";
    b.text += "G07" + obs_field(2.2e7 + i) + obs_field(1.2e8 + i) + "\n";
    b.text += "R01" + obs_field(2.3e7 + i) + obs_field(1.3e8 + i) + "\n";
    b.epochs.emplace_back(begin, b.text.size());
  }
  return b;
}

Base valid_v2(int epochs) {
  Base b;
  b.text = header_line("     2.11           OBSERVATION DATA    M", "RINEX VERSION / TYPE") +
           header_line("     7    C1    P1    L1    D1    S1    C2    L2", "# / TYPES OF OBSERV") +
           header_line("", "END OF HEADER");
  for (int i = 0; i < epochs; ++i) {
    const std::size_t begin = b.text.size();
    b.text += epoch_v2(2021, 9, 22, 6, 30, i, 0, 2) + "G05R07\n";
    for (int k = 0; k < 2; ++k) {
      b.text += obs_field(2.1e7 + i) + obs_field(2.1e7 + k) + obs_field(1.1e8, 0, 5) + obs_field(-50.0) +
                obs_field(40.0) + "\n";
      b.text += obs_field(2.1e7) + obs_field(8.5e7 + i) + "\n";
    }
    b.epochs.emplace_back(begin, b.text.size());
  }
  return b;
}

/// Reads `path` epoch by epoch as a streaming client would, failing the test if next() is called more often than
/// the file has lines (each call consumes a line or reports the end): a hang shows as a failure, not a timeout.
Result<RinexObsFile> read_bounded(const std::string& path, const std::string& text) {
  auto reader = RinexObsReader::open(path);
  if (!reader.ok()) return reader.error();
  RinexObsFile file;
  const auto lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 2;
  for (std::size_t calls = 0;; ++calls) {
    if (calls > lines) {
      ADD_FAILURE() << "next() called " << calls << " times on a file of " << lines << " lines";
      return Error{"hang", path};
    }
    auto epoch = reader->next();
    if (!epoch.ok()) return epoch.error();
    if (!*epoch) break;
    file.epochs.push_back(std::move(**epoch));
  }
  file.warnings = reader->warnings();
  return file;
}

/// What every result must satisfy: an Error names the file; warnings say "file:line: "; epochs (flags 0, 1) come
/// in increasing time.
void expect_well_formed(const Result<RinexObsFile>& file, const std::string& path) {
  if (!file.ok()) {
    EXPECT_EQ(file.error().file, path);
    EXPECT_FALSE(file.error().message.empty());
    return;
  }
  for (const std::string& w : file->warnings) {
    ASSERT_EQ(w.rfind(path + ":", 0), 0u) << w;
    EXPECT_TRUE(std::isdigit(static_cast<unsigned char>(w[path.size() + 1]))) << w;
  }
  const core::ObsEpoch* previous = nullptr;
  for (const auto& e : file->epochs) {
    if (e.flag == core::EpochFlag::CycleSlipRecords) continue;
    if (previous != nullptr) {
      EXPECT_GT(e.time - previous->time, 0.0);
    }
    previous = &e;
  }
}

TEST(RinexObservationFuzz, MutatedFilesNeverCrashOrHang) {
  test::TempDir tmp;
  std::mt19937 rng(20240624);
  const std::string printable = " 0123456789.-+>GREJCSDX\n\t";
  const std::string bases[] = {valid_v3(4).text, valid_v2(3).text};
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
      expect_well_formed(read_bounded(path, text), path);
    }
  }
}

// ----- one corrupted epoch

/// Corrupts the epoch in [begin, end) of `text` (its lines keep their newlines, unless one is deleted).
void corrupt_epoch(std::string& text, std::size_t begin, std::size_t end, int kind, std::mt19937& rng) {
  const std::string chars = " 0123456789.-+>GREJCSDXe\t";
  // Start of a random line of the epoch and that line's end (its newline).
  std::size_t line_begin = begin + rng() % (end - begin);
  while (line_begin > begin && text[line_begin - 1] != '\n') --line_begin;
  const std::size_t line_end = text.find('\n', line_begin);
  switch (kind) {
    case 0:  // overwrite a few characters, newlines kept
      for (int k = 0; k < 1 + static_cast<int>(rng() % 3); ++k) {
        const std::size_t p = begin + rng() % (end - begin);
        if (text[p] != '\n') text[p] = chars[rng() % chars.size()];
      }
      break;
    case 1: {  // a line cut short
      const std::size_t cut = line_begin + rng() % (line_end - line_begin + 1);
      text.erase(cut, line_end - cut);
      break;
    }
    case 2:  // a line of garbage bytes
      for (std::size_t p = line_begin; p < line_end; ++p) {
        text[p] = static_cast<char>(1 + rng() % 255);
        if (text[p] == '\n') text[p] = '?';
      }
      break;
    default:  // a line missing
      text.erase(line_begin, line_end + 1 - line_begin);
      break;
  }
}

bool same_epoch(const core::ObsEpoch& a, const core::ObsEpoch& b) {
  if (a.time - b.time != 0.0 || a.flag != b.flag || a.sats.size() != b.sats.size()) return false;
  for (std::size_t k = 0; k < a.sats.size(); ++k) {
    const auto& sa = a.sats[k];
    const auto& sb = b.sats[k];
    if (sa.sat != sb.sat || sa.signals.size() != sb.signals.size()) return false;
    for (std::size_t s = 0; s < sa.signals.size(); ++s) {
      const auto& x = sa.signals[s];
      const auto& y = sb.signals[s];
      const auto eq = [](double u, double v) { return (!core::has_value(u) && !core::has_value(v)) || u == v; };
      if (x.code != y.code || !eq(x.pseudorange_m, y.pseudorange_m) || !eq(x.carrier_phase_cyc, y.carrier_phase_cyc) ||
          !eq(x.doppler_hz, y.doppler_hz) || !eq(x.snr_dbhz, y.snr_dbhz) || x.lli != y.lli) {
        return false;
      }
    }
  }
  return true;
}

/// `out` read from `base` with epoch k corrupted: the epochs before k unchanged; then epoch k as read (any content)
/// or nothing; then the epochs after k unchanged, except those the corrupted epoch's time (if it parsed as a later
/// valid one) puts out of order.
void expect_only_epoch_affected(const std::vector<core::ObsEpoch>& base, const std::vector<core::ObsEpoch>& out,
                                std::size_t k) {
  ASSERT_GE(out.size(), k);
  test::expect_same_epochs({out.begin(), out.begin() + static_cast<std::ptrdiff_t>(k)},
                           {base.begin(), base.begin() + static_cast<std::ptrdiff_t>(k)}, 0.0);
  std::size_t rest = k;
  const core::ObsEpoch* variant = nullptr;
  if (out.size() > k && (k + 1 >= base.size() || !same_epoch(out[k], base[k + 1]))) {
    variant = &out[k];
    rest = k + 1;
  }
  std::vector<core::ObsEpoch> expected;
  for (std::size_t j = k + 1; j < base.size(); ++j) {
    const bool in_order =
        variant == nullptr || variant->flag == core::EpochFlag::CycleSlipRecords || base[j].time - variant->time > 0.0;
    if (in_order) expected.push_back(base[j]);
  }
  test::expect_same_epochs({out.begin() + static_cast<std::ptrdiff_t>(rest), out.end()}, expected, 0.0);
}

TEST(RinexObservationFuzz, OneCorruptedEpochLeavesEveryOtherEpochUnchanged) {
  test::TempDir tmp;
  std::mt19937 rng(20250301);
  const Base bases[] = {valid_v3(8), valid_v2(8)};
  int skipped = 0;
  for (const Base& base : bases) {
    const auto original = read_rinex_obs(tmp.write("base.rnx", base.text));
    ASSERT_TRUE(original.ok());
    ASSERT_EQ(original->epochs.size(), base.epochs.size());
    for (int trial = 0; trial < 800; ++trial) {
      const std::size_t k = rng() % base.epochs.size();
      std::string text = base.text;
      corrupt_epoch(text, base.epochs[k].first, base.epochs[k].second, trial % 4, rng);
      const std::string path = tmp.write("corrupted.rnx", text);
      const auto file = read_bounded(path, text);
      SCOPED_TRACE("trial " + std::to_string(trial) + ", epoch " + std::to_string(k) + ":\n" +
                   text.substr(base.epochs[k].first, base.epochs[k].second - base.epochs[k].first + 20));
      ASSERT_TRUE(file.ok()) << file.error().to_string();
      expect_well_formed(file, path);
      expect_only_epoch_affected(original->epochs, file->epochs, k);
      if (file->epochs.size() < base.epochs.size()) {
        EXPECT_FALSE(file->warnings.empty());
        ++skipped;
      }
      if (::testing::Test::HasFailure()) return;
    }
  }
  EXPECT_GT(skipped, 800);  // the corruptions do hit: most corrupted epochs are detected and skipped
}

}  // namespace
}  // namespace canyon::io
