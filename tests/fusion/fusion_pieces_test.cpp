// The fusion's pieces one by one, each against its model: the prior of Eqs. 3-6 (predict_with_vio), the innovation
// gates (line 6), float validation (line 8), the fill-in (line 22), the false-fix guard, the prior recovery, the
// integrity check, the heading state, the heading-free fill-in, the constant-velocity ablation and the output
// covariance (the floor, and the scaling of a solution not fixed).

#include <cmath>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/fusion/constant_velocity.hpp"
#include "canyon/fusion/false_fix_guard.hpp"
#include "canyon/fusion/float_validation.hpp"
#include "canyon/fusion/heading_free_fill_in.hpp"
#include "canyon/fusion/heading_state.hpp"
#include "canyon/fusion/innovation_gates.hpp"
#include "canyon/fusion/integrity_check.hpp"
#include "canyon/fusion/output_floor.hpp"
#include "canyon/fusion/prior_recovery.hpp"
#include "canyon/fusion/vio_fill_in.hpp"
#include "canyon/fusion/vio_prediction.hpp"

namespace canyon::fusion {
namespace {

const Eigen::Vector3d kP0(-2694045.0, -4293642.0, 3857878.0);  // a point on the ground (ECEF, m)

core::Pose pose(const Eigen::Vector3d& p, double yaw_rad) {
  return core::Pose{Eigen::Quaterniond(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ())), p};
}

TEST(FusionPieces, PredictWithVioIsEqsThreeToSix) {
  VioPredictionInput in;
  in.p_E_m = kP0;
  in.P_E_m2 = Eigen::Vector3d(0.01, 0.02, 0.03).asDiagonal();
  in.T_OI_i = pose(Eigen::Vector3d(1.0, 2.0, 0.0), 0.1);
  in.T_OI_next = pose(Eigen::Vector3d(1.5, 2.2, 0.1), 0.3);
  in.joint = Matrix12d::Identity() * 1e-6;
  in.t_IA_m = Eigen::Vector3d(0.1, 0.0, 0.05);
  in.R_EO = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 0.3, 0.9).normalized()).toRotationMatrix();
  PredictionOptions paper;
  paper.vio_sigma_factor = 1.0;  // the VIO's covariance as reported
  const MotionPrediction p = predict_with_vio(in, paper);
  const Eigen::Vector3d dp_O = in.T_OI_next.q * in.t_IA_m + in.T_OI_next.p - (in.T_OI_i.q * in.t_IA_m + in.T_OI_i.p);
  EXPECT_LT((p.increment.dp_O_m - dp_O).norm(), 1e-12);                            // the antenna's increment
  EXPECT_LT((p.dp_E_m - in.R_EO * dp_O).norm(), 1e-12);                            // Eq. 5
  EXPECT_LT((p.prior.p_E_m - (kP0 + in.R_EO * dp_O)).norm(), 1e-9);                // Eq. 3
  EXPECT_LT((p.prior.P_E_m2 - (in.P_E_m2 + p.increment.cov_E_m2)).norm(), 1e-15);  // Eq. 6
  EXPECT_LT((p.increment.cov_E_m2 - in.R_EO * p.increment.cov_O_m2 * in.R_EO.transpose()).norm(), 1e-15);
  // Eq. 4 with the joint covariance sigma^2 I: J J^T sigma^2, J = [-R_i (.. ) | R_i+1 (..)]: at least both
  // positions' 2 sigma^2 on the diagonal.
  EXPECT_GE(p.increment.cov_O_m2.diagonal().minCoeff(), 2e-6 - 1e-15);
  // Beyond the paper: an over-confident VIO's covariance taken times vio_sigma_factor^2.
  PredictionOptions inflated;
  inflated.vio_sigma_factor = 2.0;
  const MotionPrediction r = predict_with_vio(in, inflated);
  EXPECT_LT((r.Q_E_m2 - 4.0 * p.increment.cov_E_m2).norm(), 1e-15);
  EXPECT_LT((r.prior.P_E_m2 - (in.P_E_m2 + 4.0 * p.increment.cov_E_m2)).norm(), 1e-15);
  // The ablation's constant covariance and the recovery's widening.
  PredictionOptions constant;
  constant.vio_covariance = false;
  const MotionPrediction q = predict_with_vio(in, constant, 2.0);
  EXPECT_LT((q.Q_E_m2 - Eigen::Matrix3d::Identity() * (0.05 * 0.05 + 4.0)).norm(), 1e-12);
  EXPECT_LT((q.prior.P_E_m2 - (in.P_E_m2 + q.Q_E_m2)).norm(), 1e-12);
}

