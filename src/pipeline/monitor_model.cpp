// Monitor figures (see monitor_model.hpp).

#include "canyon/pipeline/monitor_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace canyon::pipeline {
namespace {

constexpr std::array<const char*, kMonitorStages> kStageNames = {"ingest",     "time_bridge", "alignment",
                                                                 "prediction", "update",      "ambiguity"};
constexpr std::array<const char*, kMonitorQueues> kQueueNames = {
    "ingest>time_bridge", "time_bridge>alignment", "alignment>prediction", "prediction>update", "update>ambiguity"};

std::string number(double v, const char* fmt = "%.3f") {
  if (!std::isfinite(v)) return "null";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, fmt, v);
  return buffer;
}

std::string percentiles_json(const Percentiles& p) {
  return "{\"p50_us\":" + number(p.p50_us, "%.1f") + ",\"p95_us\":" + number(p.p95_us, "%.1f") +
         ",\"p99_us\":" + number(p.p99_us, "%.1f") + ",\"max_us\":" + number(p.max_us, "%.1f") +
         ",\"count\":" + std::to_string(p.count) + "}";
}

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) >= 0x20) out += c;
  }
  return out + "\"";
}

std::string percentiles_text(const char* name, const Percentiles& p) {
  char line[160];
  std::snprintf(line, sizeof line, "  %-18s p50 %9.1f  p95 %9.1f  p99 %9.1f  max %9.1f us  (%zu)", name, p.p50_us,
                p.p95_us, p.p99_us, p.max_us, p.count);
  return line;
}

}  // namespace

void LatencyWindow::add(double us) {
  if (!std::isfinite(us)) return;
  values_.push_back(us);
  if (values_.size() > window_) values_.pop_front();
  ++total_;
}

Percentiles LatencyWindow::percentiles() const {
  Percentiles p;
  p.count = values_.size();
  if (values_.empty()) return p;
  std::vector<double> sorted(values_.begin(), values_.end());
  std::sort(sorted.begin(), sorted.end());
  const auto rank = [&sorted](double q) {
    const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(sorted.size())));
    return sorted[std::min(sorted.size(), std::max<std::size_t>(k, 1)) - 1];
  };
  p.p50_us = rank(0.50);
  p.p95_us = rank(0.95);
  p.p99_us = rank(0.99);
  p.max_us = sorted.back();
  return p;
}

MonitorModel::MonitorModel(std::int64_t start_ns, std::size_t window)
    : start_ns_(start_ns),
      stages_{LatencyWindow(window), LatencyWindow(window), LatencyWindow(window),
              LatencyWindow(window), LatencyWindow(window), LatencyWindow(window)},
      end_to_end_(window),
      delivery_(window),
      base_to_solution_(window) {}

void MonitorModel::add_timing(const TimingSample& sample) {
  auto [next, fresh] = next_timing_seq_.try_emplace(sample.rover_id, sample.seq);
  if (!fresh && sample.seq > next->second) lost_timing_ += sample.seq - next->second;
  next->second = sample.seq + 1;
  ++timings_;
  for (std::size_t i = 0; i < kMonitorStages; ++i) {
    stages_[i].add(static_cast<double>(sample.exit_ns[i] - sample.enter_ns[i]) * 1e-3);
  }
  end_to_end_.add(static_cast<double>(sample.exit_ns[kMonitorStages - 1] - sample.arrival_ns) * 1e-3);
  last_timing_ = sample;
}

void MonitorModel::add_solution(const SolutionSample& sample) {
  auto [next, fresh] = next_solution_seq_.try_emplace(sample.rover_id, sample.seq);
  if (!fresh && sample.seq > next->second) lost_solutions_ += sample.seq - next->second;
  next->second = sample.seq + 1;
  ++solutions_;
  if (sample.received_ns > 0 && sample.arrival_ns > 0) {
    delivery_.add(static_cast<double>(sample.received_ns - sample.arrival_ns) * 1e-3);
  }
  if (sample.received_ns > 0 && sample.base_send_ns > 0) {
    base_to_solution_.add(static_cast<double>(sample.received_ns - sample.base_send_ns) * 1e-3);
  }
  last_solution_ = sample;
}

