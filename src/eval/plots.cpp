// The trajectory and APE plots of `canyon evaluate` (see plots.hpp).

#include "canyon/eval/plots.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"

namespace canyon::eval {
namespace {

// ---- Shared look ------------------------------------------------------------------------------------------------

constexpr double kFontPx = 12.0;
constexpr double kTitlePx = 14.0;
const char* const kAxisColour = "#333333";
const char* const kGridColour = "#e3e3e3";
const char* const kTruthColour = "#1a1a1a";
/// One colour per solution in the APE plot (not the status colours).
constexpr std::array<const char*, 6> kSeriesColours = {"#1f77b4", "#ff7f0e", "#9467bd",
                                                       "#17becf", "#8c564b", "#e377c2"};

struct StatusLook {
  const char* name;
  const char* fill;
  const char* stroke;
};
/// By StatusClass index: fixed green, float yellow, single red, fill-in white with a dark outline, other grey.
constexpr std::array<StatusLook, kNumStatusClasses> kStatusLooks = {{{"fixed", "#2ca02c", "#1e6e1e"},
                                                                     {"float", "#f5c518", "#9c7c00"},
                                                                     {"single", "#d62728", "#8c1a1a"},
                                                                     {"fill-in", "#ffffff", "#222222"},
                                                                     {"other", "#8c8c8c", "#555555"}}};

std::string fmt(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

/// Tick label with as many decimals as the tick step needs.
std::string tick_label(double value, double step) {
  const int decimals = std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, std::abs(value) < 0.5 * step ? 0.0 : value);
  return buffer;
}

SvgStyle stroke_style(const std::string& colour, double width_px, const std::string& dash = {}) {
  return SvgStyle{"none", colour, width_px, 1.0, dash};
}

SvgStyle fill_style(const std::string& fill, const std::string& stroke = "none", double width_px = 1.0) {
  return SvgStyle{fill, stroke, width_px, 1.0, {}};
}

/// A plot area in pixels.
struct Area {
  double left = 0.0;
  double top = 0.0;
  double width = 0.0;
  double height = 0.0;
  [[nodiscard]] double right() const { return left + width; }
  [[nodiscard]] double bottom() const { return top + height; }
};

// ---- Trajectory -------------------------------------------------------------------------------------------------

/// East/north window of the trajectory panels (m).
struct Frame {
  double e_min_m = 0.0;
  double e_max_m = 0.0;
  double n_min_m = 0.0;
  double n_max_m = 0.0;
  [[nodiscard]] double width_m() const { return e_max_m - e_min_m; }
  [[nodiscard]] double height_m() const { return n_max_m - n_min_m; }
  void include(const Eigen::Vector2d& p) {
    e_min_m = std::min(e_min_m, p.x());
    e_max_m = std::max(e_max_m, p.x());
    n_min_m = std::min(n_min_m, p.y());
    n_max_m = std::max(n_max_m, p.y());
  }
  [[nodiscard]] bool contains(const Eigen::Vector2d& p) const {
    return p.x() >= e_min_m && p.x() <= e_max_m && p.y() >= n_min_m && p.y() <= n_max_m;
  }
};

/// Local ENU (east, north) of ECEF points at the plot origin.
class LocalFrame {
 public:
  explicit LocalFrame(const core::Geodetic& origin)
      : p_E_origin_m_(core::geodetic_to_ecef(origin)),
        R_NE_(core::rotation_enu_from_ecef(origin)),
        height_m_(origin.height_m) {}
  [[nodiscard]] Eigen::Vector2d en(const Eigen::Vector3d& p_E_m) const {
    return (R_NE_ * (p_E_m - p_E_origin_m_)).head<2>();
  }
  /// A ground point given as longitude/latitude (deg), at the origin's height.
  [[nodiscard]] Eigen::Vector2d en_of_lon_lat(const Eigen::Vector2d& lon_lat_deg) const {
    return en(
        core::geodetic_to_ecef({lon_lat_deg.y() * core::kDegToRad, lon_lat_deg.x() * core::kDegToRad, height_m_}));
  }

