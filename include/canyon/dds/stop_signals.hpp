#pragma once
// SIGINT and SIGTERM to an application's stop(), without a signal handler or a global pointer. The constructor
// blocks both signals in the calling thread: construct it in main() before any other thread exists, so that every
// thread started afterwards (Fast DDS', the pipeline's, the servers') inherits the mask and none of them is
// interrupted. forward_to() starts a watcher thread that waits for the signals on a signalfd and calls the function
// for each; a signal that came before is pending and delivered then. The returned Forwarding ends the watcher when it
// goes (declare it after the application, so that it goes first). The mask stays blocked until the process exits: a
// signal after the forwarding ended is not acted upon.

#include <functional>
#include <thread>

namespace canyon::dds {

class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  /// The watcher: calls `stop` on each SIGINT or SIGTERM until it is destroyed.
  class Forwarding {
   public:
    Forwarding(Forwarding&& other) noexcept = delete;
    Forwarding(const Forwarding&) = delete;
    Forwarding& operator=(const Forwarding&) = delete;
    Forwarding& operator=(Forwarding&&) = delete;
    ~Forwarding();

   private:
    friend class StopSignals;
    Forwarding(int signal_fd, std::function<void()> stop);
    void watch();
    int signal_fd_;
    int wake_fd_;
    std::function<void()> stop_;
    std::thread thread_;
  };

  /// Starts forwarding the signals to `stop` (called on the watcher thread).
  [[nodiscard]] Forwarding forward_to(std::function<void()> stop) const;

 private:
  int signal_fd_ = -1;
};

}  // namespace canyon::dds
