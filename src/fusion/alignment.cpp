// Alignment and lever-arm calibration with Ceres on SE(3) (model in alignment.hpp).

#include "canyon/fusion/alignment.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include <Eigen/Eigenvalues>
#include <ceres/tiny_solver.h>

#include "canyon/core/geodesy.hpp"

namespace canyon::fusion {
namespace {

constexpr double kHuberFactor = 1.5;  // coarse alignment: Huber threshold in robust sigmas
constexpr int kCoarseIterations = 10;

constexpr int kOuterIterations = 4;  // re-centrings of the SE(3) chart

}  // namespace

AlignmentProblem::AlignmentProblem(const std::vector<AlignmentPoint>& points, const core::Pose& T_0,
                                   const Eigen::Vector3d& t_IA, bool estimate_lever_arm,
                                   std::vector<HeldDirection> held)
    : points_(points), T_0_(T_0), t_IA_(t_IA), estimate_lever_arm_(estimate_lever_arm), held_(std::move(held)) {}

core::Pose AlignmentProblem::retract(const core::Pose& T_0, const double* x) {
  const Eigen::Vector3d rho(x[0], x[1], x[2]);
  const Eigen::Vector3d theta(x[3], x[4], x[5]);
  core::Pose T{T_0.q * core::so3_exp(theta), T_0.p + T_0.q * rho};
  T.q.normalize();
  return T;
}

bool AlignmentProblem::operator()(const double* x, double* residuals, double* jacobian) const {
  const core::Pose T = retract(T_0_, x);
  const Eigen::Vector3d t = estimate_lever_arm_ ? Eigen::Vector3d(x[6], x[7], x[8]) : t_IA_;
  const Eigen::Matrix3d R_0 = T_0_.rotation();
  const Eigen::Matrix3d R = T.rotation();
  const Eigen::Matrix3d J_r = core::so3_right_jacobian(Eigen::Vector3d(x[3], x[4], x[5]));
  const int rows = NumResiduals();
  Eigen::Map<Eigen::VectorXd> r(residuals, rows);
  std::optional<Eigen::Map<Eigen::MatrixXd>> J;
  if (jacobian != nullptr) {
    J.emplace(jacobian, rows, NumParameters());
    J->setZero();
  }
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const AlignmentPoint& p = points_[i];
    const Eigen::Matrix3d R_OI = p.T_OI.rotation();
    const Eigen::Vector3d x_O = p.T_OI.p + R_OI * t;
    const auto row = static_cast<Eigen::Index>(3 * i);
    r.segment<3>(row) = R * x_O + T.p - p.p_E_m;
    if (J) {
      J->block<3, 3>(row, 0) = R_0;
      J->block<3, 3>(row, 3) = -R * core::skew(x_O) * J_r;
      if (estimate_lever_arm_) J->block<3, 3>(row, 6) = R * R_OI;
    }
  }
  for (std::size_t k = 0; k < held_.size(); ++k) {
    const auto row = static_cast<Eigen::Index>(3 * points_.size() + k);
    r[row] = (held_[k].u.dot(t) - held_[k].target) * held_[k].inverse_sigma;
    if (J && estimate_lever_arm_) J->block<1, 3>(row, 6) = held_[k].u.transpose() * held_[k].inverse_sigma;
  }
  return true;
}