 private:
  Eigen::Vector3d p_E_origin_m_;
  Eigen::Matrix3d R_NE_;
  double height_m_;
};

/// The time span of all solutions, if any.
std::optional<std::pair<core::GpsTime, core::GpsTime>> solution_span(const EvaluationReport& report) {
  std::optional<std::pair<core::GpsTime, core::GpsTime>> span;
  for (const SolutionReport& r : report.solutions) {
    if (r.solutions.empty()) continue;
    const core::GpsTime first = r.solutions.front().time;
    const core::GpsTime last = r.solutions.back().time;
    if (!span) {
      span = {first, last};
    } else {
      if (first < span->first) span->first = first;
      if (span->second < last) span->second = last;
    }
  }
  return span;
}

/// The truth's points within the solutions' span (one point for a static truth).
std::vector<Eigen::Vector2d> truth_points(const Truth& truth, const EvaluationReport& report, const LocalFrame& f) {
  std::vector<Eigen::Vector2d> points;
  const auto span = solution_span(report);
  for (const TruthSample& s : truth.samples()) {
    if (truth.is_constant() || !span || (s.time - span->first >= -1.0 && span->second - s.time >= -1.0)) {
      points.push_back(f.en(s.p_E_m));
    }
  }
  return points;
}

/// The window: the truth and the solutions up to the 95th percentile of horizontal error, padded, at least 1 m,
/// and no more elongated than 3:1.
Frame trajectory_frame(const std::vector<Eigen::Vector2d>& truth_en, const EvaluationReport& report, const Truth& truth,
                       const LocalFrame& f) {
  std::vector<double> horizontal_m;
  for (const SolutionReport& r : report.solutions) {
    for (const core::Solution& s : r.solutions) {
      if (const auto p = truth.position_at(s.time)) horizontal_m.push_back((f.en(s.p_E_m) - f.en(*p)).norm());
    }
  }
  double limit_m = 0.0;
  if (!horizontal_m.empty()) {
    const auto k = static_cast<std::ptrdiff_t>(0.95 * static_cast<double>(horizontal_m.size() - 1));
    std::nth_element(horizontal_m.begin(), horizontal_m.begin() + k, horizontal_m.end());
    limit_m = horizontal_m[static_cast<std::size_t>(k)];
  }
  const Eigen::Vector2d start = truth_en.empty() ? Eigen::Vector2d::Zero() : truth_en.front();
  Frame frame{start.x(), start.x(), start.y(), start.y()};
  for (const Eigen::Vector2d& p : truth_en) frame.include(p);
  for (const SolutionReport& r : report.solutions) {
    for (const core::Solution& s : r.solutions) {
      const auto p = truth.position_at(s.time);
      if (p && (f.en(s.p_E_m) - f.en(*p)).norm() <= limit_m) frame.include(f.en(s.p_E_m));
    }
  }
  constexpr double kMinSizeM = 1.0;
  constexpr double kMaxAspect = 3.0;
  constexpr double kPadding = 0.06;
  const double pad_m = kPadding * std::max({frame.width_m(), frame.height_m(), kMinSizeM});
  double w_m = std::max(frame.width_m(), kMinSizeM) + 2.0 * pad_m;
  double h_m = std::max(frame.height_m(), kMinSizeM) + 2.0 * pad_m;
  w_m = std::max(w_m, h_m / kMaxAspect);
  h_m = std::max(h_m, w_m / kMaxAspect);
  const double e_mid_m = 0.5 * (frame.e_min_m + frame.e_max_m);
  const double n_mid_m = 0.5 * (frame.n_min_m + frame.n_max_m);
  return Frame{e_mid_m - 0.5 * w_m, e_mid_m + 0.5 * w_m, n_mid_m - 0.5 * h_m, n_mid_m + 0.5 * h_m};
}

/// Maps east/north (m) into a panel's plot area.
struct PanelMap {
  Frame frame;
  Area area;
  double px_per_m = 1.0;
  [[nodiscard]] Eigen::Vector2d px(const Eigen::Vector2d& en_m) const {
    return {area.left + (en_m.x() - frame.e_min_m) * px_per_m, area.top + (frame.n_max_m - en_m.y()) * px_per_m};
  }
};

void draw_city(SvgDocument& svg, const PanelMap& map, const CityMap& city, const LocalFrame& f) {
  double tallest_m = 1.0;
  for (const CityMapBuilding& b : city.buildings) tallest_m = std::max(tallest_m, b.height_m);
  for (const CityMapBuilding& b : city.buildings) {
    std::vector<Eigen::Vector2d> ring;
    ring.reserve(b.lon_lat_deg.size());
    for (const Eigen::Vector2d& ll : b.lon_lat_deg) ring.push_back(map.px(f.en_of_lon_lat(ll)));
    // Taller buildings darker: grey from 205 (low) down to 125 (tallest).
    const int grey = 205 - static_cast<int>(80.0 * b.height_m / tallest_m);
    char colour[16];
    std::snprintf(colour, sizeof colour, "#%02x%02x%02x", grey, grey, grey + 8);
    svg.polygon(ring, fill_style(colour, "#8a8a90", 0.6));
  }
  for (const CityMapTree& t : city.trees) {
    const Eigen::Vector2d c = map.px(f.en_of_lon_lat(t.lon_lat_deg));
    svg.circle(c.x(), c.y(), std::max(1.0, t.radius_m * map.px_per_m), SvgStyle{"#9fd49f", "none", 0.0, 0.6, {}});
  }
}

void draw_frame_axes(SvgDocument& svg, const PanelMap& map) {
  const Area& a = map.area;
  const auto e_ticks = nice_ticks(map.frame.e_min_m, map.frame.e_max_m, std::max(3, static_cast<int>(a.width / 55)));
  const auto n_ticks = nice_ticks(map.frame.n_min_m, map.frame.n_max_m, std::max(3, static_cast<int>(a.height / 50)));
  const double e_step = e_ticks.size() > 1 ? e_ticks[1] - e_ticks[0] : 1.0;
  const double n_step = n_ticks.size() > 1 ? n_ticks[1] - n_ticks[0] : 1.0;
  SvgTextStyle label{kFontPx - 1, "middle", kAxisColour, false, 0.0};
  for (const double e : e_ticks) {
    const double x = map.px({e, 0.0}).x();
    svg.line(x, a.top, x, a.bottom(), stroke_style(kGridColour, 0.6));
    svg.line(x, a.bottom(), x, a.bottom() + 4, stroke_style(kAxisColour, 1.0));
    svg.text(x, a.bottom() + 16, tick_label(e, e_step), label);
  }
  label.anchor = "end";
  for (const double n : n_ticks) {
    const double y = map.px({0.0, n}).y();
    svg.line(a.left, y, a.right(), y, stroke_style(kGridColour, 0.6));
    svg.line(a.left - 4, y, a.left, y, stroke_style(kAxisColour, 1.0));
    svg.text(a.left - 6, y + 4, tick_label(n, n_step), label);
  }
  svg.text(a.left + 0.5 * a.width, a.bottom() + 34, "east (m)", {kFontPx, "middle", kAxisColour, false, 0.0});
  svg.text(a.left - 46, a.top + 0.5 * a.height, "north (m)", {kFontPx, "middle", kAxisColour, false, -90.0});
}

/// Status classes of a solution in drawing order: most frequent first.
std::vector<std::size_t> drawing_order(const SolutionReport& r) {
  std::vector<std::size_t> order(kNumStatusClasses);
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return r.stats.by_class[a].epochs > r.stats.by_class[b].epochs;
  });
  return order;
}

