// canyon_ros2_raw: DDS samples of any type as raw serialized bytes, without canyon's IDL (tests/ros2/): the test's
// independent decoders (tests/ros2/wire_check.mjs) read what canyon put on the wire, and write what canyon reads.
//
//   canyon_ros2_raw record --topic T --type NAME --qos sensor|default --out FILE [--count N] [--timeout S] [--domain D]
//       takes every sample of DDS topic T (type name NAME, e.g. sensor_msgs::msg::dds_::NavSatFix_) and appends it to
//       FILE as a 4-byte little-endian length and the serialized payload (its CDR encapsulation header included);
//       ends after N samples, or S seconds (default 60) without one after the first.
//   canyon_ros2_raw publish --topic T --type NAME --qos sensor|default --in FILE [--rate HZ] [--wait-readers N]
//                           [--domain D]
//       publishes FILE's payloads (same framing) in order at HZ (default 50) once N readers matched (default 1), and
//       a second more (the readers' side of the discovery).
// QoS: ROS 2's sensor-data (best effort, keep last 5) or default (reliable, keep last 10) profiles of the shipped
// file, config/dds/canyon_profiles.xml. Exit 0 done, 1 a DDS or file error, 2 bad command line, 3 timeout.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>

#include "canyon/dds/dds.hpp"
#include "canyon/dds/profiles.hpp"
#include "canyon/dds/raw_samples.hpp"

