// RINEX observation reader on small files written by the tests: RINEX 2 layout (type continuation lines, records
// wrapping after five fields, satellite lists beyond twelve), type mapping, time systems, event epochs, skipped
// systems, recoverable defects; corrupt epochs in the body, skipped with a warning naming the file and the line while
// every other epoch is read unchanged; and malformed headers or bodies that must give an Error naming the file and
// the line.

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

// ----- corrupt epochs in the body: each is skipped with a warning "file:line: what, epoch skipped (lines a-b)", and
// the epochs around it are read as if it were not there

/// A RINEX 2.11 GPS header of 3 lines (C1 L1 C2 L2: one record line per satellite); the first epoch line is line 4.
std::string header_v2() {
  return version_line("     2.11", 'O', 'G') + header_line("     4    C1    L1    C2    L2", "# / TYPES OF OBSERV") +
         header_line("", "END OF HEADER");
}

/// A valid epoch of 3 lines (epoch line, G05, G07) at second `s`, values depending on `s`.
std::string good_epoch(bool v3, int s) {
  const double c = 2.1e7 + 1000.0 * s;
  const double l = 1.1e8 + 5000.0 * s;
  if (v3) return epoch_v3(2021, 9, 22, 6, 30, s, 0, 2) + record_v3("G05", c, l, s % 2) + record_v3("G07", c + 1e6, l);
  const std::string record = obs_field(c) + obs_field(l, s % 2) + obs_field(c + 2.0) + obs_field(l * 0.78) + "\n";
  return epoch_v2(2021, 9, 22, 6, 30, s, 0, 2) + "G05G07\n" + record + record;
}

struct CorruptCase {
  const char* name;
  bool v3;
  std::string corrupt;  // put after the valid epoch of second 0 (v3: at line 8, v2: at line 7)
  bool at_end;          // the file ends with it (truncation); else the valid epochs of seconds 2 and 3 follow
  const char* message_part;
  int line;             // of the warning
  const char* skipped;  // "lines a-b" the warning reports
};

std::vector<CorruptCase> corrupt_cases() {
  const std::string g05 = record_v3("G05", 2.1e7, 1.1e8);
  const std::string g07 = record_v3("G07", 2.2e7, 1.2e8);
  const std::string v2_record = obs_field(2.1e7) + obs_field(1.1e8) + "\n";
  return {
      {"bad_epoch_date", true, epoch_v3(2021, 13, 22, 6, 30, 1.0, 0, 2) + g05 + g07, false, "bad epoch date", 8,
       "lines 8-10"},
      {"bad_satellite_count", true, "> 2021 09 22 06 30  1.0000000  0 x1\n" + g05, false, "bad satellite count", 8,
       "lines 8-9"},
      {"non_numeric_seconds", true, "> 2021 09 22 06 30  1.00a0000  0  2\n" + g05 + g07, false, "bad epoch time", 8,
       "lines 8-10"},
      {"bad_epoch_flag", true, "> 2021 09 22 06 30  1.0000000  9  2\n" + g05 + g07, false, "bad epoch flag", 8,
       "lines 8-10"},
      {"epoch_line_cut_short", true, "> 2021 09 22 06 30  1.00\n" + g05 + g07, false, "bad satellite count", 8,
       "lines 8-10"},
      {"data_line_without_epoch", true, g05, false, "expected an epoch line starting with '>', got 'G05", 8, "line 8"},
      {"garbage_lines", true, "\x01\x02\xff binary\n\n>> not an epoch\n", false,
       "expected an epoch line starting with '>', got '??? binary', 2 epochs", 8, "lines 8-10"},
      {"bad_satellite", true, epoch_v3(2021, 9, 22, 6, 30, 1.0, 0, 2) + "X05" + obs_field(2.1e7) + "\n" + g07, false,
       "bad satellite 'X05'", 9, "lines 8-10"},
      {"bad_observation_value", true, epoch_v3(2021, 9, 22, 6, 30, 1.0, 0, 2) + "G05  21000x00.000\n" + g07, false,
       "bad observation value '21000x00.000' in column 4", 9, "lines 8-10"},
      {"record_line_cut_short", true, epoch_v3(2021, 9, 22, 6, 30, 1.0, 0, 2) + g05.substr(0, 30) + "\n" + g07, false,
       "observation value '110000000.' cut short in column 20", 9, "lines 8-10"},
      {"truncated_in_epoch_v3", true, epoch_v3(2021, 9, 22, 6, 30, 1.0, 0, 3) + g05, true,
       "file ends inside an epoch: 3 satellites announced, 1 present", 9, "lines 8-9"},
      {"truncated_in_record_line_v3", true, epoch_v3(2021, 9, 22, 6, 30, 1.0, 0, 2) + g05 + g07.substr(0, 25), true,
       "cut short in column 20", 10, "lines 8-10"},
      {"truncated_in_epoch_v2", false, epoch_v2(2021, 9, 22, 6, 30, 1.0, 0, 2) + "G05G07\n" + v2_record, true,
       "file ends inside an epoch", 8, "lines 7-8"},
      {"satellite_list_short_v2", false, epoch_v2(2021, 9, 22, 6, 30, 1.0, 0, 3) + "G05G07\n" + v2_record + v2_record,
       false, "3 satellites, 2 listed", 7, "lines 7-9"},
      {"bad_observation_value_v2", false,
       epoch_v2(2021, 9, 22, 6, 30, 1.0, 0, 2) + "G05G07\n" + v2_record + "  21000x00.000\n", false,
       "bad observation value '21000x00.000' in column 1", 9, "lines 7-9"},
      // The list names three satellites but only two records follow: the next epoch line is where the third record
      // should be; it is recognised, not swallowed.
      {"fewer_records_than_listed_v2", false,
       epoch_v2(2021, 9, 22, 6, 30, 1.0, 0, 3) + "G05G07G09\n" + v2_record + v2_record, false,
       "epoch line where a satellite record was expected", 10, "lines 7-9"},
      {"garbled_epoch_line_v2", false, " 21  9 2x  6 30  1.0000000  0  2G05G07\n" + v2_record + v2_record, false,
       "bad epoch time", 7, "lines 7-9"},
  };
}

