// The generated IDL type serializes and deserializes through Fast CDR: the DDS toolchain works end to end.
#include <fastdds/rtps/common/SerializedPayload.h>
#include <gtest/gtest.h>

#include "GnssObservation.h"
#include "GnssObservationPubSubTypes.h"

namespace {

TEST(GnssObservationMsgTest, RoundTripsThroughCdr) {
  canyon::msg::GnssObservationEpoch epoch;
  epoch.sequence_number(42);
  epoch.receiver_id("rover");
  epoch.gps_week(2176);
  epoch.gps_tow_s(282600.0);
  canyon::msg::SatelliteObservation sat;
  sat.system('G');
  sat.prn(5);
  canyon::msg::SignalObservation sig;
  sig.band('1');
  sig.code_attribute('C');
  sig.pseudorange_m(21234567.123);
  sig.carrier_phase_cyc(111587654.321);
  sig.lli(1);
  sat.signals().push_back(sig);
  epoch.satellites().push_back(sat);

  canyon::msg::GnssObservationEpochPubSubType type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&epoch)());
  ASSERT_TRUE(type.serialize(&epoch, &payload));
  canyon::msg::GnssObservationEpoch decoded;
  ASSERT_TRUE(type.deserialize(&payload, &decoded));
  EXPECT_EQ(decoded, epoch);
  EXPECT_EQ(decoded.satellites().at(0).signals().at(0).pseudorange_m(), 21234567.123);
}

}  // namespace