void draw_solution_panel(SvgDocument& svg, const PanelMap& map, const SolutionReport& r,
                         const std::vector<Eigen::Vector2d>& truth_en, const Truth& truth, const CityMap* city,
                         const LocalFrame& f, const std::string& clip_id) {
  const Area& a = map.area;
  svg.define_clip(clip_id, a.left, a.top, a.width, a.height);
  draw_frame_axes(svg, map);
  svg.begin_group(clip_id);
  if (city != nullptr) draw_city(svg, map, *city, f);
  int outside = 0;
  constexpr double kDotPx = 2.3;
  for (const std::size_t k : drawing_order(r)) {
    const StatusLook& look = kStatusLooks[k];
    for (const core::Solution& s : r.solutions) {
      if (static_cast<std::size_t>(status_class(s.status)) != k) continue;
      const Eigen::Vector2d en = f.en(s.p_E_m);
      if (!map.frame.contains(en)) {
        ++outside;
        continue;
      }
      const Eigen::Vector2d p = map.px(en);
      svg.circle(p.x(), p.y(), kDotPx, fill_style(look.fill, look.stroke, 0.6));
    }
  }
  std::vector<Eigen::Vector2d> line;
  line.reserve(truth_en.size());
  for (const Eigen::Vector2d& en : truth_en) line.push_back(map.px(en));
  if (truth.is_constant() && !line.empty()) {
    const Eigen::Vector2d& p = line.front();
    svg.line(p.x() - 7, p.y(), p.x() + 7, p.y(), stroke_style(kTruthColour, 1.2));
    svg.line(p.x(), p.y() - 7, p.x(), p.y() + 7, stroke_style(kTruthColour, 1.2));
  } else {
    svg.polyline(line, SvgStyle{"none", kTruthColour, 1.0, 0.9, {}});
  }
  svg.end_group();
  svg.rect(a.left, a.top, a.width, a.height, stroke_style(kAxisColour, 1.0));
  std::string figures = "fixed " + fmt("%.1f %%", 100.0 * r.stats.fixed().fraction_of_epochs_in);
  if (r.stats.overall.count > 0) figures += ", 3D RMSE " + fmt("%.3f m", r.stats.overall.rmse_3d_m);
  svg.text(a.left, a.top - 26, r.label, {kTitlePx, "start", "#111111", true, 0.0});
  svg.text(a.left, a.top - 9, figures, {kFontPx, "start", "#333333", false, 0.0});
  if (outside > 0) {
    svg.text(a.right() - 6, a.bottom() - 8, std::to_string(outside) + " outside the frame",
             {kFontPx - 1, "end", "#555555", false, 0.0});
  }
}

