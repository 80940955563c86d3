// The leave-out agreement on a constructed pair of solutions whose counts are worked out by hand: 10 epochs, the
// full solution fixed at 0..7, the left-out one fixed at 2..9 (so 2..7 fixed in both), 1 cm apart except a 1.2 m
// jump at 5 and 4.9 cm at 6; the time match tolerates the 5 ms of a receiver whose clock is not steered.

#include "canyon/eval/leave_out.hpp"

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace canyon::eval {
namespace {

using core::SolutionStatus;

const core::GpsTime kT0{2161, 358554.0};
const Eigen::Vector3d kP{-2414266.0, 5386768.0, 2407460.0};

core::Solution solution(int k, bool fixed, const Eigen::Vector3d& offset_m = Eigen::Vector3d::Zero(),
                        double late_s = 0.0) {
  core::Solution s;
  s.time = kT0 + (k + late_s);
  s.status = fixed ? SolutionStatus::Fixed : SolutionStatus::Float;
  s.p_E_m = kP + Eigen::Vector3d(0.1 * k, 0.0, 0.0) + offset_m;
  return s;
}

TEST(LeaveOut, CountsEpochsFixedInBothAndThoseThatAgree) {
  std::vector<core::Solution> full;
  std::vector<core::Solution> left_out;
  for (int k = 0; k < 10; ++k) {
    full.push_back(solution(k, k <= 7));
    Eigen::Vector3d offset(0.0, 0.01, 0.0);
    if (k == 5) offset = Eigen::Vector3d(1.2, 0.0, 0.0);
    if (k == 6) offset = Eigen::Vector3d(0.0, 0.0, 0.049);
    left_out.push_back(solution(k, k >= 2, offset, 0.004));
  }
  const LeaveOutAgreement r = leave_out_agreement(full, left_out, 0.05);
  EXPECT_EQ(r.fixed_full, 8);
  EXPECT_EQ(r.fixed_left_out, 8);
  EXPECT_EQ(r.fixed_both, 6);
  EXPECT_EQ(r.agree, 5);
  EXPECT_NEAR(r.agreement(), 5.0 / 6.0, 1e-12);
  EXPECT_NEAR(r.worst_distance_m, 1.2, 1e-6);
  EXPECT_NEAR(r.median_distance_m, 0.01, 1e-6);  // 0.01 x4, 0.049, 1.2: the lower middle
  // Ten milliseconds apart are different epochs: nothing matched.
  std::vector<core::Solution> late;
  for (int k = 0; k < 10; ++k) late.push_back(solution(k, true, Eigen::Vector3d::Zero(), 0.010));
  EXPECT_EQ(leave_out_agreement(full, late).fixed_both, 0);
  EXPECT_DOUBLE_EQ(leave_out_agreement(full, late).agreement(), 1.0);
}

TEST(LeaveOut, TableSaysWhichRunIsInconsistent) {
  LeaveOutAgreement good;
  good.left_out = 1;
  good.satellites = {*core::parse_satellite("G05")};
  good.fixed_both = 100;
  good.agree = 99;
  LeaveOutAgreement bad = good;
  bad.left_out = 2;
  bad.agree = 30;
  const std::string text = format_leave_out({good, bad}, 0.95);
  EXPECT_NE(text.find("G05"), std::string::npos) << text;
  EXPECT_NE(text.find("1 left out: consistent: 99 of 100"), std::string::npos) << text;
  EXPECT_NE(text.find("2 left out: INCONSISTENT: 30 of 100"), std::string::npos) << text;
}

}  // namespace
}  // namespace canyon::eval
