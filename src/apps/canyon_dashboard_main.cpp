// canyon-dashboard: serves the live dashboard (web page, server-sent events, Prometheus /metrics) of monitor
// snapshots read as JSON lines from a file or standard input (dashboard/dashboard.hpp has the schema). Until
// `canyon monitor --http PORT` exists it is fed by `canyon monitor --json`, canyon-rtcm-probe --json-lines, or any
// producer. Bad lines are counted and reported (the first 5 in full), never fatal.
// Exit codes: 0 stopped (signal, or the end of the input with --exit-at-eof), 1 runtime failure, 2 bad command line.

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <iostream>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include "canyon/dashboard/dashboard.hpp"

#include "main_guard.hpp"

namespace {

constexpr int kExitRuntime = 1;
constexpr int kExitUsage = 2;

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int /*signal*/) {
  g_stop.store(true);
}

#ifndef CANYON_WEB_DIST_DIR
#define CANYON_WEB_DIST_DIR ""
#endif

int run(int argc, char** argv) {
  CLI::App cli{"canyon-dashboard: live web dashboard and Prometheus /metrics of canyon monitor snapshots (JSON lines)"};
  canyon::dashboard::ServerOptions options;
  std::string input = "-";
  bool follow = false;
  bool exit_at_eof = false;
  cli.add_option("--port", options.port, "TCP port (0: any free port, printed)")->check(CLI::Range(0, 65535));
  cli.add_option("--host", options.host, "address to listen on (0.0.0.0: every interface)");
  cli.add_option("--web", options.web_dir, "folder of the bundled page (default: build/web/dist)");
  cli.add_option("--history", options.history, "snapshots kept for a new browser")->check(CLI::Range(1, 100000));
  cli.add_option("--input", input, "JSON lines file, '-' for standard input");
  cli.add_flag("--follow", follow, "keep reading a file as it grows (like tail -f)");
  cli.add_flag("--exit-at-eof", exit_at_eof, "stop at the end of the input (default: keep serving)");
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : kExitUsage;
  }
  if (options.web_dir.empty()) options.web_dir = canyon::dashboard::find_web_dir(CANYON_WEB_DIST_DIR);
  int fd = STDIN_FILENO;
  if (input != "-") {
    fd = ::open(input.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
      std::cerr << "canyon-dashboard: cannot open " << input << ": " << std::strerror(errno) << "\n";
      return kExitUsage;
    }
  }
  auto server = canyon::dashboard::DashboardServer::start(options);
  if (!server) {
    std::cerr << "canyon-dashboard: " << server.error().to_string() << "\n";
    if (fd != STDIN_FILENO) ::close(fd);
    return options.validate().empty() ? kExitRuntime : kExitUsage;
  }
  std::cerr << "canyon-dashboard: http://" << options.host << ":" << (*server)->port()
            << "/ (web: " << (options.web_dir.empty() ? std::string("not built") : options.web_dir) << ")" << std::endl;
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGPIPE, SIG_IGN);

  std::string pending;
  char buffer[65536];
  bool eof = false;
  std::uint64_t reported = 0;
  while (!g_stop.load()) {
    if (eof) {
      if (exit_at_eof) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      if (!follow) continue;
    }
    pollfd pfd{fd, POLLIN, 0};
    const int ready = ::poll(&pfd, 1, 200);
    if (ready <= 0) continue;
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      std::cerr << "canyon-dashboard: read error: " << std::strerror(errno) << "\n";
      break;
    }
    if (n == 0) {
      eof = true;
      continue;
    }
    eof = false;
    pending.append(buffer, static_cast<std::size_t>(n));
    if (pending.size() > (1U << 24U)) {  // a 16 MiB line is not a snapshot
      std::cerr << "canyon-dashboard: a line longer than 16 MiB, dropped\n";
      pending.clear();
    }
    std::size_t start = 0;
    for (std::size_t nl = pending.find('\n'); nl != std::string::npos; nl = pending.find('\n', start)) {
      std::string line = pending.substr(start, nl - start);
      start = nl + 1;
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      if (auto s = (*server)->push(line); !s.ok() && reported++ < 5) {
        std::cerr << "canyon-dashboard: bad line skipped: " << s.error().to_string() << "\n";
      }
    }
    pending.erase(0, start);
  }
  if (!pending.empty() && pending.find_first_not_of(" \t\r\n") != std::string::npos) (void)(*server)->push(pending);
  std::cerr << "canyon-dashboard: stopped: " << (*server)->snapshots() << " snapshots, " << (*server)->bad_lines()
            << " bad lines\n";
  (*server)->stop();
  if (fd != STDIN_FILENO) ::close(fd);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return canyon::apps::guarded_main("canyon-dashboard", kExitRuntime, run, argc, argv);
}
