#pragma once
// What the application classes of the DDS programs share (BaseApp: canyon base, RoverApp: canyon rover, VioApp:
// canyon vio, TopicApp: canyon record, echo and monitor). Each
//   - is constructed from its options struct; the constructor creates every DDS entity and opens every input and
//     output, and throws AppError when it cannot (STYLE.md: exceptions only where an application is constructed, as
//     in Fast DDS' examples), with the exit status that says whose fault it is;
//   - run()s once, logging as the program does, and returns the program's exit status;
//   - stop()s from any thread or from a signal handler (atomic stores only): run() then returns promptly;
//   - deletes the DDS entities it created in its destructor (members in reverse order: readers and writers before
//     their participant).
// run_app() is the part of main() after the command line: SIGINT and SIGTERM to stop(), without globals.

#include <stdexcept>
#include <utility>

#include "canyon/core/result.hpp"
#include "canyon/dds/stop_signals.hpp"

namespace canyon::dds {

/// Exit statuses of the DDS programs (docs/usage.md).
inline constexpr int kExitOk = 0;
inline constexpr int kExitRuntime = 1;  ///< input or runtime failure
inline constexpr int kExitUsage = 2;    ///< bad command line or configuration

/// An application could not be constructed: what was wrong, and the program's exit status for it.
class AppError : public std::runtime_error {
 public:
  AppError(int exit_status, const Error& error) : std::runtime_error(error.to_string()), exit_status_(exit_status) {}
  [[nodiscard]] int exit_status() const noexcept { return exit_status_; }

 private:
  int exit_status_;
};

/// The value of `result`, or throws AppError(exit_status, its error).
template <typename T>
T value_or_throw(Result<T>&& result, int exit_status) {
  if (!result) throw AppError(exit_status, result.error());
  return std::move(*result);
}

/// Throws AppError(exit_status, the error) if `status` is one.
inline void check_or_throw(const Status& status, int exit_status) {
  if (!status) throw AppError(exit_status, status.error());
}

/// main() after the command line: blocks SIGINT and SIGTERM before the application's threads exist, constructs an
/// App from `options`, forwards the signals to its stop() while it runs, and returns run()'s exit status; if the
/// application cannot be constructed, `report(error)` and the error's exit status.
template <typename App, typename Options, typename Report>
int run_app(Options&& options, Report&& report) {
  const StopSignals signals;
  try {
    App app(std::forward<Options>(options));
    const StopSignals::Forwarding forwarding = signals.forward_to([&app] { app.stop(); });
    return app.run();
  } catch (const AppError& e) {
    report(e);
    return e.exit_status();
  }
}

}  // namespace canyon::dds