TEST(RinexObservationReader, CorruptEpochsAreSkippedWithAWarningAndTheOthersRead) {
  test::TempDir tmp;
  for (const CorruptCase& c : corrupt_cases()) {
    SCOPED_TRACE(c.name);
    const std::string before = (c.v3 ? header_v3() : header_v2()) + good_epoch(c.v3, 0);
    const std::string after = c.at_end ? "" : good_epoch(c.v3, 2) + good_epoch(c.v3, 3);
    const RinexObsFile reference = read_ok(tmp.write(std::string(c.name) + "_ref.rnx", before + after));
    ASSERT_EQ(reference.epochs.size(), c.at_end ? 1u : 3u);
    std::string text = before;
    text += c.corrupt;
    text += after;
    const std::string path = tmp.write(std::string(c.name) + ".rnx", text);
    const RinexObsFile file = read_ok(path);
    test::expect_same_epochs(file.epochs, reference.epochs, 0.0);
    ASSERT_EQ(file.warnings.size(), 1u);
    const std::string& warning = file.warnings[0];
    EXPECT_EQ(warning.rfind(path + ":" + std::to_string(c.line) + ": ", 0), 0u) << warning;
    EXPECT_NE(warning.find(c.message_part), std::string::npos) << warning;
    EXPECT_NE(warning.find(std::string(" skipped (") + c.skipped + ")"), std::string::npos) << warning;
  }
}

TEST(RinexObservationReader, EpochWithFewerSatellitesThanAnnouncedKeepsItsRecordsAndTheNextEpoch) {
  test::TempDir tmp;
  // RINEX 3: the next '>' line ends the short epoch (see ShortEpochIsRecoveredWithAWarning); RINEX 2 lists its
  // satellites, so a record missing there cannot be told which, and the epoch is skipped (above).
  std::string text = header_v3() + good_epoch(true, 0);
  text += epoch_v3(2021, 9, 22, 6, 30, 1.0, 0, 5) + record_v3("G05", 2.1e7, 1.1e8);  // line 8: 5 announced, 1 present
  text += good_epoch(true, 2);
  const std::string path = tmp.write("short.rnx", text);
  const RinexObsFile file = read_ok(path);
  ASSERT_EQ(file.epochs.size(), 3u);
  EXPECT_EQ(file.epochs[1].sats.size(), 1u);
  EXPECT_EQ(file.epochs[2].sats.size(), 2u);
  ASSERT_EQ(file.warnings.size(), 1u);
  EXPECT_EQ(file.warnings[0], path + ":8: epoch announces 5 satellites, 1 present");
}

TEST(RinexObservationReader, EpochWithMoreRecordsThanAnnouncedKeepsItsCountAndSkipsTheRest) {
  test::TempDir tmp;
  std::string text = header_v3() + good_epoch(true, 0);
  text += epoch_v3(2021, 9, 22, 6, 30, 1.0, 0, 1) + record_v3("G05", 2.1e7, 1.1e8) + record_v3("G07", 2.2e7, 1.2e8);
  text += good_epoch(true, 2);
  const std::string path = tmp.write("long.rnx", text);
  const RinexObsFile file = read_ok(path);
  ASSERT_EQ(file.epochs.size(), 3u);
  EXPECT_EQ(file.epochs[1].sats.size(), 1u);
  EXPECT_EQ(file.epochs[2].sats.size(), 2u);
  ASSERT_EQ(file.warnings.size(), 1u);
  EXPECT_EQ(file.warnings[0].rfind(path + ":10: expected an epoch line", 0), 0u) << file.warnings[0];
}

