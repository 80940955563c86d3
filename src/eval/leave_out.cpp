// Leave-out agreement of fixed epochs (see leave_out.hpp).

#include "canyon/eval/leave_out.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace canyon::eval {
namespace {

constexpr double kTimeToleranceS = 0.005;  // epochs of the two runs are the same rover epochs

bool is_fixed(const core::Solution& s) {
  return s.status == core::SolutionStatus::Fixed;
}

/// The fixed solutions, in time order.
std::vector<const core::Solution*> fixed_of(const std::vector<core::Solution>& solutions) {
  std::vector<const core::Solution*> fixed;
  for (const core::Solution& s : solutions) {
    if (is_fixed(s)) fixed.push_back(&s);
  }
  std::sort(fixed.begin(), fixed.end(),
            [](const core::Solution* a, const core::Solution* b) { return (a->time - b->time) < 0.0; });
  return fixed;
}

}  // namespace

LeaveOutAgreement leave_out_agreement(const std::vector<core::Solution>& full,
                                      const std::vector<core::Solution>& left_out, double tolerance_m) {
  LeaveOutAgreement r;
  r.tolerance_m = tolerance_m;
  const std::vector<const core::Solution*> a = fixed_of(full);
  const std::vector<const core::Solution*> b = fixed_of(left_out);
  r.fixed_full = static_cast<int>(a.size());
  r.fixed_left_out = static_cast<int>(b.size());
  std::vector<double> distances;
  std::size_t j = 0;
  for (const core::Solution* s : a) {
    while (j < b.size() && (b[j]->time - s->time) < -kTimeToleranceS) ++j;
    if (j == b.size()) break;
    if (std::abs(b[j]->time - s->time) > kTimeToleranceS) continue;
    distances.push_back((b[j]->p_E_m - s->p_E_m).norm());
  }
  r.fixed_both = static_cast<int>(distances.size());
  r.agree = static_cast<int>(
      std::count_if(distances.begin(), distances.end(), [tolerance_m](double d) { return d <= tolerance_m; }));
  if (!distances.empty()) {
    std::sort(distances.begin(), distances.end());
    r.median_distance_m = distances[(distances.size() - 1) / 2];
    r.worst_distance_m = distances.back();
  }
  return r;
}

std::string format_leave_out(const std::vector<LeaveOutAgreement>& runs, double min_agreement) {
  std::string out =
      "left out  satellites            fixed (full)  fixed (left out)  fixed in both  agree       median m  "
      "worst m\n";
  char line[256];
  for (const LeaveOutAgreement& r : runs) {
    std::string sats;
    for (const core::SatelliteId& sat : r.satellites) sats += (sats.empty() ? "" : ",") + sat.to_string();
    std::snprintf(line, sizeof line, "%8d  %-20s  %12d  %16d  %13d  %4d %5.1f%%  %8.3f  %7.3f\n", r.left_out,
                  sats.c_str(), r.fixed_full, r.fixed_left_out, r.fixed_both, r.agree, 100.0 * r.agreement(),
                  r.median_distance_m, r.worst_distance_m);
    out += line;
  }
  for (const LeaveOutAgreement& r : runs) {
    std::snprintf(line, sizeof line,
                  "%d left out: %s: %d of %d epochs fixed in both within %.0f cm (%.1f %%, needs %.0f %%)\n",
                  r.left_out, r.agreement() >= min_agreement ? "consistent" : "INCONSISTENT", r.agree, r.fixed_both,
                  100.0 * r.tolerance_m, 100.0 * r.agreement(), 100.0 * min_agreement);
    out += line;
  }
  return out;
}

}  // namespace canyon::eval
