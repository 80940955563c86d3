// The fusion's summary for the end of a run (see FusionEngine::report()).

#include <cstdio>

#include "canyon/core/constants.hpp"
#include "canyon/fusion/fusion_engine.hpp"

namespace canyon::fusion {
namespace {

std::string format(const char* fmt, double a, double b = 0.0, double c = 0.0, double d = 0.0) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, fmt, a, b, c, d);
  return buffer;
}

}  // namespace

std::vector<std::string> FusionEngine::report() const {
  std::vector<std::string> lines;
  const FusionStats& s = stats_;
  lines.push_back(
      format("fusion: %.0f epochs: %.0f VIO-aided, %.0f VIO fill-in (Q 7), %.0f RTK motion model "
             "(not aligned or no VIO)",
             s.epochs, s.aided, s.fill_in, s.fallback));
  lines.push_back(
      format("fusion: heading-free VIO fill-in (Q 7; not aligned, no GNSS solution): %.0f epochs", s.heading_free));
  lines.push_back(
      format("fusion: float validation failed: %.0f no DD phase, %.0f post-fit residuals, %.0f "
             "inconsistent with the VIO prior",
             s.float_rejected_no_phase, s.float_rejected_post_fit, s.float_rejected_prior));
  lines.push_back(
      format("fusion: false-fix guard fired in %.0f epochs (%.0f candidate fixes); %.0f fixes after ILS "
             "pruning; %.0f DD rows gated",
             s.guard_epochs, s.guard_candidates, s.ar_pruned_epochs, s.gated_rows) +
      format("; %.0f signals screened out by C/N0; %.0f epochs with fixes of a poorly determined position",
             s.cn0_screened, s.undetermined_fix_epochs) +
      format("; %.0f epochs with fewer than 4 satellites to fix (no fix tried)", s.too_few_to_fix) +
      format("; %.0f epochs whose float fit no integer vector (success rates scaled)", s.float_inconsistent) +
      format("; %.0f ambiguities started from the position (slips repaired, signals re-acquired)",
             s.ambiguities_from_position));
  if (options_.heading.enabled) {
    lines.push_back(
        format("fusion: heading state: T_EO turned by %.2f deg in all by the filter's heading estimates, "
               "heading sigma %.2f deg at the end",
               s.heading_folded_rad * core::kRadToDeg, s.heading_sigma_rad * core::kRadToDeg));
  }
  if (options_.prediction.scale_state) {
    lines.push_back(
        format("fusion: scale state: the VIO's increments taken times 1 %+.3f %% (sigma %.3f %%) at the end",
               100.0 * s.scale_error, 100.0 * s.scale_sigma));
  }
  if (options_.integrity.enabled) {
    lines.push_back(
        format("fusion: integrity check: %.0f restarts from the single point (median offset over %.0f s "
               "beyond %.0f m)",
               s.integrity_restarts, options_.integrity.window_s, options_.integrity.max_offset_m));
  }
  int coarse = 0, fine = 0;
  for (const AlignmentEvent& a : s.alignment.events) (a.kind == "coarse" ? coarse : fine) += 1;
  lines.push_back(format("fusion: alignments: %.0f fine of %.0f windows tried (%.0f with FER >= the limit, ", fine,
                         s.alignment.tries, s.alignment.rejected_fer) +
                  format("%.0f with RMSE >= the limit), %.0f coarse; %.3f s CPU", s.alignment.rejected_rmse, coarse,
                         s.alignment.cpu_s));
  // The first coarse alignment of each run of them, the last one, and every fine alignment but the re-alignments.
  const AlignmentEvent* last_coarse = nullptr;
  int coarse_run = 0;
  const auto coarse_line = [&lines](const AlignmentEvent& a, const char* what) {
    lines.push_back("fusion: " + core::format_gpst(a.time) + ": " + what + ", " + std::to_string(a.points) +
                    format(" solutions, yaw sigma %.2f deg, horizontal RMSE %.2f m", a.yaw_sigma_deg, a.rmse_m));
  };
  const auto flush_coarse = [&]() {
    if (last_coarse != nullptr && coarse_run > 1) coarse_line(*last_coarse, "last coarse alignment of this run");
    last_coarse = nullptr;
    coarse_run = 0;
  };
  for (const AlignmentEvent& a : s.alignment.events) {
    if (a.kind == "coarse") {
      if (coarse_run++ == 0) coarse_line(a, "coarse alignment");
      last_coarse = &a;
      continue;
    }
    flush_coarse();
    if (a.kind == "realign") continue;
    lines.push_back("fusion: " + core::format_gpst(a.time) + ": " + a.kind + " alignment, " + std::to_string(a.points) +
                    format(" solutions, FER %.3f, RMSE %.3f m (without calibration %.3f m)", a.first_eigenvalue_ratio,
                           a.rmse_m, a.rmse_without_calibration_m));
  }
  flush_coarse();
  if (s.alignment.calibration) {
    const Eigen::Vector3d& t = s.alignment.calibration->t_IA_m;
    lines.push_back(format("fusion: lever arm t_IA = [%.3f, %.3f, %.3f] m; ", t.x(), t.y(), t.z()) +
                    s.alignment.calibration->lever_arm.describe());
  }
  for (const std::string& note : s.notes) lines.push_back("fusion: " + note);
  return lines;
}

}  // namespace canyon::fusion
