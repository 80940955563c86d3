// The satellite-exclusion experiment's selection: the N satellites tracked in the most rover epochs.

#include <vector>

#include <gtest/gtest.h>

#include "canyon/commands/process.hpp"

namespace canyon::commands {
namespace {

core::SatelliteObs tracked(core::Constellation system, int prn) {
  core::SatelliteObs sat;
  sat.sat = {system, static_cast<std::uint8_t>(prn)};
  core::SignalObs signal;
  signal.pseudorange_m = 2.2e7;
  sat.signals.push_back(signal);
  return sat;
}

/// An epoch per entry; each entry lists (system, prn) of the tracked satellites.
std::vector<core::ObsEpoch> epochs(const std::vector<std::vector<core::SatelliteObs>>& sats) {
  std::vector<core::ObsEpoch> out;
  for (const auto& list : sats) {
    core::ObsEpoch e;
    e.sats = list;
    out.push_back(e);
  }
  return out;
}

constexpr core::Constellation G = core::Constellation::Gps;
constexpr core::Constellation E = core::Constellation::Galileo;
constexpr core::Constellation R = core::Constellation::Glonass;

TEST(MostObservedSatellites, OrdersByEpochCountThenId) {
  // G07 in 3 epochs, E11 and G02 in 2 (tie: G before E), G09 in 1.
  const auto data = epochs({{tracked(G, 7), tracked(E, 11), tracked(G, 9)},
                            {tracked(G, 7), tracked(E, 11), tracked(G, 2)},
                            {tracked(G, 7), tracked(G, 2)}});
  const auto all = most_observed_satellites(data, 10, core::ConstellationFlags{});
  ASSERT_EQ(all.size(), 4U);
  EXPECT_EQ(all[0].to_string(), "G07");
  EXPECT_EQ(all[1].to_string(), "G02");
  EXPECT_EQ(all[2].to_string(), "E11");
  EXPECT_EQ(all[3].to_string(), "G09");
  const auto two = most_observed_satellites(data, 2, core::ConstellationFlags{});
  ASSERT_EQ(two.size(), 2U);
  EXPECT_EQ(two[1].to_string(), "G02");
  EXPECT_TRUE(most_observed_satellites(data, 0, core::ConstellationFlags{}).empty());
}

TEST(MostObservedSatellites, OnlyUsedConstellationsAndTrackedSignalsCount) {
  core::SatelliteObs untracked = tracked(G, 3);
  untracked.signals[0].pseudorange_m = core::kNoValue;  // a signal with SNR only is not tracked
  untracked.signals[0].snr_dbhz = 30.0;
  core::SatelliteObs phase_only = tracked(G, 4);
  phase_only.signals[0].pseudorange_m = core::kNoValue;
  phase_only.signals[0].carrier_phase_cyc = 1.0e8;
  const auto data = epochs(
      {{tracked(R, 1), untracked, phase_only}, {tracked(R, 1), untracked, phase_only}, {tracked(R, 1), tracked(E, 5)}});
  core::ConstellationFlags no_glonass;
  no_glonass.use_glonass = false;
  const auto sats = most_observed_satellites(data, 5, no_glonass);
  ASSERT_EQ(sats.size(), 2U);
  EXPECT_EQ(sats[0].to_string(), "G04");
  EXPECT_EQ(sats[1].to_string(), "E05");
}

}  // namespace
}  // namespace canyon::commands