/// An innovation as a gate sees it, from a DD row with prior variance h P h^T = `hPh`.
struct Row {
  rtk::DdRow row;
  Eigen::MatrixXd P;
  Row(bool phase, double innovation_m, double hPh) : P(Eigen::MatrixXd::Identity(3, 3) * hPh) {
    row.phase = phase;
    row.h_pos = Eigen::Vector3d(1.0, 0.0, 0.0);
    row.innovation_m = innovation_m;
  }
  [[nodiscard]] rtk::DdInnovation view(double r) const { return rtk::DdInnovation(row, P, r); }
};

TEST(FusionPieces, TheGatesAreFiveTimesTheMotionAndChiSquare) {
  GateOptions paper;
  paper.kind = GateKind::Paper;
  paper.nlos_sigmas = 0.0;                     // the paper's gate alone
  const VioInnovationGates gates(paper, 0.4);  // 5 x 0.4 m = 2 m
  ASSERT_TRUE(gates.max_phase_innovation_m().has_value());
  EXPECT_DOUBLE_EQ(*gates.max_phase_innovation_m(), 2.0);
  EXPECT_FALSE(gates.passes(Row(true, 2.5, 0.01).view(1e-5)));
  EXPECT_TRUE(gates.passes(Row(true, 1.5, 0.01).view(1e-5)));
  EXPECT_TRUE(gates.passes(Row(true, 2.5, 1.0).view(1e-5)));    // predicted worse than a third of the gate: no test
  EXPECT_TRUE(gates.passes(Row(false, 25.0, 0.01).view(1.0)));  // code is not gated by the motion
  EXPECT_DOUBLE_EQ(*VioInnovationGates(paper, 0.01).max_phase_innovation_m(), paper.min_gate_m);
  GateOptions speed_aware = paper;
  speed_aware.max_gate_m = 1.5;  // a vehicle's 3 m per epoch is capped; a walker's 0.2 m is the paper's 1 m
  EXPECT_DOUBLE_EQ(*VioInnovationGates(speed_aware, 3.0).max_phase_innovation_m(), 1.5);
  EXPECT_DOUBLE_EQ(*VioInnovationGates(speed_aware, 0.2).max_phase_innovation_m(), 1.0);
  EXPECT_DOUBLE_EQ(*VioInnovationGates(speed_aware, 0.01).max_phase_innovation_m(), paper.min_gate_m);
  speed_aware.max_gate_m = 0.4;
  EXPECT_FALSE(speed_aware.validate().empty());  // a cap below the floor
  GateOptions chi;
  chi.kind = GateKind::ChiSquare;
  chi.nlos_sigmas = 0.0;
  const VioInnovationGates chi_gates(chi, 0.4);
  EXPECT_FALSE(chi_gates.max_phase_innovation_m().has_value());
  EXPECT_FALSE(chi_gates.passes(Row(false, 5.0, 0.44).view(0.56)));  // 5 > 4 sqrt(1)
  EXPECT_TRUE(chi_gates.passes(Row(false, 3.9, 0.44).view(0.56)));
  GateOptions off;
  off.kind = GateKind::Off;
  EXPECT_TRUE(VioInnovationGates(off, 0.4).passes(Row(true, 1e6, 0.0).view(0.0)));
}

TEST(FusionPieces, TheNlosGateRefusesCodesLongerThanThePriorAllowsAndTheirSignals) {
  GateOptions options;  // the shipped set-up: both gates and NLOS at 3 sigma
  const VioInnovationGates gates(options, 0.4);
  EXPECT_TRUE(gates.refuses_signal_with_code());
  EXPECT_FALSE(gates.passes(Row(false, 3.1, 0.44).view(0.56)));  // 3.1 > 3 sqrt(1) upward: a reflection's extra path
  EXPECT_TRUE(gates.passes(Row(false, -3.1, 0.44).view(0.56)));  // downward: no reflection, the chi-square judges
  EXPECT_TRUE(gates.passes(Row(false, 2.9, 0.44).view(0.56)));
  EXPECT_TRUE(gates.passes(Row(true, 0.04, 0.0004).view(1e-5)));  // phase rows are not judged by it
  GateOptions off = options;
  off.nlos_sigmas = 0.0;
  EXPECT_FALSE(VioInnovationGates(off, 0.4).refuses_signal_with_code());
  EXPECT_TRUE(VioInnovationGates(off, 0.4).passes(Row(false, 3.1, 0.44).view(0.56)));
  GateOptions none = options;
  none.kind = GateKind::Off;  // no gate at all: no NLOS gate either
  EXPECT_FALSE(VioInnovationGates(none, 0.4).refuses_signal_with_code());
  EXPECT_TRUE(VioInnovationGates(none, 0.4).passes(Row(false, 30.0, 0.44).view(0.56)));
  GateOptions bad = options;
  bad.nlos_sigmas = -1.0;
  EXPECT_NE(bad.validate().find("gate_nlos_sigmas"), std::string::npos);
}