std::string MonitorModel::json_line(std::int64_t now_ns) const {
  std::string j = "{\"t_s\":" + number(static_cast<double>(now_ns - start_ns_) * 1e-9);
  j += ",\"epochs\":" + std::to_string(timings_) + ",\"solutions\":" + std::to_string(solutions_);
  j += ",\"rovers\":" + std::to_string(next_solution_seq_.size());
  j += ",\"lost_solutions\":" + std::to_string(lost_solutions_) + ",\"lost_timing\":" + std::to_string(lost_timing_);
  j += ",\"stages\":{";
  for (std::size_t i = 0; i < kMonitorStages; ++i) {
    if (i > 0) j += ',';
    j += std::string("\"") + kStageNames[i] + "\":" + percentiles_json(stages_[i].percentiles());
  }
  j += "},\"end_to_end\":" + percentiles_json(end_to_end_.percentiles());
  j += ",\"delivery\":" + percentiles_json(delivery_.percentiles());
  j += ",\"base_to_solution\":" + percentiles_json(base_to_solution_.percentiles());
  const TimingSample* t = last_timing_ ? &*last_timing_ : nullptr;
  j += ",\"correction_age_s\":" + (t != nullptr ? number(t->correction_age_s) : std::string("null"));
  j += ",\"queues\":{";
  for (std::size_t i = 0; i < kMonitorQueues; ++i) {
    if (i > 0) j += ',';
    j += std::string("\"") + kQueueNames[i] + "\":" + std::to_string(t != nullptr ? t->queue_depth[i] : 0);
  }
  j += "},\"queue_full_waits\":{";
  for (std::size_t i = 0; i < kMonitorQueues; ++i) {
    if (i > 0) j += ',';
    j += std::string("\"") + kQueueNames[i] + "\":" + std::to_string(t != nullptr ? t->queue_full_waits[i] : 0);
  }
  j += "},\"drops\":{\"vio\":" + std::to_string(t != nullptr ? t->vio_dropped : 0) +
       ",\"vio_late\":" + std::to_string(t != nullptr ? t->vio_late : 0) +
       ",\"base_late\":" + std::to_string(t != nullptr ? t->base_late : 0) +
       ",\"malformed\":" + std::to_string(t != nullptr ? t->malformed_samples : 0) +
       ",\"solutions\":" + std::to_string(lost_solutions_) + "}";
  const auto link = [](const LinkCounts& c) {
    return "{\"dropped_bytes\":" + std::to_string(c.dropped_bytes) +
           ",\"failures\":" + std::to_string(c.link_failures) + ",\"bad_frames\":" + std::to_string(c.bad_frames) +
           ",\"undecodable\":" + std::to_string(c.undecodable) + "}";
  };
  j += ",\"links\":{\"rover\":" + link(t != nullptr ? t->rover_link : LinkCounts{}) +
       ",\"base\":" + link(t != nullptr ? t->base_link : LinkCounts{}) + "}";
  if (last_solution_) {
    const SolutionSample& s = *last_solution_;
    j += ",\"solution\":{\"seq\":" + std::to_string(s.seq) + ",\"status\":" + std::to_string(s.status) +
         ",\"lat_deg\":" + number(s.lat_deg, "%.9f") + ",\"lon_deg\":" + number(s.lon_deg, "%.9f") +
         ",\"height_m\":" + number(s.height_m, "%.4f") + ",\"n_sats\":" + std::to_string(s.n_sats) + ",\"pruned\":[";
    for (std::size_t i = 0; i < s.pruned.size(); ++i) j += (i > 0 ? "," : "") + quoted(s.pruned[i]);
    j += "],\"ratio\":" + number(s.ratio, "%.2f") + ",\"hpl_m\":" + number(s.hpl_m, "%.3f") +
         ",\"vpl_m\":" + number(s.vpl_m, "%.3f") + "}";
  } else {
    j += ",\"solution\":null";
  }
  if (t != nullptr && std::isfinite(t->alignment_rmse_m)) {
    j += ",\"alignment\":{\"rmse_m\":" + number(t->alignment_rmse_m, "%.4f") +
         ",\"eigen_ratio\":" + number(t->alignment_eigen_ratio, "%.4f") + ",\"lever_arm_m\":[" +
         number(t->lever_arm_m.x(), "%.4f") + "," + number(t->lever_arm_m.y(), "%.4f") + "," +
         number(t->lever_arm_m.z(), "%.4f") + "]}";
  } else {
    j += ",\"alignment\":null";
  }
  return j + "}";
}

