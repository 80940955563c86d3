// Rover pipeline messages (see rover_msgs.hpp).

#include "canyon/dds/rover_msgs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <Eigen/Cholesky>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/core/protection_level.hpp"

namespace canyon::dds {
namespace {

constexpr std::size_t kMaxSatellites = 128;  // idl bound of the satellite lists
constexpr std::size_t kMaxNote = 255;        // string<256>

using SatName = eprosima::fastrtps::fixed_string<4>;

std::vector<SatName> satellite_names(const std::vector<core::SatelliteId>& sats) {
  std::vector<SatName> names;
  for (const core::SatelliteId& s : sats) {
    if (names.size() >= kMaxSatellites) break;
    names.emplace_back(s.to_string());
  }
  return names;
}

std::array<double, 6> upper(const Eigen::Matrix3d& P) {
  return {P(0, 0), P(0, 1), P(0, 2), P(1, 1), P(1, 2), P(2, 2)};
}

Eigen::Matrix3d from_upper(const std::array<double, 6>& u) {
  Eigen::Matrix3d P;
  P << u[0], u[1], u[2], u[1], u[3], u[4], u[2], u[4], u[5];
  return P;
}

}  // namespace

msg::StageStamps to_msg_stamps(const pipeline::IngestedEpoch& item) {
  msg::StageStamps s;
  s.arrival_monotonic_ns(item.arrival_ns);
  s.base_send_monotonic_ns(item.base_send_ns);
  std::array<std::int64_t, 6> enter{};
  std::array<std::int64_t, 6> exit{};
  for (std::size_t i = 0; i < pipeline::kNumStages; ++i) {
    enter[i] = item.clock.enter_ns[i];
    exit[i] = item.clock.exit_ns[i];
  }
  s.enter_monotonic_ns(enter);
  s.exit_monotonic_ns(exit);
  return s;
}

namespace {

/// A message about `item`'s epoch with its sequence number and the rover epoch's GPST set.
template <typename Msg>
Msg epoch_message(const pipeline::IngestedEpoch& item) {
  Msg m;
  m.sequence_number(item.seq);
  m.gps_week(item.rover.time.week);
  m.gps_tow_s(item.rover.time.tow_s);
  return m;
}

}  // namespace

msg::Solution to_msg_solution(const pipeline::SolvedEpoch& solved, const EpochContext& context) {
  const pipeline::IngestedEpoch& item = solved.epoch();
  msg::Solution m;
  m.sequence_number(item.seq);
  m.rover_id(context.rover_id);
  const core::GpsTime t = solved.output ? solved.output->solution.time : item.rover.time;
  m.gps_week(t.week);
  m.gps_tow_s(t.tow_s);
  if (solved.output) {
    const pipeline::EpochOutput& o = *solved.output;
    const core::Solution& s = o.solution;
    m.status(core::exact_status(s));
    m.p_E_m({s.p_E_m.x(), s.p_E_m.y(), s.p_E_m.z()});
    m.covariance_E_m2(upper(s.P_E_m2));
    const core::ProtectionLevels pl = core::protection_levels(s.p_E_m, s.P_E_m2);
    m.hpl_m(pl.horizontal_m);
    m.vpl_m(pl.vertical_m);
    if (s.v_E_mps) m.v_E_mps({s.v_E_mps->x(), s.v_E_mps->y(), s.v_E_mps->z()});
    const core::Geodetic g = core::ecef_to_geodetic(s.p_E_m);
    m.lat_deg(g.lat_rad * core::kRadToDeg);
    m.lon_deg(g.lon_rad * core::kRadToDeg);
    m.height_m(g.height_m);
    m.num_satellites(static_cast<std::uint8_t>(std::clamp(s.num_satellites, 0, 255)));
    m.ratio(s.ratio);
    m.age_s(s.age_s);
    m.hdop(o.hdop);
    m.aided(o.aided);
    m.pruned(satellite_names(o.ar_pruned));
    m.rejected(satellite_names(o.rejected));
    m.note(o.note.substr(0, kMaxNote));
  } else {
    m.status(0);
    m.hpl_m(std::numeric_limits<double>::quiet_NaN());
    m.vpl_m(std::numeric_limits<double>::quiet_NaN());
    m.note(solved.output.error().message.substr(0, kMaxNote));
  }
  m.stamps(to_msg_stamps(item));
  return m;
}

msg::StageTiming to_msg_timing(const pipeline::SolvedEpoch& solved, const EpochContext& context) {
  const pipeline::IngestedEpoch& item = solved.epoch();
  auto m = epoch_message<msg::StageTiming>(item);
  m.rover_id(context.rover_id);
  m.stamps(to_msg_stamps(item));
  m.correction_age_s(item.base ? item.rover.time - item.base->time : std::numeric_limits<double>::quiet_NaN());
  std::array<std::uint32_t, 5> depth{};
  std::array<std::uint64_t, 5> waits{};
  for (std::size_t i = 0; i < depth.size(); ++i) {
    depth[i] = static_cast<std::uint32_t>(context.queue_depth[i]);
    waits[i] = context.queue_full_waits[i];
  }
  m.queue_depth(depth);
  m.queue_full_waits(waits);
  m.vio_dropped(context.vio_dropped);
  m.vio_late(context.vio_late);
  m.base_late(context.base_late);
  m.malformed_samples(context.malformed_samples);
  const auto losses = [](const pipeline::LinkCounts& c) {
    return std::array<std::uint64_t, 4>{c.dropped_bytes, c.link_failures, c.bad_frames, c.undecodable};
  };
  m.rover_link_losses(losses(item.rover_link));
  m.base_link_losses(losses(item.base_link));
  m.alignment_rmse_m(context.alignment_rmse_m);
  m.alignment_eigen_ratio(context.alignment_eigen_ratio);
  m.lever_arm_m({context.lever_arm_m.x(), context.lever_arm_m.y(), context.lever_arm_m.z()});
  m.publish_monotonic_ns(core::pipeline_now_ns());
  return m;
}

msg::BridgedEpoch to_msg_bridged(const pipeline::SolvedEpoch& solved) {
  const pipeline::IngestedEpoch& item = solved.epoch();
  auto m = epoch_message<msg::BridgedEpoch>(item);
  m.valid(solved.pose().has_value());
  if (solved.pose()) {
    m.vio_segment(solved.pose()->segment);
    const Eigen::Vector3d& p = solved.pose()->T_OI.p;
    const Eigen::Quaterniond& q = solved.pose()->T_OI.q;
    m.p_O_m({p.x(), p.y(), p.z()});
    m.q_OI_xyzw({q.x(), q.y(), q.z(), q.w()});
  }
  m.stamps(to_msg_stamps(item));
  return m;
}

msg::Prior to_msg_prior(const pipeline::SolvedEpoch& solved) {
  const pipeline::IngestedEpoch& item = solved.epoch();
  auto m = epoch_message<msg::Prior>(item);
  if (solved.output && solved.output->has_prior) {
    const pipeline::EpochOutput& o = *solved.output;
    m.aided(true);
    m.p_E_m({o.prior_p_E_m.x(), o.prior_p_E_m.y(), o.prior_p_E_m.z()});
    m.covariance_E_m2(upper(o.prior_P_E_m2));
  }
  m.stamps(to_msg_stamps(item));
  return m;
}

msg::FloatSolution to_msg_float(const pipeline::SolvedEpoch& solved) {
  const pipeline::IngestedEpoch& item = solved.epoch();
  auto m = epoch_message<msg::FloatSolution>(item);
  if (solved.output && solved.output->has_float) {
    const pipeline::EpochOutput& o = *solved.output;
    m.valid(true);
    m.p_E_m({o.float_p_E_m.x(), o.float_p_E_m.y(), o.float_p_E_m.z()});
    m.covariance_E_m2(upper(o.float_P_E_m2));
    m.dd_phase_rows(o.dd_phase_rows);
    m.dd_code_rows(o.dd_code_rows);
    m.max_post_fit_normalised(o.max_post_fit_normalised);
    m.rejected(satellite_names(o.rejected));
  }
  m.stamps(to_msg_stamps(item));
  return m;
}

msg::Alignment to_msg_alignment(const pipeline::SolvedEpoch& solved) {
  const pipeline::IngestedEpoch& item = solved.epoch();
  auto m = epoch_message<msg::Alignment>(item);
  m.kind("none");
  if (solved.output && solved.output->alignment) {
    const pipeline::EpochOutput::Alignment& a = *solved.output->alignment;
    m.aligned(true);
    m.kind(a.kind.substr(0, 15));
    m.rmse_m(a.rmse_m);
    m.first_eigenvalue_ratio(a.first_eigenvalue_ratio);
    m.t_IA_m({a.t_IA_m.x(), a.t_IA_m.y(), a.t_IA_m.z()});
  }
  m.stamps(to_msg_stamps(item));
  return m;
}

std::string describe(const msg::Prior& m) {
  char line[200];
  std::snprintf(line, sizeof line, "prior #%llu %d %.3f %s p_E [%.3f %.3f %.3f] sigma %.3f m",
                static_cast<unsigned long long>(m.sequence_number()), m.gps_week(), m.gps_tow_s(),
                m.aided() ? "aided" : "not-aided", m.p_E_m()[0], m.p_E_m()[1], m.p_E_m()[2],
                std::sqrt(std::max(0.0, m.covariance_E_m2()[0] + m.covariance_E_m2()[3] + m.covariance_E_m2()[5])));
  return line;
}

std::string describe(const msg::FloatSolution& m) {
  char line[200];
  std::snprintf(line, sizeof line, "float #%llu %d %.3f %s p_E [%.3f %.3f %.3f] DD phase %d code %d post-fit %.2f",
                static_cast<unsigned long long>(m.sequence_number()), m.gps_week(), m.gps_tow_s(),
                m.valid() ? "valid" : "none", m.p_E_m()[0], m.p_E_m()[1], m.p_E_m()[2], m.dd_phase_rows(),
                m.dd_code_rows(), m.max_post_fit_normalised());
  return line;
}

std::string describe(const msg::Alignment& m) {
  char line[200];
  std::snprintf(line, sizeof line, "alignment #%llu %d %.3f %s RMSE %.3f m FER %.3f t_IA [%.3f %.3f %.3f] m",
                static_cast<unsigned long long>(m.sequence_number()), m.gps_week(), m.gps_tow_s(), m.kind().c_str(),
                m.rmse_m(), m.first_eigenvalue_ratio(), m.t_IA_m()[0], m.t_IA_m()[1], m.t_IA_m()[2]);
  return line;
}

std::string describe(const msg::VioPose& m) {
  char line[200];
  std::snprintf(line, sizeof line, "vio #%llu t %lld ns p [%.3f %.3f %.3f] m q [%.4f %.4f %.4f %.4f]%s",
                static_cast<unsigned long long>(m.sequence_number()), static_cast<long long>(m.device_time_ns()),
                m.p_O_m()[0], m.p_O_m()[1], m.p_O_m()[2], m.q_OI_xyzw()[0], m.q_OI_xyzw()[1], m.q_OI_xyzw()[2],
                m.q_OI_xyzw()[3], m.has_cross_previous() ? " (with cross-covariance)" : "");
  return line;
}

std::string describe(const msg::TimeSyncSample& m) {
  char line[120];
  std::snprintf(line, sizeof line, "timesync t %lld ns = GPST %d %.9f", static_cast<long long>(m.device_time_ns()),
                m.gps_week(), m.gps_tow_s());
  return line;
}

msg::VioPose to_msg(const io::VioRecord& pose, std::uint64_t sequence_number) {
  msg::VioPose m;
  m.sequence_number(sequence_number);
  m.device_time_ns(pose.t_ns);
  m.p_O_m({pose.T_OI.p.x(), pose.T_OI.p.y(), pose.T_OI.p.z()});
  m.q_OI_xyzw({pose.T_OI.q.x(), pose.T_OI.q.y(), pose.T_OI.q.z(), pose.T_OI.q.w()});
  std::size_t k = 0;
  for (int row = 0; row < 6; ++row) {
    for (int col = row; col < 6; ++col) m.covariance_upper()[k++] = pose.covariance(row, col);
  }
  m.has_cross_previous(pose.cross_previous.has_value());
  if (pose.cross_previous) {
    k = 0;
    for (int row = 0; row < 6; ++row) {
      for (int col = 0; col < 6; ++col) m.cross_previous()[k++] = (*pose.cross_previous)(row, col);
    }
  }
  m.send_monotonic_ns(core::pipeline_now_ns());
  return m;
}

Result<io::VioRecord> from_msg(const msg::VioPose& m) {
  const std::string which = "VioPose " + std::to_string(m.sequence_number());
  const auto finite = [](const auto& values) {
    return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
  };
  if (!finite(m.p_O_m()) || !finite(m.q_OI_xyzw()) || !finite(m.covariance_upper()) ||
      (m.has_cross_previous() && !finite(m.cross_previous()))) {
    return Error{which + ": a value is not finite"};
  }
  io::VioRecord r;
  r.t_ns = m.device_time_ns();
  r.line = static_cast<int>(m.sequence_number() % 1000000000);
  r.T_OI.p = Eigen::Vector3d(m.p_O_m()[0], m.p_O_m()[1], m.p_O_m()[2]);
  const Eigen::Quaterniond q(m.q_OI_xyzw()[3], m.q_OI_xyzw()[0], m.q_OI_xyzw()[1], m.q_OI_xyzw()[2]);
  const double norm = q.norm();
  if (!(norm >= 0.5 && norm <= 1.5)) {
    return Error{which + ": quaternion norm " + std::to_string(norm) + ", not a rotation"};
  }
  // A quaternion normalised by the sender stays bit for bit as sent.
  r.T_OI.q = std::abs(norm - 1.0) <= 1e-12 ? q : q.normalized();
  std::size_t k = 0;
  for (int row = 0; row < 6; ++row) {
    for (int col = row; col < 6; ++col) r.covariance(row, col) = r.covariance(col, row) = m.covariance_upper()[k++];
  }
  if (Eigen::LLT<core::Matrix6d>(r.covariance).info() != Eigen::Success) {
    return Error{which + ": covariance is not positive definite"};
  }
  if (m.has_cross_previous()) {
    core::Matrix6d c;
    k = 0;
    for (int row = 0; row < 6; ++row) {
      for (int col = 0; col < 6; ++col) c(row, col) = m.cross_previous()[k++];
    }
    r.cross_previous = c;
  }
  return r;
}

msg::TimeSyncSample to_msg(const io::TimeSyncPair& pair) {
  msg::TimeSyncSample m;
  m.device_time_ns(pair.t_ns);
  m.gps_week(pair.time.week);
  m.gps_tow_s(pair.time.tow_s);
  return m;
}

Result<io::TimeSyncPair> from_msg(const msg::TimeSyncSample& m) {
  if (m.gps_week() < 0 || !(m.gps_tow_s() >= 0.0 && m.gps_tow_s() < core::kSecondsPerWeek)) {
    return Error{"TimeSyncSample: GPS time " + std::to_string(m.gps_week()) + " " + std::to_string(m.gps_tow_s()) +
                 " out of range"};
  }
  io::TimeSyncPair p;
  p.t_ns = m.device_time_ns();
  p.time = core::GpsTime{static_cast<int>(m.gps_week()), m.gps_tow_s()};
  return p;
}

Result<core::Solution> from_msg(const msg::Solution& m) {
  const std::string which = "Solution " + std::to_string(m.sequence_number());
  const int status = m.status();
  if (status != 0 && status != 1 && status != 2 && status != 5 && status != 7 && status != core::kPartialFixStatus) {
    return Error{which + ": status " + std::to_string(status) + " is not 0, 1, 2, 5, 7 or 8"};
  }
  if (m.pruned().size() > kMaxSatellites || m.rejected().size() > kMaxSatellites || m.note().size() > kMaxNote) {
    return Error{which + ": a list exceeds its IDL bound"};
  }
  core::Solution s;
  s.time = core::GpsTime{m.gps_week(), m.gps_tow_s()};
  // A partial fix is a float conditioned on fixed combinations (how many is not on the wire: at least one).
  s.status =
      status == core::kPartialFixStatus ? core::SolutionStatus::Float : static_cast<core::SolutionStatus>(status);
  s.fixed_combinations = status == core::kPartialFixStatus ? 1 : 0;
  s.p_E_m = Eigen::Vector3d(m.p_E_m()[0], m.p_E_m()[1], m.p_E_m()[2]);
  s.P_E_m2 = from_upper(m.covariance_E_m2());
  s.num_satellites = m.num_satellites();
  s.age_s = m.age_s();
  s.ratio = m.ratio();
  if (status != 0 && (!s.p_E_m.allFinite() || !std::isfinite(m.gps_tow_s()))) return Error{which + ": not finite"};
  if (m.hpl_m() < 0.0 || m.vpl_m() < 0.0) return Error{which + ": a negative protection level"};
  return s;
}

pipeline::SolutionSample to_sample(const msg::Solution& m, std::int64_t received_ns) {
  pipeline::SolutionSample s;
  s.rover_id = m.rover_id().to_string();
  s.seq = m.sequence_number();
  s.status = m.status();
  s.lat_deg = m.lat_deg();
  s.lon_deg = m.lon_deg();
  s.height_m = m.height_m();
  s.n_sats = m.num_satellites();
  s.ratio = m.ratio();
  s.hpl_m = m.hpl_m();
  s.vpl_m = m.vpl_m();
  for (const auto& p : m.pruned()) s.pruned.push_back(p.to_string());
  s.arrival_ns = m.stamps().arrival_monotonic_ns();
  s.base_send_ns = m.stamps().base_send_monotonic_ns();
  s.received_ns = received_ns;
  return s;
}

pipeline::TimingSample to_sample(const msg::StageTiming& m) {
  pipeline::TimingSample s;
  s.rover_id = m.rover_id().to_string();
  s.seq = m.sequence_number();
  s.arrival_ns = m.stamps().arrival_monotonic_ns();
  for (std::size_t i = 0; i < pipeline::kMonitorStages; ++i) {
    s.enter_ns[i] = m.stamps().enter_monotonic_ns()[i];
    s.exit_ns[i] = m.stamps().exit_monotonic_ns()[i];
  }
  s.correction_age_s = m.correction_age_s();
  for (std::size_t i = 0; i < pipeline::kMonitorQueues; ++i) {
    s.queue_depth[i] = m.queue_depth()[i];
    s.queue_full_waits[i] = m.queue_full_waits()[i];
  }
  s.vio_dropped = m.vio_dropped();
  s.vio_late = m.vio_late();
  s.base_late = m.base_late();
  s.malformed_samples = m.malformed_samples();
  const auto counts = [](const std::array<std::uint64_t, 4>& a) {
    return pipeline::LinkCounts{a[0], a[1], a[2], a[3]};
  };
  s.rover_link = counts(m.rover_link_losses());
  s.base_link = counts(m.base_link_losses());
  s.alignment_rmse_m = m.alignment_rmse_m();
  s.alignment_eigen_ratio = m.alignment_eigen_ratio();
  s.lever_arm_m = Eigen::Vector3d(m.lever_arm_m()[0], m.lever_arm_m()[1], m.lever_arm_m()[2]);
  return s;
}

std::string describe(const msg::Solution& m) {
  char line[512];
  std::string pruned;
  for (const auto& p : m.pruned()) pruned += " " + p.to_string();
  std::snprintf(line, sizeof line,
                "solution #%llu %s %d %.3f Q%d %.9f %.9f %.4f ns %d ratio %.1f age %.1f HPL %.3f VPL %.3f%s%s%s",
                static_cast<unsigned long long>(m.sequence_number()), m.rover_id().c_str(), m.gps_week(), m.gps_tow_s(),
                m.status(), m.lat_deg(), m.lon_deg(), m.height_m(), m.num_satellites(), m.ratio(), m.age_s(), m.hpl_m(),
                m.vpl_m(), pruned.empty() ? "" : " pruned", pruned.c_str(),
                m.note().size() == 0 ? "" : (" (" + m.note().to_string() + ")").c_str());
  return line;
}

std::string describe(const msg::StageTiming& m) {
  std::string line = "timing #" + std::to_string(m.sequence_number()) + " " + m.rover_id().to_string() + " us:";
  const char* names[] = {"ingest", "bridge", "align", "predict", "update", "ambiguity"};
  for (std::size_t i = 0; i < 6; ++i) {
    char part[48];
    std::snprintf(part, sizeof part, " %s %.1f", names[i],
                  static_cast<double>(m.stamps().exit_monotonic_ns()[i] - m.stamps().enter_monotonic_ns()[i]) * 1e-3);
    line += part;
  }
  char tail[96];
  std::snprintf(tail, sizeof tail, " end-to-end %.1f",
                static_cast<double>(m.stamps().exit_monotonic_ns()[5] - m.stamps().arrival_monotonic_ns()) * 1e-3);
  return line + tail;
}

std::string describe(const msg::BridgedEpoch& m) {
  char line[200];
  std::snprintf(line, sizeof line, "bridged #%llu %d %.3f %s segment %d p_O [%.3f %.3f %.3f]",
                static_cast<unsigned long long>(m.sequence_number()), m.gps_week(), m.gps_tow_s(),
                m.valid() ? "pose" : "no-pose", m.vio_segment(), m.p_O_m()[0], m.p_O_m()[1], m.p_O_m()[2]);
  return line;
}

}  // namespace canyon::dds