rtk::RtkEpoch aided_epoch(const Eigen::Vector3d& float_offset_m) {
  rtk::RtkEpoch e;
  e.aided = true;
  e.num_dd_measurements = 8;
  e.max_post_fit_normalised = 0.5;
  e.prior_p_E_m = kP0;
  e.prior_P_E_m2 = Eigen::Matrix3d::Identity() * 0.01;
  e.float_p_E_m = kP0 + float_offset_m;
  e.solution.status = core::SolutionStatus::Float;
  e.solution.p_E_m = e.float_p_E_m;
  return e;
}

TEST(FusionPieces, FloatValidationAndTheFillIn) {
  const FloatValidationOptions options;
  EXPECT_EQ(validate_float(aided_epoch(Eigen::Vector3d(0.1, 0.1, 0.1)), options), "");
  const rtk::RtkEpoch far = aided_epoch(Eigen::Vector3d(1.0, 0.0, 0.0));  // chi-square 100
  const std::string verdict = validate_float(far, options);
  EXPECT_NE(verdict.find("from the VIO prior"), std::string::npos) << verdict;
  EXPECT_TRUE(failed_on_prior_only(far, verdict, options));
  rtk::RtkEpoch residuals = aided_epoch(Eigen::Vector3d::Zero());
  residuals.max_post_fit_normalised = 1.5;
  const std::string post_fit = validate_float(residuals, options);
  EXPECT_NE(post_fit.find("post-fit residual"), std::string::npos);
  EXPECT_FALSE(failed_on_prior_only(residuals, post_fit, options));
  rtk::RtkEpoch none = aided_epoch(Eigen::Vector3d::Zero());
  none.num_dd_measurements = 0;
  EXPECT_EQ(validate_float(none, options), "no double-differenced phase");
  // Line 22: the filter's prior with status VIO fill-in, or the fusion's when the filter's time update did not run.
  const core::Solution fill =
      vio_fill_in(far, Prior{kP0 + Eigen::Vector3d::Ones(), Eigen::Matrix3d::Identity()}, core::GpsTime{2200, 10.0});
  EXPECT_EQ(fill.status, core::SolutionStatus::VioFillIn);
  EXPECT_EQ(fill.p_E_m, kP0);
  EXPECT_DOUBLE_EQ(fill.ratio, 0.0);
  rtk::RtkEpoch not_aided = far;
  not_aided.aided = false;
  not_aided.solution.status = core::SolutionStatus::None;
  const core::Solution from_fusion =
      vio_fill_in(not_aided, Prior{kP0 + Eigen::Vector3d::Ones(), Eigen::Matrix3d()}, core::GpsTime{2200, 10.0});
  EXPECT_EQ(from_fusion.p_E_m, kP0 + Eigen::Vector3d::Ones());
  EXPECT_DOUBLE_EQ(from_fusion.time.tow_s, 10.0);
}

TEST(FusionPieces, TheGuardRefusesFixesFarFromThePriorOrPoorlyDetermined) {
  FalseFixGuard guard(FalseFixGuardOptions{});
  const Prior prior{kP0, Eigen::Matrix3d::Identity() * 0.01};
  rtk::FixCandidate fix;
  fix.position_ok = true;
  fix.p_E_m = kP0 + Eigen::Vector3d(0.05, 0.0, 0.0);
  fix.P_E_m2 = Eigen::Matrix3d::Identity() * 1e-4;
  guard.start_epoch();
  EXPECT_TRUE(guard.accepts(fix, prior));
  fix.p_E_m = kP0 + Eigen::Vector3d(1.0, 0.0, 0.0);
  EXPECT_FALSE(guard.accepts(fix, prior));
  EXPECT_EQ(guard.refused_by_prior(), 1);
  fix.p_E_m = kP0;
  fix.P_E_m2(2, 2) = 0.04;  // sigma 0.2 m > 0.1 m
  EXPECT_FALSE(guard.accepts(fix, prior));
  EXPECT_EQ(guard.refused_as_undetermined(), 1);
  fix.position_ok = false;
  EXPECT_FALSE(guard.accepts(fix, prior));
  guard.start_epoch();
  EXPECT_EQ(guard.refused_by_prior() + guard.refused_as_undetermined(), 0);
  FalseFixGuardOptions off;
  off.enabled = false;
  FalseFixGuard no_guard(off);
  fix.position_ok = true;
  fix.P_E_m2 = Eigen::Matrix3d::Identity() * 1e-4;
  fix.p_E_m = kP0 + Eigen::Vector3d(5.0, 0.0, 0.0);
  EXPECT_TRUE(no_guard.accepts(fix, prior));
}