/// Estimated width of `text` at kFontPx (DejaVu Sans averages about 0.6 em per character).
double text_width_px(const std::string& text) {
  return 0.6 * kFontPx * static_cast<double>(text.size());
}

/// Width of a legend entry: marker, gap, text, space before the next entry.
double legend_entry_width_px(const std::string& text) {
  return 22.0 + text_width_px(text) + 20.0;
}

/// One legend entry: a marker drawn by `draw` centred at (x + 8, y - 4), then the text; returns the x after it.
template <typename Draw>
double legend_entry(SvgDocument& svg, double x, double y, const std::string& text, Draw draw) {
  draw(x + 8, y - 4);
  svg.text(x + 22, y, text, {kFontPx, "start", kAxisColour, false, 0.0});
  return x + legend_entry_width_px(text);
}

double trajectory_legend_width_px() {
  double width_px = 0.0;
  for (const StatusLook& look : kStatusLooks) width_px += legend_entry_width_px(look.name);
  for (const char* name : {"truth", "building", "tree"}) width_px += legend_entry_width_px(name);
  return width_px;
}

void draw_trajectory_legend(SvgDocument& svg, double x, double y, bool with_city, bool static_truth) {
  for (const StatusLook& look : kStatusLooks) {
    x = legend_entry(svg, x, y, look.name,
                     [&](double cx, double cy) { svg.circle(cx, cy, 3.5, fill_style(look.fill, look.stroke, 0.8)); });
  }
  x = legend_entry(svg, x, y, "truth", [&](double cx, double cy) {
    if (static_truth) {
      svg.line(cx - 6, cy, cx + 6, cy, stroke_style(kTruthColour, 1.2));
      svg.line(cx, cy - 6, cx, cy + 6, stroke_style(kTruthColour, 1.2));
    } else {
      svg.line(cx - 8, cy, cx + 8, cy, stroke_style(kTruthColour, 1.0));
    }
  });
  if (!with_city) return;
  x = legend_entry(svg, x, y, "building", [&](double cx, double cy) {
    svg.rect(cx - 6, cy - 5, 12, 10, fill_style("#a8a8b0", "#8a8a90", 0.6));
  });
  legend_entry(svg, x, y, "tree", [&](double cx, double cy) {
    svg.circle(cx, cy, 5, SvgStyle{"#9fd49f", "none", 0.0, 0.6, {}});
  });
}

