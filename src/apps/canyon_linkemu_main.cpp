// canyon-linkemu: a user-space WAN link emulator on an NFQUEUE (this kernel has no netem qdisc). Every IPv4 packet
// that an iptables rule sends to the queue is admitted to netemu::LinkModel (delay, jitter, loss, bandwidth, outage,
// duplication, reordering, corruption), held, and given back to the kernel with an ACCEPT verdict at its release
// time, or dropped. Duplicates are sent through a raw socket with the mark 0x77 (the iptables rule must skip that
// mark, as deploy/netns/twohost.sh does). Corrupted UDP packets get their UDP checksum cleared so that the receiver
// really sees the flipped byte (a corrupted checksum-protected packet would only be a loss).
//
// Options come from --config FILE (key=value lines, link_model.hpp) and --set key=value; SIGHUP re-reads the file.
// --stats FILE gets the counters as one JSON object every second. SIGINT/SIGTERM release every held packet and stop.
// Exit codes: 0 stopped by a signal, 1 runtime failure (no NFQUEUE: not root or no kernel support), 2 bad options.

#include <cerrno>
#include <csignal>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <queue>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <arpa/inet.h>
#include <libnetfilter_queue/libnetfilter_queue.h>
#include <linux/netfilter.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include "canyon/netemu/link_model.hpp"

#include "main_guard.hpp"

namespace {

constexpr int kExitRuntime = 1;
constexpr int kExitUsage = 2;
constexpr std::uint32_t kDuplicateMark = 0x77;

volatile std::sig_atomic_t g_stop = 0;
volatile std::sig_atomic_t g_reload = 0;

extern "C" void on_stop(int /*signal*/) {
  g_stop = 1;
}
extern "C" void on_hup(int /*signal*/) {
  g_reload = 1;
}

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000LL + ts.tv_nsec;
}

std::string one_line(std::string text) {
  while (!text.empty() && text.back() == '\n') text.pop_back();
  for (char& c : text) {
    if (c == '\n') c = ' ';
  }
  return text;
}

struct Held {
  std::int64_t release_ns = 0;
  std::uint64_t order = 0;
  std::uint32_t id = 0;
  bool modified = false;
  bool duplicate = false;
  std::vector<unsigned char> data;  // the packet, kept when modified or duplicated
  bool operator>(const Held& other) const {
    return release_ns != other.release_ns ? release_ns > other.release_ns : order > other.order;
  }
};

struct Emulator {
  canyon::netemu::LinkModel model{canyon::netemu::LinkOptions{}};
  std::priority_queue<Held, std::vector<Held>, std::greater<>> held;
  nfq_q_handle* queue = nullptr;
  int raw_fd = -1;
  std::uint64_t order = 0;
  std::uint64_t verdict_errors = 0;
  std::uint64_t duplicate_errors = 0;
  std::uint64_t max_held = 0;
};

/// Flips the byte `offset` (modulo the payload) of a UDP payload, or of the IP payload of other protocols.
void corrupt(std::vector<unsigned char>& p, std::uint32_t offset, std::uint8_t mask) {
  if (p.size() < 20 || (p[0] >> 4) != 4) return;
  const std::size_t ihl = static_cast<std::size_t>(p[0] & 0x0F) * 4;
  const bool udp = p[9] == IPPROTO_UDP;
  const std::size_t start = ihl + (udp ? 8 : 0);
  if (p.size() <= start) return;
  p[start + offset % (p.size() - start)] ^= mask;
  if (udp) {
    p[ihl + 6] = 0;  // UDP over IPv4: checksum 0 means "none"
    p[ihl + 7] = 0;
  }
}

int on_packet(nfq_q_handle* /*queue*/, nfgenmsg* /*message*/, nfq_data* nfa, void* context) {
  auto* emu = static_cast<Emulator*>(context);
  const nfqnl_msg_packet_hdr* header = nfq_get_msg_packet_hdr(nfa);
  if (header == nullptr) return 0;
  const std::uint32_t id = ntohl(header->packet_id);
  unsigned char* payload = nullptr;
  const int length = nfq_get_payload(nfa, &payload);
  const std::size_t size = length > 0 ? static_cast<std::size_t>(length) : 0;
  const canyon::netemu::Verdict v = emu->model.admit(now_ns(), size);
  if (v.drop) {
    if (nfq_set_verdict(emu->queue, id, NF_DROP, 0, nullptr) < 0) ++emu->verdict_errors;
    return 0;
  }
  Held h;
  h.release_ns = v.release_ns;
  h.order = emu->order++;
  h.id = id;
  h.duplicate = v.duplicate;
  if ((v.corrupt || v.duplicate) && size > 0) h.data.assign(payload, payload + size);
  if (v.corrupt && size > 0) {
    corrupt(h.data, v.corrupt_offset, v.corrupt_mask);
    h.modified = true;
  }
  emu->held.push(std::move(h));
  emu->max_held = std::max<std::uint64_t>(emu->max_held, emu->held.size());
  return 0;
}

