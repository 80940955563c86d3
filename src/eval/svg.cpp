// The small SVG writer (see svg.hpp).

#include "canyon/eval/svg.hpp"

#include <cmath>
#include <cstdio>

#include "canyon/io/text_file_writer.hpp"

namespace canyon::eval {
namespace {

std::string points_attribute(const std::vector<Eigen::Vector2d>& points_px) {
  std::string out;
  out.reserve(points_px.size() * 14);
  for (const Eigen::Vector2d& p : points_px) {
    if (!out.empty()) out += ' ';
    out += svg_number(p.x()) + "," + svg_number(p.y());
  }
  return out;
}

}  // namespace

std::string xml_escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default:
        // XML 1.0 allows no control characters other than tab, line feed and carriage return.
        if (static_cast<unsigned char>(c) >= 0x20 || c == '\t' || c == '\n' || c == '\r') out += c;
    }
  }
  return out;
}

std::string svg_number(double value, int decimals) {
  if (!std::isfinite(value)) return "0";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  std::string out = buffer;
  if (out.find('.') != std::string::npos) {
    while (out.back() == '0') out.pop_back();
    if (out.back() == '.') out.pop_back();
  }
  if (out == "-0") out = "0";
  return out;
}

SvgDocument::SvgDocument(double width_px, double height_px) : width_px_(width_px), height_px_(height_px) {
  rect(0.0, 0.0, width_px, height_px, SvgStyle{"white", "none", 0.0, 1.0, {}});
}

void SvgDocument::append_style(const SvgStyle& style) {
  body_ += " fill=\"" + xml_escape(style.fill) + "\" stroke=\"" + xml_escape(style.stroke) + "\"";
  if (style.stroke != "none") body_ += " stroke-width=\"" + svg_number(style.stroke_width_px) + "\"";
  if (style.opacity < 1.0) body_ += " opacity=\"" + svg_number(style.opacity, 3) + "\"";
  if (!style.dash.empty()) body_ += " stroke-dasharray=\"" + xml_escape(style.dash) + "\"";
}

void SvgDocument::rect(double x, double y, double width, double height, const SvgStyle& style) {
  body_ += "<rect x=\"" + svg_number(x) + "\" y=\"" + svg_number(y) + "\" width=\"" + svg_number(width) +
           "\" height=\"" + svg_number(height) + "\"";
  append_style(style);
  body_ += "/>\n";
}

void SvgDocument::line(double x1, double y1, double x2, double y2, const SvgStyle& style) {
  body_ += "<line x1=\"" + svg_number(x1) + "\" y1=\"" + svg_number(y1) + "\" x2=\"" + svg_number(x2) + "\" y2=\"" +
           svg_number(y2) + "\"";
  append_style(style);
  body_ += "/>\n";
}

void SvgDocument::circle(double cx, double cy, double r, const SvgStyle& style) {
  body_ += "<circle cx=\"" + svg_number(cx) + "\" cy=\"" + svg_number(cy) + "\" r=\"" + svg_number(r) + "\"";
  append_style(style);
  body_ += "/>\n";
}

void SvgDocument::polyline(const std::vector<Eigen::Vector2d>& points_px, const SvgStyle& style) {
  if (points_px.size() < 2) return;
  body_ += "<polyline points=\"" + points_attribute(points_px) + "\"";
  append_style(style);
  body_ += " stroke-linejoin=\"round\" stroke-linecap=\"round\"/>\n";
}

void SvgDocument::polygon(const std::vector<Eigen::Vector2d>& points_px, const SvgStyle& style) {
  if (points_px.size() < 3) return;
  body_ += "<polygon points=\"" + points_attribute(points_px) + "\"";
  append_style(style);
  body_ += "/>\n";
}

void SvgDocument::text(double x, double y, const std::string& text, const SvgTextStyle& style) {
  body_ += "<text x=\"" + svg_number(x) + "\" y=\"" + svg_number(y) + "\" font-size=\"" + svg_number(style.size_px) +
           "\" text-anchor=\"" + xml_escape(style.anchor) + "\" fill=\"" + xml_escape(style.fill) + "\"";
  if (style.bold) body_ += " font-weight=\"bold\"";
  if (style.rotate_deg != 0.0) {
    body_ += " transform=\"rotate(" + svg_number(style.rotate_deg) + " " + svg_number(x) + " " + svg_number(y) + ")\"";
  }
  body_ += ">" + xml_escape(text) + "</text>\n";
}

void SvgDocument::define_clip(const std::string& id, double x, double y, double width, double height) {
  defs_ += "<clipPath id=\"" + xml_escape(id) + "\"><rect x=\"" + svg_number(x) + "\" y=\"" + svg_number(y) +
           "\" width=\"" + svg_number(width) + "\" height=\"" + svg_number(height) + "\"/></clipPath>\n";
}

void SvgDocument::begin_group(const std::string& clip_id) {
  body_ += clip_id.empty() ? "<g>\n" : "<g clip-path=\"url(#" + xml_escape(clip_id) + ")\">\n";
  ++open_groups_;
}

void SvgDocument::end_group() {
  if (open_groups_ == 0) return;
  body_ += "</g>\n";
  --open_groups_;
}

std::string SvgDocument::str() const {
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out += "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" + svg_number(width_px_) + "\" height=\"" +
         svg_number(height_px_) + "\" viewBox=\"0 0 " + svg_number(width_px_) + " " + svg_number(height_px_) +
         "\" font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\">\n";
  if (!defs_.empty()) out += "<defs>\n" + defs_ + "</defs>\n";
  out += body_;
  for (int k = 0; k < open_groups_; ++k) out += "</g>\n";
  out += "</svg>\n";
  return out;
}

Status SvgDocument::write(const std::string& path) const {
  return io::write_text_file(path, str(), "SVG file");
}

}  // namespace canyon::eval
