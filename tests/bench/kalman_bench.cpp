// Timing of the RTK filter's Kalman update kernels (rtk/kalman.hpp) at RTK sizes: one epoch's code rows in compressed
// form then its phase rows at the code-updated covariance, and the symmetric covariance update, as
// rtk/dd_update.cpp runs them. BM_KalmanUpdate/states/satellites: a dual-frequency epoch with `satellites`
// satellites (2 (s - 1) DD phase and as many code rows), `states` filter states (position, ambiguities, ionosphere).
// Reproduce: build/tests/bench/bench_kalman --benchmark_repetitions=15 --benchmark_report_aggregates_only=true
// The figures (hand-written Cholesky and triangular solves against Eigen's) are in docs/results/rtk.md.

#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "canyon/rtk/kalman.hpp"

namespace {

using canyon::rtk::DdRow;
using canyon::rtk::KalmanStep;

struct Problem {
  Eigen::MatrixXd P;
  std::vector<DdRow> code;
  std::vector<DdRow> phase;
  Eigen::MatrixXd R_code;
  Eigen::MatrixXd R_phase;
};

Problem make_problem(int states, int satellites, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  Problem p;
  Eigen::MatrixXd A(states, states);
  for (Eigen::Index i = 0; i < A.size(); ++i) A.data()[i] = normal(rng);
  p.P = A * A.transpose() * 0.01 + Eigen::MatrixXd::Identity(states, states);
  const int rows = 2 * (satellites - 1);
  for (int r = 0; r < rows; ++r) {
    DdRow code;
    code.phase = false;
    code.h_pos = Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    code.innovation_m = normal(rng);
    DdRow phase = code;
    phase.phase = true;
    phase.add(4 + r % (states - 4), 0.19);  // satellite s's ambiguity
    phase.add(3, -0.19);                    // the reference's
    p.code.push_back(code);
    p.phase.push_back(phase);
  }
  p.R_code = Eigen::MatrixXd::Constant(rows, rows, 0.1);
  p.R_code.diagonal().setConstant(0.2);
  p.R_phase = Eigen::MatrixXd::Constant(rows, rows, 1e-5);
  p.R_phase.diagonal().setConstant(2e-5);
  return p;
}

void BM_KalmanUpdate(benchmark::State& state) {
  const auto states = static_cast<int>(state.range(0));
  const auto satellites = static_cast<int>(state.range(1));
  const Problem p = make_problem(states, satellites, 7);
  std::vector<const DdRow*> code_rows, phase_rows;
  for (const DdRow& r : p.code) code_rows.push_back(&r);
  for (const DdRow& r : p.phase) phase_rows.push_back(&r);
  Eigen::VectorXd v_code(static_cast<Eigen::Index>(p.code.size()));
  Eigen::VectorXd v_phase(static_cast<Eigen::Index>(p.phase.size()));
  for (std::size_t a = 0; a < p.code.size(); ++a) v_code[static_cast<Eigen::Index>(a)] = p.code[a].innovation_m;
  for (std::size_t a = 0; a < p.phase.size(); ++a) v_phase[static_cast<Eigen::Index>(a)] = p.phase[a].innovation_m;
  for (auto _ : state) {
    Eigen::MatrixXd P = p.P;
    auto code = canyon::rtk::compressed_update(P, code_rows, v_code, p.R_code);
    auto phase = canyon::rtk::dense_update(P, *code, phase_rows, v_phase, p.R_phase);
    Eigen::MatrixXd U(P.rows(), code->U.cols() + phase->U.cols());
    Eigen::MatrixXd V(P.rows(), U.cols());
    U << code->U, phase->U;
    V << code->V, phase->V;
    canyon::rtk::subtract_symmetric_product(P, U, V);
    benchmark::DoNotOptimize(P.data());
  }
}
BENCHMARK(BM_KalmanUpdate)->Args({25, 8})->Args({45, 12})->Args({70, 18})->Unit(benchmark::kMicrosecond);

}  // namespace
