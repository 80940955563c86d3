#pragma once
// canyon play: publishes an MCAP session recorded by canyon record again, so that a field session re-runs at the
// desk: every message of every channel canyon knows, as the bytes it recorded, on the channel's topic with the
// channel's type name and the QoS profile of the topic's original writer, in recorded order at the recorded pace
// (--pace; 0: as fast as the writers take them). (app.hpp: constructed, run() once, stop() from anywhere.)
// Bad input: a file cut short plays the messages before the cut (a warning names the byte); a channel whose schema
// canyon does not know (another encoding, another type, a topic canyon does not publish) is left out with a warning
// naming it; a file with no channel to play is an error, and so is a selected topic (--topic) the file does not have.

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "canyon/dds/app.hpp"
#include "canyon/dds/dds.hpp"
#include "canyon/io/mcap.hpp"

namespace canyon::dds {

struct PlayOptions {
  std::string session;              ///< the MCAP file
  double pace = 1.0;                ///< 1 real time, 10 ten times faster, 0 as fast as the writers take them
  std::vector<std::string> topics;  ///< play only these (each must be in the session); empty: every channel
  int domain = 0;                   ///< DDS domain id
  std::string profiles;             ///< deployment profile file on top of the shipped QoS; "": none
  int wait_readers = 0;             ///< start once this many readers of each played topic are matched
  double wait_timeout_s = 30.0;     ///< give up waiting for readers after this long (s)
  double linger_s = 2.0;            ///< at the end, stay up this long (s) while readers are matched
};

class PlayApp {
 public:
  /// Reads the session, loads the profiles, creates the participant and a writer per channel; AppError if any fails.
  explicit PlayApp(PlayOptions options);
  ~PlayApp();
  PlayApp(const PlayApp&) = delete;
  PlayApp& operator=(const PlayApp&) = delete;

  /// Publishes every message (or until stop()); 0, or 1 if the writers refused samples.
  int run();
  void stop() { stop_.store(true); }

 private:
  struct Channel;
  bool wait_for_readers() const;

  PlayOptions options_;
  io::McapContent session_;
  std::unique_ptr<DdsParticipant> participant_;
  std::vector<std::unique_ptr<Channel>> channels_;  ///< by MCAP channel id (null: not played)
  std::atomic<bool> stop_{false};
};

}  // namespace canyon::dds
