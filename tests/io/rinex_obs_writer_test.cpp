// RINEX 3.04 observation writer on epochs built in the test (as an RTCM decoder or a scenario generator would
// produce them): observation types collected from the epochs, header records, event epochs, values out of range.

#include <fstream>
#include <sstream>
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

constexpr double kMaxRoundTripError = 0.0005;

core::SignalObs signal(SignalCode code, double range_m, double phase_cyc, double snr_dbhz, std::uint8_t lli = 0) {
  core::SignalObs s;
  s.code = code;
  s.pseudorange_m = range_m;
  s.carrier_phase_cyc = phase_cyc;
  s.snr_dbhz = snr_dbhz;
  s.lli = lli;
  return s;
}

std::vector<core::ObsEpoch> make_epochs() {
  std::vector<core::ObsEpoch> epochs;
  const core::GpsTime t0 = core::calendar_to_gps({2024, 2, 29, 23, 59, 59.0});
  for (int i = 0; i < 3; ++i) {
    core::ObsEpoch e;
    e.time = t0 + 0.5 * i;  // crosses midnight and a leap day
    e.receiver_clock_offset_s = i == 1 ? 1.25e-4 : core::kNoValue;
    e.sats.push_back({SatelliteId{Constellation::Gps, 5},
                      {signal({'1', 'C'}, 21000000.123 + i, 110000000.456 + i, 45.5, i == 2 ? 1 : 0),
                       signal({'5', 'Q'}, 21000003.5, core::kNoValue, 40.0)}});
    e.sats.push_back(
        {SatelliteId{Constellation::Glonass, 24}, {signal({'1', 'C'}, 19000000.0, -95000000.25, 38.0, 3)}});
    e.sats.push_back({SatelliteId{Constellation::BeiDou, 61}, {signal({'2', 'I'}, 38000000.0, 197000000.0, 30.0)}});
    e.sats.push_back({SatelliteId{Constellation::Qzss, 3}, {signal({'1', 'C'}, 36000000.0, core::kNoValue, 41.0)}});
    core::SignalObs doppler_only;
    doppler_only.code = {'7', 'Q'};
    doppler_only.doppler_hz = -1234.567;
    e.sats.push_back({SatelliteId{Constellation::Galileo, 36}, {doppler_only}});
    epochs.push_back(e);
  }
  core::ObsEpoch event;  // written as an event without records; the reader reads past it
  event.time = t0 + 0.75;
  event.flag = core::EpochFlag::ExternalEvent;
  epochs.insert(epochs.begin() + 2, event);
  return epochs;
}