// ---- APE over time ----------------------------------------------------------------------------------------------

struct ErrorPoint {
  double t_s = 0.0;      ///< since the plot's time origin
  double error_m = 0.0;  ///< 3D
};

std::vector<ErrorPoint> error_series(const SolutionReport& r, const Truth& truth, const core::GpsTime& t0) {
  std::vector<ErrorPoint> out;
  out.reserve(r.solutions.size());
  for (const core::Solution& s : r.solutions) {
    if (const auto p = truth.position_at(s.time)) out.push_back({s.time - t0, (s.p_E_m - *p).norm()});
  }
  return out;
}

std::string metres_label(double value_m) {
  if (value_m < 0.0095) return fmt("%.0f mm", value_m * 1000.0);
  if (value_m < 0.95) return fmt("%.0f cm", value_m * 100.0);
  if (value_m < 950.0) return fmt("%.0f m", value_m);
  return fmt("%.0f km", value_m / 1000.0);
}

/// Log-scale y axis from 10^lo to 10^hi decades.
struct LogAxis {
  int lo_decade = -3;
  int hi_decade = 0;
  Area area;
  [[nodiscard]] double y(double value_m) const {
    const double lo = std::pow(10.0, lo_decade);
    const double v = std::log10(std::max(value_m, lo));
    return area.bottom() - (v - lo_decade) / (hi_decade - lo_decade) * area.height;
  }
};

void draw_ape_axes(SvgDocument& svg, const LogAxis& y_axis, double t_max_s, const std::string& time_origin) {
  const Area& a = y_axis.area;
  for (int d = y_axis.lo_decade; d <= y_axis.hi_decade; ++d) {
    const double decade_m = std::pow(10.0, d);
    const double y = y_axis.y(decade_m);
    svg.line(a.left, y, a.right(), y, stroke_style("#d0d0d0", 0.7));
    svg.line(a.left - 5, y, a.left, y, stroke_style(kAxisColour, 1.0));
    svg.text(a.left - 8, y + 4, metres_label(decade_m), {kFontPx - 1, "end", kAxisColour, false, 0.0});
    if (d == y_axis.hi_decade) break;
    for (int m = 2; m <= 9; ++m) {
      const double ym = y_axis.y(m * decade_m);
      svg.line(a.left, ym, a.right(), ym, stroke_style("#f0f0f0", 0.6));
      svg.line(a.left - 3, ym, a.left, ym, stroke_style(kAxisColour, 0.7));
    }
  }
  const auto ticks = nice_ticks(0.0, t_max_s, std::max(3, static_cast<int>(a.width / 80)));
  const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 1.0;
  for (const double t : ticks) {
    const double x = a.left + t / t_max_s * a.width;
    svg.line(x, a.top, x, a.bottom(), stroke_style(kGridColour, 0.6));
    svg.line(x, a.bottom(), x, a.bottom() + 4, stroke_style(kAxisColour, 1.0));
    svg.text(x, a.bottom() + 17, tick_label(t, step), {kFontPx - 1, "middle", kAxisColour, false, 0.0});
  }
  svg.rect(a.left, a.top, a.width, a.height, stroke_style(kAxisColour, 1.0));
  svg.text(a.left + 0.5 * a.width, a.bottom() + 36, "time since " + time_origin + " (s)",
           {kFontPx, "middle", kAxisColour, false, 0.0});
  svg.text(a.left - 58, a.top + 0.5 * a.height, "3D position error (log scale)",
           {kFontPx, "middle", kAxisColour, false, -90.0});
}

