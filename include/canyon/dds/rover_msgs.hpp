#pragma once
// idl/RoverPipeline.idl <-> canyon's types: the rover's stage outputs as messages, and messages back to what the
// consumers need (core::Solution for .pos files, the monitor's samples). Sizes are checked here (Fast DDS does not
// enforce IDL bounds).

#include <cstdint>
#include <string>
#include <vector>

#include "canyon/core/result.hpp"
#include "canyon/core/solution.hpp"
#include "canyon/dds/dds.hpp"
#include "canyon/io/vio_file.hpp"
#include "canyon/pipeline/epoch_pipeline.hpp"
#include "canyon/pipeline/monitor_model.hpp"

#include "RoverPipeline.h"
#include "RoverPipelinePubSubTypes.h"

namespace canyon::dds {

/// What the rover adds to an epoch's solution for its messages.
struct EpochContext {
  std::string rover_id;
  std::array<std::size_t, pipeline::kNumStages - 1> queue_depth{};
  std::array<std::uint64_t, pipeline::kNumStages - 1> queue_full_waits{};
  std::uint64_t vio_dropped = 0;  ///< VIO poses and pairs dropped (pipeline::LiveVio queue full)
  std::uint64_t vio_late = 0;     ///< epochs that went on without their VIO (pipeline::LiveVio)
  std::uint64_t base_late = 0;
  std::uint64_t malformed_samples = 0;  ///< DDS samples refused as malformed (GuardedPubSubType)
  double alignment_rmse_m = 0.0;        ///< NaN: not aligned
  double alignment_eigen_ratio = 0.0;
  Eigen::Vector3d lever_arm_m = Eigen::Vector3d::Zero();
};

[[nodiscard]] msg::StageStamps to_msg_stamps(const pipeline::IngestedEpoch& item);
/// The epoch's solution (status 0 with the reason in `note` when it has none).
[[nodiscard]] msg::Solution to_msg_solution(const pipeline::SolvedEpoch& solved, const EpochContext& context);
[[nodiscard]] msg::StageTiming to_msg_timing(const pipeline::SolvedEpoch& solved, const EpochContext& context);
[[nodiscard]] msg::BridgedEpoch to_msg_bridged(const pipeline::SolvedEpoch& solved);
/// The prediction's prior, the update's float solution and the alignment in use, of an epoch that left the last
/// stage (the engines hand them over with the epoch's result).
[[nodiscard]] msg::Prior to_msg_prior(const pipeline::SolvedEpoch& solved);
[[nodiscard]] msg::FloatSolution to_msg_float(const pipeline::SolvedEpoch& solved);
[[nodiscard]] msg::Alignment to_msg_alignment(const pipeline::SolvedEpoch& solved);

/// The solution for a .pos/NMEA writer; Error if the message is malformed (bad status, sizes, non-finite values).
Result<core::Solution> from_msg(const msg::Solution& m);
[[nodiscard]] pipeline::SolutionSample to_sample(const msg::Solution& m, std::int64_t received_ns);
[[nodiscard]] pipeline::TimingSample to_sample(const msg::StageTiming& m);

/// VIO poses and time-sync pairs (vio.csv and timesync.csv records) <-> messages, exactly (no value is rounded or
/// re-normalised on the way, so a rover fed over DDS sees the numbers canyon process reads from the files). Error if
/// the message is malformed: a non-finite value, a quaternion that is not a rotation, a GPS time out of range.
[[nodiscard]] msg::VioPose to_msg(const io::VioRecord& pose, std::uint64_t sequence_number);
Result<io::VioRecord> from_msg(const msg::VioPose& m);
[[nodiscard]] msg::TimeSyncSample to_msg(const io::TimeSyncPair& pair);
Result<io::TimeSyncPair> from_msg(const msg::TimeSyncSample& m);

using SolutionWriter = DdsWriter<msg::Solution, msg::SolutionPubSubType>;
using SolutionReader = DdsReader<msg::Solution, msg::SolutionPubSubType>;
using TimingWriter = DdsWriter<msg::StageTiming, msg::StageTimingPubSubType>;
using TimingReader = DdsReader<msg::StageTiming, msg::StageTimingPubSubType>;
using BridgedWriter = DdsWriter<msg::BridgedEpoch, msg::BridgedEpochPubSubType>;
using BridgedReader = DdsReader<msg::BridgedEpoch, msg::BridgedEpochPubSubType>;
using PriorWriter = DdsWriter<msg::Prior, msg::PriorPubSubType>;
using PriorReader = DdsReader<msg::Prior, msg::PriorPubSubType>;
using FloatWriter = DdsWriter<msg::FloatSolution, msg::FloatSolutionPubSubType>;
using FloatReader = DdsReader<msg::FloatSolution, msg::FloatSolutionPubSubType>;
using AlignmentWriter = DdsWriter<msg::Alignment, msg::AlignmentPubSubType>;
using AlignmentReader = DdsReader<msg::Alignment, msg::AlignmentPubSubType>;
using VioPoseWriter = DdsWriter<msg::VioPose, msg::VioPosePubSubType>;
using VioPoseReader = DdsReader<msg::VioPose, msg::VioPosePubSubType>;
using TimeSyncWriter = DdsWriter<msg::TimeSyncSample, msg::TimeSyncSamplePubSubType>;
using TimeSyncReader = DdsReader<msg::TimeSyncSample, msg::TimeSyncSamplePubSubType>;

/// One line of text per message (canyon echo).
[[nodiscard]] std::string describe(const msg::Solution& m);
[[nodiscard]] std::string describe(const msg::StageTiming& m);
[[nodiscard]] std::string describe(const msg::BridgedEpoch& m);
[[nodiscard]] std::string describe(const msg::Prior& m);
[[nodiscard]] std::string describe(const msg::FloatSolution& m);
[[nodiscard]] std::string describe(const msg::Alignment& m);
[[nodiscard]] std::string describe(const msg::VioPose& m);
[[nodiscard]] std::string describe(const msg::TimeSyncSample& m);

}  // namespace canyon::dds