namespace {

/// The points about their centroids (O: the IMU positions; E: the antenna positions).
struct Centred {
  Eigen::Vector3d c_O = Eigen::Vector3d::Zero();
  Eigen::Vector3d c_E = Eigen::Vector3d::Zero();
  std::vector<AlignmentPoint> points;
};

Centred centre(const std::vector<AlignmentPoint>& points) {
  Centred c;
  for (const AlignmentPoint& p : points) {
    c.c_O += p.T_OI.p;
    c.c_E += p.p_E_m;
  }
  c.c_O /= static_cast<double>(points.size());
  c.c_E /= static_cast<double>(points.size());
  c.points.reserve(points.size());
  for (const AlignmentPoint& p : points) {
    c.points.push_back(AlignmentPoint{core::Pose{p.T_OI.q, p.T_OI.p - c.c_O}, p.p_E_m - c.c_E});
  }
  return c;
}

/// T_EO = Trans(c_E) T' Trans(-c_O), and back.
core::Pose uncentre(const core::Pose& T_centred, const Centred& c) {
  return {T_centred.q, c.c_E + T_centred.p - T_centred.q * c.c_O};
}
core::Pose centred_of(const core::Pose& T_EO, const Centred& c) {
  return {T_EO.q, T_EO.p - c.c_E + T_EO.q * c.c_O};
}

double rmse(const std::vector<AlignmentPoint>& points, const core::Pose& T_EO, const Eigen::Vector3d& t_IA) {
  double sum = 0.0;
  for (const AlignmentPoint& p : points) sum += (T_EO * (p.T_OI * t_IA) - p.p_E_m).squaredNorm();
  return std::sqrt(sum / static_cast<double>(points.size()));
}

/// Levenberg-Marquardt on the SE(3) chart at `pose`, re-centred after each solve; t_IA estimated when `held` is given.
bool solve(const Centred& c, core::Pose& pose, Eigen::Vector3d& t_IA, bool estimate_lever_arm,
           const std::vector<AlignmentProblem::HeldDirection>& held, int max_iterations) {
  using Solver = ceres::TinySolver<AlignmentProblem>;
  Solver solver;
  solver.options.max_num_iterations = max_iterations;
  solver.options.gradient_tolerance = 1e-12;
  solver.options.parameter_tolerance = 1e-12;
  solver.options.function_tolerance = 1e-12;
  for (int outer = 0; outer < kOuterIterations; ++outer) {
    const AlignmentProblem problem(c.points, pose, t_IA, estimate_lever_arm, held);
    Solver::Parameters x = Solver::Parameters::Zero(problem.NumParameters());
    if (estimate_lever_arm) x.tail<3>() = t_IA;
    const auto& summary = solver.Solve(problem, &x);
    if (!x.allFinite()) return false;
    pose = AlignmentProblem::retract(pose, x.data());
    if (estimate_lever_arm) t_IA = x.tail<3>();
    if (x.head<6>().norm() < 1e-10 || summary.status == Solver::COST_TOO_SMALL) break;
  }
  return true;
}

}  // namespace

std::string AlignmentOptions::validate() const {
  if (!(max_first_eigenvalue_ratio > 1.0 / 3.0 && max_first_eigenvalue_ratio <= 1.0)) {
    return "max_first_eigenvalue_ratio must be in (1/3, 1]";
  }
  if (!(max_rmse_m > 0.0)) return "max_rmse_m must be > 0";
  if (min_points < 3) return "min_points must be >= 3";
  if (!(min_lever_arm_excitation >= 0.0)) return "min_lever_arm_excitation must be >= 0";
  if (!(lever_arm_prior_sigma_m > 0.0)) return "lever_arm_prior_sigma_m must be > 0";
  if (max_iterations < 1) return "max_iterations must be >= 1";
  return {};
}

double first_eigenvalue_ratio(const std::vector<Eigen::Vector3d>& positions) {
  if (positions.size() < 2) return 1.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : positions) mean += p;
  mean /= static_cast<double>(positions.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : positions) cov += (p - mean) * (p - mean).transpose();
  const Eigen::Vector3d lambda = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvalues().cwiseMax(0.0);
  const double sum = lambda.sum();
  return sum > 0.0 ? lambda.maxCoeff() / sum : 1.0;
}

std::string LeverArmObservability::describe() const {
  std::string out;
  for (int k = 2; k >= 0; --k) {  // largest excitation first
    const Eigen::Vector3d u = directions_I.col(k);
    int axis = 0;
    u.cwiseAbs().maxCoeff(&axis);
    char buffer[96];
    std::snprintf(buffer, sizeof buffer, "%s%c: %s (%.3f)", out.empty() ? "" : ", ", "xyz"[axis],
                  excited[static_cast<std::size_t>(k)] ? "excited" : "not excited, kept at its prior", excitation[k]);
    out += buffer;
  }
  return out;
}

