// Serial port (see serial_port.hpp).

#include "canyon/net/serial_port.hpp"

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

namespace canyon::net {
namespace {

speed_t speed_of(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 921600: return B921600;
    default: return B0;
  }
}

}  // namespace

Result<SerialPort> SerialPort::open(const std::string& path, int baud) {
  const speed_t speed = speed_of(baud);
  if (speed == B0) return Error{"serial port " + path + ": unsupported baud rate " + std::to_string(baud)};
  Fd fd(::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC));
  if (!fd.valid()) return Error{"cannot open serial port " + path + ": " + std::strerror(errno)};
  termios tio{};
  if (::tcgetattr(fd.get(), &tio) != 0) {
    return Error{"serial port " + path + ": not a terminal device (" + std::strerror(errno) + ")"};
  }
  ::cfmakeraw(&tio);
  tio.c_cflag |= CLOCAL | CREAD;
  tio.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | PARENB | CRTSCTS);
  ::cfsetispeed(&tio, speed);
  ::cfsetospeed(&tio, speed);
  if (::tcsetattr(fd.get(), TCSANOW, &tio) != 0) {
    return Error{"serial port " + path + ": cannot set " + std::to_string(baud) + " baud: " + std::strerror(errno)};
  }
  return SerialPort(std::move(fd), path);
}

Result<std::size_t> SerialPort::read(std::span<std::uint8_t> buffer, int timeout_ms) {
  pollfd p{fd_.get(), POLLIN, 0};
  const int ready = ::poll(&p, 1, timeout_ms);
  if (ready < 0 && errno != EINTR) return Error{"serial port " + path_ + ": " + std::strerror(errno)};
  if (ready <= 0) return std::size_t{0};
  if ((p.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0) return Error{"serial port " + path_ + ": device gone"};
  const ssize_t n = ::read(fd_.get(), buffer.data(), buffer.size());
  if (n < 0) {
    if (errno == EAGAIN || errno == EINTR) return std::size_t{0};
    return Error{"serial port " + path_ + ": " + std::strerror(errno)};
  }
  return static_cast<std::size_t>(n);
}

Status SerialPort::write(std::span<const std::uint8_t> data, int timeout_ms) {
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd_.get(), data.data() + done, data.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EINTR) return Error{"serial port " + path_ + ": " + std::strerror(errno)};
    pollfd p{fd_.get(), POLLOUT, 0};
    if (::poll(&p, 1, timeout_ms) <= 0) return Error{"serial port " + path_ + ": write timed out"};
  }
  return Ok{};
}

}  // namespace canyon::net