TEST(FusionPieces, PriorRecoveryReanchorsAfterRepeatedPriorOnlyFailuresAndWidensAfterGateConflicts) {
  PriorRecoveryOptions options;
  options.max_prior_rejections = 2;
  options.gate_conflict_epochs = 3;
  PriorRecovery recovery(options);
  EXPECT_FALSE(recovery.reanchor(true));
  EXPECT_FALSE(recovery.reanchor(true));
  EXPECT_TRUE(recovery.reanchor(true));   // the third in a row
  EXPECT_FALSE(recovery.reanchor(true));  // counting again
  EXPECT_FALSE(recovery.reanchor(false));
  EXPECT_FALSE(recovery.take_widening().has_value());
  recovery.count_gate_conflict(5, 3);
  recovery.count_gate_conflict(5, 3);
  recovery.count_gate_conflict(1, 3);  // not a conflict: the count starts again
  recovery.count_gate_conflict(5, 3);
  recovery.count_gate_conflict(5, 3);
  EXPECT_FALSE(recovery.take_widening().has_value());
  recovery.count_gate_conflict(5, 3);
  ASSERT_TRUE(recovery.take_widening().has_value());
  EXPECT_FALSE(recovery.take_widening().has_value());  // once
}

TEST(FusionPieces, TheIntegrityCheckRestartsWhenTheMedianSinglePointIsFarOff) {
  IntegrityCheckOptions options;
  options.window_s = 10.0;
  options.min_points = 10;
  options.max_offset_m = 20.0;
  IntegrityCheck check(options);
  const Eigen::Matrix3d R_EN = core::rotation_enu_from_ecef(core::ecef_to_geodetic(kP0)).transpose();
  const Eigen::Matrix3d P_out = Eigen::Matrix3d::Identity() * 0.01;
  std::optional<IntegrityRestart> restart;
  for (int k = 0; k <= 10 && !restart; ++k) {
    const Eigen::Vector3d spp = kP0 + R_EN * Eigen::Vector3d(30.0 + (k % 3), -5.0, 2.0);
    restart = check.check(core::GpsTime{2200, static_cast<double>(k)}, kP0, P_out, spp);
    if (k < 10) {
      // fewer than min_points, then (k = 9) fewer than half of them in the window's older half
      EXPECT_FALSE(restart.has_value()) << k;
    }
  }
  ASSERT_TRUE(restart.has_value());
  const Eigen::Vector3d moved_N = R_EN.transpose() * (restart->p_E_m - kP0);
  EXPECT_NEAR(moved_N.x(), 31.0, 1e-6);  // the median east offset
  EXPECT_NEAR(moved_N.y(), -5.0, 1e-6);
  EXPECT_NEAR(moved_N.z(), 0.0, 1e-6);  // the vertical stays
  EXPECT_NEAR(restart->offset_m, std::hypot(31.0, 5.0), 1e-6);
  // Single points that come back after a blockage, many and all far off within a few seconds (downtown seed 17), are
  // no median over the window: no restart until the window's older half holds half of min_points of them too.
  IntegrityCheck after_blockage(options);
  std::optional<double> restarted_at_s;
  for (int k = 0; k < 100 && !restarted_at_s; ++k) {
    const double t_s = 6.0 + 0.1 * k;
    if (after_blockage.check(core::GpsTime{2200, t_s}, kP0, P_out, kP0 + R_EN * Eigen::Vector3d(0.0, -80.0, 0.0))) {
      restarted_at_s = t_s;
    }
  }
  ASSERT_TRUE(restarted_at_s.has_value());
  EXPECT_GT(*restarted_at_s, 11.3);  // 5 points before t - 5 s: t >= 11.4 s
  EXPECT_LT(*restarted_at_s, 11.6);
  // Points close to the output never restart; no single point, no test.
  IntegrityCheck quiet(options);
  for (int k = 0; k < 20; ++k) {
    EXPECT_FALSE(
        quiet.check(core::GpsTime{2200, static_cast<double>(k)}, kP0, P_out, kP0 + R_EN * Eigen::Vector3d(3, 0, 0)));
    EXPECT_FALSE(quiet.check(core::GpsTime{2200, static_cast<double>(k)}, kP0, P_out, std::nullopt));
  }
  // A split group (downtown): 3 in 10 single points near the output, the rest 200 m off. The median is far, but the
  // output still agrees with min_agreeing_share (0.2) of them: no restart. With 1 in 10 near it restarts.
  for (const int near_every : {3, 10}) {
    IntegrityCheck split(options);
    std::optional<IntegrityRestart> moved;
    for (int k = 0; k < 30; ++k) {
      const bool near = k % 10 < (near_every == 3 ? 3 : 1);
      const Eigen::Vector3d spp = kP0 + R_EN * (near ? Eigen::Vector3d(5.0, 0.0, 0.0) : Eigen::Vector3d(0.0, 200.0, 0));
      moved = split.check(core::GpsTime{2200, static_cast<double>(k)}, kP0, P_out, spp);
      if (moved) break;
    }
    EXPECT_EQ(moved.has_value(), near_every == 10) << near_every;
  }
}

