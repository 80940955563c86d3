#pragma once
// The plots of `canyon evaluate`, as SVG (canyon's own writer, svg.hpp):
//  - trajectory_plot: one panel per solution, east/north (m) in the local ENU frame N at the plot origin (the
//    city's origin if a city is given and has one, else the truth's first point); buildings as filled polygons
//    (darker when taller), trees as light discs, the truth as a thin dark line, solution epochs as dots coloured by
//    status (fixed green, float yellow, single red, fill-in white with a dark outline, other grey; the most
//    frequent status drawn first so that rare ones stay visible). All panels share one frame and one scale (equal
//    in east and north) that holds the truth and the solutions up to the 95th percentile of their horizontal
//    errors; points beyond it are clipped and counted in the panel.
//  - ape_plot: the 3D error (APE) of every solution over time, log scale (1 mm up), one colour per solution, with
//    the wrong-fix threshold dashed; lines break where a solution has no epoch with truth for more than 2.5 of its
//    usual intervals.

#include <vector>

#include "canyon/eval/city_map.hpp"
#include "canyon/eval/report.hpp"
#include "canyon/eval/svg.hpp"
#include "canyon/eval/truth.hpp"

namespace canyon::eval {

/// The plot origin: the city's origin when there is one, else the truth's first point.
[[nodiscard]] core::Geodetic plot_origin(const Truth& truth, const CityMap* city);

[[nodiscard]] SvgDocument trajectory_plot(const EvaluationReport& report, const Truth& truth, const CityMap* city);
[[nodiscard]] SvgDocument ape_plot(const EvaluationReport& report, const Truth& truth);

/// Tick values at 1, 2 or 5 times a power of ten, covering [lo, hi] with at most about `max_ticks` ticks (at least
/// two ticks for lo < hi).
[[nodiscard]] std::vector<double> nice_ticks(double lo, double hi, int max_ticks);

}  // namespace canyon::eval