TEST(RinexObservationReader, SystemWithoutObservationTypesIsSkippedWithOneWarning) {
  test::TempDir tmp;
  // The header declares GPS only; GLONASS records are skipped, the epochs and their GPS records kept.
  std::string text = header_v3();
  for (int s = 0; s < 2; ++s) {
    text += epoch_v3(2021, 9, 22, 6, 30, s, 0, 2) + record_v3("G05", 2.1e7, 1.1e8) + "R05" + obs_field(2.1e7) + "\n";
  }
  const std::string path = tmp.write("glonass.rnx", text);
  const RinexObsFile file = read_ok(path);
  ASSERT_EQ(file.epochs.size(), 2u);
  for (const auto& e : file.epochs) {
    ASSERT_EQ(e.sats.size(), 1u);
    EXPECT_EQ(e.sats[0].sat, (SatelliteId{Constellation::Gps, 5}));
  }
  ASSERT_EQ(file.warnings.size(), 1u);
  EXPECT_EQ(file.warnings[0],
            path + ":7: satellite R05: no observation types declared for GLONASS, records of the " + "system skipped");
}

TEST(RinexObservationReader, DuplicateAndBackwardEpochsAreSkipped) {
  test::TempDir tmp;
  std::string text = header_v3() + good_epoch(true, 0) + good_epoch(true, 2);    // lines 5 and 8
  text += epoch_v3(2021, 9, 22, 6, 30, 2.0, 0, 1) + record_v3("G05", 9e6, 9e7);  // line 11: same time as line 8
  text += epoch_v3(2021, 9, 22, 6, 30, 1.0, 0, 1) + record_v3("G05", 9e6, 9e7);  // line 13: earlier
  text += good_epoch(true, 3);
  const std::string path = tmp.write("order.rnx", text);
  const RinexObsFile file = read_ok(path);
  const RinexObsFile reference =
      read_ok(tmp.write("ref.rnx", header_v3() + good_epoch(true, 0) + good_epoch(true, 2) + good_epoch(true, 3)));
  test::expect_same_epochs(file.epochs, reference.epochs, 0.0);
  ASSERT_EQ(file.warnings.size(), 2u);
  EXPECT_EQ(file.warnings[0],
            path + ":11: epoch 2021-09-22 06:30:02.0000000 repeats the time of the epoch of line 8, epoch skipped");
  EXPECT_EQ(file.warnings[1],
            path + ":13: epoch 2021-09-22 06:30:01.0000000 is earlier than the epoch of line 8, epoch skipped");
}

TEST(RinexObservationReader, CorruptFirstEpochIsSkipped) {
  test::TempDir tmp;
  const std::string text = header_v3() + "> 2021 09 22 06 30  0.0000000  0 x2\n" + record_v3("G05", 2.1e7, 1.1e8) +
                           record_v3("G07", 2.2e7, 1.2e8) + good_epoch(true, 1) + good_epoch(true, 2);
  const std::string path = tmp.write("first.rnx", text);
  const RinexObsFile file = read_ok(path);
  ASSERT_EQ(file.epochs.size(), 2u);
  ASSERT_EQ(file.warnings.size(), 1u);
  EXPECT_EQ(file.warnings[0].rfind(path + ":5: bad satellite count", 0), 0u) << file.warnings[0];
}

TEST(RinexObservationReader, TruncatedEventRecordsEndTheFileWithAWarning) {
  test::TempDir tmp;
  const std::string text =
      header_v3() + good_epoch(true, 0) + epoch_v3(2021, 9, 22, 6, 30, 1.0, 4, 3) + header_line("X", "COMMENT");
  const std::string path = tmp.write("event.rnx", text);
  const RinexObsFile file = read_ok(path);
  ASSERT_EQ(file.epochs.size(), 1u);
  ASSERT_EQ(file.warnings.size(), 1u);
  EXPECT_EQ(file.warnings[0], path + ":9: file ends inside the header records of an event epoch");
}