/// The series as polylines, broken where no epoch with truth came for 2.5 usual intervals.
void draw_series(SvgDocument& svg, const std::vector<ErrorPoint>& series, const LogAxis& y_axis, double t_max_s,
                 const std::string& colour) {
  std::vector<double> gaps_s;
  for (std::size_t i = 1; i < series.size(); ++i) gaps_s.push_back(series[i].t_s - series[i - 1].t_s);
  double usual_s = 1.0;
  if (!gaps_s.empty()) {
    std::nth_element(gaps_s.begin(), gaps_s.begin() + static_cast<std::ptrdiff_t>(gaps_s.size() / 2), gaps_s.end());
    usual_s = gaps_s[gaps_s.size() / 2];
  }
  const Area& a = y_axis.area;
  std::vector<Eigen::Vector2d> run;
  const auto flush = [&]() {
    if (run.size() == 1) svg.circle(run.front().x(), run.front().y(), 1.5, fill_style(colour));
    svg.polyline(run, SvgStyle{"none", colour, 1.3, 0.9, {}});
    run.clear();
  };
  for (std::size_t i = 0; i < series.size(); ++i) {
    if (i > 0 && series[i].t_s - series[i - 1].t_s > 2.5 * usual_s) flush();
    run.emplace_back(a.left + series[i].t_s / t_max_s * a.width, y_axis.y(series[i].error_m));
  }
  flush();
}

}  // namespace

std::vector<double> nice_ticks(double lo, double hi, int max_ticks) {
  if (!(hi > lo) || max_ticks < 2) return {lo};
  const double raw_step = (hi - lo) / (max_ticks - 1);
  const double power = std::pow(10.0, std::floor(std::log10(raw_step)));
  double step = 10.0 * power;
  for (const double m : {1.0, 2.0, 5.0}) {
    if (m * power >= raw_step) {
      step = m * power;
      break;
    }
  }
  std::vector<double> ticks;
  for (double k = std::ceil(lo / step - 1e-9); k * step <= hi + 1e-9 * step; k += 1.0) ticks.push_back(k * step);
  if (ticks.size() < 2) return nice_ticks(lo, hi, max_ticks + 1);
  return ticks;
}

core::Geodetic plot_origin(const Truth& truth, const CityMap* city) {
  if (city != nullptr && city->origin) return *city->origin;
  return core::ecef_to_geodetic(truth.samples().front().p_E_m);
}

SvgDocument trajectory_plot(const EvaluationReport& report, const Truth& truth, const CityMap* city) {
  const LocalFrame f(plot_origin(truth, city));
  const std::vector<Eigen::Vector2d> truth_en = truth_points(truth, report, f);
  const Frame frame = trajectory_frame(truth_en, report, truth, f);
  // Panels: up to three in a row; the longer side of a plot area 440 px (600 px for a single panel).
  const double long_side_px = report.solutions.size() == 1 ? 600.0 : 440.0;
  constexpr double kLeftPx = 72.0;
  constexpr double kRightPx = 24.0;
  constexpr double kTopPx = 70.0;
  constexpr double kBottomPx = 52.0;
  constexpr double kLegendPx = 34.0;
  const double px_per_m = long_side_px / std::max(frame.width_m(), frame.height_m());
  const double plot_w = frame.width_m() * px_per_m;
  const double plot_h = frame.height_m() * px_per_m;
  const auto n = static_cast<int>(report.solutions.size());
  const int columns = std::min(n, 3);
  const int rows = (n + columns - 1) / columns;
  const double panel_w = kLeftPx + plot_w + kRightPx;
  const double panel_h = kTopPx + plot_h + kBottomPx;
  SvgDocument svg(std::max(columns * panel_w, kLeftPx + trajectory_legend_width_px() + 16.0),
                  rows * panel_h + kLegendPx + 30);
  const std::string origin_text = city != nullptr && city->origin ? "city origin" : "first truth point";
  svg.text(16, 24, "Trajectories in local ENU (origin: " + origin_text + ")",
           {kTitlePx + 2, "start", "#111111", true, 0.0});
  for (int k = 0; k < n; ++k) {
    const int column = k % columns;
    const int row = k / columns;
    const Area area{column * panel_w + kLeftPx, 30 + row * panel_h + kTopPx - 20, plot_w, plot_h};
    draw_solution_panel(svg, PanelMap{frame, area, px_per_m}, report.solutions[static_cast<std::size_t>(k)], truth_en,
                        truth, city, f, "panel" + std::to_string(k));
  }
  draw_trajectory_legend(svg, kLeftPx, svg.height_px() - 18, city != nullptr, truth.is_constant());
  return svg;
}

