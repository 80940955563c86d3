// One tracking-code preference for the single point and the RTK filter (core::code_priority): for every system's
// first band and every pair of tracking codes a receiver may report there, the single point (gnss::spp_signal) and
// the RTK filter's observables (rtk::select_observables) choose the same signal. Before, SPP and RTK ranked GPS L1 and
// Galileo E1 with two different tables ("CPYWMLSX" / "CPWYMSLXN", "CBXAZ" / "CXBAZ") and could use different signals
// of one satellite.

#include <string>

#include <gtest/gtest.h>

#include "canyon/core/observation.hpp"
#include "canyon/core/satellite.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/gnss/spp.hpp"
#include "canyon/rtk/observables.hpp"

namespace canyon::rtk {
namespace {

core::SignalObs signal(char band, char attribute, double pseudorange_m) {
  core::SignalObs s;
  s.code = core::SignalCode{band, attribute};
  s.pseudorange_m = pseudorange_m;
  s.carrier_phase_cyc = pseudorange_m / 0.19;
  return s;
}

TEST(SignalPriority, TheTableRanksTheCodesOfEachBand) {
  EXPECT_STREQ(core::code_priority(core::Constellation::Gps, '1'), "CPWYMSLXN");
  EXPECT_STREQ(core::code_priority(core::Constellation::Galileo, '1'), "CXBAZ");
  EXPECT_STREQ(core::code_priority(core::Constellation::Gps, '9'), "");
}

TEST(SignalPriority, SinglePointAndRtkChooseTheSameSignalOfEveryPair) {
  const gnss::EphemerisStore eph{core::NavigationData{}};
  const struct {
    core::Constellation system;
    char band;
  } first_bands[] = {{core::Constellation::Gps, '1'},
                     {core::Constellation::Galileo, '1'},
                     {core::Constellation::BeiDou, '2'},
                     {core::Constellation::Qzss, '1'}};
  int pairs = 0;
  for (const auto& [system, band] : first_bands) {
    const std::string codes = core::code_priority(system, band);
    for (const char a : codes) {
      for (const char b : codes) {
        if (a == b) continue;
        core::ObsEpoch epoch;
        core::SatelliteObs so;
        so.sat = core::SatelliteId{system, 7};
        so.signals = {signal(band, a, 2.1e7), signal(band, b, 2.1e7 + 50.0)};
        epoch.sats.push_back(so);
        ObservableOptions options;
        options.num_frequencies = 1;
        const ReceiverObservables rtk = select_observables(epoch, eph, options);
        const core::SignalObs* spp = gnss::spp_signal(so);
        ASSERT_EQ(rtk.signals.size(), 1U);
        ASSERT_NE(spp, nullptr);
        EXPECT_EQ(spp->code, rtk.signals[0].code) << core::system_letter(system) << band << a << " vs " << b;
        EXPECT_EQ(spp->code.attribute, codes.find(a) < codes.find(b) ? a : b);
        ++pairs;
      }
    }
  }
  EXPECT_GT(pairs, 100);
}

}  // namespace
}  // namespace canyon::rtk
