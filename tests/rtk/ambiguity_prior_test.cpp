// A new ambiguity started from the filter's position (rtk/ambiguity_prior.hpp): its value and covariances are the DD
// phase row solved for it, and it keeps the code start when the position is too uncertain or the phase lies off an
// integer (a reflection).

#include "canyon/rtk/ambiguity_prior.hpp"

#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

namespace canyon::rtk {
namespace {

constexpr double kLambda = 0.1903;      // m, GPS L1
constexpr double kReferenceSd = 100.3;  // the reference's SD ambiguity (cycles): not an integer, the receiver's bias
constexpr int kTrueDd = 17;             // the true DD ambiguity (cycles)

core::SatelliteId gps(int prn) {
  return core::SatelliteId{core::Constellation::Gps, static_cast<std::uint8_t>(prn)};
}

SingleDiff sd_of(int prn, const Eigen::Vector3d& los, double phase_m) {
  SingleDiff sd;
  sd.sat = gps(prn);
  sd.frequency = 0;
  sd.group = 0;
  sd.wavelength_m = kLambda;
  sd.phase_m = phase_m;
  sd.code_m = phase_m + 3.0;
  sd.phase_variance_m2 = 1e-6;
  sd.los_E = los.normalized();
  return sd;
}

struct Case {
  FilterState state;
  std::vector<SingleDiff> sds;
  Eigen::Vector3d h;  // the DD row's position part, -(los_s - los_r)
};

/// A held reference (PRN 3) and a new signal (PRN 7) started from its code; the truth is `offset_m` from the filter's
/// position along x, the new phase is `extra_cyc` cycles off the true integer, the position sigma `sigma_m` per axis.
Case make_case(double offset_m, double extra_cyc, double sigma_m) {
  Case c;
  c.state.restore_values(Eigen::Vector3d(-2.4e6, 5.3e6, 2.4e6), Eigen::Matrix3d::Identity() * sigma_m * sigma_m);
  c.state.add({{{gps(3), 0}, kReferenceSd, 900.0}});
  const Eigen::Vector3d los_r(0.2, 0.7, 0.6);
  const Eigen::Vector3d los_s(-0.6, 0.3, 0.7);
  SingleDiff ref = sd_of(3, los_r, 0.0);
  SingleDiff sd = sd_of(7, los_s, 0.0);
  c.h = -(sd.los_E - ref.los_E);
  sd.phase_m = c.h.dot(Eigen::Vector3d(offset_m, 0.0, 0.0)) + kLambda * (kTrueDd + extra_cyc);
  c.sds = {ref, sd};
  c.state.add({{{gps(7), 0}, (sd.phase_m - sd.code_m) / kLambda, 900.0}});  // the code start
  return c;
}

TEST(AmbiguityPrior, StartIsTheDdPhaseRowSolvedWithItsCovariances) {
  Case c = make_case(0.004, 0.0, 0.01);
  const Eigen::Matrix3d P_pp = c.state.position_covariance_E_m2();
  ASSERT_EQ(start_ambiguities_from_position(c.state, c.sds, {{gps(7), 0}}, 0.15).size(), 1U);
  const int s = c.state.index({gps(7), 0});
  const int r = c.state.index({gps(3), 0});
  ASSERT_GE(s, 0);
  // Value: the reference plus the DD phase at the filter's position (4 mm off: a fraction of a cycle).
  const double dd = c.state.x()[s] - c.state.x()[r];
  EXPECT_NEAR(dd, kTrueDd + c.h.x() * 0.004 / kLambda, 1e-9);
  // Covariances: with the position -h'/lambda P_pp, with the reference its variance, the DD's variance the
  // position's share plus the two phases' noise.
  const Eigen::Vector3d expected_cross = -(P_pp * c.h) / kLambda;
  EXPECT_TRUE((c.state.P().block<3, 1>(0, s).isApprox(expected_cross, 1e-12)));
  EXPECT_NEAR(c.state.P()(s, r), 900.0, 1e-9);
  const double dd_variance = c.state.P()(s, s) - 2.0 * c.state.P()(s, r) + c.state.P()(r, r);
  EXPECT_NEAR(dd_variance, c.h.dot(P_pp * c.h) / (kLambda * kLambda) + 2e-6 / (kLambda * kLambda), 1e-9);
}

TEST(AmbiguityPrior, UncertainPositionKeepsTheCodeStart) {
  Case c = make_case(0.0, 0.0, 0.5);  // 50 cm per axis: several cycles
  const double code_start = c.state.x()[c.state.index({gps(7), 0})];
  EXPECT_EQ(start_ambiguities_from_position(c.state, c.sds, {{gps(7), 0}}, 0.15).size(), 0U);
  EXPECT_EQ(c.state.x()[c.state.index({gps(7), 0})], code_start);
  EXPECT_EQ(c.state.P()(c.state.index({gps(7), 0}), c.state.index({gps(7), 0})), 900.0);
}

TEST(AmbiguityPrior, PhaseOffAnIntegerKeepsTheCodeStart) {
  Case c = make_case(0.0, 0.4, 0.005);  // a reflection's extra path: 0.4 cycles beyond the integer
  EXPECT_EQ(start_ambiguities_from_position(c.state, c.sds, {{gps(7), 0}}, 0.15).size(), 0U);
  EXPECT_EQ(c.state.P()(c.state.index({gps(7), 0}), c.state.index({gps(7), 0})), 900.0);
}

TEST(AmbiguityPrior, NothingWithoutAHeldReferenceOrWhenOff) {
  Case c = make_case(0.0, 0.0, 0.005);
  EXPECT_EQ(start_ambiguities_from_position(c.state, c.sds, {{gps(7), 0}}, 0.0).size(), 0U);
  // The reference new this epoch as well: no held ambiguity to start from.
  EXPECT_EQ(start_ambiguities_from_position(c.state, c.sds, {{gps(3), 0}, {gps(7), 0}}, 0.15).size(), 0U);
}

}  // namespace
}  // namespace canyon::rtk