void send_duplicate(Emulator& emu, const std::vector<unsigned char>& p) {
  if (emu.raw_fd < 0 || p.size() < 20) return;
  sockaddr_in to{};
  to.sin_family = AF_INET;
  std::memcpy(&to.sin_addr, p.data() + 16, 4);
  if (sendto(emu.raw_fd, p.data(), p.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to) < 0) {
    ++emu.duplicate_errors;
  }
}

void release(Emulator& emu, std::int64_t until_ns) {
  while (!emu.held.empty() && emu.held.top().release_ns <= until_ns) {
    const Held& h = emu.held.top();
    const int rc = h.modified ? nfq_set_verdict(emu.queue, h.id, NF_ACCEPT, static_cast<std::uint32_t>(h.data.size()),
                                                h.data.data())
                              : nfq_set_verdict(emu.queue, h.id, NF_ACCEPT, 0, nullptr);
    if (rc < 0) ++emu.verdict_errors;
    if (h.duplicate) send_duplicate(emu, h.data);
    emu.held.pop();
  }
}

void write_stats(const Emulator& emu, const std::string& path, double t_s) {
  if (path.empty()) return;
  const auto& c = emu.model.counters();
  const auto& o = emu.model.options();
  std::ostringstream out;
  out << "{\"t_s\":" << t_s << ",\"packets\":" << c.packets << ",\"bytes\":" << c.bytes << ",\"lost\":" << c.lost
      << ",\"outage_drops\":" << c.outage_drops << ",\"queue_drops\":" << c.queue_drops
      << ",\"duplicated\":" << c.duplicated << ",\"reordered\":" << c.reordered << ",\"corrupted\":" << c.corrupted
      << ",\"held\":" << emu.held.size() << ",\"max_held\":" << emu.max_held
      << ",\"verdict_errors\":" << emu.verdict_errors << ",\"options\":{\"delay_ms\":" << o.delay_ms
      << ",\"jitter_ms\":" << o.jitter_ms << ",\"loss\":" << o.loss << ",\"rate_kbps\":" << o.rate_kbps
      << ",\"duplicate\":" << o.duplicate << ",\"reorder\":" << o.reorder << ",\"corrupt\":" << o.corrupt
      << ",\"outage\":" << (o.outage ? "true" : "false") << "}}\n";
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::trunc);
    f << out.str();
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
}

canyon::Result<canyon::netemu::LinkOptions> load_options(const std::string& config_file,
                                                         const std::vector<std::string>& sets) {
  canyon::netemu::LinkOptions base;
  if (!config_file.empty()) {
    std::ifstream in(config_file);
    if (!in) return canyon::Error{"cannot read the link configuration", config_file, 0};
    std::stringstream text;
    text << in.rdbuf();
    auto parsed = canyon::netemu::parse_link_options(text.str(), config_file);
    if (!parsed) return parsed.error();
    base = *parsed;
  }
  std::string joined;
  for (const auto& s : sets) joined += s + "\n";
  return canyon::netemu::parse_link_options(joined, "--set", base);
}

