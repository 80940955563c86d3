// Live dashboard server (see dashboard.hpp).

#include "canyon/dashboard/dashboard.hpp"

#include <chrono>
#include <filesystem>
#include <sstream>

#include <httplib.h>
#include <nlohmann/json.hpp>
#include <sys/socket.h>

namespace canyon::dashboard {
namespace {

using Json = nlohmann::json;

std::string label_value(const std::string& s) {
  std::string out;
  for (const char c : s) {
    if (c == '\\' || c == '"') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else {
      out += c;
    }
  }
  return out;
}

std::string number(double v) {
  std::ostringstream out;
  out.precision(10);
  out << v;
  return out.str();
}

/// Writes `name{labels} value` when `j` holds a number.
void sample(std::ostringstream& out, const std::string& name, const std::string& labels, const Json& j) {
  if (!j.is_number()) return;
  out << name;
  if (!labels.empty()) out << "{" << labels << "}";
  out << " " << number(j.get<double>()) << "\n";
}

void header(std::ostringstream& out, const std::string& name, const std::string& type, const std::string& help) {
  out << "# HELP " << name << " " << help << "\n# TYPE " << name << " " << type << "\n";
}

void percentiles(std::ostringstream& out, const std::string& name, const std::string& labels, const Json& p) {
  if (!p.is_object()) return;
  const std::string sep = labels.empty() ? "" : ",";
  for (const auto& [key, q] : {std::pair{"p50_us", "0.5"}, std::pair{"p95_us", "0.95"}, std::pair{"p99_us", "0.99"},
                               std::pair{"max_us", "1"}}) {
    if (p.contains(key)) sample(out, name, labels + sep + "quantile=\"" + q + "\"", p[key]);
  }
}

const char* kNoBundle =
    "<!doctype html><title>canyon dashboard</title><h1>canyon dashboard</h1><p>The web bundle is not built: "
    "<code>cmake --build build --target canyon_web</code> (needs node and npm, scripts/setup.sh). The data is live at "
    "<a href=\"/events\">/events</a>, <a href=\"/api/snapshot\">/api/snapshot</a> and <a "
    "href=\"/metrics\">/metrics</a>.";

}  // namespace

Result<std::string> parse_snapshot(const std::string& line) {
  Json j = Json::parse(line, nullptr, false);
  if (j.is_discarded()) return Error{"not JSON: '" + line.substr(0, 80) + "'"};
  if (!j.is_object()) return Error{"not a JSON object: '" + line.substr(0, 80) + "'"};
  if (!j.contains("t_s") || !j["t_s"].is_number()) return Error{"no number 't_s' in the snapshot"};
  for (const char* key : {"stages", "end_to_end", "queues", "drops", "solution", "alignment"}) {
    if (!j.contains(key)) continue;
    if (j[key].is_null()) {
      j.erase(key);  // canyon monitor writes null before the first solution and without alignment (rtk mode)
    } else if (!j[key].is_object()) {
      return Error{std::string("'") + key + "' is not an object"};
    }
  }
  return j.dump();
}

std::string prometheus_text(const std::string& snapshot_json, std::uint64_t snapshots, std::uint64_t bad_lines) {
  std::ostringstream out;
  header(out, "canyon_dashboard_snapshots_total", "counter", "Monitor snapshots received by the dashboard.");
  out << "canyon_dashboard_snapshots_total " << snapshots << "\n";
  header(out, "canyon_dashboard_bad_lines_total", "counter", "Input lines that were not a snapshot.");
  out << "canyon_dashboard_bad_lines_total " << bad_lines << "\n";
  const Json j = Json::parse(snapshot_json, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return out.str();

  header(out, "canyon_snapshot_time_seconds", "gauge", "Monitor time of the newest snapshot.");
  sample(out, "canyon_snapshot_time_seconds", "", j.value("t_s", Json()));
  if (j.contains("stages") && j["stages"].is_object()) {
    header(out, "canyon_stage_latency_us", "gauge", "Stage latency percentiles in microseconds (quantile 1: max).");
    for (const auto& [stage, p] : j["stages"].items()) {
      percentiles(out, "canyon_stage_latency_us", "stage=\"" + label_value(stage) + "\"", p);
    }
    header(out, "canyon_stage_messages_total", "counter", "Messages timed per stage.");
    for (const auto& [stage, p] : j["stages"].items()) {
      if (p.is_object())
        sample(out, "canyon_stage_messages_total", "stage=\"" + label_value(stage) + "\"", p.value("count", Json()));
    }
  }
  if (j.contains("end_to_end")) {
    header(out, "canyon_end_to_end_latency_us", "gauge", "End-to-end latency percentiles in microseconds.");
    percentiles(out, "canyon_end_to_end_latency_us", "", j["end_to_end"]);
  }
  if (j.contains("correction_age_s")) {
    header(out, "canyon_correction_age_seconds", "gauge", "Age of the newest base correction.");
    sample(out, "canyon_correction_age_seconds", "", j["correction_age_s"]);
  }
  if (j.contains("queues") && j["queues"].is_object()) {
    header(out, "canyon_queue_depth", "gauge", "Messages waiting in each stage queue.");
    for (const auto& [q, v] : j["queues"].items())
      sample(out, "canyon_queue_depth", "queue=\"" + label_value(q) + "\"", v);
  }
  if (j.contains("drops") && j["drops"].is_object()) {
    header(out, "canyon_drops_total", "counter", "Dropped messages (and link losses) by cause.");
    for (const auto& [d, v] : j["drops"].items())
      sample(out, "canyon_drops_total", "name=\"" + label_value(d) + "\"", v);
  }
  if (j.contains("solution") && j["solution"].is_object()) {
    const Json& s = j["solution"];
    header(out, "canyon_solution_status", "gauge",
           "Solution status (1 fixed, 2 float, 5 single, 7 VIO fill-in, 8 partial fix).");
    sample(out, "canyon_solution_status", "", s.value("status", Json()));
    header(out, "canyon_solution_sequence", "counter", "Sequence number of the newest solution.");
    sample(out, "canyon_solution_sequence", "", s.value("seq", Json()));
    header(out, "canyon_solution_satellites", "gauge", "Satellites used in the newest solution.");
    sample(out, "canyon_solution_satellites", "", s.value("n_sats", Json()));
    header(out, "canyon_solution_pruned_satellites", "gauge", "Satellites pruned from the newest solution.");
    if (s.contains("pruned") && s["pruned"].is_array()) {
      out << "canyon_solution_pruned_satellites " << s["pruned"].size() << "\n";
    }
    header(out, "canyon_solution_ratio", "gauge", "Ambiguity ratio test value of the newest solution.");
    sample(out, "canyon_solution_ratio", "", s.value("ratio", Json()));
    header(out, "canyon_solution_hpl_m", "gauge", "Horizontal protection level of the newest solution (6 sigma).");
    sample(out, "canyon_solution_hpl_m", "", s.value("hpl_m", Json()));
    header(out, "canyon_solution_vpl_m", "gauge", "Vertical protection level of the newest solution (6 sigma).");
    sample(out, "canyon_solution_vpl_m", "", s.value("vpl_m", Json()));
    header(out, "canyon_solution_height_m", "gauge", "Ellipsoidal height of the newest solution.");
    sample(out, "canyon_solution_height_m", "", s.value("height_m", Json()));
  }
  if (j.contains("alignment") && j["alignment"].is_object()) {
    const Json& a = j["alignment"];
    header(out, "canyon_alignment_rmse_m", "gauge", "RMSE of the VIO-to-ECEF alignment.");
    sample(out, "canyon_alignment_rmse_m", "", a.value("rmse_m", Json()));
    header(out, "canyon_alignment_eigen_ratio", "gauge", "Eigenvalue ratio of the alignment (observability).");
    sample(out, "canyon_alignment_eigen_ratio", "", a.value("eigen_ratio", Json()));
    if (a.contains("lever_arm_m") && a["lever_arm_m"].is_array() && a["lever_arm_m"].size() == 3) {
      header(out, "canyon_lever_arm_m", "gauge", "Calibrated lever arm t_IA (antenna in the IMU frame).");
      const char* axes[] = {"x", "y", "z"};
      for (std::size_t i = 0; i < 3; ++i) {
        sample(out, "canyon_lever_arm_m", std::string("axis=\"") + axes[i] + "\"", a["lever_arm_m"][i]);
      }
    }
  }
  return out.str();
}

std::string ServerOptions::validate() const {
  if (port < 0 || port > 65535) return "port must be in [0, 65535] (is " + std::to_string(port) + ")";
  if (history == 0 || history > 100000) return "history must be in [1, 100000] (is " + std::to_string(history) + ")";
  if (!web_dir.empty() && !std::filesystem::is_directory(web_dir)) return "web folder '" + web_dir + "' does not exist";
  return {};
}

DashboardServer::DashboardServer(const ServerOptions& options)
    : options_(options), http_(std::make_unique<httplib::Server>()) {}

Result<std::unique_ptr<DashboardServer>> DashboardServer::start(const ServerOptions& options) {
  if (const std::string e = options.validate(); !e.empty()) return Error{"dashboard: " + e};
  std::unique_ptr<DashboardServer> s(new DashboardServer(options));
  s->routes();
  // SO_REUSEADDR only: httplib's default also sets SO_REUSEPORT, with which a second dashboard on the same port
  // would silently share it instead of failing.
  s->http_->set_socket_options([](int sock) {
    const int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  const int port = options.port == 0 ? s->http_->bind_to_any_port(options.host)
                                     : (s->http_->bind_to_port(options.host, options.port) ? options.port : -1);
  if (port <= 0) {
    return Error{"dashboard: cannot listen on " + options.host + ":" + std::to_string(options.port) +
                 " (address in use or not local?)"};
  }
  s->port_ = port;
  DashboardServer* raw = s.get();
  s->thread_ = std::thread([raw] { raw->http_->listen_after_bind(); });
  // Running before returning: a stop() that came before the accept loop started would be missed (and join hang).
  for (int i = 0; i < 500 && !s->http_->is_running(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  return s;
}

DashboardServer::~DashboardServer() {
  stop();
}

void DashboardServer::stop() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  if (http_) http_->stop();
  if (thread_.joinable()) thread_.join();
}

std::uint64_t DashboardServer::snapshots() const {
  const std::lock_guard lock(mutex_);
  return snapshots_;
}

std::uint64_t DashboardServer::bad_lines() const {
  const std::lock_guard lock(mutex_);
  return bad_lines_;
}

Status DashboardServer::push(const std::string& line) {
  auto snapshot = parse_snapshot(line);
  {
    const std::lock_guard lock(mutex_);
    if (!snapshot) {
      ++bad_lines_;
      return snapshot.error();
    }
    history_.push_back(std::move(*snapshot));
    while (history_.size() > options_.history) history_.pop_front();
    ++snapshots_;
  }
  changed_.notify_all();
  return Ok{};
}

void DashboardServer::routes() {
  httplib::Server& http = *http_;
  http.Get("/healthz", [](const httplib::Request&, httplib::Response& res) { res.set_content("ok\n", "text/plain"); });
  http.Get("/api/snapshot", [this](const httplib::Request&, httplib::Response& res) {
    const std::lock_guard lock(mutex_);
    if (history_.empty()) {
      res.status = 204;
      return;
    }
    res.set_content(history_.back(), "application/json");
  });
  http.Get("/metrics", [this](const httplib::Request&, httplib::Response& res) {
    std::string newest;
    std::uint64_t n = 0;
    std::uint64_t bad = 0;
    {
      const std::lock_guard lock(mutex_);
      if (!history_.empty()) newest = history_.back();
      n = snapshots_;
      bad = bad_lines_;
    }
    res.set_content(prometheus_text(newest, n, bad), "text/plain; version=0.0.4; charset=utf-8");
  });
  http.Get("/events", [this](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-cache");
    res.set_header("X-Accel-Buffering", "no");
    auto sent = std::make_shared<std::uint64_t>(0);
    auto started = std::make_shared<bool>(false);
    res.set_chunked_content_provider("text/event-stream", [this, sent, started](std::size_t, httplib::DataSink& sink) {
      std::string chunk;
      {
        std::unique_lock lock(mutex_);
        if (!*started) {
          *started = true;
          chunk = "retry: 1000\nevent: history\ndata: [";
          for (std::size_t i = 0; i < history_.size(); ++i) chunk += (i > 0 ? "," : "") + history_[i];
          chunk += "]\n\n";
          *sent = snapshots_;
        } else {
          changed_.wait_for(lock, std::chrono::seconds(5), [&] { return stopping_ || snapshots_ > *sent; });
          if (stopping_) return false;
          const std::uint64_t fresh = std::min<std::uint64_t>(snapshots_ - *sent, history_.size());
          for (std::size_t i = history_.size() - fresh; i < history_.size(); ++i) {
            chunk += "data: " + history_[i] + "\n\n";
          }
          *sent = snapshots_;
          if (chunk.empty()) chunk = ": keep-alive\n\n";
        }
      }
      return sink.write(chunk.data(), chunk.size());
    });
  });
  if (!options_.web_dir.empty() && std::filesystem::exists(std::filesystem::path(options_.web_dir) / "index.html")) {
    http.set_mount_point("/", options_.web_dir);
  } else {
    http.Get("/", [](const httplib::Request&, httplib::Response& res) { res.set_content(kNoBundle, "text/html"); });
  }
}

std::string find_web_dir(const std::string& compiled_dist_dir) {
  std::error_code ec;
  const auto self = std::filesystem::canonical("/proc/self/exe", ec);
  if (!ec) {
    for (const auto& dir :
         {self.parent_path() / "web" / "dist", self.parent_path() / ".." / "share" / "canyon" / "web"}) {
      if (std::filesystem::exists(dir / "index.html", ec)) return dir.string();
    }
  }
  if (!compiled_dist_dir.empty() &&
      std::filesystem::exists(std::filesystem::path(compiled_dist_dir) / "index.html", ec))
    return compiled_dist_dir;
  return {};
}

}  // namespace canyon::dashboard
