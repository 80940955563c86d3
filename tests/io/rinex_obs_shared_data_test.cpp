// RINEX observation reader and writer on the shared real datasets: every observation file reads without error,
// epoch counts and satellites as the dataset READMEs give them, spot values against the text of the files, gzip
// input, and read -> write -> read round trips.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <zlib.h>

#include "canyon/io/rinex_obs.hpp"

#include "io/rinex_test_util.hpp"

namespace canyon::io {
namespace {

namespace fs = std::filesystem;
using core::Constellation;
using core::SatelliteId;
using core::SignalCode;

constexpr double kMaxRoundTripErrorM = 0.0005;  // RINEX F14.3 resolution / 2 (also cycles, Hz, dB-Hz)
constexpr double kExactValueTolerance = 1e-9;

const std::string kData = CANYON_SHARED_DATA_DIR;

#define SKIP_WITHOUT_SHARED_DATA()                                                                         \
  if (!fs::is_directory(kData)) {                                                                          \
    GTEST_SKIP() << "shared datasets not found at " << kData << " (set CANYON_SHARED_DATA_DIR to enable)"; \
  }

/// Every observation file under the shared data folder (*.obs, *.??o, *.??O).
std::vector<std::string> observation_files() {
  std::vector<std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(kData)) {
    if (!entry.is_regular_file()) continue;
    const std::string name = entry.path().filename().string();
    const std::string ext = entry.path().extension().string();
    const bool rinex2_style = ext.size() == 4 && std::isdigit(static_cast<unsigned char>(ext[1])) &&
                              std::isdigit(static_cast<unsigned char>(ext[2])) && (ext[3] == 'o' || ext[3] == 'O');
    if (ext == ".obs" || rinex2_style) files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

RinexObsFile read_ok(const std::string& path) {
  auto file = read_rinex_obs(path);
  EXPECT_TRUE(file.ok()) << (file.ok() ? "" : file.error().to_string());
  if (!file.ok()) return {};
  return std::move(file).value();
}

std::set<SatelliteId> satellites(const RinexObsFile& file) {
  std::set<SatelliteId> sats;
  for (const auto& e : file.epochs) {
    for (const auto& s : e.sats) sats.insert(s.sat);
  }
  return sats;
}

int count_system(const std::set<SatelliteId>& sats, Constellation system) {
  return static_cast<int>(std::count_if(sats.begin(), sats.end(), [&](auto s) { return s.system == system; }));
}

const core::SignalObs* find_signal(const core::ObsEpoch& epoch, SatelliteId sat, SignalCode code) {
  for (const auto& s : epoch.sats) {
    if (s.sat == sat) return s.find(code);
  }
  return nullptr;
}

TEST(RinexObservationSharedData, EveryObservationFileReads) {
  SKIP_WITHOUT_SHARED_DATA();
  const auto files = observation_files();
  ASSERT_GE(files.size(), 16u) << "expected the 16 observation files of the shared datasets";
  for (const std::string& path : files) {
    SCOPED_TRACE(path);
    const RinexObsFile file = read_ok(path);
    EXPECT_FALSE(file.epochs.empty());
    for (const auto& epoch : file.epochs) {
      for (const auto& sat : epoch.sats) {
        EXPECT_TRUE(sat.sat.valid());
        for (const auto& s : sat.signals) {
          const bool any = core::has_value(s.pseudorange_m) || core::has_value(s.carrier_phase_cyc) ||
                           core::has_value(s.doppler_hz) || core::has_value(s.snr_dbhz);
          EXPECT_TRUE(any) << sat.sat.to_string() << " " << s.code.to_string();
        }
      }
    }
  }
}

struct EpochCountCase {
  const char* path;
  std::size_t epochs;
  std::size_t warnings;
};

TEST(RinexObservationSharedData, EpochCountsMatchTheReadmes) {
  SKIP_WITHOUT_SHARED_DATA();
  const EpochCountCase cases[] = {
      {"rtklib-test-gsi-2005/07590920.05o", 120, 0},
      {"rtklib-test-gsi-2005/30400920.05o", 120, 0},
      {"cssrlib-static-doy078/SEPT078M1.21O", 60, 0},
      {"cssrlib-static-doy078/3034078M1.21O", 60, 0},
      {"cssrlib-kinematic-doy265/SEPT265G.21O", 360, 0},
      {"cssrlib-kinematic-doy265/3034265G.21O", 360, 0},
      {"matrtklib-static/rover.obs", 301, 0},
      {"matrtklib-static/base.obs", 301, 0},
      {"m8p-galway-20181004/rinex/20181004_rover-20181004-1532.obs", 1180, 0},
      {"m8p-galway-20181004/rinex/20181004_base-20181004-1452.obs", 763, 0},
      {"instinct-spirent-rtk-sim/iono-Klob_tropo-Saast/Base-static_MO_Spirent.obs", 601, 0},
      {"instinct-spirent-rtk-sim/iono-Klob_tropo-Saast/Rover-dynamic_MO_Spirent.obs", 601, 0},
      {"instinct-spirent-rtk-sim/iono-Klob_tropo-Saast/Rover-static-2km-east_MO_Spirent.obs", 601, 0},
      {"instinct-spirent-rtk-sim/iono-none_tropo-none/Base-static_MO_Spirent.obs", 601, 200},
      {"instinct-spirent-rtk-sim/iono-none_tropo-none/Rover-dynamic_MO_Spirent.obs", 601, 0},
      {"instinct-spirent-rtk-sim/iono-none_tropo-none/Rover-static-2km-east_MO_Spirent.obs", 601, 200},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.path);
    const RinexObsFile file = read_ok(kData + "/" + c.path);
    EXPECT_EQ(file.epochs.size(), c.epochs);
    EXPECT_EQ(file.warnings.size(), c.warnings);
    for (const auto& e : file.epochs) EXPECT_FALSE(e.sats.empty());
  }
}

TEST(RinexObservationSharedData, SatellitesMatchTheReadmes) {
  SKIP_WITHOUT_SHARED_DATA();
  {
    // cssrlib-kinematic: G8 E6-8 J4 (no GLONASS or BeiDou).
    const auto sats = satellites(read_ok(kData + "/cssrlib-kinematic-doy265/SEPT265G.21O"));
    EXPECT_EQ(count_system(sats, Constellation::Gps), 8);
    EXPECT_GE(count_system(sats, Constellation::Galileo), 6);
    EXPECT_LE(count_system(sats, Constellation::Galileo), 8);
    EXPECT_EQ(count_system(sats, Constellation::Qzss), 4);
    EXPECT_EQ(count_system(sats, Constellation::Glonass) + count_system(sats, Constellation::BeiDou), 0);
  }
  {
    // matrtklib: G12 E9 R8-9 C25-26 J2-3.
    const auto sats = satellites(read_ok(kData + "/matrtklib-static/rover.obs"));
    EXPECT_EQ(count_system(sats, Constellation::Gps), 12);
    EXPECT_EQ(count_system(sats, Constellation::Galileo), 9);
    EXPECT_GE(count_system(sats, Constellation::Glonass), 8);
    EXPECT_LE(count_system(sats, Constellation::Glonass), 9);
    EXPECT_GE(count_system(sats, Constellation::BeiDou), 25);
    EXPECT_LE(count_system(sats, Constellation::BeiDou), 26);
    EXPECT_GE(count_system(sats, Constellation::Qzss), 2);
    EXPECT_LE(count_system(sats, Constellation::Qzss), 3);
  }
  {
    // m8p rover: G13 R11 J1.
    const auto sats = satellites(read_ok(kData + "/m8p-galway-20181004/rinex/20181004_rover-20181004-1532.obs"));
    EXPECT_EQ(count_system(sats, Constellation::Gps), 13);
    EXPECT_EQ(count_system(sats, Constellation::Glonass), 11);
    EXPECT_EQ(count_system(sats, Constellation::Qzss), 1);
  }
  {
    // instinct: G12 E8.
    const auto sats =
        satellites(read_ok(kData + "/instinct-spirent-rtk-sim/iono-Klob_tropo-Saast/Base-static_MO_Spirent.obs"));
    EXPECT_EQ(count_system(sats, Constellation::Gps), 12);
    EXPECT_EQ(count_system(sats, Constellation::Galileo), 8);
  }
}

TEST(RinexObservationSharedData, Rinex210SpotValues) {
  SKIP_WITHOUT_SHARED_DATA();
  // " 05  4  2  0  0  0.0000000  0  8G 3G 7G 8G11G19G20G24G28"
  // "  55923622.160    24767686.375    43647388.2424   24767684.8224"   (L1 C1 L2 P2)
  const RinexObsFile file = read_ok(kData + "/rtklib-test-gsi-2005/07590920.05o");
  ASSERT_EQ(file.epochs.size(), 120u);
  const core::ObsEpoch& e = file.epochs.front();
  EXPECT_EQ(e.time.week, 1316);
  EXPECT_NEAR(e.time.tow_s, 518400.0, kExactValueTolerance);
  EXPECT_EQ(e.sats.size(), 8u);
  // The last epoch of this file is tagged 00:59:30.005 (receiver clock steering), not 00:59:30.
  EXPECT_NEAR(file.epochs.back().time - e.time, 119 * 30.0 + 0.005, 1e-7);
  const SatelliteId g03{Constellation::Gps, 3};
  const auto* l1 = find_signal(e, g03, {'1', 'C'});
  const auto* l2 = find_signal(e, g03, {'2', 'W'});
  ASSERT_NE(l1, nullptr);
  ASSERT_NE(l2, nullptr);
  EXPECT_DOUBLE_EQ(l1->carrier_phase_cyc, 55923622.160);
  EXPECT_DOUBLE_EQ(l1->pseudorange_m, 24767686.375);
  EXPECT_EQ(l1->lli, 0);
  EXPECT_DOUBLE_EQ(l2->carrier_phase_cyc, 43647388.242);
  EXPECT_EQ(l2->lli, 4);  // RINEX 2 bit 2: anti-spoofing on
  EXPECT_DOUBLE_EQ(l2->pseudorange_m, 24767684.822);
  EXPECT_FALSE(core::has_value(l1->snr_dbhz));
  ASSERT_TRUE(file.header.receiver.approx_position_E_m.has_value());
  EXPECT_DOUBLE_EQ(file.header.receiver.approx_position_E_m->x(), -3976219.5082);
  EXPECT_EQ(file.header.receiver.marker_name, "0759");
  EXPECT_EQ(file.header.receiver.receiver_type, "TRIMBLE 5700");
  EXPECT_EQ(file.header.receiver.antenna_type, "TRM29659.00");
  EXPECT_DOUBLE_EQ(file.header.interval_s, 30.0);
  const std::vector<std::string> expected_types = {"L1C", "C1C", "L2W", "C2W"};
  EXPECT_EQ(file.header.obs_types.at(Constellation::Gps), expected_types);
}

TEST(RinexObservationSharedData, Rinex303SpotValuesM8p) {
  SKIP_WITHOUT_SHARED_DATA();
  // "> 2018 10 04 15 33 40.9870000  0 19"
  // "G09  16162213.120    84932986.5651       -310.798          52.000"
  const RinexObsFile file = read_ok(kData + "/m8p-galway-20181004/rinex/20181004_rover-20181004-1532.obs");
  ASSERT_FALSE(file.epochs.empty());
  const core::ObsEpoch& e = file.epochs.front();
  const core::GpsTime expected = core::calendar_to_gps({2018, 10, 4, 15, 33, 40.987});
  EXPECT_NEAR(e.time - expected, 0.0, 1e-7);
  EXPECT_EQ(e.sats.size(), 19u);
  const auto* s = find_signal(e, {Constellation::Gps, 9}, {'1', 'C'});
  ASSERT_NE(s, nullptr);
  EXPECT_DOUBLE_EQ(s->pseudorange_m, 16162213.120);
  EXPECT_DOUBLE_EQ(s->carrier_phase_cyc, 84932986.565);
  EXPECT_EQ(s->lli, core::kLliLossOfLock);
  EXPECT_DOUBLE_EQ(s->doppler_hz, -310.798);
  EXPECT_DOUBLE_EQ(s->snr_dbhz, 52.0);
  // GLONASS SLOT / FRQ # with a continuation line: 11 slots, R24 -> +2.
  const auto& slots = file.header.receiver.glonass_slot_channels;
  EXPECT_EQ(slots.size(), 11u);
  EXPECT_NE(std::find(slots.begin(), slots.end(), std::pair<int, int>{24, 2}), slots.end());
  EXPECT_NE(std::find(slots.begin(), slots.end(), std::pair<int, int>{10, -7}), slots.end());
  EXPECT_EQ(file.header.receiver.phase_shifts.size(), 3u);
}

TEST(RinexObservationSharedData, Rinex304SpotValuesMatrtklib) {
  SKIP_WITHOUT_SHARED_DATA();
  // "G13        13.000    20102767.198 7 105640763.82007      -794.792 7        47.063    20102760.962 6
  //   82317456.05306      -619.319 6        39.656"        (X1 C1C L1C D1C S1C C2W L2W D2W S2W ...)
  // "C01         9.000    36842422.530 7 191848164.08007       161.587 7        44.438 ..." (X1 C2I L2I D2I S2I)
  const RinexObsFile file = read_ok(kData + "/matrtklib-static/rover.obs");
  ASSERT_EQ(file.epochs.size(), 301u);
  const core::ObsEpoch& e = file.epochs.front();
  EXPECT_EQ(e.sats.size(), 57u);
  const auto* l1 = find_signal(e, {Constellation::Gps, 13}, {'1', 'C'});
  const auto* l2 = find_signal(e, {Constellation::Gps, 13}, {'2', 'W'});
  ASSERT_NE(l1, nullptr);
  ASSERT_NE(l2, nullptr);
  EXPECT_DOUBLE_EQ(l1->pseudorange_m, 20102767.198);
  EXPECT_DOUBLE_EQ(l1->carrier_phase_cyc, 105640763.820);
  EXPECT_EQ(l1->lli, 0);
  EXPECT_DOUBLE_EQ(l1->doppler_hz, -794.792);
  EXPECT_DOUBLE_EQ(l1->snr_dbhz, 47.063);
  EXPECT_DOUBLE_EQ(l2->pseudorange_m, 20102760.962);
  EXPECT_DOUBLE_EQ(l2->carrier_phase_cyc, 82317456.053);
  EXPECT_DOUBLE_EQ(l2->snr_dbhz, 39.656);
  const auto* b1 = find_signal(e, {Constellation::BeiDou, 1}, {'2', 'I'});
  ASSERT_NE(b1, nullptr);
  EXPECT_DOUBLE_EQ(b1->pseudorange_m, 36842422.530);
  EXPECT_DOUBLE_EQ(b1->carrier_phase_cyc, 191848164.080);
  EXPECT_EQ(file.header.leap_seconds, 18);
  EXPECT_EQ(file.header.receiver.receiver_type, "SEPT MOSAIC-X5");
  EXPECT_EQ(file.header.receiver.glonass_slot_channels.size(), 8u);
  EXPECT_EQ(file.header.receiver.phase_shifts.size(), 15u);
  EXPECT_EQ(file.header.obs_types.at(Constellation::Gps).size(), 17u);  // continuation line
}

TEST(RinexObservationSharedData, InstinctShortEpochsAreRecovered) {
  SKIP_WITHOUT_SHARED_DATA();
  const std::string dir = kData + "/instinct-spirent-rtk-sim/iono-none_tropo-none/";
  const RinexObsFile base = read_ok(dir + "Base-static_MO_Spirent.obs");
  const RinexObsFile rover = read_ok(dir + "Rover-static-2km-east_MO_Spirent.obs");
  ASSERT_EQ(base.epochs.size(), 601u);
  ASSERT_EQ(rover.epochs.size(), 601u);
  ASSERT_EQ(base.warnings.size(), 200u);
  EXPECT_NE(base.warnings.front().find("epoch announces 20 satellites, 19 present"), std::string::npos)
      << base.warnings.front();
  EXPECT_EQ(base.warnings.front().rfind(dir + "Base-static_MO_Spirent.obs:", 0), 0u) << base.warnings.front();
  // 10:05:00 is epoch 300: the base lacks G14 there, keeps the other 19, and the next epoch is complete again.
  const core::ObsEpoch& short_epoch = base.epochs[300];
  EXPECT_NEAR(short_epoch.time - core::calendar_to_gps({2023, 1, 8, 10, 5, 0.0}), 0.0, 1e-9);
  EXPECT_EQ(short_epoch.sats.size(), 19u);
  EXPECT_EQ(base.epochs[299].sats.size(), 20u);
  EXPECT_EQ(base.epochs[500].sats.size(), 20u);
  EXPECT_EQ(std::count_if(short_epoch.sats.begin(), short_epoch.sats.end(),
                          [](const auto& s) {
                            return s.sat == SatelliteId{Constellation::Gps, 14};
                          }),
            0);
  for (std::size_t i = 0; i < 601; ++i) {
    EXPECT_NEAR(base.epochs[i].time - rover.epochs[i].time, 0.0, 1e-9);
    EXPECT_FALSE(rover.epochs[i].sats.empty());
  }
}

// ----- gzip

/// Compresses `from` into `to` with zlib.
void gzip_file(const std::string& from, const std::string& to) {
  std::ifstream in(from, std::ios::binary);
  const std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  gzFile out = gzopen(to.c_str(), "wb");
  ASSERT_NE(out, nullptr);
  ASSERT_EQ(gzwrite(out, content.data(), static_cast<unsigned>(content.size())), static_cast<int>(content.size()));
  ASSERT_EQ(gzclose(out), Z_OK);
}

TEST(RinexObservationSharedData, GzipFileGivesTheSameEpochs) {
  SKIP_WITHOUT_SHARED_DATA();
  test::TempDir tmp;
  for (const char* name : {"rtklib-test-gsi-2005/07590920.05o", "cssrlib-kinematic-doy265/SEPT265G.21O"}) {
    SCOPED_TRACE(name);
    const std::string plain = kData + "/" + name;
    const std::string gz = tmp.file(fs::path(name).filename().string() + ".gz");
    gzip_file(plain, gz);
    const RinexObsFile a = read_ok(plain);
    const RinexObsFile b = read_ok(gz);
    test::expect_same_epochs(a.epochs, b.epochs, 0.0);
  }
}

TEST(RinexObservationSharedData, TruncatedGzipKeepsTheEpochsBeforeTheCut) {
  SKIP_WITHOUT_SHARED_DATA();
  test::TempDir tmp;
  const std::string plain = kData + "/cssrlib-kinematic-doy265/SEPT265G.21O";
  const RinexObsFile full = read_ok(plain);
  const std::string gz = tmp.file("full.obs.gz");
  gzip_file(plain, gz);
  std::ifstream in(gz, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const double fraction : {0.1, 0.5, 0.9, 0.999}) {
    SCOPED_TRACE(fraction);
    const std::string cut = tmp.write("cut.obs.gz", bytes.substr(0, static_cast<std::size_t>(bytes.size() * fraction)));
    const RinexObsFile file = read_ok(cut);
    // Every complete epoch before the cut, unchanged; the one the cut falls in is dropped with a warning that says
    // where and why.
    ASSERT_LT(file.epochs.size(), full.epochs.size());
    EXPECT_GT(file.epochs.size(), static_cast<std::size_t>(full.epochs.size() * fraction * 0.5));
    const std::vector<core::ObsEpoch> before(full.epochs.begin(),
                                             full.epochs.begin() + static_cast<std::ptrdiff_t>(file.epochs.size()));
    test::expect_same_epochs(file.epochs, before, 0.0);
    ASSERT_EQ(file.warnings.size(), 1u);
    const std::string& warning = file.warnings[0];
    EXPECT_EQ(warning.rfind(cut + ":", 0), 0u) << warning;
    EXPECT_NE(warning.find("file ends inside an epoch"), std::string::npos) << warning;
    EXPECT_NE(warning.find("(read error: "), std::string::npos) << warning;
    EXPECT_NE(warning.find("epoch skipped (lines "), std::string::npos) << warning;
  }
  // Cut inside the header: nothing can be read, an Error.
  const std::string header_cut = tmp.write("header_cut.obs.gz", bytes.substr(0, 200));
  const auto file = read_rinex_obs(header_cut);
  ASSERT_FALSE(file.ok());
  EXPECT_EQ(file.error().file, header_cut);
  EXPECT_GT(file.error().line, 0);
  EXPECT_NE(file.error().message.find("the file ends inside the header (read error: "), std::string::npos)
      << file.error().to_string();
}

// ----- writer round trips

void expect_round_trip(const std::string& path) {
  SCOPED_TRACE(path);
  test::TempDir tmp;
  const RinexObsFile original = read_ok(path);
  const std::string out = tmp.file("roundtrip.rnx");
  const Status written = write_rinex_obs(out, original.header, original.epochs);
  ASSERT_TRUE(written.ok()) << written.error().to_string();
  const RinexObsFile again = read_ok(out);
  EXPECT_DOUBLE_EQ(again.header.version, 3.04);
  EXPECT_TRUE(again.warnings.empty());
  test::expect_same_epochs(original.epochs, again.epochs, kMaxRoundTripErrorM);
  for (std::size_t i = 0; i < original.epochs.size(); ++i) {
    const double a = original.epochs[i].receiver_clock_offset_s;
    const double b = again.epochs[i].receiver_clock_offset_s;
    EXPECT_TRUE((!core::has_value(a) && !core::has_value(b)) || std::abs(a - b) < 1e-12);
  }
  const core::ReceiverInfo& ra = original.header.receiver;
  const core::ReceiverInfo& rb = again.header.receiver;
  EXPECT_EQ(ra.marker_name, rb.marker_name);
  EXPECT_EQ(ra.receiver_type, rb.receiver_type);
  EXPECT_EQ(ra.antenna_type, rb.antenna_type);
  EXPECT_EQ(ra.approx_position_E_m.has_value(), rb.approx_position_E_m.has_value());
  if (ra.approx_position_E_m && rb.approx_position_E_m) {
    EXPECT_LT((*ra.approx_position_E_m - *rb.approx_position_E_m).norm(), 1e-4);
  }
  EXPECT_EQ(ra.glonass_slot_channels, rb.glonass_slot_channels);
  ASSERT_EQ(ra.phase_shifts.size(), rb.phase_shifts.size());
  for (std::size_t i = 0; i < ra.phase_shifts.size(); ++i) {
    EXPECT_EQ(ra.phase_shifts[i].system, rb.phase_shifts[i].system);
    EXPECT_EQ(ra.phase_shifts[i].code, rb.phase_shifts[i].code);
    EXPECT_NEAR(ra.phase_shifts[i].shift_cyc, rb.phase_shifts[i].shift_cyc, 1e-5);
  }
  EXPECT_DOUBLE_EQ(original.header.interval_s, again.header.interval_s);
  ASSERT_TRUE(again.header.first_obs.has_value());
  EXPECT_NEAR(*again.header.first_obs - original.epochs.front().time, 0.0, 1e-7);
}

TEST(RinexObservationSharedData, RoundTripRinex210Gsi) {
  SKIP_WITHOUT_SHARED_DATA();
  expect_round_trip(kData + "/rtklib-test-gsi-2005/07590920.05o");
}

TEST(RinexObservationSharedData, RoundTripRinex304CssrlibRover) {
  SKIP_WITHOUT_SHARED_DATA();
  expect_round_trip(kData + "/cssrlib-kinematic-doy265/SEPT265G.21O");
}

TEST(RinexObservationSharedData, RoundTripMatrtklibFiveConstellations) {
  SKIP_WITHOUT_SHARED_DATA();
  expect_round_trip(kData + "/matrtklib-static/rover.obs");
}

TEST(RinexObservationSharedData, RoundTripEveryOtherFile) {
  SKIP_WITHOUT_SHARED_DATA();
  for (const std::string& path : observation_files()) expect_round_trip(path);
}

/// What a filter should keep of an unfiltered read: the same epochs, with only the kept systems and signals.
RinexObsFile expected_after_filter(RinexObsFile file, const ObsFilter& filter) {
  for (core::ObsEpoch& epoch : file.epochs) {
    std::erase_if(epoch.sats, [&](const core::SatelliteObs& s) { return !filter.systems.uses(s.sat.system); });
    for (core::SatelliteObs& sat : epoch.sats) {
      std::erase_if(sat.signals, [&](const core::SignalObs& s) {
        const auto rank = core::frequency_rank(sat.sat.system, s.code.band);
        return !rank || *rank > filter.max_frequency_rank;
      });
    }
  }
  return file;
}

TEST(RinexObservationSharedData, FilteredReadKeepsExactlyTheSystemsAndFrequenciesAsked) {
  SKIP_WITHOUT_SHARED_DATA();
  // GPS + Galileo + QZSS, three frequencies, Galileo E5a and E5 AltBOC: QZSS and ranks > 0 or > 1 left out.
  const std::string path = kData + "/cssrlib-kinematic-doy265/SEPT265G.21O";
  const RinexObsFile all = read_ok(path);
  for (const int max_rank : {0, 1}) {
    ObsFilter filter;
    filter.systems.use_glonass = false;
    filter.systems.use_beidou = false;
    filter.systems.use_qzss = false;
    filter.max_frequency_rank = max_rank;
    auto filtered = read_rinex_obs(path, filter);
    ASSERT_TRUE(filtered.ok()) << filtered.error().to_string();
    const RinexObsFile expected = expected_after_filter(all, filter);
    ASSERT_EQ(filtered->epochs.size(), expected.epochs.size());
    std::size_t signals = 0;
    for (std::size_t e = 0; e < expected.epochs.size(); ++e) {
      const auto& got = filtered->epochs[e];
      const auto& want = expected.epochs[e];
      ASSERT_EQ(got.time, want.time);
      ASSERT_EQ(got.sats.size(), want.sats.size()) << "epoch " << e;
      for (std::size_t k = 0; k < want.sats.size(); ++k) {
        ASSERT_EQ(got.sats[k].sat, want.sats[k].sat);
        ASSERT_EQ(got.sats[k].signals.size(), want.sats[k].signals.size()) << want.sats[k].sat.to_string();
        for (std::size_t j = 0; j < want.sats[k].signals.size(); ++j) {
          const core::SignalObs& g = got.sats[k].signals[j];
          const core::SignalObs& w = want.sats[k].signals[j];
          EXPECT_EQ(g.code, w.code);
          EXPECT_TRUE(g.pseudorange_m == w.pseudorange_m ||
                      (std::isnan(g.pseudorange_m) && std::isnan(w.pseudorange_m)));
          EXPECT_TRUE(g.carrier_phase_cyc == w.carrier_phase_cyc ||
                      (std::isnan(g.carrier_phase_cyc) && std::isnan(w.carrier_phase_cyc)));
          EXPECT_EQ(g.lli, w.lli);
          ++signals;
        }
      }
    }
    EXPECT_GT(signals, 0U);
    // No warnings for what the filter leaves out (QZSS is declared in the header, so the unfiltered read has none).
    EXPECT_EQ(filtered->warnings.size(), all.warnings.size());
  }
}

}  // namespace
}  // namespace canyon::io
