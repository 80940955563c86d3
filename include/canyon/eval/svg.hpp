#pragma once
// A small SVG 1.1 writer for canyon's plots: shapes, text, groups and rectangular clip regions, written as a
// standalone, well-formed XML document (text and attribute values escaped). Coordinates in pixels, y down.
// Colours are any SVG colour ("#2ca02c", "none", "white").

#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/result.hpp"

namespace canyon::eval {

/// How a shape is painted.
struct SvgStyle {
  std::string fill = "none";
  std::string stroke = "none";
  double stroke_width_px = 1.0;
  double opacity = 1.0;  ///< of the whole shape
  std::string dash;      ///< stroke-dasharray, e.g. "4 3"; empty: solid
};

struct SvgTextStyle {
  double size_px = 12.0;
  std::string anchor = "start";  ///< start, middle, end
  std::string fill = "#222222";
  bool bold = false;
  double rotate_deg = 0.0;  ///< about the anchor point, clockwise
};

class SvgDocument {
 public:
  /// A document of `width_px` x `height_px` with a white background.
  SvgDocument(double width_px, double height_px);

  void rect(double x, double y, double width, double height, const SvgStyle& style);
  void line(double x1, double y1, double x2, double y2, const SvgStyle& style);
  void circle(double cx, double cy, double r, const SvgStyle& style);
  /// Open path through the points (nothing for fewer than two).
  void polyline(const std::vector<Eigen::Vector2d>& points_px, const SvgStyle& style);
  /// Closed polygon (nothing for fewer than three points).
  void polygon(const std::vector<Eigen::Vector2d>& points_px, const SvgStyle& style);
  void text(double x, double y, const std::string& text, const SvgTextStyle& style);

  /// Defines a rectangular clip region, to be used by begin_group(clip_id).
  void define_clip(const std::string& id, double x, double y, double width, double height);
  /// Opens a group, clipped by a region defined before (empty: not clipped). Groups nest; end_group() closes.
  void begin_group(const std::string& clip_id = {});
  void end_group();

  /// The document text (closes any open groups).
  [[nodiscard]] std::string str() const;
  /// Writes the document to `path`. Error naming the path if it cannot be written.
  [[nodiscard]] Status write(const std::string& path) const;

  [[nodiscard]] double width_px() const { return width_px_; }
  [[nodiscard]] double height_px() const { return height_px_; }

 private:
  void append_style(const SvgStyle& style);

  double width_px_;
  double height_px_;
  std::string defs_;
  std::string body_;
  int open_groups_ = 0;
};

/// `text` with XML's special characters escaped (&, <, >, ", ').
[[nodiscard]] std::string xml_escape(const std::string& text);

/// A number as SVG wants it: at most `decimals` decimals, no trailing zeros ("12.5", "3", "-0.25").
[[nodiscard]] std::string svg_number(double value, int decimals = 2);

}  // namespace canyon::eval
