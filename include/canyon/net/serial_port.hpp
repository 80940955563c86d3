#pragma once
// A serial port (a receiver on /dev/ttyACM0, /dev/ttyUSB0): raw 8N1 at a standard baud rate, read with a timeout.

#include <cstdint>
#include <span>
#include <string>

#include "canyon/core/result.hpp"
#include "canyon/net/socket.hpp"

namespace canyon::net {

class SerialPort {
 public:
  /// Opens `path` raw (no echo, no line discipline) at `baud` (9600 ... 921600). Error naming the device.
  static Result<SerialPort> open(const std::string& path, int baud);
  /// Reads what is available within `timeout_ms` (0 bytes on timeout). Error if the device failed or vanished.
  Result<std::size_t> read(std::span<std::uint8_t> buffer, int timeout_ms);
  /// Writes all of `data` (receiver configuration commands).
  Status write(std::span<const std::uint8_t> data, int timeout_ms);
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  SerialPort(Fd fd, std::string path) : fd_(std::move(fd)), path_(std::move(path)) {}
  Fd fd_;
  std::string path_;
};

}  // namespace canyon::net