TEST(FusionPieces, TheHeadingStateCouplesTheIncrementAndFoldsItsEstimate) {
  VioAlignment alignment;
  alignment.yaw_sigma_rad = 0.05;
  rtk::ExternalMotion motion;
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d dp(1000.0, 0.0, 0.0);
  couple_heading(motion, dp, up, alignment, HeadingStateOptions{});
  EXPECT_EQ(motion.dp_d_heading_E_m, Eigen::Vector3d(0.0, 1000.0, 0.0));        // up x dp
  EXPECT_NEAR(motion.heading_noise_rad2, std::pow(core::kDegToRad, 2), 1e-18);  // 1 deg / sqrt(km) over 1 km
  EXPECT_DOUBLE_EQ(motion.heading_variance_rad2, 0.0025);
  EXPECT_TRUE(motion.restart_heading);
  EXPECT_TRUE(alignment.heading_started);
  couple_heading(motion, dp, up, alignment, HeadingStateOptions{});
  EXPECT_FALSE(motion.restart_heading);
}

TEST(FusionPieces, TheHeadingFreeFillInMovesVerticallyAndGrowsHorizontally) {
  HeadingFreeFillIn fill_in(HeadingFreeFillInOptions{});
  EXPECT_FALSE(fill_in.anchor_time(0).has_value());
  core::Solution anchor;
  anchor.p_E_m = kP0;
  anchor.P_E_m2 = Eigen::Matrix3d::Identity() * 0.01;
  fill_in.anchor(anchor, core::GpsTime{2200, 1.0}, 4);
  EXPECT_FALSE(fill_in.anchor_time(5).has_value());  // another segment
  ASSERT_TRUE(fill_in.anchor_time(4).has_value());
  VioIncrement inc;
  inc.dp_O_m = Eigen::Vector3d(3.0, 4.0, 0.5);
  inc.cov_O_m2(2, 2) = 1e-4;
  const core::Solution s = fill_in.fill(core::GpsTime{2200, 2.0}, inc);
  EXPECT_EQ(s.status, core::SolutionStatus::VioFillIn);
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(core::ecef_to_geodetic(kP0));
  const Eigen::Vector3d d_N = R_NE * (s.p_E_m - kP0);
  EXPECT_NEAR(d_N.z(), 0.5, 1e-9);
  EXPECT_NEAR(d_N.head<2>().norm(), 0.0, 1e-9);  // the horizontal direction is unknown
  const Eigen::Matrix3d P_N = R_NE * s.P_E_m2 * R_NE.transpose();
  EXPECT_NEAR(P_N(0, 0), 0.01 + 25.0 / 2.0, 1e-9);  // h = 5 m: sigma h / sqrt(2) per axis
  EXPECT_NEAR(P_N(2, 2), 0.01 + 1e-4, 1e-12);
}