LeverArmObservability lever_arm_observability(const std::vector<AlignmentPoint>& points, double min_excitation) {
  LeverArmObservability o;
  if (points.empty()) return o;
  Eigen::Matrix3d mean = Eigen::Matrix3d::Zero();
  for (const AlignmentPoint& p : points) mean += p.T_OI.rotation();
  mean /= static_cast<double>(points.size());
  const Eigen::Matrix3d info = Eigen::Matrix3d::Identity() - mean.transpose() * mean;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (info + info.transpose()));
  o.directions_I = eig.eigenvectors();
  o.excitation = eig.eigenvalues().cwiseMax(0.0);
  for (int k = 0; k < 3; ++k) o.excited[static_cast<std::size_t>(k)] = o.excitation[k] >= min_excitation;
  return o;
}

Result<AlignmentResult> align_and_calibrate(const std::vector<AlignmentPoint>& points,
                                            const Eigen::Vector3d& t_IA_prior, bool calibrate,
                                            const AlignmentOptions& options) {
  if (const std::string e = options.validate(); !e.empty()) return Error{"alignment: " + e};
  if (static_cast<int>(points.size()) < options.min_points) {
    return Error{"alignment: " + std::to_string(points.size()) + " points, at least " +
                 std::to_string(options.min_points) + " needed"};
  }
  AlignmentResult result;
  result.points = static_cast<int>(points.size());
  std::vector<Eigen::Vector3d> positions;
  positions.reserve(points.size());
  for (const AlignmentPoint& p : points) positions.push_back(p.p_E_m);
  result.first_eigenvalue_ratio = first_eigenvalue_ratio(positions);
  result.lever_arm = lever_arm_observability(points, options.min_lever_arm_excitation);

  const Centred c = centre(points);
  // Pass 1: identity start, t_IA = 0 (or the prior when not calibrating: the "without calibration" alignment).
  core::Pose pose;
  Eigen::Vector3d t = calibrate ? Eigen::Vector3d::Zero() : t_IA_prior;
  bool ok = solve(c, pose, t, false, {}, options.max_iterations);
  core::Pose T_EO = uncentre(pose, c);
  result.rmse_without_calibration_m = rmse(points, T_EO, t);
  if (ok && calibrate) {
    // Pass 2: jointly, from pass 1; unexcited lever-arm directions held at the prior.
    std::vector<AlignmentProblem::HeldDirection> held;
    for (int k = 0; k < 3; ++k) {
      if (result.lever_arm.excited[static_cast<std::size_t>(k)]) continue;
      const Eigen::Vector3d u = result.lever_arm.directions_I.col(k);
      held.push_back(AlignmentProblem::HeldDirection{u, u.dot(t_IA_prior), 1.0 / options.lever_arm_prior_sigma_m});
    }
    t = t_IA_prior;
    ok = solve(c, pose, t, true, held, options.max_iterations);
    T_EO = uncentre(pose, c);
    result.calibrated = ok;
  }
  result.converged = ok;
  result.T_EO = T_EO;
  result.t_IA_m = t;
  result.rmse_m = rmse(points, T_EO, t);
  return result;
}

Result<AlignmentResult> realign(const std::vector<AlignmentPoint>& points, const Eigen::Vector3d& t_IA,
                                const core::Pose& T_EO_start, const AlignmentOptions& options) {
  if (const std::string e = options.validate(); !e.empty()) return Error{"alignment: " + e};
  if (static_cast<int>(points.size()) < options.min_points) {
    return Error{"alignment: " + std::to_string(points.size()) + " points, at least " +
                 std::to_string(options.min_points) + " needed"};
  }
  AlignmentResult result;
  result.points = static_cast<int>(points.size());
  std::vector<Eigen::Vector3d> positions;
  positions.reserve(points.size());
  for (const AlignmentPoint& p : points) positions.push_back(p.p_E_m);
  result.first_eigenvalue_ratio = first_eigenvalue_ratio(positions);
  result.lever_arm = lever_arm_observability(points, options.min_lever_arm_excitation);
  const Centred c = centre(points);
  core::Pose pose = centred_of(T_EO_start, c);
  Eigen::Vector3d t = t_IA;
  result.converged = solve(c, pose, t, false, {}, options.max_iterations);
  result.T_EO = uncentre(pose, c);
  result.t_IA_m = t_IA;
  result.rmse_m = rmse(points, result.T_EO, t_IA);
  result.rmse_without_calibration_m = result.rmse_m;
  return result;
}