std::vector<std::string> MonitorModel::text(std::int64_t now_ns) const {
  std::vector<std::string> lines;
  char line[256];
  std::snprintf(line, sizeof line, "canyon monitor  t %.1f s  epochs %llu  solutions %llu  lost %llu",
                static_cast<double>(now_ns - start_ns_) * 1e-9, static_cast<unsigned long long>(timings_),
                static_cast<unsigned long long>(solutions_), static_cast<unsigned long long>(lost_solutions_));
  lines.emplace_back(line);
  lines.emplace_back("latency (time in stage; end to end in the rover; delivery and base to solution here)");
  for (std::size_t i = 0; i < kMonitorStages; ++i) {
    lines.push_back(percentiles_text(kStageNames[i], stages_[i].percentiles()));
  }
  lines.push_back(percentiles_text("end_to_end", end_to_end_.percentiles()));
  lines.push_back(percentiles_text("delivery", delivery_.percentiles()));
  lines.push_back(percentiles_text("base_to_solution", base_to_solution_.percentiles()));
  if (last_timing_) {
    const TimingSample& t = *last_timing_;
    std::string q = "queues";
    for (std::size_t i = 0; i < kMonitorQueues; ++i) {
      q += std::string("  ") + kQueueNames[i] + " " + std::to_string(t.queue_depth[i]);
    }
    lines.push_back(q);
    std::snprintf(line, sizeof line,
                  "correction age %s s  drops: vio %llu, vio late %llu, base late %llu, malformed %llu",
                  number(t.correction_age_s, "%.2f").c_str(), static_cast<unsigned long long>(t.vio_dropped),
                  static_cast<unsigned long long>(t.vio_late), static_cast<unsigned long long>(t.base_late),
                  static_cast<unsigned long long>(t.malformed_samples));
    lines.emplace_back(line);
    const auto link = [](const char* name, const LinkCounts& c) {
      return std::string(name) + " dropped " + std::to_string(c.dropped_bytes) + " B, " +
             std::to_string(c.link_failures) + " failed connections, " + std::to_string(c.bad_frames) + " bad, " +
             std::to_string(c.undecodable) + " undecodable";
    };
    lines.push_back("links: " + link("rover", t.rover_link) + "; " + link("base", t.base_link));
    if (std::isfinite(t.alignment_rmse_m)) {
      std::snprintf(line, sizeof line, "alignment RMSE %.3f m  FER %.3f  lever arm [%.3f %.3f %.3f] m",
                    t.alignment_rmse_m, t.alignment_eigen_ratio, t.lever_arm_m.x(), t.lever_arm_m.y(),
                    t.lever_arm_m.z());
      lines.emplace_back(line);
    }
  }
  if (last_solution_) {
    const SolutionSample& s = *last_solution_;
    std::string pruned;
    for (const std::string& p : s.pruned) pruned += " " + p;
    std::snprintf(line, sizeof line,
                  "solution #%llu  Q %d  %.8f %.8f %.3f m  %d sats  ratio %.1f  HPL %.2f VPL %.2f m  pruned:%s",
                  static_cast<unsigned long long>(s.seq), s.status, s.lat_deg, s.lon_deg, s.height_m, s.n_sats, s.ratio,
                  s.hpl_m, s.vpl_m, pruned.empty() ? " -" : pruned.c_str());
    lines.emplace_back(line);
  }
  return lines;
}

}  // namespace canyon::pipeline