TEST(RinexObservationReader, Rinex2EventRecordsStopAtTheNextEpochLine) {
  test::TempDir tmp;
  // A flag 4 epoch announcing 3 header records holds one: the epoch line after it is not taken as a record.
  const std::string text = header_v2() + good_epoch(false, 0) + epoch_v2(2021, 9, 22, 6, 30, 1.0, 4, 3) + "\n" +
                           header_line("X", "COMMENT") + good_epoch(false, 2);
  const std::string path = tmp.write("event.21o", text);
  const RinexObsFile file = read_ok(path);
  ASSERT_EQ(file.epochs.size(), 2u);
  ASSERT_EQ(file.warnings.size(), 1u);
  EXPECT_EQ(file.warnings[0], path + ":9: event epoch announces 3 header records, 1 present");
}

// ----- malformed files: each gives an Error naming the problem, the file and the line

struct MalformedCase {
  const char* name;
  std::string text;
  const char* message_part;
  int line;
};

/// A body of `lines` lines that are not observation data (navigation records).
std::string nav_lines(int lines) {
  std::string text;
  for (int i = 0; i < lines; ++i) {
    text += i % 8 == 0 ? "G01 2021 09 22 06 00 00 1.234567890123E-04-1.136868377216E-12 0.000000000000E+00\n"
                       : "     1.000000000000E+01 2.000000000000E+01 3.000000000000E+01 4.000000000000E+01\n";
  }
  return text;
}

std::vector<MalformedCase> malformed_cases() {
  const std::string valid = epoch_v3(2021, 9, 22, 6, 30, 0.0, 0, 1) + record_v3("G05", 2.1e7, 1.1e8);
  const std::string valid_later = epoch_v3(2021, 9, 22, 6, 30, 1.0, 0, 1) + record_v3("G05", 2.1e7, 1.1e8);
  const std::string bad_epoch = "> 2021 09 22 06 30  0.0000000  9  1\n" + record_v3("G05", 2.1e7, 1.1e8);
  return {
      {"empty", "", "empty file", 0},
      {"comment_first", header_line("made by hand", "COMMENT") + header_v3(), "RINEX VERSION / TYPE", 1},
      {"navigation_file", version_line("     3.04", 'N') + header_line("", "END OF HEADER"), "navigation file", 1},
      {"version_4", version_line("     4.01") + header_line("", "END OF HEADER"), "unsupported RINEX version 4.01", 1},
      {"version_1", version_line("     1.00") + header_line("", "END OF HEADER"), "unsupported RINEX version 1.00", 1},
      {"end_of_header_missing_at_eof", version_line("     3.04") + header_line("G    2 C1C L1C", "SYS / # / OBS TYPES"),
       "END OF HEADER", 2},
      {"end_of_header_missing_before_data",
       version_line("     3.04") + header_line("G    2 C1C L1C", "SYS / # / OBS TYPES") + valid, "END OF HEADER", 3},
      {"no_obs_types_v3", version_line("     3.04") + header_line("", "END OF HEADER") + valid, "SYS / # / OBS TYPES",
       2},
      {"no_obs_types_v2",
       version_line("     2.11", 'O', 'G') + header_line("X", "MARKER NAME") + header_line("", "END OF HEADER"),
       "# / TYPES OF OBSERV", 3},
      {"fewer_obs_types_than_announced",
       version_line("     3.04") + header_line("G   20 C1C L1C", "SYS / # / OBS TYPES") +
           header_line("", "END OF HEADER"),
       "fewer types than announced", 2},
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
      // Bodies that are not observation data: an Error as soon as that is clear, naming where.
      {"only_corrupt_epoch", header_v3() + bad_epoch, "not usable observation data, 1 of the 1 epochs are corrupt", 5},
      {"more_corrupt_than_valid", header_v3() + valid + bad_epoch + valid_later + bad_epoch + bad_epoch,
       "3 of the 5 epochs are corrupt; the first: bad epoch flag '9', epoch skipped (lines 7-8)", 7},
      {"short_navigation_body", header_v3() + nav_lines(40), "1 of the 1 epochs are corrupt", 5},
      {"long_navigation_body", header_v3() + nav_lines(RinexObsReader::kMaxLinesBeforeFirstEpoch + 10),
       "no epoch line in the 1000 lines after the header: not RINEX 3.04 observation data",
       4 + RinexObsReader::kMaxLinesBeforeFirstEpoch},
      {"rinex2_body_in_rinex3_file", header_v3() + good_epoch(false, 0) + good_epoch(false, 1),
       "1 of the 1 epochs are corrupt; the first: expected an epoch line starting with '>'", 5},
      {"event_epoch_with_bad_types",
       header_v3() + valid + epoch_v3(2021, 9, 22, 6, 30, 1.0, 4, 1) + header_line("G    x", "SYS / # / OBS TYPES"),
       "bad number of observation types", 8},
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