int run(int argc, char** argv) {
  CLI::App cli{
      "canyon-linkemu: emulates a WAN link (delay, jitter, loss, bandwidth, outages, duplication, "
      "reordering, corruption) on the packets of an NFQUEUE"};
  int queue_num = 0;
  std::string config_file;
  std::vector<std::string> sets;
  std::string stats_file;
  cli.add_option("--queue", queue_num, "NFQUEUE number (iptables ... -j NFQUEUE --queue-num N)")
      ->required()
      ->check(CLI::Range(0, 65535));
  cli.add_option("--config", config_file, "key=value link options, re-read on SIGHUP")->check(CLI::ExistingFile);
  cli.add_option("--set", sets,
                 "key=value over the file (delay_ms, jitter_ms, loss, rate_kbps, queue_limit_ms, "
                 "duplicate, reorder, reorder_ms, corrupt, outage, seed)");
  cli.add_option("--stats", stats_file, "write the counters as JSON to this file every second");
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : kExitUsage;
  }
  auto options = load_options(config_file, sets);
  if (!options) {
    std::cerr << "canyon-linkemu: " << options.error().to_string() << "\n";
    return kExitUsage;
  }
  Emulator emu;
  emu.model.set_options(*options);

  nfq_handle* handle = nfq_open();
  if (handle == nullptr) {
    std::cerr << "canyon-linkemu: cannot open NFQUEUE (needs root or CAP_NET_ADMIN and nfnetlink_queue in the "
                 "kernel): "
              << std::strerror(errno) << "\n";
    return kExitRuntime;
  }
  nfq_bind_pf(handle, AF_INET);  // needed by old kernels only; its failure is harmless
  emu.queue = nfq_create_queue(handle, static_cast<std::uint16_t>(queue_num), &on_packet, &emu);
  if (emu.queue == nullptr) {
    std::cerr << "canyon-linkemu: cannot bind NFQUEUE " << queue_num << " (in use by another program?)\n";
    nfq_close(handle);
    return kExitRuntime;
  }
  if (nfq_set_mode(emu.queue, NFQNL_COPY_PACKET, 0xFFFF) < 0 || nfq_set_queue_maxlen(emu.queue, 16384) < 0) {
    std::cerr << "canyon-linkemu: cannot configure NFQUEUE " << queue_num << "\n";
    nfq_destroy_queue(emu.queue);
    nfq_close(handle);
    return kExitRuntime;
  }
  nfnl_rcvbufsiz(nfq_nfnlh(handle), 16U << 20U);
  emu.raw_fd = socket(AF_INET, SOCK_RAW, IPPROTO_RAW);
  if (emu.raw_fd >= 0) {
    const std::uint32_t mark = kDuplicateMark;
    if (setsockopt(emu.raw_fd, SOL_SOCKET, SO_MARK, &mark, sizeof mark) < 0) {
      close(emu.raw_fd);
      emu.raw_fd = -1;
    }
  }
  if (emu.raw_fd < 0) std::cerr << "canyon-linkemu: warning: no raw socket, duplicates are not sent\n";

  struct sigaction stop_action {};
  stop_action.sa_handler = on_stop;
  sigaction(SIGINT, &stop_action, nullptr);
  sigaction(SIGTERM, &stop_action, nullptr);
  struct sigaction hup_action {};
  hup_action.sa_handler = on_hup;
  sigaction(SIGHUP, &hup_action, nullptr);

  std::cerr << "canyon-linkemu: queue " << queue_num << ", " << one_line(emu.model.options().to_text()) << "\n"
            << std::flush;
  const int fd = nfq_fd(handle);
  std::vector<char> buffer(1U << 17U);
  const std::int64_t start_ns = now_ns();
  std::int64_t next_stats_ns = start_ns;
  while (g_stop == 0) {
    if (g_reload != 0) {
      g_reload = 0;
      auto reloaded = load_options(config_file, sets);
      if (reloaded) {
        emu.model.set_options(*reloaded);
        std::cerr << "canyon-linkemu: reloaded: " << one_line(reloaded->to_text()) << std::endl;
      } else {
        std::cerr << "canyon-linkemu: reload refused, options kept: " << reloaded.error().to_string() << "\n";
      }
    }
    const std::int64_t now = now_ns();
    std::int64_t wait_ns = 200'000'000;
    if (!emu.held.empty()) wait_ns = std::min(wait_ns, std::max<std::int64_t>(0, emu.held.top().release_ns - now));
    wait_ns = std::min(wait_ns, std::max<std::int64_t>(0, next_stats_ns - now));
    pollfd pfd{fd, POLLIN, 0};
    const timespec timeout{static_cast<time_t>(wait_ns / 1000000000), static_cast<long>(wait_ns % 1000000000)};
    const int ready = ppoll(&pfd, 1, &timeout, nullptr);
    if (ready > 0 && (pfd.revents & POLLIN) != 0) {
      for (;;) {
        const ssize_t n = recv(fd, buffer.data(), buffer.size(), MSG_DONTWAIT);
        if (n < 0) {
          if (errno == ENOBUFS) continue;  // the kernel dropped queue messages: keep reading
          break;
        }
        nfq_handle_packet(handle, buffer.data(), static_cast<int>(n));
      }
    }
    const std::int64_t after = now_ns();
    release(emu, after);
    if (after >= next_stats_ns) {
      write_stats(emu, stats_file, static_cast<double>(after - start_ns) * 1e-9);
      next_stats_ns = after + 1'000'000'000;
    }
  }
  release(emu, INT64_MAX);  // nothing stays queued in the kernel
  write_stats(emu, stats_file, static_cast<double>(now_ns() - start_ns) * 1e-9);
  const auto& c = emu.model.counters();
  std::cerr << "canyon-linkemu: stopped: " << c.packets << " packets, " << c.lost << " lost, " << c.outage_drops
            << " outage drops, " << c.queue_drops << " queue drops, " << c.duplicated << " duplicated, " << c.reordered
            << " reordered, " << c.corrupted << " corrupted\n";
  if (emu.raw_fd >= 0) close(emu.raw_fd);
  nfq_destroy_queue(emu.queue);
  nfq_close(handle);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return canyon::apps::guarded_main("canyon-linkemu", kExitRuntime, run, argc, argv);
}
