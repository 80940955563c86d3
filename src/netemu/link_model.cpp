// Link model (see link_model.hpp).

#include "canyon/netemu/link_model.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>

namespace canyon::netemu {
namespace {

std::string probability_rule(const char* name, double p) {
  if (!(p >= 0.0 && p <= 1.0)) {
    std::ostringstream out;
    out << name << " must be in [0, 1] (is " << p << ")";
    return out.str();
  }
  return {};
}

std::string non_negative_rule(const char* name, double v) {
  if (!(v >= 0.0) || !std::isfinite(v)) {
    std::ostringstream out;
    out << name << " must be a finite number >= 0 (is " << v << ")";
    return out.str();
  }
  return {};
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

}  // namespace

std::string LinkOptions::validate() const {
  for (const auto& [name, v] :
       {std::pair{"delay_ms", delay_ms}, std::pair{"jitter_ms", jitter_ms}, std::pair{"rate_kbps", rate_kbps},
        std::pair{"queue_limit_ms", queue_limit_ms}, std::pair{"reorder_ms", reorder_ms}}) {
    if (auto e = non_negative_rule(name, v); !e.empty()) return e;
  }
  for (const auto& [name, v] : {std::pair{"loss", loss}, std::pair{"duplicate", duplicate},
                                std::pair{"reorder", reorder}, std::pair{"corrupt", corrupt}}) {
    if (auto e = probability_rule(name, v); !e.empty()) return e;
  }
  if (jitter_ms > delay_ms) {
    std::ostringstream out;
    out << "jitter_ms must be <= delay_ms (is " << jitter_ms << " > " << delay_ms << ")";
    return out.str();
  }
  return {};
}

std::string LinkOptions::to_text() const {
  std::ostringstream out;
  out << "delay_ms=" << delay_ms << "\njitter_ms=" << jitter_ms << "\nloss=" << loss << "\nrate_kbps=" << rate_kbps
      << "\nqueue_limit_ms=" << queue_limit_ms << "\nduplicate=" << duplicate << "\nreorder=" << reorder
      << "\nreorder_ms=" << reorder_ms << "\ncorrupt=" << corrupt << "\noutage=" << (outage ? 1 : 0)
      << "\nseed=" << seed << "\n";
  return out.str();
}

Result<LinkOptions> parse_link_options(const std::string& text, const std::string& source, const LinkOptions& base) {
  LinkOptions o = base;
  std::istringstream in(text);
  std::string raw;
  int line = 0;
  while (std::getline(in, raw)) {
    ++line;
    const std::string content = trim(raw.substr(0, raw.find('#')));
    if (content.empty()) continue;
    const auto eq = content.find('=');
    if (eq == std::string::npos) return Error{"expected key=value, got '" + content + "'", source, line};
    const std::string key = trim(content.substr(0, eq));
    const std::string value = trim(content.substr(eq + 1));
    double number = 0.0;
    const char* first = value.data();
    const char* last = first + value.size();
    const auto [ptr, ec] = std::from_chars(first, last, number);
    if (value.empty() || ec != std::errc() || ptr != last) {
      std::string message = "'";
      message.append(key).append("': not a number: '").append(value).append("'");
      return Error{message, source, line};
    }
    if (key == "delay_ms") {
      o.delay_ms = number;
    } else if (key == "jitter_ms") {
      o.jitter_ms = number;
    } else if (key == "loss") {
      o.loss = number;
    } else if (key == "rate_kbps") {
      o.rate_kbps = number;
    } else if (key == "queue_limit_ms") {
      o.queue_limit_ms = number;
    } else if (key == "duplicate") {
      o.duplicate = number;
    } else if (key == "reorder") {
      o.reorder = number;
    } else if (key == "reorder_ms") {
      o.reorder_ms = number;
    } else if (key == "corrupt") {
      o.corrupt = number;
    } else if (key == "outage") {
      if (number != 0.0 && number != 1.0) return Error{"'outage' must be 0 or 1", source, line};
      o.outage = number == 1.0;
    } else if (key == "seed") {
      if (number < 0 || number != std::floor(number)) return Error{"'seed' must be an integer >= 0", source, line};
      o.seed = static_cast<std::uint64_t>(number);
    } else {
      return Error{"unknown key '" + key +
                       "' (known: delay_ms, jitter_ms, loss, rate_kbps, queue_limit_ms, duplicate, reorder, "
                       "reorder_ms, corrupt, outage, seed)",
                   source, line};
    }
  }
  if (auto e = o.validate(); !e.empty()) return Error{e, source, 0};
  return o;
}

LinkModel::LinkModel(const LinkOptions& options) : options_(options), rng_(options.seed) {}

void LinkModel::set_options(const LinkOptions& options) {
  if (options.seed != options_.seed) rng_.seed(options.seed);
  options_ = options;
}

double LinkModel::uniform() {
  // 53 random bits into [0, 1): the same on every standard library.
  return static_cast<double>(rng_() >> 11) * 0x1.0p-53;
}

Verdict LinkModel::admit(std::int64_t arrival_ns, std::size_t size_bytes) {
  Verdict v;
  ++counters_.packets;
  counters_.bytes += size_bytes;
  // Draw every random number for every packet, so that one option does not shift the stream of the others.
  const double u_loss = uniform();
  const double u_jitter = uniform();
  const double u_dup = uniform();
  const double u_reorder = uniform();
  const double u_corrupt = uniform();
  const double u_offset = uniform();
  const double u_mask = uniform();
  if (options_.outage) {
    v.drop = v.outage = true;
    ++counters_.outage_drops;
    return v;
  }
  if (u_loss < options_.loss) {
    v.drop = true;
    ++counters_.lost;
    return v;
  }
  const std::int64_t start_ns = std::max(arrival_ns, link_free_ns_);
  if (options_.rate_kbps > 0.0 && static_cast<double>(start_ns - arrival_ns) > options_.queue_limit_ms * 1e6) {
    v.drop = v.queue_full = true;
    ++counters_.queue_drops;
    return v;
  }
  const double tx_ns =
      options_.rate_kbps > 0.0 ? static_cast<double>(size_bytes) * 8.0 / options_.rate_kbps * 1e6 : 0.0;
  link_free_ns_ = start_ns + static_cast<std::int64_t>(std::llround(tx_ns));
  const double delay_ns = (options_.delay_ms + (2.0 * u_jitter - 1.0) * options_.jitter_ms) * 1e6;
  std::int64_t release = std::max(link_free_ns_ + static_cast<std::int64_t>(std::llround(delay_ns)), last_release_ns_);
  last_release_ns_ = release;
  if (u_reorder < options_.reorder) {
    release += static_cast<std::int64_t>(std::llround(options_.reorder_ms * 1e6));
    v.reordered = true;
    ++counters_.reordered;
  }
  v.release_ns = release;
  if (u_dup < options_.duplicate) {
    v.duplicate = true;
    ++counters_.duplicated;
  }
  if (u_corrupt < options_.corrupt) {
    v.corrupt = true;
    v.corrupt_offset = static_cast<std::uint32_t>(u_offset * 4294967296.0);
    v.corrupt_mask = static_cast<std::uint8_t>(1U << static_cast<unsigned>(u_mask * 8.0));
    ++counters_.corrupted;
  }
  return v;
}

}  // namespace canyon::netemu