TEST(RinexObservationWriter, TypesFromEpochsRoundTrip) {
  test::TempDir tmp;
  RinexObsHeader header;
  header.receiver.marker_name = "SCENARIO";
  header.receiver.receiver_type = "CANYON SIM";
  header.receiver.antenna_type = "ANT";
  header.receiver.approx_position_E_m = Eigen::Vector3d(4157177.0658, 671230.4766, 4774767.0311);
  header.receiver.antenna_delta_hen_m = Eigen::Vector3d(1.5, 0.0, 0.0);
  header.receiver.phase_shifts.push_back({Constellation::Gps, {'5', 'Q'}, -0.25});
  for (int slot = 1; slot <= 10; ++slot) header.receiver.glonass_slot_channels.emplace_back(slot, slot - 7);
  header.interval_s = 0.5;
  header.leap_seconds = 18;
  const auto epochs = make_epochs();
  const std::string path = tmp.file("scenario.rnx");
  const Status written = write_rinex_obs(path, header, epochs);
  ASSERT_TRUE(written.ok()) << written.error().to_string();

  auto back = read_rinex_obs(path);
  ASSERT_TRUE(back.ok()) << back.error().to_string();
  EXPECT_TRUE(back->warnings.empty());
  ASSERT_EQ(back->epochs.size(), 3u);  // the event epoch is read past
  const std::vector<std::string> gps = {"C1C", "L1C", "S1C", "C5Q", "S5Q"};
  EXPECT_EQ(back->header.obs_types.at(Constellation::Gps), gps);
  EXPECT_EQ(back->header.obs_types.size(), 5u);
  EXPECT_EQ(back->header.receiver.marker_name, "SCENARIO");
  EXPECT_EQ(back->header.receiver.receiver_type, "CANYON SIM");
  EXPECT_EQ(back->header.receiver.glonass_slot_channels, header.receiver.glonass_slot_channels);
  ASSERT_EQ(back->header.receiver.phase_shifts.size(), 1u);
  EXPECT_DOUBLE_EQ(back->header.receiver.phase_shifts[0].shift_cyc, -0.25);
  EXPECT_DOUBLE_EQ(back->header.receiver.antenna_delta_hen_m.x(), 1.5);
  EXPECT_EQ(back->header.leap_seconds, 18);
  EXPECT_DOUBLE_EQ(back->header.interval_s, 0.5);

  const std::vector<core::ObsEpoch> expected = {epochs[0], epochs[1], epochs[3]};
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const auto& a = expected[i];
    const auto& b = back->epochs[i];
    EXPECT_NEAR(b.time - a.time, 0.0, 1e-7);
    EXPECT_EQ(core::has_value(a.receiver_clock_offset_s), core::has_value(b.receiver_clock_offset_s));
    ASSERT_EQ(a.sats.size(), b.sats.size());
    for (std::size_t k = 0; k < a.sats.size(); ++k) {
      ASSERT_EQ(a.sats[k].sat, b.sats[k].sat);
      ASSERT_EQ(a.sats[k].signals.size(), b.sats[k].signals.size());
      for (const auto& x : a.sats[k].signals) {
        const auto* y = b.sats[k].find(x.code);
        ASSERT_NE(y, nullptr);
        for (const auto& [u, v] :
             {std::pair{x.pseudorange_m, y->pseudorange_m}, std::pair{x.carrier_phase_cyc, y->carrier_phase_cyc},
              std::pair{x.doppler_hz, y->doppler_hz}, std::pair{x.snr_dbhz, y->snr_dbhz}}) {
          EXPECT_EQ(core::has_value(u), core::has_value(v));
          if (core::has_value(u)) {
            EXPECT_NEAR(u, v, kMaxRoundTripError);
          }
        }
        EXPECT_EQ(x.lli, y->lli);
      }
    }
  }
  EXPECT_NEAR(back->epochs[1].receiver_clock_offset_s, 1.25e-4, 1e-12);

  // The text itself: an epoch line across midnight and a record with LLI and signal strength digits.
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("> 2024 02 29 23 59 59.5000000  0  5       0.000125000000\n"), std::string::npos);
  EXPECT_NE(text.str().find("> 2024 02 29 23 59 59.7500000  5  0\n"), std::string::npos);
  EXPECT_NE(text.str().find("> 2024 03 01 00 00  0.0000000  0  5\n"), std::string::npos);
  EXPECT_NE(text.str().find("G05  21000000.123 7 110000000.456 7"), std::string::npos);
  EXPECT_NE(text.str().find("     3.04           OBSERVATION DATA    M"), std::string::npos);
}

TEST(RinexObservationWriter, ValueOutOfRangeIsAnError) {
  test::TempDir tmp;
  core::ObsEpoch e;
  e.time = core::calendar_to_gps({2024, 2, 29, 12, 0, 0.0});
  e.sats.push_back({SatelliteId{Constellation::Gps, 5}, {signal({'1', 'C'}, 2.1e7, 1.0e11, 45.0)}});
  const std::string path = tmp.file("bad.rnx");
  const Status written = write_rinex_obs(path, {}, {e});
  ASSERT_FALSE(written.ok());
  EXPECT_NE(written.error().message.find("F14.3"), std::string::npos) << written.error().to_string();
  EXPECT_EQ(written.error().file, path);
}

TEST(RinexObservationWriter, FixedProgramDateMakesTheFileDependOnItsContentOnly) {
  test::TempDir tmp;
  RinexObsHeader header;
  header.program_date = "20230614 180000 GPS";
  const std::string a = tmp.file("a.rnx"), b = tmp.file("b.rnx");
  ASSERT_TRUE(write_rinex_obs(a, header, make_epochs()).ok());
  ASSERT_TRUE(write_rinex_obs(b, header, make_epochs()).ok());
  const auto read_all = [](const std::string& path) {
    std::ostringstream text;
    text << std::ifstream(path, std::ios::binary).rdbuf();
    return text.str();
  };
  EXPECT_EQ(read_all(a), read_all(b));
  EXPECT_NE(read_all(a).find("canyon                                  20230614 180000 GPS PGM / RUN BY / DATE\n"),
            std::string::npos);
  // Without it, the writer stamps the current UTC time.
  ASSERT_TRUE(write_rinex_obs(a, {}, make_epochs()).ok());
  EXPECT_NE(read_all(a).find(" UTC PGM / RUN BY / DATE\n"), std::string::npos);
}

TEST(RinexObservationWriter, UnwritablePathIsAnError) {
  const Status written = write_rinex_obs("/nonexistent/canyon/out.rnx", {}, {});
  ASSERT_FALSE(written.ok());
  EXPECT_EQ(written.error().file, "/nonexistent/canyon/out.rnx");
}

}  // namespace
}  // namespace canyon::io
