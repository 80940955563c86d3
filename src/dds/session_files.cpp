// A recorded session's rover inputs as files (see session_files.hpp).

#include "canyon/dds/session_files.hpp"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <fastdds/rtps/common/SerializedPayload.h>

#include "canyon/dds/observation_msgs.hpp"
#include "canyon/dds/rover_msgs.hpp"
#include "canyon/dds/rtcm_frame.hpp"
#include "canyon/io/gnss_stream.hpp"
#include "canyon/io/mcap.hpp"
#include "canyon/io/rinex_nav.hpp"
#include "canyon/io/rinex_obs.hpp"
#include "canyon/io/vio_file.hpp"

namespace canyon::dds {
namespace {

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

/// The message of a recorded CDR payload (encapsulation header included); false if it does not decode.
template <typename Msg, typename PubSub>
bool decode(const std::vector<std::uint8_t>& bytes, Msg& message) {
  GuardedPubSubType<PubSub> type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(bytes.size()));
  if (!bytes.empty()) std::memcpy(payload.data, bytes.data(), bytes.size());
  payload.length = static_cast<std::uint32_t>(bytes.size());
  return type.deserialize(&payload, &message);
}

/// What one topic of the session gave: its decoded records, and how many messages were refused.
template <typename T>
struct Taken {
  std::vector<T> records;
  std::set<std::uint64_t> sequences;  ///< taken once each
  std::uint64_t refused = 0;
  std::string first_problem;

  void refuse(const std::string& problem) {
    if (refused++ == 0) first_problem = problem;
  }
};

struct SessionInputs {
  Taken<core::ObsEpoch> observations;
  Taken<base::BaseFrame> rtcm;
  Taken<io::VioRecord> vio;
  Taken<io::TimeSyncPair> timesync;
};

/// A recorded message decoded, taken once (by its `sequence`) and converted by its from_msg; refusals counted.
template <typename Msg, typename PubSub, typename T, typename Sequence>
void take_one(const io::McapMessage& m, Taken<T>& taken, Sequence sequence) {
  Msg message;
  if (!decode<Msg, PubSub>(m.data, message)) return taken.refuse("a message that does not decode");
  if (!taken.sequences.insert(static_cast<std::uint64_t>(sequence(message))).second) return;
  auto record = from_msg(message);
  if (!record) return taken.refuse(record.error().to_string());
  taken.records.push_back(std::move(*record));
}

void take(const std::string& topic, const io::McapMessage& m, SessionInputs& in) {
  if (topic.rfind("rt/", 0) == 0) return;  // ROS 2 topics hold outputs only
  const auto by_number = [](const auto& message) { return message.sequence_number(); };
  if (ends_with(topic, "observations")) {
    take_one<msg::GnssObservationEpoch, msg::GnssObservationEpochPubSubType>(m, in.observations, by_number);
  } else if (ends_with(topic, "rtcm")) {
    take_one<msg::RtcmFrame, msg::RtcmFramePubSubType>(m, in.rtcm, by_number);
  } else if (ends_with(topic, "vio")) {
    take_one<msg::VioPose, msg::VioPosePubSubType>(m, in.vio, by_number);
  } else if (ends_with(topic, "timesync")) {
    take_one<msg::TimeSyncSample, msg::TimeSyncSamplePubSubType>(
        m, in.timesync, [](const msg::TimeSyncSample& pair) { return pair.device_time_ns(); });
  }
}

template <typename T>
void note_refused(const char* topic, const Taken<T>& taken, std::vector<std::string>& problems) {
  if (taken.refused == 0) return;
  problems.push_back(std::string(topic) + ": " + std::to_string(taken.refused) +
                     " message(s) left out, the first: " + taken.first_problem);
}

Status write_lines(const std::string& path, const std::string& header, const std::vector<std::string>& rows) {
  std::ofstream out(path, std::ios::trunc);
  out << header << '\n';
  for (const std::string& row : rows) out << row << '\n';
  out.close();
  if (!out) return Error{"cannot write the file", path, 0};
  return Ok{};
}

Status write_rover(const std::vector<core::ObsEpoch>& epochs, const std::string& path) {
  io::RinexObsHeader header;
  header.version = 3.04;
  header.receiver.marker_name = "ROVER";
  header.first_obs = epochs.front().time;
  header.program_date = "20000101 000000 UTC";  // the file depends on the session only
  return io::write_rinex_obs(path, header, epochs);
}

/// The frames as one stream, and the ephemerides in them (RINEX navigation) when there are any.
Status write_base(const std::vector<base::BaseFrame>& frames, const std::optional<core::GpsTime>& reference,
                  SessionFiles& files, const std::string& dir) {
  files.base_rtcm = dir + "/base.rtcm3";
  std::ofstream out(files.base_rtcm, std::ios::binary | std::ios::trunc);
  io::GnssStreamOptions options;
  options.format = io::StreamFormat::Rtcm3;
  if (reference) options.rtcm3.reference_time = *reference;
  io::GnssStreamDecoder decoder(options);
  for (const base::BaseFrame& frame : frames) {
    out.write(reinterpret_cast<const char*>(frame.bytes.data()), static_cast<std::streamsize>(frame.bytes.size()));
    decoder.push(frame.bytes);
  }
  out.close();
  if (!out) return Error{"cannot write the file", files.base_rtcm, 0};
  decoder.finish();
  const core::NavigationData& nav = decoder.navigation();
  if (nav.kepler.empty() && nav.glonass.empty()) return Ok{};
  files.nav = dir + "/nav.rnx";
  return io::write_rinex_nav(files.nav, nav);
}

}  // namespace

