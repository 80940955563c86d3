// canyon record, echo and monitor (see topic_app.hpp).

#include "canyon/dds/topic_app.hpp"

#include <chrono>
#include <cstdio>
#include <iostream>
#include <thread>
#include <utility>

#include "canyon/io/vio_file.hpp"

namespace canyon::dds {
namespace {

constexpr const char* kKnownTopics =
    "canyon/solution, canyon/timing, canyon/rtcm, canyon/bridged, canyon/alignment, canyon/prior, canyon/float, "
    "canyon/vio or canyon/timesync";

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

bool known_topic(const std::string& topic) {
  bool known = false;
  for (const char* suffix :
       {"solution", "timing", "rtcm", "bridged", "prior", "float", "alignment", "vio", "timesync"}) {
    known = known || ends_with(topic, suffix);
  }
  return known;
}

void print_line(const std::string& line) {
  std::printf("%s\n", line.c_str());
  std::fflush(stdout);
}

}  // namespace

const char* tool_name(TopicTool tool) {
  switch (tool) {
    case TopicTool::Record: return "record";
    case TopicTool::Echo: return "echo";
    case TopicTool::Monitor: return "monitor";
  }
  return "?";
}

struct TopicApp::AnyReader {
  virtual ~AnyReader() = default;
  [[nodiscard]] virtual int matched() const = 0;
};

template <typename Reader, typename Msg>
void TopicApp::add_reader(const std::string& topic, const char* profile, void (TopicApp::*on_sample)(Msg&&)) {
  struct Holder final : AnyReader {
    explicit Holder(std::unique_ptr<Reader> r) : reader(std::move(r)) {}
    [[nodiscard]] int matched() const override { return reader->matched(); }
    std::unique_ptr<Reader> reader;
  };
  auto reader =
      Reader::create(*participant_, topic, profile, [this, on_sample](Msg&& m) { (this->*on_sample)(std::move(m)); });
  readers_.push_back(std::make_unique<Holder>(value_or_throw(std::move(reader), kExitRuntime)));
}

/// A reader of one topic's samples as bytes (record to .mcap).
struct TopicApp::McapReader final : AnyReader, fdds::DataReaderListener {
  McapReader(TopicApp& app, std::uint16_t channel) : app(app), channel(channel) {}
  ~McapReader() override {
    if (reader != nullptr) {
      reader->set_listener(nullptr);
      subscriber->delete_datareader(reader);
    }
    if (subscriber != nullptr) app.participant_->get()->delete_subscriber(subscriber);
  }
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;
  [[nodiscard]] int matched() const override { return matched_now.load(); }
  void on_subscription_matched(fdds::DataReader* /*reader*/, const fdds::SubscriptionMatchedStatus& info) override {
    matched_now.store(info.current_count);
  }
  void on_data_available(fdds::DataReader* r) override {
    RawSample bytes;
    fdds::SampleInfo info;
    while (r->take_next_sample(&bytes, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      const auto publish_ns =
          static_cast<std::uint64_t>(info.source_timestamp.seconds()) * 1000000000ULL + info.source_timestamp.nanosec();
      app.on_mcap_sample(channel, std::move(bytes), publish_ns);
    }
  }
  TopicApp& app;
  std::uint16_t channel;
  fdds::Subscriber* subscriber = nullptr;
  fdds::DataReader* reader = nullptr;
  std::atomic<int> matched_now{0};
};

TopicApp::TopicApp(TopicOptions options)
    : options_(std::move(options)), solutions_(ends_with(options_.topic, "solution")), model_(core::pipeline_now_ns()) {
  const bool monitor = options_.tool == TopicTool::Monitor;
  const bool mcap = options_.tool == TopicTool::Record && ends_with(options_.out, ".mcap");
  if (!options_.more_topics.empty() && !mcap) {
    throw AppError(kExitUsage, Error{"several topics need a recording to .mcap (--out SESSION.mcap)"});
  }
  if (mcap) {
    for (const std::string& topic : mcap_topics()) {
      if (!recorded_topic(topic)) {
        throw AppError(kExitUsage, Error{"unknown topic '" + topic + "': " + kKnownTopics +
                                         ", or ROS 2 topics rt/...fix, rt/...odometry, rt/...diagnostics, rt/...rtcm"});
      }
    }
  } else if (!monitor && !known_topic(options_.topic)) {
    throw AppError(kExitUsage, Error{"unknown topic '" + options_.topic + "': " + kKnownTopics});
  }
  const ProfileSet profiles = value_or_throw(load_profiles(options_.profiles), kExitUsage);
  start_dashboard();
  participant_ = value_or_throw(DdsParticipant::create(options_.domain, profiles.participant_profile()), kExitRuntime);
  if (options_.tool == TopicTool::Record) open_record_output();
  create_readers();
}

TopicApp::~TopicApp() {
  readers_.clear();  // no callback after this
}

void TopicApp::start_dashboard() {
#ifdef CANYON_WITH_DASHBOARD
  if (options_.http_port < 0) return;
  dashboard::ServerOptions& d = options_.dashboard;
  d.port = options_.http_port;
  if (const std::string e = d.validate(); !e.empty()) throw AppError(kExitUsage, Error{e});
  dashboard_ = value_or_throw(dashboard::DashboardServer::start(d), kExitRuntime);
  std::cerr << "canyon monitor: dashboard on http://" << d.host << ":" << dashboard_->port() << "/"
            << (d.web_dir.empty() ? " (page not built: /events and /metrics only)" : "") << std::endl;
#endif
}

std::vector<std::string> TopicApp::mcap_topics() const {
  std::vector<std::string> topics{options_.topic};
  topics.insert(topics.end(), options_.more_topics.begin(), options_.more_topics.end());
  return topics;
}

void TopicApp::create_mcap_readers() {
  for (const std::string& topic : mcap_topics()) {
    const RecordedTopic recorded = *recorded_topic(topic);
    const std::uint16_t channel = value_or_throw(mcap_->channel(topic, recorded.type_name), kExitRuntime);
    auto dds_topic = value_or_throw(
        participant_->topic(topic, fdds::TypeSupport(new RawSampleType(recorded.type_name))), kExitRuntime);
    auto holder = std::make_unique<McapReader>(*this, channel);
    holder->subscriber = participant_->get()->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
    if (holder->subscriber == nullptr) throw AppError(kExitRuntime, Error{"DDS: cannot create a subscriber"});
    holder->reader =
        holder->subscriber->create_datareader_with_profile(dds_topic, recorded.reader_profile, holder.get());
    if (holder->reader == nullptr) {
      throw AppError(kExitRuntime, Error{"DDS: cannot create a data reader on topic '" + topic + "'"});
    }
    readers_.push_back(std::move(holder));
  }
}

void TopicApp::on_mcap_sample(std::uint16_t channel, RawSample&& bytes, std::uint64_t publish_time_ns) {
  if (Status s = mcap_->record(channel, std::move(bytes), publish_time_ns); !s) {
    const std::lock_guard lock(mutex_);
    note_error(s.error().to_string());
    stop();
    return;
  }
  received_.fetch_add(1);
}

void TopicApp::open_record_output() {
  const std::string& out = options_.out;
  if (ends_with(out, ".mcap")) {
    io::McapWriterOptions mcap = options_.mcap;
    mcap.chunk_size = static_cast<std::size_t>(options_.mcap_chunk_kib) * 1024U;
    mcap_ = value_or_throw(SessionRecorder::create(out, mcap), kExitRuntime);
    return;
  }
  if (solutions_ && ends_with(out, ".pos")) {
    pos_ = value_or_throw(io::PosWriter::create(out, {io::PosCoordinates::Llh,
                                                      io::PosTimeFormat::WeekTow,
                                                      {"program   : canyon record " + options_.topic}}),
                          kExitRuntime);
    return;
  }
  if (solutions_ && ends_with(out, ".nmea")) {
    nmea_ = value_or_throw(io::NmeaWriter::create(out), kExitRuntime);
    return;
  }
  raw_.open(out, std::ios::binary | std::ios::trunc);
  if (!raw_) throw AppError(kExitRuntime, Error{"cannot create " + out});
  if (solutions_) {
    raw_ << "seq,gps_week,gps_tow_s,status,x_m,y_m,z_m,lat_deg,lon_deg,height_m,n_sats,ratio,age_s,hpl_m,vpl_m,"
            "received_monotonic_ns\n";
  } else if (ends_with(options_.topic, "vio")) {
    raw_ << io::vio_csv_header() << '\n';
  } else if (ends_with(options_.topic, "timesync")) {
    raw_ << io::timesync_csv_header() << '\n';
  }
}

void TopicApp::create_readers() {
  if (mcap_) {
    create_mcap_readers();
    return;
  }
  const std::string& topic = options_.topic;
  if (options_.tool == TopicTool::Monitor) {
    add_reader<SolutionReader>(options_.solution_topic, profile::kSolutionReader, &TopicApp::on_solution);
    add_reader<TimingReader>(options_.timing_topic, profile::kTimingReader, &TopicApp::on_timing);
    return;
  }
  if (solutions_) add_reader<SolutionReader>(topic, profile::kSolutionReader, &TopicApp::on_solution);
  if (ends_with(topic, "timing")) add_reader<TimingReader>(topic, profile::kTimingReader, &TopicApp::on_timing);
  if (ends_with(topic, "rtcm")) add_reader<RtcmReader>(topic, profile::kRtcmReader, &TopicApp::on_rtcm);
  if (ends_with(topic, "bridged")) add_reader<BridgedReader>(topic, profile::kStageReader, &TopicApp::on_bridged);
  if (ends_with(topic, "prior")) add_reader<PriorReader>(topic, profile::kStageReader, &TopicApp::on_prior);
  if (ends_with(topic, "float")) add_reader<FloatReader>(topic, profile::kStageReader, &TopicApp::on_float);
  if (ends_with(topic, "alignment")) {
    add_reader<AlignmentReader>(topic, profile::kStageReader, &TopicApp::on_alignment);
  }
  if (ends_with(topic, "vio")) add_reader<VioPoseReader>(topic, profile::kVioReader, &TopicApp::on_vio);
  if (ends_with(topic, "timesync")) add_reader<TimeSyncReader>(topic, profile::kVioReader, &TopicApp::on_timesync);
}

int TopicApp::matched() const {
  int n = 0;
  for (const auto& r : readers_) n += r->matched();
  return n;
}

void TopicApp::note_error(const std::string& error) {
  if (error_.empty()) error_ = error;
}

void TopicApp::on_solution(msg::Solution&& m) {
  const std::int64_t now = core::pipeline_now_ns();
  const std::lock_guard lock(mutex_);
  received_.fetch_add(1);
  switch (options_.tool) {
    case TopicTool::Monitor: model_.add_solution(to_sample(m, now)); return;
    case TopicTool::Echo: print_line(describe(m)); return;
    case TopicTool::Record: record_solution(m, now); return;
  }
}

void TopicApp::record_solution(const msg::Solution& m, std::int64_t now) {
  if (!pos_ && !nmea_) {
    // CSV: every sample, those without a solution (status 0) too, so that the sequence numbers account for every
    // epoch; received_monotonic_ns is this recorder's clock (CLOCK_MONOTONIC, shared by a host's namespaces).
    char line[360];
    std::snprintf(line, sizeof line, "%llu,%d,%.3f,%d,%.4f,%.4f,%.4f,%.9f,%.9f,%.4f,%d,%.2f,%.2f,%.3f,%.3f,%lld\n",
                  static_cast<unsigned long long>(m.sequence_number()), m.gps_week(), m.gps_tow_s(), m.status(),
                  m.p_E_m()[0], m.p_E_m()[1], m.p_E_m()[2], m.lat_deg(), m.lon_deg(), m.height_m(), m.num_satellites(),
                  m.ratio(), m.age_s(), m.hpl_m(), m.vpl_m(), static_cast<long long>(now));
    raw_ << line << std::flush;  // followed live (a line a second): each sample reaches the file at once
    if (m.status() != 0 && !from_msg(m)) ++bad_;
    return;
  }
  if (m.status() == 0) return;  // no solution: not a record
  auto s = from_msg(m);
  if (!s) {
    ++bad_;
    note_error(s.error().to_string());
    return;
  }
  if (pos_) {
    if (auto w = pos_->write(*s); !w) note_error(w.error().to_string());
  } else if (auto w = nmea_->write(*s, m.hdop()); !w) {
    note_error(w.error().to_string());
  }
}

void TopicApp::on_timing(msg::StageTiming&& m) {
  const std::lock_guard lock(mutex_);
  received_.fetch_add(1);
  if (options_.tool == TopicTool::Monitor) {
    model_.add_timing(to_sample(m));
  } else if (options_.tool == TopicTool::Echo) {
    print_line(describe(m));
  } else {
    const auto& st = m.stamps();
    raw_ << m.sequence_number() << ',' << m.gps_week() << ',' << m.gps_tow_s() << ',' << st.arrival_monotonic_ns();
    for (std::size_t i = 0; i < 6; ++i) raw_ << ',' << st.enter_monotonic_ns()[i] << ',' << st.exit_monotonic_ns()[i];
    raw_ << '\n';
  }
}

void TopicApp::on_rtcm(msg::RtcmFrame&& m) {
  const std::lock_guard lock(mutex_);
  received_.fetch_add(1);
  auto f = from_msg(m);
  if (!f) {
    ++bad_;
    note_error(f.error().to_string());
    return;
  }
  if (options_.tool == TopicTool::Echo) {
    std::printf("rtcm #%llu message %u station %u %d %.3f %zu bytes\n",
                static_cast<unsigned long long>(m.sequence_number()), m.message_number(), m.station_id(), m.gps_week(),
                m.gps_tow_s(), f->bytes.size());
    std::fflush(stdout);
  } else {
    raw_.write(reinterpret_cast<const char*>(f->bytes.data()), static_cast<std::streamsize>(f->bytes.size()));
  }
}

void TopicApp::on_text(const std::string& line) {
  const std::lock_guard lock(mutex_);
  received_.fetch_add(1);
  if (options_.tool == TopicTool::Echo) {
    print_line(line);
  } else {
    raw_ << line << '\n';
  }
}

void TopicApp::on_vio(msg::VioPose&& m) {
  if (options_.tool == TopicTool::Echo) return on_text(describe(m));
  auto pose = from_msg(m);
  if (!pose) {
    const std::lock_guard lock(mutex_);
    ++bad_;
    note_error(pose.error().to_string());
    return;
  }
  on_text(io::vio_csv_row(*pose));
}

void TopicApp::on_timesync(msg::TimeSyncSample&& m) {
  if (options_.tool == TopicTool::Echo) return on_text(describe(m));
  io::TimeSyncPair pair;
  pair.t_ns = m.device_time_ns();
  pair.time = core::GpsTime{m.gps_week(), m.gps_tow_s()};
  on_text(io::timesync_csv_row(pair));
}

void TopicApp::report() {
  const std::lock_guard lock(mutex_);
  const std::int64_t now = core::pipeline_now_ns();
#ifdef CANYON_WITH_DASHBOARD
  // One snapshot for the terminal (--json) and the dashboard alike; the model makes only valid lines.
  const std::string line = (options_.json || dashboard_) ? model_.json_line(now) : std::string();
  if (dashboard_) (void)dashboard_->push(line);
#else
  const std::string line = options_.json ? model_.json_line(now) : std::string();
#endif
  if (options_.json) {
    std::printf("%s\n", line.c_str());
  } else {
    std::printf("\033[H\033[2J");
    for (const std::string& row : model_.text(now)) std::printf("%s\n", row.c_str());
  }
  std::fflush(stdout);
}

void TopicApp::wait_until_done() {
  const auto start = std::chrono::steady_clock::now();
  auto next_refresh = start + std::chrono::duration<double>(options_.interval_s);
  bool seen_publisher = false;
  while (!stop_.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    const auto now = std::chrono::steady_clock::now();
    if (options_.count > 0 && received_.load() >= options_.count) break;
    if (options_.duration_s > 0 && now - start >= std::chrono::duration<double>(options_.duration_s)) break;
    const int m = matched();
    if (m > 0) seen_publisher = true;
    if (options_.until_gone && seen_publisher && m == 0) break;
    if (options_.tool == TopicTool::Monitor && now >= next_refresh) {
      report();
      next_refresh += std::chrono::duration<double>(options_.interval_s);
    }
  }
}

void TopicApp::close_outputs() {
  if (pos_) {
    if (auto c = pos_->close(); !c) note_error(c.error().to_string());
  }
  if (nmea_) {
    if (auto c = nmea_->close(); !c) note_error(c.error().to_string());
  }
  if (raw_.is_open()) {
    raw_.close();
    if (!raw_) note_error("cannot write " + options_.out);
  }
  if (mcap_) {
    if (auto c = mcap_->close(); !c) note_error(c.error().to_string());
  }
}

int TopicApp::run() {
  wait_until_done();
  readers_.clear();  // readers first (no callback after this), then the outputs
  if (options_.tool == TopicTool::Monitor) report();
  close_outputs();
  if (options_.tool == TopicTool::Record) {
    std::string topics = options_.topic;
    for (const std::string& t : options_.more_topics) topics += ", " + t;
    std::fprintf(stderr, "canyon record: %lld samples of %s to %s%s\n", static_cast<long long>(received_.load()),
                 topics.c_str(), options_.out.c_str(),
                 bad_ > 0 ? (" (" + std::to_string(bad_) + " malformed, skipped)").c_str() : "");
  }
  if (!error_.empty()) {
    std::cerr << "canyon " << tool_name(options_.tool) << ": error: " << error_ << "\n";
    return kExitRuntime;
  }
  return kExitOk;
}

}  // namespace canyon::dds
