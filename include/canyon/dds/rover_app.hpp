#pragma once
// canyon rover: the real-time rover. The rover's observations (RINEX replayed at real-time pace or faster, or a
// receiver's UBX), base corrections (a RINEX file, the DDS RtcmFrame topic, NTRIP or TCP), VIO from files or from the
// DDS VioPose and TimeSyncSample topics, through the six-stage pipeline (pipeline/epoch_pipeline.hpp, the stages of
// canyon process); solutions and stage timing published on DDS (RoverOutputs). app.hpp: constructed, run() once,
// stop() from anywhere: ingest stops, the epochs in flight are finished and published.

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <readerwriterqueue/readerwritercircularbuffer.h>

#include "canyon/commands/process.hpp"
#include "canyon/config/rover_config.hpp"
#include "canyon/dds/app.hpp"
#include "canyon/dds/dds.hpp"
#include "canyon/dds/ros2_msgs.hpp"
#include "canyon/dds/rover_msgs.hpp"
#include "canyon/dds/rover_outputs.hpp"
#include "canyon/dds/rtcm_frame.hpp"
#include "canyon/fusion/fusion_engine.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/pipeline/epoch_pipeline.hpp"
#include "canyon/pipeline/live_vio.hpp"
#include "canyon/pipeline/rover_ingest.hpp"
#include "canyon/rtk/engine.hpp"

namespace canyon::dds {

struct RoverOptions {
  config::RoverConfig config;    ///< validated (config::RoverConfig::validate, pipeline.unavailable_cpu)
  std::string config_file;       ///< the YAML file, for messages
  int wait_subscribers = 0;      ///< start once this many readers of the solution topic are matched
  double wait_timeout_s = 30.0;  ///< give up waiting for them after this long (s)
};

class RoverApp {
 public:
  /// Loads the profiles, creates the participant, the writers and the readers, opens the rover and base inputs,
  /// builds the estimator and the pipeline; AppError if any fails (2 for the profiles and the base input, else 1).
  explicit RoverApp(RoverOptions options);
  ~RoverApp();
  RoverApp(const RoverApp&) = delete;
  RoverApp& operator=(const RoverApp&) = delete;

  /// Runs the pipeline until the rover input ends, stop() or an error; 0, or 1 on an error.
  int run();
  /// Stops ingest; the epochs already ingested are finished and published (thread- and async-signal-safe).
  void stop();

  /// Epochs through the sink, solved and fixed so far (after run(): the run's).
  [[nodiscard]] std::uint64_t epochs() const { return outputs_->epochs(); }
  [[nodiscard]] std::uint64_t solved() const { return outputs_->solved(); }
  [[nodiscard]] std::uint64_t fixed() const { return outputs_->fixed(); }
  /// input.vio dds: what the live VIO received and used so far.
  [[nodiscard]] std::optional<pipeline::LiveVioCounts> live_vio_counts() const {
    return live_vio_ ? std::optional(live_vio_->counts()) : std::nullopt;
  }

 private:
  /// An RTCM frame from the DDS listener to ingest.
  struct BaseFrameSample {
    std::vector<std::uint8_t> bytes;
    std::int64_t send_ns = 0;
  };
  void create_rtcm_reader();
  void build_estimator(commands::ProcessSummary& notes);
  void open_live_vio();
  /// input.vio ros2: the Odometry reader that fills the live VIO (refused samples named in the log).
  void open_ros2_vio(pipeline::LiveVio& feed);
  void open_pos();
  pipeline::BaseInput open_base(const io::ObsFilter& filter, const std::optional<core::GpsTime>& rover_start);
  void build_pipeline(pipeline::RoverInput rover, pipeline::BaseInput base);
  void wait_for_subscribers() const;
  void log_start() const;
  void report_inputs() const;
  void report_stats(double wall_s) const;

  RoverOptions options_;
  const config::RoverConfig& config_;  ///< options_.config
  std::atomic<bool> stop_{false};
  std::unique_ptr<DdsParticipant> participant_;
  std::unique_ptr<RoverOutputs> outputs_;
  // Base frames: the DDS listener only queues them (dropped and counted when the queue is full).
  moodycamel::BlockingReaderWriterCircularBuffer<BaseFrameSample> base_frames_;
  std::atomic<std::uint64_t> base_frames_dropped_{0};
  std::atomic<std::uint64_t> base_frames_bad_{0};
  std::unique_ptr<RtcmReader> rtcm_reader_;
  std::unique_ptr<gnss::EphemerisStore> ephemerides_;  // grows by the streams' ephemerides (EphemerisFeed)
  Eigen::Vector3d p_E_base_ = Eigen::Vector3d::Zero();
  std::shared_ptr<pipeline::ByteLink> base_link_;  // ntrip, tcp: the link (the rover's position goes up as GGA)
  std::unique_ptr<rtk::RtkEngine> rtk_engine_;
  std::unique_ptr<fusion::FusionEngine> fusion_engine_;
  std::unique_ptr<pipeline::LiveVio> live_vio_;
  std::unique_ptr<VioPoseReader> vio_reader_;
  std::unique_ptr<TimeSyncReader> timesync_reader_;
  std::unique_ptr<OdometryReader> ros2_vio_reader_;  // input.vio ros2
  std::unique_ptr<pipeline::EpochEstimator> estimator_;
  std::unique_ptr<pipeline::EphemerisFeed> feed_;
  std::unique_ptr<pipeline::RoverIngest> source_;
  std::unique_ptr<pipeline::EpochPipeline> pipeline_;
};

}  // namespace canyon::dds
