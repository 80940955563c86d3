#pragma once
// canyon record, echo and monitor: the consumers of the rover's and the base's topics, one application class with a
// tool (app.hpp: constructed, run() once, stop() from anywhere).
//   record TOPIC --out FILE: canyon/solution to .pos (RTKLIB format), .nmea (GGA) or .csv (every sample, status 0
//     too, with its sequence number and arrival time); canyon/rtcm to the raw RTCM 3 stream; canyon/timing and the
//     stage outputs to CSV or text lines; canyon/vio and canyon/timesync to replayable vio.csv and timesync.csv.
//   record TOPIC... --out SESSION.mcap: every sample of every topic as it came off the wire (CDR), with its type's OMG
//     IDL as the channel's schema (io/mcap.hpp, dds/raw_samples.hpp), for Foxglove, the mcap tools and canyon play.
//   echo TOPIC: one line per sample on stdout.
//   monitor: latency percentiles, correction age, queues, drops and the solution of the solution and timing topics,
//     refreshed on the terminal or as JSON lines, and with http_port the live dashboard.
// One class rather than three: the three are one executable with the same options, the same readers for a topic
// and the same way of stopping (stop(), count, duration, every publisher gone); only what happens to a sample
// differs, which is one switch per sample type (on_solution(), on_timing(), ...).

#include <atomic>
#include <cstdint>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "canyon/dds/app.hpp"
#include "canyon/dds/dds.hpp"
#include "canyon/dds/raw_samples.hpp"
#include "canyon/dds/rover_msgs.hpp"
#include "canyon/dds/rtcm_frame.hpp"
#include "canyon/io/mcap.hpp"
#include "canyon/io/nmea.hpp"
#include "canyon/io/pos_file.hpp"
#include "canyon/pipeline/monitor_model.hpp"
#ifdef CANYON_WITH_DASHBOARD
#include "canyon/dashboard/dashboard.hpp"
#endif

namespace canyon::dds {

enum class TopicTool { Record, Echo, Monitor };

/// "record", "echo", "monitor".
[[nodiscard]] const char* tool_name(TopicTool tool);

struct TopicOptions {
  TopicTool tool = TopicTool::Echo;
  std::string topic;                               ///< record, echo: canyon/solution, canyon/rtcm, ... (by suffix)
  std::vector<std::string> more_topics;            ///< record to .mcap: the other topics of the session
  std::string out;                                 ///< record: .pos, .nmea, .csv, .rtcm3, .mcap or another text file
  io::McapWriterOptions mcap;                      ///< record to .mcap: compression (chunk_size from mcap_chunk_kib)
  int mcap_chunk_kib = 256;                        ///< record to .mcap: uncompressed KiB per chunk
  int domain = 0;                                  ///< DDS domain id
  std::string profiles;                            ///< deployment profile file on top of the shipped QoS; "": none
  std::int64_t count = 0;                          ///< stop after this many samples; 0: no limit
  double duration_s = 0.0;                         ///< stop after this long (s); 0: no limit
  bool until_gone = true;                          ///< stop once every matched publisher has left
  bool json = false;                               ///< monitor: JSON lines instead of the terminal page
  double interval_s = 1.0;                         ///< monitor: refresh period (s)
  std::string solution_topic = "canyon/solution";  ///< monitor
  std::string timing_topic = "canyon/timing";      ///< monitor
#ifdef CANYON_WITH_DASHBOARD
  int http_port = -1;                  ///< monitor: also serve the live dashboard on this port; -1: no dashboard
  dashboard::ServerOptions dashboard;  ///< monitor with http_port: host and page folder (its port is http_port)
#endif
};

class TopicApp {
 public:
  /// Checks the topic, loads the profiles, starts the dashboard, creates the participant, the output file and the
  /// readers; AppError if any fails.
  explicit TopicApp(TopicOptions options);
  ~TopicApp();
  TopicApp(const TopicApp&) = delete;
  TopicApp& operator=(const TopicApp&) = delete;

  /// Takes samples until stop(), the count, the duration, or every matched publisher gone; closes the outputs.
  /// 0, or 1 after a write error or a malformed sample (reported on stderr).
  int run();
  /// Ends run() promptly (thread- and async-signal-safe).
  void stop() { stop_.store(true); }

  /// Samples received so far.
  [[nodiscard]] std::int64_t received() const { return received_.load(); }
  /// Publishers matched by the readers now.
  [[nodiscard]] int matched() const;

 private:
  struct AnyReader;
  struct McapReader;
  /// record to .mcap: a raw reader, a schema and a channel per topic.
  void create_mcap_readers();
  [[nodiscard]] std::vector<std::string> mcap_topics() const;
  void on_mcap_sample(std::uint16_t channel, RawSample&& bytes, std::uint64_t publish_time_ns);
  void start_dashboard();
  void open_record_output();
  void create_readers();
  template <typename Reader, typename Msg>
  void add_reader(const std::string& topic, const char* profile, void (TopicApp::*on_sample)(Msg&&));
  void on_solution(msg::Solution&& m);
  void record_solution(const msg::Solution& m, std::int64_t now);
  void on_timing(msg::StageTiming&& m);
  void on_rtcm(msg::RtcmFrame&& m);
  void on_bridged(msg::BridgedEpoch&& m) { on_text(describe(m)); }
  void on_prior(msg::Prior&& m) { on_text(describe(m)); }
  void on_float(msg::FloatSolution&& m) { on_text(describe(m)); }
  void on_alignment(msg::Alignment&& m) { on_text(describe(m)); }
  void on_vio(msg::VioPose&& m);
  void on_timesync(msg::TimeSyncSample&& m);
  /// A sample as one line of text: printed (echo) or written (record).
  void on_text(const std::string& line);
  void note_error(const std::string& error);  ///< the first error (under mutex_)
  /// The monitor's snapshot: terminal page or JSON line, and the dashboard's.
  void report();
  void wait_until_done();
  void close_outputs();

  TopicOptions options_;
  bool solutions_ = false;  ///< the topic is canyon/solution
#ifdef CANYON_WITH_DASHBOARD
  std::unique_ptr<dashboard::DashboardServer> dashboard_;
#endif
  std::unique_ptr<DdsParticipant> participant_;
  std::mutex mutex_;  // the listeners of different readers may run on different threads
  std::atomic<std::int64_t> received_{0};
  std::string error_;
  std::int64_t bad_ = 0;  ///< malformed samples skipped
  std::optional<io::PosWriter> pos_;
  std::optional<io::NmeaWriter> nmea_;
  std::ofstream raw_;
  std::unique_ptr<SessionRecorder> mcap_;  ///< record to .mcap
  pipeline::MonitorModel model_;
  std::vector<std::unique_ptr<AnyReader>> readers_;  ///< last: deleted first, so no callback runs after
  std::atomic<bool> stop_{false};
};

}  // namespace canyon::dds