SvgDocument ape_plot(const EvaluationReport& report, const Truth& truth) {
  constexpr double kWidthPx = 920.0;
  constexpr double kHeightPx = 400.0;
  const Area area{92.0, 48.0, kWidthPx - 92.0 - 28.0, kHeightPx - 48.0 - 64.0};
  SvgDocument svg(kWidthPx, kHeightPx);
  const auto span = solution_span(report);
  core::GpsTime t0 = report.epochs.first.value_or(span ? span->first : core::GpsTime{});
  if (span && span->first < t0) t0 = span->first;
  std::vector<std::vector<ErrorPoint>> series;
  double min_m = 0.0;
  double max_m = 0.0;
  double t_max_s = 1.0;
  for (const SolutionReport& r : report.solutions) {
    series.push_back(error_series(r, truth, t0));
    for (const ErrorPoint& p : series.back()) {
      if (p.error_m > 0.0 && (min_m == 0.0 || p.error_m < min_m)) min_m = p.error_m;
      max_m = std::max(max_m, p.error_m);
      t_max_s = std::max(t_max_s, p.t_s);
    }
  }
  LogAxis y_axis;
  y_axis.area = area;
  // From the smallest error (1 mm at least), or from below the wrong-fix threshold so that its line shows, to the
  // largest error.
  const int threshold_decade = static_cast<int>(std::floor(std::log10(report.wrong_fix_threshold_m) - 0.3));
  y_axis.lo_decade = min_m > 0.0 ? std::max(-3, static_cast<int>(std::floor(std::log10(min_m) + 1e-6))) : -3;
  y_axis.lo_decade = std::min(y_axis.lo_decade, threshold_decade);
  y_axis.hi_decade =
      std::max(y_axis.lo_decade + 1,
               static_cast<int>(std::ceil(std::log10(std::max(max_m, report.wrong_fix_threshold_m)) - 1e-6)));
  svg.text(16, 26, "Absolute position error (3D) over time", {kTitlePx + 2, "start", "#111111", true, 0.0});
  draw_ape_axes(svg, y_axis, t_max_s, core::format_calendar(core::gps_to_calendar(t0.normalized()), 0) + " GPST");
  const double threshold_y = y_axis.y(report.wrong_fix_threshold_m);
  svg.define_clip("ape-area", area.left, area.top, area.width, area.height);
  svg.begin_group("ape-area");
  svg.line(area.left, threshold_y, area.right(), threshold_y, stroke_style("#d62728", 1.0, "6 4"));
  for (std::size_t k = 0; k < series.size(); ++k) {
    draw_series(svg, series[k], y_axis, t_max_s, kSeriesColours[k % kSeriesColours.size()]);
  }
  svg.end_group();
  svg.text(area.right() - 6, threshold_y - 5, "wrong-fix threshold " + metres_label(report.wrong_fix_threshold_m),
           {kFontPx - 1, "end", "#d62728", false, 0.0});
  double legend_px = 0.0;
  for (const SolutionReport& r : report.solutions) legend_px += legend_entry_width_px(r.label);
  double x = std::max(area.left + 330.0, area.right() - legend_px + 20.0);
  for (std::size_t k = 0; k < report.solutions.size(); ++k) {
    const std::string colour = kSeriesColours[k % kSeriesColours.size()];
    x = legend_entry(svg, x, 27, report.solutions[k].label,
                     [&](double cx, double cy) { svg.line(cx - 8, cy, cx + 8, cy, stroke_style(colour, 2.5)); });
  }
  if (max_m == 0.0) {
    svg.text(area.left + 0.5 * area.width, area.top + 0.5 * area.height, "no epoch with truth",
             {kTitlePx, "middle", "#555555", false, 0.0});
  }
  return svg;
}

}  // namespace canyon::eval
