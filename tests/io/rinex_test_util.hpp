#pragma once
// Helpers for the RINEX tests: a per-test temporary folder, builders for fixed-column RINEX text, and a comparison
// of epoch sequences.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "canyon/core/observation.hpp"

namespace canyon::io::test {

/// Fresh folder under the system temp dir, named after the running test, removed at destruction.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ =
        std::filesystem::temp_directory_path() / ("canyon_io_" + std::string(info->test_suite_name()) + "_" +
                                                  info->name() + "_" + std::to_string(static_cast<long>(::getpid())));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    if (!::testing::Test::HasFailure()) std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  [[nodiscard]] std::string file(const std::string& name) const { return (path_ / name).string(); }
  /// Writes `content` to a file in the folder and returns its path.
  [[nodiscard]] std::string write(const std::string& name, std::string_view content) const {
    const std::string p = file(name);
    std::ofstream(p, std::ios::binary) << content;
    return p;
  }

 private:
  std::filesystem::path path_;
};

/// A header line: content padded to 60 columns, then the label.
inline std::string header_line(std::string content, std::string_view label) {
  content.resize(60, ' ');
  return content + std::string(label) + "\n";
}

/// One F14.3 observation field with LLI and SSI digits (blank when negative); a blank field for NaN.
inline std::string obs_field(double value, int lli = -1, int ssi = -1) {
  if (value != value) return std::string(16, ' ');
  char text[32];
  std::snprintf(text, sizeof text, "%14.3f%c%c", value, lli < 0 ? ' ' : static_cast<char>('0' + lli),
                ssi < 0 ? ' ' : static_cast<char>('0' + ssi));
  return text;
}

/// RINEX 3 epoch line.
inline std::string epoch_v3(int year, int month, int day, int hour, int minute, double second, int flag, int count) {
  char text[64];
  std::snprintf(text, sizeof text, "> %04d %02d %02d %02d %02d%11.7f  %d%3d\n", year, month, day, hour, minute, second,
                flag, count);
  return text;
}

/// RINEX 2 epoch line without the satellite list and newline.
inline std::string epoch_v2(int year, int month, int day, int hour, int minute, double second, int flag, int count) {
  char text[64];
  std::snprintf(text, sizeof text, " %02d %2d %2d %2d %2d%11.7f  %d%3d", year % 100, month, day, hour, minute, second,
                flag, count);
  return text;
}

/// Same epochs: times, flags, satellites and signals, values within `tolerance` (missing in both counts as equal).
inline void expect_same_epochs(const std::vector<core::ObsEpoch>& a, const std::vector<core::ObsEpoch>& b,
                               double tolerance) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto& ea = a[i];
    const auto& eb = b[i];
    ASSERT_NEAR(ea.time - eb.time, 0.0, 1e-7) << "epoch " << i;
    ASSERT_EQ(ea.flag, eb.flag);
    ASSERT_EQ(ea.sats.size(), eb.sats.size()) << "epoch " << i;
    for (std::size_t k = 0; k < ea.sats.size(); ++k) {
      const auto& sa = ea.sats[k];
      const auto& sb = eb.sats[k];
      ASSERT_EQ(sa.sat, sb.sat);
      ASSERT_EQ(sa.signals.size(), sb.signals.size()) << sa.sat.to_string() << " epoch " << i;
      for (const auto& x : sa.signals) {
        const core::SignalObs* y = sb.find(x.code);
        ASSERT_NE(y, nullptr) << sa.sat.to_string() << " " << x.code.to_string();
        const auto near = [&](double u, double v) {
          return (!core::has_value(u) && !core::has_value(v)) || std::abs(u - v) <= tolerance;
        };
        EXPECT_TRUE(near(x.pseudorange_m, y->pseudorange_m)) << x.pseudorange_m << " " << y->pseudorange_m;
        EXPECT_TRUE(near(x.carrier_phase_cyc, y->carrier_phase_cyc))
            << x.carrier_phase_cyc << " " << y->carrier_phase_cyc;
        EXPECT_TRUE(near(x.doppler_hz, y->doppler_hz));
        EXPECT_TRUE(near(x.snr_dbhz, y->snr_dbhz));
        EXPECT_EQ(x.lli, y->lli);
      }
    }
  }
}

}  // namespace canyon::io::test
