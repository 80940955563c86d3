// SIGINT and SIGTERM to stop() on a watcher thread (see stop_signals.hpp).

#include "canyon/dds/stop_signals.hpp"

#include <array>
#include <cerrno>
#include <csignal>
#include <cstdint>
#include <system_error>
#include <utility>

#include <poll.h>
#include <pthread.h>
#include <sys/eventfd.h>
#include <sys/signalfd.h>
#include <unistd.h>

namespace canyon::dds {
namespace {

sigset_t stop_set() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  return set;
}

}  // namespace

StopSignals::StopSignals() {
  const sigset_t set = stop_set();
  if (const int e = pthread_sigmask(SIG_BLOCK, &set, nullptr); e != 0) {
    throw std::system_error(e, std::generic_category(), "cannot block SIGINT and SIGTERM");
  }
  signal_fd_ = signalfd(-1, &set, SFD_CLOEXEC);
  if (signal_fd_ < 0) throw std::system_error(errno, std::generic_category(), "signalfd");
}

StopSignals::~StopSignals() {
  ::close(signal_fd_);
}

StopSignals::Forwarding StopSignals::forward_to(std::function<void()> stop) const {
  return Forwarding(signal_fd_, std::move(stop));
}

StopSignals::Forwarding::Forwarding(int signal_fd, std::function<void()> stop)
    : signal_fd_(signal_fd), wake_fd_(eventfd(0, EFD_CLOEXEC)), stop_(std::move(stop)) {
  if (wake_fd_ < 0) throw std::system_error(errno, std::generic_category(), "eventfd");
  thread_ = std::thread([this] { watch(); });
}

StopSignals::Forwarding::~Forwarding() {
  const std::uint64_t one = 1;
  (void)!::write(wake_fd_, &one, sizeof one);
  thread_.join();
  ::close(wake_fd_);
}

void StopSignals::Forwarding::watch() {
  std::array<pollfd, 2> fds{pollfd{signal_fd_, POLLIN, 0}, pollfd{wake_fd_, POLLIN, 0}};
  while (true) {
    if (::poll(fds.data(), fds.size(), -1) < 0) {
      if (errno == EINTR) continue;
      return;
    }
    if ((fds[1].revents & POLLIN) != 0) return;
    signalfd_siginfo info{};
    if ((fds[0].revents & POLLIN) != 0 && ::read(signal_fd_, &info, sizeof info) == sizeof info) stop_();
  }
}

}  // namespace canyon::dds
