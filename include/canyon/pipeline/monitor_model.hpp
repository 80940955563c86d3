#pragma once
// The figures `canyon monitor` shows, aggregated from the rover's StageTiming and Solution samples; no DDS here, so
// any front end (the terminal monitor, a web dashboard) can feed it and render it.
//
// JSON line schema (json_line(); one object per line, every number finite or null):
//   {"t_s": seconds since the model was created (monitor's monotonic clock),
//    "epochs": timing samples received, "solutions": solution samples received,
//    "rovers": rovers seen, "lost_solutions": gaps in the solutions' sequence numbers (per rover, summed),
//    "lost_timing": gaps in the timing's,
//    "stages": {"ingest"|"time_bridge"|"alignment"|"prediction"|"update"|"ambiguity":
//               {"p50_us","p95_us","p99_us","max_us","count"}},   // time in the stage (exit - enter)
//    "end_to_end": {same},        // in the rover: arrival at ingest -> exit of the ambiguity stage
//    "delivery": {same},          // arrival at ingest -> solution received here (needs one host: monotonic clock)
//    "base_to_solution": {same},  // base's send of the epoch's last RTCM frame -> solution received here (DDS base)
//    "correction_age_s": latest rover - base epoch time (null: no base),
//    "queues": {"ingest>time_bridge"|...: depth}, "queue_full_waits": {same: count},
//    "drops": {"vio": count, "vio_late": count, "base_late": count, "malformed": DDS samples refused,
//              "solutions": lost solutions},
//    "links": {"rover": LINK, "base": LINK}, LINK = {"dropped_bytes", "failures", "bad_frames", "undecodable"}
//              (the receiver's and the correction stream's losses so far; zeros for files),
//    "solution": {"seq","status","lat_deg","lon_deg","height_m","n_sats","pruned":["G05",...],"ratio","hpl_m","vpl_m"}
//    or null, "alignment": {"rmse_m","eigen_ratio","lever_arm_m":[x,y,z]} or null}
// Percentiles are over the last `window` samples (nearest rank).

#include <array>
#include <cstdint>
#include <deque>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/pipeline/link_counts.hpp"

namespace canyon::pipeline {

inline constexpr std::size_t kMonitorStages = 6;
inline constexpr std::size_t kMonitorQueues = 5;

/// One StageTiming sample (all times monotonic ns on the one host).
struct TimingSample {
  std::string rover_id;
  std::uint64_t seq = 0;
  std::int64_t arrival_ns = 0;
  std::array<std::int64_t, kMonitorStages> enter_ns{};
  std::array<std::int64_t, kMonitorStages> exit_ns{};
  double correction_age_s = 0.0;  ///< NaN: no base
  std::array<std::uint32_t, kMonitorQueues> queue_depth{};
  std::array<std::uint64_t, kMonitorQueues> queue_full_waits{};
  std::uint64_t vio_dropped = 0;  ///< VIO poses and pairs dropped (rover queue full)
  std::uint64_t vio_late = 0;     ///< epochs that went on without their VIO
  std::uint64_t base_late = 0;
  std::uint64_t malformed_samples = 0;  ///< DDS samples the rover refused as malformed
  LinkCounts rover_link;                ///< the receiver's stream's losses so far
  LinkCounts base_link;                 ///< the correction stream's losses so far
  double alignment_rmse_m = 0.0;        ///< NaN: not aligned
  double alignment_eigen_ratio = 0.0;
  Eigen::Vector3d lever_arm_m = Eigen::Vector3d::Zero();
};

/// One Solution sample.
struct SolutionSample {
  std::string rover_id;  ///< sequence numbers are per rover: several rovers may publish on one topic
  std::uint64_t seq = 0;
  int status = 0;
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  double height_m = 0.0;
  int n_sats = 0;
  double ratio = 0.0;
  double hpl_m = std::numeric_limits<double>::quiet_NaN();  ///< horizontal protection level (NaN: none)
  double vpl_m = std::numeric_limits<double>::quiet_NaN();  ///< vertical protection level (NaN: none)
  std::vector<std::string> pruned;
  std::int64_t arrival_ns = 0;    ///< rover arrival at ingest
  std::int64_t base_send_ns = 0;  ///< 0: none
  std::int64_t received_ns = 0;   ///< at the monitor
};

struct Percentiles {
  double p50_us = 0.0, p95_us = 0.0, p99_us = 0.0, max_us = 0.0;
  std::size_t count = 0;
};

/// Latencies in microseconds over a sliding window.
class LatencyWindow {
 public:
  explicit LatencyWindow(std::size_t window = 20000) : window_(window) {}
  void add(double us);
  [[nodiscard]] Percentiles percentiles() const;
  [[nodiscard]] std::size_t total() const { return total_; }

 private:
  std::size_t window_;
  std::deque<double> values_;
  std::size_t total_ = 0;
};

class MonitorModel {
 public:
  explicit MonitorModel(std::int64_t start_ns, std::size_t window = 20000);
  void add_timing(const TimingSample& sample);
  void add_solution(const SolutionSample& sample);

  /// One JSON object (no newline), schema above; `now_ns` on the monitor's monotonic clock.
  [[nodiscard]] std::string json_line(std::int64_t now_ns) const;
  /// A terminal page (lines).
  [[nodiscard]] std::vector<std::string> text(std::int64_t now_ns) const;

  [[nodiscard]] const LatencyWindow& stage(std::size_t i) const { return stages_.at(i); }
  [[nodiscard]] const LatencyWindow& end_to_end() const { return end_to_end_; }
  [[nodiscard]] const LatencyWindow& delivery() const { return delivery_; }
  [[nodiscard]] const LatencyWindow& base_to_solution() const { return base_to_solution_; }
  [[nodiscard]] std::uint64_t lost_solutions() const { return lost_solutions_; }
  [[nodiscard]] std::uint64_t solutions() const { return solutions_; }

 private:
  std::int64_t start_ns_;
  std::array<LatencyWindow, kMonitorStages> stages_;
  LatencyWindow end_to_end_, delivery_, base_to_solution_;
  std::optional<TimingSample> last_timing_;
  std::optional<SolutionSample> last_solution_;
  std::map<std::string, std::uint64_t> next_solution_seq_, next_timing_seq_;  // per rover
  std::uint64_t timings_ = 0, solutions_ = 0, lost_solutions_ = 0, lost_timing_ = 0;
};

}  // namespace canyon::pipeline