Result<SessionFiles> extract_session(const std::string& session, const std::string& dir) {
  std::string problem;
  auto content = io::read_mcap_partial(session, &problem);
  if (!content) return content.error();
  SessionFiles files;
  if (!content->complete) files.problems.push_back(problem + "; the files hold the messages before it");
  SessionInputs in;
  for (const io::McapMessage& m : content->messages) {
    const auto channel = content->channels.find(m.channel_id);
    if (channel != content->channels.end()) take(channel->second.topic, m, in);
  }
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Error{"cannot create the folder: " + ec.message(), dir, 0};
  std::optional<core::GpsTime> first_rover;
  if (!in.observations.records.empty()) {
    files.rover_obs = dir + "/rover.obs";
    first_rover = in.observations.records.front().time;
    if (Status s = write_rover(in.observations.records, files.rover_obs); !s) return s.error();
  }
  if (!in.rtcm.records.empty()) {
    if (Status s = write_base(in.rtcm.records, first_rover, files, dir); !s) return s.error();
  }
  if (!in.vio.records.empty()) {
    files.vio = dir + "/vio.csv";
    std::vector<std::string> rows;
    for (const io::VioRecord& r : in.vio.records) rows.push_back(io::vio_csv_row(r));
    if (Status s = write_lines(files.vio, io::vio_csv_header(), rows); !s) return s.error();
  }
  if (!in.timesync.records.empty()) {
    files.timesync = dir + "/timesync.csv";
    std::vector<std::string> rows;
    for (const io::TimeSyncPair& p : in.timesync.records) rows.push_back(io::timesync_csv_row(p));
    if (Status s = write_lines(files.timesync, io::timesync_csv_header(), rows); !s) return s.error();
  }
  note_refused("canyon/observations", in.observations, files.problems);
  note_refused("canyon/rtcm", in.rtcm, files.problems);
  note_refused("canyon/vio", in.vio, files.problems);
  note_refused("canyon/timesync", in.timesync, files.problems);
  const auto count = [](const char* what, std::size_t n, const std::string& path) {
    return std::string(what) + ": " + std::to_string(n) + (path.empty() ? " (none)" : " -> " + path);
  };
  files.written.push_back(count("rover epochs", in.observations.records.size(), files.rover_obs));
  files.written.push_back(count("base RTCM 3 frames", in.rtcm.records.size(), files.base_rtcm) +
                          (files.nav.empty() ? "" : ", ephemerides -> " + files.nav));
  files.written.push_back(count("VIO poses", in.vio.records.size(), files.vio));
  files.written.push_back(count("time-sync pairs", in.timesync.records.size(), files.timesync));
  return files;
}

}  // namespace canyon::dds