namespace {

namespace fdds = eprosima::fastdds::dds;
using Bytes = canyon::dds::RawSample;

struct Args {
  std::string mode, topic, type, qos = "sensor", file;
  long count = 0;
  double timeout_s = 60.0;
  double rate_hz = 50.0;
  int wait_readers = 1;
  int domain = 0;
};

bool parse(int argc, char** argv, Args& a) {
  if (argc < 2) return false;
  a.mode = argv[1];
  const std::map<std::string, std::function<void(const std::string&)>> options = {
      {"--topic", [&](const std::string& v) { a.topic = v; }},
      {"--type", [&](const std::string& v) { a.type = v; }},
      {"--qos", [&](const std::string& v) { a.qos = v; }},
      {"--out", [&](const std::string& v) { a.file = v; }},
      {"--in", [&](const std::string& v) { a.file = v; }},
      {"--count", [&](const std::string& v) { a.count = std::stol(v); }},
      {"--timeout", [&](const std::string& v) { a.timeout_s = std::stod(v); }},
      {"--rate", [&](const std::string& v) { a.rate_hz = std::stod(v); }},
      {"--wait-readers", [&](const std::string& v) { a.wait_readers = std::stoi(v); }},
      {"--domain", [&](const std::string& v) { a.domain = std::stoi(v); }},
  };
  for (int i = 2; i + 1 < argc; i += 2) {
    const auto it = options.find(argv[i]);
    if (it == options.end()) return false;
    it->second(argv[i + 1]);
  }
  return (a.mode == "record" || a.mode == "publish") && !a.topic.empty() && !a.type.empty() && !a.file.empty() &&
         (a.qos == "sensor" || a.qos == "default");
}

struct Recorder : fdds::DataReaderListener {
  std::ofstream out;
  std::atomic<long> samples{0};
  std::atomic<std::int64_t> last_ns{0};
  void on_data_available(fdds::DataReader* reader) override {
    Bytes bytes;
    fdds::SampleInfo info;
    while (reader->take_next_sample(&bytes, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      const auto n = static_cast<std::uint32_t>(bytes.size());
      const std::uint8_t length[4] = {static_cast<std::uint8_t>(n), static_cast<std::uint8_t>(n >> 8U),
                                      static_cast<std::uint8_t>(n >> 16U), static_cast<std::uint8_t>(n >> 24U)};
      out.write(reinterpret_cast<const char*>(length), 4);
      out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(n));
      out.flush();
      samples.fetch_add(1);
      last_ns.store(std::chrono::steady_clock::now().time_since_epoch().count());
    }
  }
};

std::vector<Bytes> read_frames(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::vector<Bytes> frames;
  std::uint8_t length[4];
  while (in.read(reinterpret_cast<char*>(length), 4)) {
    const std::uint32_t n = length[0] | (length[1] << 8U) | (length[2] << 16U) | (std::uint32_t(length[3]) << 24U);
    Bytes bytes(n);
    if (!in.read(reinterpret_cast<char*>(bytes.data()), n)) throw std::runtime_error(path + ": a frame is cut short");
    frames.push_back(std::move(bytes));
  }
  return frames;
}

int run(const Args& a) {
  auto profiles = canyon::dds::load_profiles("");
  if (!profiles) throw std::runtime_error(profiles.error().to_string());
  auto participant = canyon::dds::DdsParticipant::create(a.domain, canyon::dds::profile::kParticipant);
  if (!participant) throw std::runtime_error(participant.error().to_string());
  auto topic = (*participant)->topic(a.topic, fdds::TypeSupport(new canyon::dds::RawSampleType(a.type)));
  if (!topic) throw std::runtime_error(topic.error().to_string());
  fdds::DomainParticipant* p = (*participant)->get();
  const bool sensor = a.qos == "sensor";
  if (a.mode == "record") {
    Recorder recorder;
    recorder.out.open(a.file, std::ios::binary | std::ios::trunc);
    if (!recorder.out) throw std::runtime_error("cannot write " + a.file);
    fdds::Subscriber* subscriber = p->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
    fdds::DataReader* reader = subscriber->create_datareader_with_profile(
        *topic, sensor ? canyon::dds::profile::kRos2SensorDataReader : canyon::dds::profile::kRos2DefaultReader,
        &recorder);
    if (reader == nullptr) throw std::runtime_error("cannot create the data reader");
    const auto start = std::chrono::steady_clock::now();
    int rc = 0;
    while (a.count == 0 || recorder.samples.load() < a.count) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      const std::int64_t last = recorder.last_ns.load();
      const auto now = std::chrono::steady_clock::now();
      const double idle_s = last == 0 ? std::chrono::duration<double>(now - start).count()
                                      : 1e-9 * double(now.time_since_epoch().count() - last);
      if (idle_s > a.timeout_s) {
        rc = a.count > 0 || last == 0 ? 3 : 0;
        break;
      }
    }
    reader->set_listener(nullptr);
    subscriber->delete_datareader(reader);
    p->delete_subscriber(subscriber);
    std::fprintf(stderr, "canyon_ros2_raw: %ld samples of %s on %s\n", recorder.samples.load(), a.type.c_str(),
                 a.topic.c_str());
    return rc;
  }
  const std::vector<Bytes> frames = read_frames(a.file);
  fdds::Publisher* publisher = p->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
  fdds::DataWriter* writer = publisher->create_datawriter_with_profile(
      *topic, sensor ? canyon::dds::profile::kRos2SensorDataWriter : canyon::dds::profile::kRos2DefaultWriter);
  if (writer == nullptr) throw std::runtime_error("cannot create the data writer");
  fdds::PublicationMatchedStatus matched;
  const auto start = std::chrono::steady_clock::now();
  while (writer->get_publication_matched_status(matched) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK &&
         matched.current_count < a.wait_readers) {
    if (std::chrono::steady_clock::now() - start > std::chrono::duration<double>(a.timeout_s)) return 3;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  // Matched on this side does not mean the reader has matched this writer yet (discovery is two-way): settle.
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const auto period = std::chrono::duration<double>(1.0 / a.rate_hz);
  auto next = std::chrono::steady_clock::now();
  for (Bytes frame : frames) {
    std::this_thread::sleep_until(next);
    next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
    if (!writer->write(&frame)) throw std::runtime_error("a write was refused");
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  publisher->delete_datawriter(writer);
  p->delete_publisher(publisher);
  std::fprintf(stderr, "canyon_ros2_raw: published %zu samples of %s on %s\n", frames.size(), a.type.c_str(),
               a.topic.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (!parse(argc, argv, args)) {
    std::cerr << "usage: canyon_ros2_raw record|publish --topic T --type NAME --qos sensor|default "
                 "--out FILE|--in FILE [--count N] [--timeout S] [--rate HZ] [--wait-readers N] [--domain D]\n";
    return 2;
  }
  try {
    return run(args);
  } catch (const std::exception& e) {
    std::cerr << "canyon_ros2_raw: error: " << e.what() << "\n";
    return 1;
  }
}
