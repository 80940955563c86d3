#pragma once
// A byte stream from where a receiver or a correction service delivers it, read with a timeout: a file (gzip or
// not), a serial port, a TCP server, or an NTRIP caster's mount point. `canyon rover` reads its rover receiver (UBX)
// and its base corrections (RTCM 3) through it; the bytes go to io::GnssStreamDecoder, the decoder canyon convert
// and canyon base use.
//
// Addresses (LinkAddress::parse):
//   file:PATH                                    a file, read at once (the reader paces the epochs it decodes)
//   serial:///dev/ttyACM0?baud=115200            a serial device, raw 8N1 (baud default 115200)
//   tcp://HOST:PORT                              a TCP server (str2str tcpsvr://, canyon base outputs.tcp)
//   ntrip://[USER[:PASSWORD]@]HOST:PORT/MOUNT    an NTRIP caster (canyon base outputs.ntrip, str2str ntripc://)
//
// Network links reconnect (net::StreamClient: back-off, stall detection) and give up after
// LinkOptions::attempts failed attempts in a row: read() then returns an Error naming the address and the last
// failure. Bytes that arrive faster than they are read are queued up to LinkOptions::max_queued_bytes; beyond that
// they are dropped and counted (LinkStats::dropped_bytes), never silently.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "canyon/core/result.hpp"
#include "canyon/net/stream_url.hpp"

namespace canyon::pipeline {

struct LinkAddress {
  enum class Kind : std::uint8_t { File, Serial, Tcp, Ntrip };
  Kind kind = Kind::File;
  std::string path;  ///< file or serial device
  int baud = 115200;
  net::StreamUrl url;  ///< tcp, ntrip
  std::string text;    ///< as written, a password replaced by *** (messages name the link by it)

  /// One of the forms in the file comment; a relative file path is taken relative to `folder` (if not empty).
  /// Error naming the text and the accepted forms.
  static Result<LinkAddress> parse(const std::string& text, const std::string& folder = {});
};

struct LinkOptions {
  int attempts = 5;                          ///< network: give up after this many failed attempts in a row (0: never)
  double stall_timeout_s = 10.0;             ///< network: no byte for this long counts as a dead connection
  double backoff_min_s = 0.5;                ///< network: first wait before reconnecting (doubles up to backoff_max_s)
  double backoff_max_s = 8.0;                ///< network: longest wait between attempts
  std::size_t max_queued_bytes = 16u << 20;  ///< network: bytes received and not read yet; beyond: dropped, counted
  double gga_interval_s = 0.0;               ///< ntrip: upload the set_gga() sentence this often (0: never)

  /// Empty if usable, else the broken rule.
  [[nodiscard]] std::string validate() const;
};

struct LinkStats {
  std::uint64_t bytes = 0;          ///< bytes handed to read()
  std::uint64_t dropped_bytes = 0;  ///< network bytes dropped because max_queued_bytes were waiting
  std::uint64_t connections = 0;    ///< network connections that delivered data
  std::uint64_t failures = 0;       ///< failed network attempts (refused, timed out, stalled, lost)
};

class ByteLink {
 public:
  /// A link event, e.g. "tcp://127.0.0.1:2102: connection refused"; `problem` false for news ("connected to").
  using LogFn = std::function<void(bool problem, const std::string& text)>;
  virtual ~ByteLink() = default;

  /// Opens the link (a file is read, a serial device opened, a network client started; `log` gets the network
  /// client's events and a gzip file's warning, each with the address). Error naming the address on failure.
  static Result<std::unique_ptr<ByteLink>> open(const LinkAddress& address, const LinkOptions& options, LogFn log);

  /// Appends what arrives within `timeout_ms` to `out` (possibly nothing). false at the end of a file; Error if the
  /// link failed for good (a serial device vanished, a network link gave up), naming the address and why.
  virtual Result<bool> read(std::vector<std::uint8_t>& out, int timeout_ms) = 0;
  [[nodiscard]] virtual LinkStats stats() const = 0;
  [[nodiscard]] const LinkAddress& address() const { return address_; }
  /// ntrip: the NMEA GGA sentence to upload every LinkOptions::gga_interval_s from now on (the rover's position, for
  /// network RTK casters that compute corrections for it); other links ignore it. Thread-safe.
  virtual void set_gga(const std::string& /*sentence*/) {}

 protected:
  explicit ByteLink(LinkAddress address) : address_(std::move(address)) {}

 private:
  LinkAddress address_;
};

}  // namespace canyon::pipeline
