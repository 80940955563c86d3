#pragma once
// The live dashboard of canyon (no DDS): monitor snapshots in, a web page with live charts, server-sent events and a
// Prometheus text endpoint out. `canyon monitor --http PORT` (issue 7) and `canyon-dashboard` (JSON lines from a file
// or stdin) feed it through DashboardServer::push.
//
// Snapshot: one JSON object per line (fields optional except t_s; unknown fields are kept and passed on):
//   {"t_s": s, "stages": {NAME: {"p50_us","p95_us","p99_us","max_us","count"}}, "end_to_end": {same},
//    "correction_age_s": s, "queues": {NAME: depth}, "drops": {NAME: count},
//    "solution": {"seq","status","lat_deg","lon_deg","height_m","n_sats","pruned":[...],"ratio","hpl_m","vpl_m"},
//    "alignment": {"rmse_m","eigen_ratio","lever_arm_m":[x,y,z]}}
// status: 1 fixed, 2 float, 5 single, 7 VIO fill-in (DESIGN.md).
//
// HTTP: GET / and static files from the web folder (the bundled page), GET /events (text/event-stream: an event
// "history" with the kept snapshots as a JSON array, then one message per snapshot, a comment every 5 s to keep the
// connection open), GET /api/snapshot (the newest), GET /metrics (Prometheus text format 0.0.4), GET /healthz.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "canyon/core/result.hpp"

namespace httplib {
class Server;
}

namespace canyon::dashboard {

/// The snapshot of one line as compact JSON; an error names what is wrong ("not JSON: ...", "no number 't_s'").
Result<std::string> parse_snapshot(const std::string& line);

/// Prometheus text exposition of a snapshot (compact JSON from parse_snapshot) and the server's own counters.
std::string prometheus_text(const std::string& snapshot_json, std::uint64_t snapshots, std::uint64_t bad_lines);

/// The bundled page's folder: web/dist next to the running executable, ../share/canyon/web, or `compiled_dist_dir`
/// (the build tree's, given at compile time), the first holding index.html; empty when none does.
std::string find_web_dir(const std::string& compiled_dist_dir);

struct ServerOptions {
  std::string host = "127.0.0.1";  ///< address to listen on ("0.0.0.0": every interface)
  int port = 8080;                 ///< TCP port; 0: any free port (see DashboardServer::port)
  std::string web_dir;             ///< folder of index.html and the bundle; empty: a page saying it is not built
  std::size_t history = 600;       ///< snapshots kept and sent to a new browser
  [[nodiscard]] std::string validate() const;
};

class DashboardServer {
 public:
  /// Listens (in a background thread) or fails naming the address.
  static Result<std::unique_ptr<DashboardServer>> start(const ServerOptions& options);
  ~DashboardServer();
  DashboardServer(const DashboardServer&) = delete;
  DashboardServer& operator=(const DashboardServer&) = delete;

  /// One JSON line; a bad line is counted and its error returned, the server carries on.
  Status push(const std::string& line);
  [[nodiscard]] int port() const { return port_; }
  [[nodiscard]] std::uint64_t snapshots() const;
  [[nodiscard]] std::uint64_t bad_lines() const;
  /// Stops listening and ends every event stream.
  void stop();

 private:
  explicit DashboardServer(const ServerOptions& options);
  void routes();
  ServerOptions options_;
  std::unique_ptr<httplib::Server> http_;
  std::thread thread_;
  int port_ = 0;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::string> history_;
  std::uint64_t snapshots_ = 0;
  std::uint64_t bad_lines_ = 0;
  bool stopping_ = false;
};

}  // namespace canyon::dashboard
