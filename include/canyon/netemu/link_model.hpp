#pragma once
// The model of one direction of an emulated WAN link (canyon-linkemu applies it to the packets of an NFQUEUE):
// what happens to each packet, decided when it enters the link.
//
//   transmit start  s = max(t_in, end of the previous packet's transmission)       (bandwidth: a FIFO serialiser)
//   transmit end    e = s + 8 * size / rate                                           (rate 0: e = s)
//   release         r = max(e + delay + U(-jitter, +jitter), previous release)       (jitter keeps the order)
//   reordered       r += reorder_ms with probability `reorder` (and not bound by the order of later packets)
// A packet is dropped when the link is in an outage, with probability `loss`, or when its transmission would wait
// longer than `queue_limit_ms` behind earlier packets (tail drop). With probability `duplicate` a second copy is
// released at the same time; with probability `corrupt` one byte of the payload is flipped. Random numbers come from
// std::mt19937_64 seeded by `seed`, so a run is reproducible for the same packet arrivals.

#include <cstdint>
#include <random>
#include <string>

#include "canyon/core/result.hpp"

namespace canyon::netemu {

struct LinkOptions {
  double delay_ms = 0.0;          ///< one-way delay added to every packet, ms
  double jitter_ms = 0.0;         ///< uniform jitter of the delay, +- ms (packets stay in order)
  double loss = 0.0;              ///< probability that a packet is lost, [0, 1]
  double rate_kbps = 0.0;         ///< link bandwidth, kbit/s; 0: unlimited
  double queue_limit_ms = 500.0;  ///< tail drop when a packet would wait longer than this for the link, ms
  double duplicate = 0.0;         ///< probability that a packet is delivered twice, [0, 1]
  double reorder = 0.0;           ///< probability that a packet is held `reorder_ms` longer, [0, 1]
  double reorder_ms = 10.0;       ///< extra delay of a reordered packet, ms
  double corrupt = 0.0;           ///< probability that one payload byte is flipped, [0, 1]
  bool outage = false;            ///< every packet is dropped while true
  std::uint64_t seed = 1;         ///< random seed

  /// Empty when valid, else the broken rule, e.g. "loss must be in [0, 1] (is 1.5)".
  [[nodiscard]] std::string validate() const;
  /// One `key=value` per line, in the syntax `parse_link_options` reads.
  [[nodiscard]] std::string to_text() const;
  bool operator==(const LinkOptions&) const = default;
};

/// Reads `key=value` lines ('#' starts a comment; blank lines ignored) over `base`; an unknown key, a bad number or
/// an invalid result is an error naming `source` and the line.
Result<LinkOptions> parse_link_options(const std::string& text, const std::string& source,
                                       const LinkOptions& base = {});

/// What happens to one packet.
struct Verdict {
  bool drop = false;        ///< true: never delivered
  bool outage = false;      ///< dropped because of an outage
  bool queue_full = false;  ///< dropped by the tail-drop limit
  bool duplicate = false;   ///< deliver a second copy at `release_ns`
  bool reordered = false;   ///< held `reorder_ms` longer than the packets around it
  bool corrupt = false;     ///< flip byte `corrupt_offset` (counted from the start of the payload) with `corrupt_mask`
  std::uint32_t corrupt_offset = 0;
  std::uint8_t corrupt_mask = 0;
  std::int64_t release_ns = 0;  ///< when to deliver (same clock as the arrival time)
};

/// Counters of a link since start.
struct LinkCounters {
  std::uint64_t packets = 0;
  std::uint64_t bytes = 0;
  std::uint64_t lost = 0;
  std::uint64_t outage_drops = 0;
  std::uint64_t queue_drops = 0;
  std::uint64_t duplicated = 0;
  std::uint64_t reordered = 0;
  std::uint64_t corrupted = 0;
};

class LinkModel {
 public:
  explicit LinkModel(const LinkOptions& options);
  /// Replaces the options (the random stream is reseeded only when the seed changes).
  void set_options(const LinkOptions& options);
  [[nodiscard]] const LinkOptions& options() const { return options_; }
  /// The fate of a packet of `size_bytes` arriving at `arrival_ns`; arrivals must not go back in time.
  Verdict admit(std::int64_t arrival_ns, std::size_t size_bytes);
  [[nodiscard]] const LinkCounters& counters() const { return counters_; }

 private:
  double uniform();
  LinkOptions options_;
  std::mt19937_64 rng_;
  std::int64_t link_free_ns_ = 0;
  std::int64_t last_release_ns_ = 0;
  LinkCounters counters_;
};

}  // namespace canyon::netemu