TEST(FusionPieces, ConstantVelocityFromTheLastTwoSolutions) {
  core::Solution a, b;
  a.time = core::GpsTime{2200, 10.0};
  b.time = core::GpsTime{2200, 11.0};
  a.p_E_m = kP0;
  b.p_E_m = kP0 + Eigen::Vector3d(1.0, 0.0, 0.0);
  const auto p = predict_constant_velocity({a, b}, core::GpsTime{2200, 11.5}, b.time, 10.0, 3.0);
  ASSERT_TRUE(p.has_value());
  EXPECT_LT((p->dp_E_m - Eigen::Vector3d(0.5, 0.0, 0.0)).norm(), 1e-12);
  EXPECT_NEAR(p->Q_E_m2(0, 0), 9.0 * 0.125 / 3.0, 1e-12);
  EXPECT_FALSE(predict_constant_velocity({a, b}, core::GpsTime{2200, 11.5}, b.time, 0.5, 3.0));  // too fast
  EXPECT_FALSE(predict_constant_velocity({b}, core::GpsTime{2200, 11.5}, b.time, 10.0, 3.0));
}

TEST(FusionPieces, TheOutputFloorAddsItsSigmasInTheLocalFrame) {
  core::Solution s;
  s.status = core::SolutionStatus::Fixed;
  s.p_E_m = kP0;
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(core::ecef_to_geodetic(kP0));
  s.P_E_m2 = R_NE.transpose() * Eigen::Vector3d(1e-6, 4e-6, 9e-6).asDiagonal() * R_NE;  // 1, 2, 3 mm
  add_output_floor(s, OutputFloorOptions{0.01, 0.02});
  const Eigen::Matrix3d P_N = R_NE * s.P_E_m2 * R_NE.transpose();
  EXPECT_NEAR(P_N(0, 0), 1e-6 + 1e-4, 1e-12);
  EXPECT_NEAR(P_N(1, 1), 4e-6 + 1e-4, 1e-12);
  EXPECT_NEAR(P_N(2, 2), 9e-6 + 4e-4, 1e-12);
  EXPECT_NEAR(P_N(0, 1), 0.0, 1e-12);
  // No solution, no covariance to floor; a zero floor changes nothing.
  core::Solution none;
  add_output_floor(none, OutputFloorOptions{0.01, 0.02});
  EXPECT_TRUE(none.P_E_m2.isZero());
  const Eigen::Matrix3d before = s.P_E_m2;
  add_output_floor(s, OutputFloorOptions{0.0, 0.0});
  EXPECT_EQ(s.P_E_m2, before);
  EXPECT_FALSE((OutputFloorOptions{-0.01, 0.02}.validate().empty()));
}

TEST(FusionPieces, ASolutionNotFixedIsOutputWithItsSigmasScaledThenFloored) {
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(core::ecef_to_geodetic(kP0));
  const Eigen::Matrix3d P_E = R_NE.transpose() * Eigen::Vector3d(0.01, 0.04, 0.09).asDiagonal() * R_NE;  // 0.1-0.3 m
  for (const core::SolutionStatus status : {core::SolutionStatus::Float, core::SolutionStatus::VioFillIn,
                                            core::SolutionStatus::Single, core::SolutionStatus::Fixed}) {
    core::Solution s;
    s.status = status;
    s.p_E_m = kP0;
    s.P_E_m2 = P_E;
    add_output_floor(s, OutputFloorOptions{0.01, 0.02, 3.0});
    const Eigen::Matrix3d P_N = R_NE * s.P_E_m2 * R_NE.transpose();
    const double k2 = status == core::SolutionStatus::Fixed ? 1.0 : 9.0;  // a fix keeps the filter's covariance
    EXPECT_NEAR(P_N(0, 0), k2 * 0.01 + 1e-4, 1e-12) << static_cast<int>(status);
    EXPECT_NEAR(P_N(2, 2), k2 * 0.09 + 4e-4, 1e-12) << static_cast<int>(status);
    EXPECT_EQ(s.p_E_m, kP0);  // the position is not touched
  }
  // A factor of 1 and no floor leave the covariance as it is; a factor below 1 would hide errors: refused.
  core::Solution s;
  s.status = core::SolutionStatus::Float;
  s.p_E_m = kP0;
  s.P_E_m2 = P_E;
  add_output_floor(s, OutputFloorOptions{0.0, 0.0, 1.0});
  EXPECT_EQ(s.P_E_m2, P_E);
  EXPECT_FALSE((OutputFloorOptions{0.01, 0.02, 0.5}.validate().empty()));
}

}  // namespace
}  // namespace canyon::fusion