Result<CoarseAlignment> coarse_align(const std::vector<AlignmentPoint>& points, const Eigen::Vector3d& t_IA,
                                     const AlignmentOptions& options) {
  if (static_cast<int>(points.size()) < options.min_points) {
    return Error{"coarse alignment: " + std::to_string(points.size()) + " points, at least " +
                 std::to_string(options.min_points) + " needed"};
  }
  const auto n = points.size();
  // Antenna positions in O (O is gravity-aligned) and in ENU at the centroid of the GNSS positions.
  Eigen::Vector3d c_E = Eigen::Vector3d::Zero();
  for (const AlignmentPoint& p : points) c_E += p.p_E_m;
  c_E /= static_cast<double>(n);
  const core::Geodetic g = core::ecef_to_geodetic(c_E);
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(g);
  std::vector<Eigen::Vector3d> x_O(n), x_N(n);
  for (std::size_t i = 0; i < n; ++i) {
    x_O[i] = points[i].T_OI * t_IA;
    x_N[i] = R_NE * (points[i].p_E_m - c_E);
  }
  std::vector<double> w(n, 1.0);
  double psi = 0.0;
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();  // x_N = Rz(psi) x_O + shift
  CoarseAlignment out;
  for (int iteration = 0; iteration < kCoarseIterations; ++iteration) {
    double sw = 0.0;
    Eigen::Vector3d m_O = Eigen::Vector3d::Zero(), m_N = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      sw += w[i];
      m_O += w[i] * x_O[i];
      m_N += w[i] * x_N[i];
    }
    m_O /= sw;
    m_N /= sw;
    double h_cos = 0.0, h_sin = 0.0, spread2 = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d a = (x_O[i] - m_O).head<2>();
      const Eigen::Vector2d b = (x_N[i] - m_N).head<2>();
      h_cos += w[i] * a.dot(b);
      h_sin += w[i] * (a.x() * b.y() - a.y() * b.x());
      spread2 += w[i] * a.squaredNorm();
    }
    psi = std::atan2(h_sin, h_cos);
    const Eigen::Matrix3d Rz = Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    shift = m_N - Rz * m_O;
    std::vector<double> r(n);
    double sum2 = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      r[i] = (Rz * x_O[i] + shift - x_N[i]).head<2>().norm();
      sum2 += w[i] * r[i] * r[i];
    }
    out.rmse_m = std::sqrt(sum2 / sw);
    out.spread_m = std::sqrt(spread2 / sw);
    std::vector<double> sorted = r;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(n / 2), sorted.end());
    const double k = std::max(kHuberFactor * 1.4826 * sorted[n / 2], 1e-3);
    for (std::size_t i = 0; i < n; ++i) w[i] = r[i] <= k ? 1.0 : k / r[i];
  }
  if (!(out.spread_m > 0.0)) return Error{"coarse alignment: the VIO positions do not spread horizontally"};
  out.yaw_sigma_rad = out.rmse_m / out.spread_m;
  // T_EO: R_EO = R_EN Rz(psi); p_E = c_E + R_EN (Rz x_O + shift) for an antenna point x_O (and any point alike).
  const Eigen::Matrix3d R_EN = R_NE.transpose();
  const Eigen::Matrix3d R_EO = R_EN * Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  out.T_EO.q = Eigen::Quaterniond(R_EO).normalized();
  out.T_EO.p = c_E + R_EN * shift;
  return out;
}

}  // namespace canyon::fusion
