// RINEX observation reader on small files written by the tests: RINEX 2 layout (type continuation lines, records
// wrapping after five fields, satellite lists beyond twelve), type mapping, time systems, event epochs, skipped
// systems, recoverable defects, and malformed files that must give an Error naming the file and the line.

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "canyon/io/rinex_obs.hpp"

#include "io/rinex_test_util.hpp"

namespace canyon::io {
namespace {

using core::Constellation;
using core::SatelliteId;
using core::SignalCode;
using test::epoch_v2;
using test::epoch_v3;
using test::header_line;
using test::obs_field;

constexpr double kNan = core::kNoValue;

std::string version_line(const char* version, char type = 'O', char system = 'M') {
  return header_line(std::string(version) + std::string(11, ' ') +
                         (type == 'O' ? "OBSERVATION DATA    " : "N: GNSS NAV DATA     ") + system,
                     "RINEX VERSION / TYPE");
}

/// A valid RINEX 3.04 header of 4 lines (GPS C1C L1C D1C S1C); the first epoch line is line 5.
std::string header_v3(const std::string& time_system = "GPS") {
  return version_line("     3.04") + header_line("G    4 C1C L1C D1C S1C", "SYS / # / OBS TYPES") +
         header_line("  2021     9    22     6    30    0.0000000     " + time_system, "TIME OF FIRST OBS") +
         header_line("", "END OF HEADER");
}

std::string record_v3(const char* sat, double c1, double l1, int lli = -1) {
  return std::string(sat) + obs_field(c1) + obs_field(l1, lli) + obs_field(-1234.5) + obs_field(45.25) + "\n";
}

const core::SignalObs* find_signal(const core::ObsEpoch& epoch, SatelliteId sat, SignalCode code) {
  for (const auto& s : epoch.sats) {
    if (s.sat == sat) return s.find(code);
  }
  return nullptr;
}

RinexObsFile read_ok(const std::string& path) {
  auto file = read_rinex_obs(path);
  EXPECT_TRUE(file.ok()) << (file.ok() ? "" : file.error().to_string());
  return file.ok() ? std::move(file).value() : RinexObsFile{};
}

// ----- RINEX 2

TEST(RinexObservationReader, Rinex211MixedWithContinuationsAndWrapping) {
  test::TempDir tmp;
  // 11 types over two "# / TYPES OF OBSERV" lines; records wrap after 5 fields (3 lines per satellite);
  // 14 satellites (one SBAS) over two epoch lines.
  std::string text =
      version_line("     2.11") +
      header_line("    11    C1    P1    L1    D1    S1    C2    P2    L2    S2", "# / TYPES OF OBSERV") +
      header_line("          C5    L5", "# / TYPES OF OBSERV") +
      header_line("  2021     9    22     6    30    0.0000000     GPS", "TIME OF FIRST OBS") +
      header_line("", "END OF HEADER");
  const char* sats[] = {"G01", "G02", "G03", "G04", "G05", "R06", "R07",
                        "E08", "E09", "S20", "G11", "G12", "G13", " 14"};
  std::string list;
  for (int k = 0; k < 12; ++k) list += sats[k];
  text += epoch_v2(2021, 9, 22, 6, 30, 0.0, 0, 14) + list + "\n";
  text += std::string(32, ' ') + sats[12] + sats[13] + "\n";
  for (int k = 0; k < 14; ++k) {
    const double base = 20000000.0 + k * 1000.0;
    // C1 P1 L1 D1 S1 / C2 P2 L2 S2 C5 / L5
    text += obs_field(base) + obs_field(base + 1.0) + obs_field(base * 5.25, 1, 7) + obs_field(-100.5) +
            obs_field(44.0) + "\n";
    text += obs_field(base + 2.0) + obs_field(base + 3.0) + obs_field(base * 4.09, 0, 5) + obs_field(30.0) +
            obs_field(k == 0 ? kNan : base + 5.0) + "\n";
    text += obs_field(k == 0 ? 0.0 : base * 3.91) + "\n";
  }
  const std::string path = tmp.write("mixed.21o", text);
  const RinexObsFile file = read_ok(path);
  ASSERT_EQ(file.epochs.size(), 1u);
  const core::ObsEpoch& e = file.epochs[0];
  EXPECT_EQ(e.sats.size(), 13u);  // S20 skipped
  ASSERT_EQ(file.warnings.size(), 1u);
  EXPECT_NE(file.warnings[0].find("system 'S'"), std::string::npos) << file.warnings[0];

  const SatelliteId g01{Constellation::Gps, 1};
  const auto* g1c = find_signal(e, g01, {'1', 'C'});
  const auto* g1w = find_signal(e, g01, {'1', 'W'});
  const auto* g2c = find_signal(e, g01, {'2', 'C'});
  const auto* g2w = find_signal(e, g01, {'2', 'W'});
  ASSERT_TRUE(g1c && g1w && g2c && g2w);
  EXPECT_DOUBLE_EQ(g1c->pseudorange_m, 20000000.0);
  EXPECT_DOUBLE_EQ(g1w->pseudorange_m, 20000001.0);
  EXPECT_FALSE(core::has_value(g1w->carrier_phase_cyc));
  EXPECT_DOUBLE_EQ(g1c->carrier_phase_cyc, 20000000.0 * 5.25);
  EXPECT_EQ(g1c->lli, 1);
  EXPECT_DOUBLE_EQ(g1c->doppler_hz, -100.5);
  EXPECT_DOUBLE_EQ(g1c->snr_dbhz, 44.0);
  EXPECT_DOUBLE_EQ(g2c->pseudorange_m, 20000002.0);
  EXPECT_DOUBLE_EQ(g2w->pseudorange_m, 20000003.0);
  EXPECT_DOUBLE_EQ(g2w->snr_dbhz, 30.0);
  EXPECT_EQ(find_signal(e, g01, {'5', 'X'}), nullptr);  // C5 blank, L5 0.0: no observable, no signal

  const SatelliteId g14{Constellation::Gps, 14};  // " 14": blank system means GPS
  const auto* g14_5 = find_signal(e, g14, {'5', 'X'});
  ASSERT_NE(g14_5, nullptr);
  EXPECT_DOUBLE_EQ(g14_5->pseudorange_m, 20000000.0 + 13 * 1000.0 + 5.0);
  EXPECT_DOUBLE_EQ(g14_5->carrier_phase_cyc, (20000000.0 + 13 * 1000.0) * 3.91);

  const SatelliteId r06{Constellation::Glonass, 6};
  EXPECT_NE(find_signal(e, r06, {'1', 'P'}), nullptr);
  EXPECT_NE(find_signal(e, r06, {'2', 'P'}), nullptr);
  const SatelliteId e08{Constellation::Galileo, 8};
  EXPECT_NE(find_signal(e, e08, {'1', 'X'}), nullptr);
  EXPECT_NE(find_signal(e, e08, {'5', 'X'}), nullptr);
  EXPECT_EQ(find_signal(e, e08, {'2', 'W'}), nullptr);  // no Galileo mapping for C2/P2/L2

  const std::vector<std::string> gps = {"C1C", "C1W", "L1C", "D1C", "S1C", "C2C", "C2W", "L2W", "S2W", "C5X", "L5X"};
  EXPECT_EQ(file.header.obs_types.at(Constellation::Gps), gps);
  EXPECT_EQ(file.header.obs_types.at(Constellation::Glonass).size(), 9u);
}

TEST(RinexObservationReader, Rinex210GlonassFileUsesGlonassTime) {
  test::TempDir tmp;
  // A GLONASS-only file without a time system: epochs are GLONASS time = UTC + 3 h; builtin leap seconds (18 s).
  const std::string text = version_line("     2.10", 'O', 'R') +
                           header_line("     2    C1    L1", "# / TYPES OF OBSERV") +
                           header_line("  2021     9    22     9    30    0.0000000", "TIME OF FIRST OBS") +
                           header_line("", "END OF HEADER") + epoch_v2(2021, 9, 22, 9, 30, 0.0, 0, 1) + "R05\n" +
                           obs_field(21000000.0) + obs_field(110000000.0) + "\n";
  const RinexObsFile file = read_ok(tmp.write("glo.21o", text));
  ASSERT_EQ(file.epochs.size(), 1u);
  EXPECT_EQ(file.header.time_system, "GLO");
  const core::GpsTime expected = core::calendar_to_gps({2021, 9, 22, 6, 30, 18.0});
  EXPECT_NEAR(file.epochs[0].time - expected, 0.0, 1e-9);
  ASSERT_TRUE(file.header.first_obs.has_value());
  EXPECT_NEAR(*file.header.first_obs - expected, 0.0, 1e-9);
}

// ----- RINEX 3

TEST(RinexObservationReader, Rinex302BeidouBand1IsB1IAndBdtTime) {
  test::TempDir tmp;
  const std::string text =
      version_line("     3.02", 'O', 'C') + header_line("C    4 C1I L1I C7I L7I", "SYS / # / OBS TYPES") +
      header_line("C L1I  0.00000", "SYS / PHASE SHIFT") +
      header_line("  2021     9    22     6    30    0.0000000     BDT", "TIME OF FIRST OBS") +
      header_line("", "END OF HEADER") + epoch_v3(2021, 9, 22, 6, 30, 0.0, 0, 1) + "C11" + obs_field(38000000.0) +
      obs_field(197000000.0, 1) + obs_field(38000001.0) + obs_field(153000000.0) + "\n";
  const RinexObsFile file = read_ok(tmp.write("bds.rnx", text));
  ASSERT_EQ(file.epochs.size(), 1u);
  const std::vector<std::string> types = {"C2I", "L2I", "C7I", "L7I"};
  EXPECT_EQ(file.header.obs_types.at(Constellation::BeiDou), types);
  const auto* b1 = find_signal(file.epochs[0], {Constellation::BeiDou, 11}, {'2', 'I'});
  ASSERT_NE(b1, nullptr);
  EXPECT_DOUBLE_EQ(b1->carrier_phase_cyc, 197000000.0);
  EXPECT_EQ(b1->lli, 1);
  ASSERT_EQ(file.header.receiver.phase_shifts.size(), 1u);
  EXPECT_EQ(file.header.receiver.phase_shifts[0].code, (SignalCode{'2', 'I'}));
  // BDT = GPST - 14 s.
  EXPECT_NEAR(file.epochs[0].time - core::calendar_to_gps({2021, 9, 22, 6, 30, 14.0}), 0.0, 1e-9);
}

TEST(RinexObservationReader, EventEpochsAreReadPastAndCycleSlipEpochsReturned) {
  test::TempDir tmp;
  std::string text = header_v3();
  text += epoch_v3(2021, 9, 22, 6, 30, 0.0, 0, 1) + record_v3("G05", 21000000.0, 110000000.0);
  // Flag 4 with two header records, one of them a new marker name.
  text += epoch_v3(2021, 9, 22, 6, 30, 0.5, 4, 2) + header_line("NEW MARKER", "MARKER NAME") +
          header_line("a comment", "COMMENT");
  // Flag 5 (external event), no records.
  text += epoch_v3(2021, 9, 22, 6, 30, 0.7, 5, 0);
  text += epoch_v3(2021, 9, 22, 6, 30, 1.0, 1, 1) + record_v3("G05", 21000001.0, 110000005.0);
  text += epoch_v3(2021, 9, 22, 6, 30, 1.0, 6, 1) + record_v3("G05", 21000001.0, 110000005.0, 1);
  text += "\n\n";  // trailing blank lines
  auto reader = RinexObsReader::open(tmp.write("events.rnx", text));
  ASSERT_TRUE(reader.ok()) << reader.error().to_string();
  std::vector<core::ObsEpoch> epochs;
  for (;;) {
    auto e = reader->next();
    ASSERT_TRUE(e.ok()) << e.error().to_string();
    if (!*e) break;
    epochs.push_back(std::move(**e));
  }
  ASSERT_EQ(epochs.size(), 3u);
  EXPECT_EQ(epochs[0].flag, core::EpochFlag::Ok);
  EXPECT_EQ(epochs[1].flag, core::EpochFlag::PowerFailure);
  EXPECT_EQ(epochs[2].flag, core::EpochFlag::CycleSlipRecords);
  EXPECT_EQ(epochs[2].sats.at(0).signals.at(0).lli, 1);
  EXPECT_EQ(reader->header().receiver.marker_name, "NEW MARKER");
  EXPECT_TRUE(reader->warnings().empty());
}

TEST(RinexObservationReader, ShortEpochIsRecoveredWithAWarning) {
  test::TempDir tmp;
  std::string text = header_v3();
  text += epoch_v3(2021, 9, 22, 6, 30, 0.0, 0, 3) + record_v3("G05", 21000000.0, 110000000.0) +
          record_v3("G07", 22000000.0, 115000000.0);  // line 5: announces 3, 2 present
  text += epoch_v3(2021, 9, 22, 6, 30, 1.0, 0, 2) + record_v3("G05", 21000001.0, 110000005.0) +
          record_v3("G07", 22000001.0, 115000005.0);
  const std::string path = tmp.write("short.rnx", text);
  const RinexObsFile file = read_ok(path);
  ASSERT_EQ(file.epochs.size(), 2u);
  EXPECT_EQ(file.epochs[0].sats.size(), 2u);
  EXPECT_EQ(file.epochs[1].sats.size(), 2u);
  ASSERT_EQ(file.warnings.size(), 1u);
  EXPECT_EQ(file.warnings[0], path + ":5: epoch announces 3 satellites, 2 present");
}

TEST(RinexObservationReader, OtherSystemsAreSkippedWithOneWarningEach) {
  test::TempDir tmp;
  const std::string text = version_line("     3.04") + header_line("G    2 C1C L1C", "SYS / # / OBS TYPES") +
                           header_line("S    2 C1C L1C", "SYS / # / OBS TYPES") +
                           header_line("I    2 C5A L5A", "SYS / # / OBS TYPES") + header_line("", "END OF HEADER") +
                           epoch_v3(2021, 9, 22, 6, 30, 0.0, 0, 4) + "S20" + obs_field(38000000.0) + "\n" + "G05" +
                           obs_field(21000000.0) + "\n" + "S27" + obs_field(38000000.0) + "\n" + "I02" +
                           obs_field(36000000.0) + "\n";
  const RinexObsFile file = read_ok(tmp.write("sbas.rnx", text));
  ASSERT_EQ(file.epochs.size(), 1u);
  ASSERT_EQ(file.epochs[0].sats.size(), 1u);
  EXPECT_EQ(file.warnings.size(), 2u);
  EXPECT_EQ(file.header.obs_types.size(), 1u);
}

TEST(RinexObservationReader, ScaleFactorsDivideTheValues) {
  test::TempDir tmp;
  // L1C and D1C scaled by 10 (listed on a continuation line), every GLONASS type by 100.
  const std::string text =
      version_line("     3.04") + header_line("G    4 C1C L1C D1C S1C", "SYS / # / OBS TYPES") +
      header_line("R    2 C1C L1C", "SYS / # / OBS TYPES") + header_line("G   10  2", "SYS / SCALE FACTOR") +
      header_line("           L1C D1C", "SYS / SCALE FACTOR") + header_line("R  100", "SYS / SCALE FACTOR") +
      header_line("", "END OF HEADER") + epoch_v3(2021, 9, 22, 6, 30, 0.0, 0, 2) +
      record_v3("G05", 21000000.0, 1100000000.5) + "R01" + obs_field(2100000000.0) + obs_field(950000000.0) + "\n";
  const RinexObsFile file = read_ok(tmp.write("scaled.rnx", text));
  ASSERT_EQ(file.epochs.size(), 1u);
  const auto* g = find_signal(file.epochs[0], {Constellation::Gps, 5}, {'1', 'C'});
  ASSERT_NE(g, nullptr);
  EXPECT_DOUBLE_EQ(g->pseudorange_m, 21000000.0);
  EXPECT_DOUBLE_EQ(g->carrier_phase_cyc, 110000000.05);
  EXPECT_DOUBLE_EQ(g->doppler_hz, -123.45);
  EXPECT_DOUBLE_EQ(g->snr_dbhz, 45.25);
  const auto* r = find_signal(file.epochs[0], {Constellation::Glonass, 1}, {'1', 'C'});
  ASSERT_NE(r, nullptr);
  EXPECT_DOUBLE_EQ(r->pseudorange_m, 21000000.0);
  EXPECT_DOUBLE_EQ(r->carrier_phase_cyc, 9500000.0);
}

TEST(RinexObservationReader, MissingValuesAreNanAndEmptySignalsDropped) {
  test::TempDir tmp;
  const std::string text = header_v3() + epoch_v3(2021, 9, 22, 6, 30, 0.0, 0, 2) + "G05" + obs_field(21000000.0) +
                           obs_field(0.0, 1) + "\n" + "G07" + obs_field(kNan) + obs_field(0.0) + "\n";
  const RinexObsFile file = read_ok(tmp.write("missing.rnx", text));
  ASSERT_EQ(file.epochs.size(), 1u);
  const auto& sats = file.epochs[0].sats;
  ASSERT_EQ(sats.size(), 2u);
  ASSERT_EQ(sats[0].signals.size(), 1u);
  EXPECT_FALSE(core::has_value(sats[0].signals[0].carrier_phase_cyc));
  EXPECT_FALSE(core::has_value(sats[0].signals[0].snr_dbhz));
  EXPECT_TRUE(sats[1].signals.empty());
}

// ----- malformed files: each gives an Error naming the problem, the file and the line

struct MalformedCase {
  const char* name;
  std::string text;
  const char* message_part;
  int line;
};

std::vector<MalformedCase> malformed_cases() {
  const std::string good_epoch = epoch_v3(2021, 9, 22, 6, 30, 0.0, 0, 1) + record_v3("G05", 2.1e7, 1.1e8);
  return {
      {"empty", "", "empty file", 0},
      {"comment_first", header_line("made by hand", "COMMENT") + header_v3(), "RINEX VERSION / TYPE", 1},
      {"navigation_file", version_line("     3.04", 'N') + header_line("", "END OF HEADER"), "navigation file", 1},
      {"version_4", version_line("     4.01") + header_line("", "END OF HEADER"), "unsupported RINEX version 4.01", 1},
      {"version_1", version_line("     1.00") + header_line("", "END OF HEADER"), "unsupported RINEX version 1.00", 1},
      {"end_of_header_missing_at_eof", version_line("     3.04") + header_line("G    2 C1C L1C", "SYS / # / OBS TYPES"),
       "END OF HEADER", 2},
      {"end_of_header_missing_before_data",
       version_line("     3.04") + header_line("G    2 C1C L1C", "SYS / # / OBS TYPES") + good_epoch, "END OF HEADER",
       3},
      {"no_obs_types_v3", version_line("     3.04") + header_line("", "END OF HEADER") + good_epoch,
       "SYS / # / OBS TYPES", 2},
      {"no_obs_types_v2",
       version_line("     2.11", 'O', 'G') + header_line("X", "MARKER NAME") + header_line("", "END OF HEADER"),
       "# / TYPES OF OBSERV", 3},
      {"fewer_obs_types_than_announced",
       version_line("     3.04") + header_line("G   20 C1C L1C", "SYS / # / OBS TYPES") +
           header_line("", "END OF HEADER"),
       "fewer types than announced", 2},
      {"bad_epoch_date", header_v3() + epoch_v3(2021, 13, 22, 6, 30, 0.0, 0, 1) + record_v3("G05", 2.1e7, 1.1e8),
       "bad epoch date", 5},
      {"bad_satellite_count", header_v3() + "> 2021 09 22 06 30  0.0000000  0 x1\n", "bad satellite count", 5},
      {"non_numeric_seconds", header_v3() + good_epoch + "> 2021 09 22 06 30  0.00a0000  0  1\n", "bad epoch time", 7},
      {"bad_epoch_flag", header_v3() + "> 2021 09 22 06 30  0.0000000  9  1\n", "bad epoch flag", 5},
      {"data_line_without_epoch", header_v3() + good_epoch + record_v3("G05", 2.1e7, 1.1e8), "expected an epoch line",
       7},
      {"truncated_in_epoch_v3", header_v3() + epoch_v3(2021, 9, 22, 6, 30, 0.0, 0, 3) + record_v3("G05", 2.1e7, 1.1e8),
       "file ends inside an epoch", 6},
      {"truncated_in_epoch_v2",
       version_line("     2.11", 'O', 'G') +
           header_line("     6    C1    L1    C2    L2    S1    S2", "# / TYPES OF OBSERV") +
           header_line("", "END OF HEADER") + epoch_v2(2021, 9, 22, 6, 30, 0.0, 0, 2) + "G05G07\n" + obs_field(2.1e7) +
           "\n" + obs_field(2.1e7) + "\n" + obs_field(2.2e7) + "\n",
       "file ends inside an epoch", 7},
      {"satellite_list_short_v2",
       version_line("     2.11", 'O', 'G') + header_line("     1    C1", "# / TYPES OF OBSERV") +
           header_line("", "END OF HEADER") + epoch_v2(2021, 9, 22, 6, 30, 0.0, 0, 3) + "G05G07\n",
       "3 satellites, 2 listed", 4},
      {"system_without_obs_types",
       header_v3() + epoch_v3(2021, 9, 22, 6, 30, 0.0, 0, 2) + record_v3("G05", 2.1e7, 1.1e8) + "R05" +
           obs_field(2.1e7) + "\n",
       "no observation types declared for GLONASS", 7},
      {"bad_satellite", header_v3() + epoch_v3(2021, 9, 22, 6, 30, 0.0, 0, 1) + "X05" + obs_field(2.1e7) + "\n",
       "bad satellite 'X05'", 6},
      {"bad_observation_value", header_v3() + epoch_v3(2021, 9, 22, 6, 30, 0.0, 0, 1) + "G05  21000x00.000\n",
       "bad observation value '21000x00.000'", 6},
      {"binary_garbage",
       std::string("\x7f"
                   "ELF\x02\x01\x00\xff\xfe garbage\x01\n\x03\x04",
                   21),
       "not a RINEX file", 1},
      {"gzip_magic_garbage", std::string("\x1f\x8b\x00\xff\xfe garbage\x01\x02\n\x03\x04", 18), "read error", 0},
      {"crinex", header_line("1.0                 COMPACT RINEX FORMAT", "CRINEX VERS   / TYPE") + header_v3(),
       "Hatanaka", 1},
      {"bad_time_of_first_obs",
       version_line("     3.04") +
           header_line("  2021    19    22     6    30    0.0000000     GPS", "TIME OF FIRST OBS"),
       "TIME OF FIRST OBS", 2},
  };
}

TEST(RinexObservationReader, MalformedFilesGiveErrorsWithFileAndLine) {
  test::TempDir tmp;
  for (const MalformedCase& c : malformed_cases()) {
    SCOPED_TRACE(c.name);
    const std::string path = tmp.write(std::string(c.name) + ".rnx", c.text);
    const auto file = read_rinex_obs(path);
    ASSERT_FALSE(file.ok());
    const Error& error = file.error();
    EXPECT_NE(error.message.find(c.message_part), std::string::npos) << error.to_string();
    EXPECT_EQ(error.file, path);
    EXPECT_EQ(error.line, c.line) << error.to_string();
  }
}

TEST(RinexObservationReader, MissingFileIsAnError) {
  const auto file = read_rinex_obs("/nonexistent/canyon/file.obs");
  ASSERT_FALSE(file.ok());
  EXPECT_EQ(file.error().file, "/nonexistent/canyon/file.obs");
}

TEST(RinexObservationReader, NextAfterTheEndKeepsReturningNothing) {
  test::TempDir tmp;
  auto reader = RinexObsReader::open(
      tmp.write("one.rnx", header_v3() + epoch_v3(2021, 9, 22, 6, 30, 0.0, 0, 1) + record_v3("G05", 2.1e7, 1.1e8)));
  ASSERT_TRUE(reader.ok());
  auto first = reader->next();
  ASSERT_TRUE(first.ok() && first->has_value());
  for (int i = 0; i < 3; ++i) {
    auto e = reader->next();
    ASSERT_TRUE(e.ok());
    EXPECT_FALSE(e->has_value());
  }
}

}  // namespace
}  // namespace canyon::io
