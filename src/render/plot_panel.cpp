#include "plot_panel.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>

#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/render/ticks.hpp>

#include "axis_labels.hpp"
#include "canvas.hpp"
#include "clip.hpp"
#include "raster_image.hpp"

namespace priormap::render::detail {
namespace {

constexpr double kAxisFont = 11.0, kTitleFont = 13.0, kLegendFont = 11.0;
// Left of the plot: the y tick labels end kYLabelGap before it; the rotated y label, centred
// kYTitleInset into the cell, needs kYTitleRoom of the margin.
constexpr double kLeft = 70, kYLabelGap = 7, kYTitleInset = 14, kYTitleRoom = 24;
// Between a tick label and the cell's edge, at least.
constexpr double kEdgeGap = 2;
// Marks this far beyond the figure are left out: Cairo's fixed point wraps at ~8.4 M px.
constexpr double kFarOutsidePx = 1e6;

void SetStroke(cairo_t* cr, const Color& color, double width_px, std::span<const double> dash_px) {
  SetColor(cr, color);
  cairo_set_line_width(cr, width_px);
  cairo_set_dash(cr, dash_px.data(), static_cast<int>(dash_px.size()), 0.0);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
}

void CrossPath(cairo_t* cr, const Vec2& d, double h) {
  cairo_move_to(cr, d.x() - h, d.y() - h);
  cairo_line_to(cr, d.x() + h, d.y() + h);
  cairo_move_to(cr, d.x() - h, d.y() + h);
  cairo_line_to(cr, d.x() + h, d.y() - h);
}

// Powers of ten inside [lo, hi] (log10 units), with 2 and 5 times them when fewer than three.
std::vector<double> LogTicks(double lo, double hi) {
  std::vector<double> ticks;
  const auto add = [&](double factor) {
    for (double k = std::floor(lo); k <= std::ceil(hi); ++k) {
      const double t = k + std::log10(factor);
      if (t >= lo - 1e-9 && t <= hi + 1e-9) ticks.push_back(t);
    }
  };
  add(1.0);
  if (ticks.size() < 3) {
    add(2.0);
    add(5.0);
    std::sort(ticks.begin(), ticks.end());
  }
  return ticks;
}

}  // namespace

Panel::Panel(cairo_t* cr, const Rect& cell, double x_lo, double x_hi, double y_lo, double y_hi,
             PanelOptions options)
    : cr_(cr), cell_(cell), options_(std::move(options)) {
  PRIORMAP_CHECK(x_lo < x_hi && y_lo < y_hi, "a panel needs non-empty ranges");
  PRIORMAP_CHECK(!options_.log_y || y_lo > 0.0, "a logarithmic axis needs positive values");
  x_lo_ = x_lo;
  x_hi_ = x_hi;
  y_lo_ = options_.log_y ? std::log10(y_lo) : y_lo;
  y_hi_ = options_.log_y ? std::log10(y_hi) : y_hi;
  top_ = options_.title.empty() ? 10 : 38;
  bottom_ = 46 + (options_.legend_row ? 24 : 0);
  double left = kLeft, right = options_.right_margin_px;
  LayOut(left, right);
  // Wide y labels ran into the y label: the margin grows (measured on the ticks of this height;
  // equal_aspect may give fewer, no wider).
  double widest = 0.0;
  for (const std::string& label : YLabels(YTicks()))
    widest = std::max(widest, TextWidth(label, kAxisFont));
  left = std::max(left, widest + kYLabelGap + kYTitleRoom);
  y_title_ = left - kYTitleInset;
  // The x labels are centred on their ticks: the margins grow until those at the ends stay in
  // the cell (the last was cut at the figure's edge, or ran into the next panel).
  GrowMarginsForEndLabels(left, right, [&](double l, double r) {
    LayOut(l, r);
    const auto [before, after] =
        LabelOverhang(LabelTicks(XTicks(), kAxisFont), x_lo_, x_hi_, plot_.width);
    return std::pair{before + kEdgeGap - (plot_.x - cell_.x),
                     after + kEdgeGap - (cell_.x + cell_.width - plot_.x - plot_.width)};
  });
}

void Panel::LayOut(double left, double right) {
  plot_ = {cell_.x + left, cell_.y + top_, std::max(cell_.width - left - right, 10.0),
           std::max(cell_.height - top_ - bottom_, 10.0)};
  if (options_.equal_aspect) {
    const double scale = std::min(plot_.width / (x_hi_ - x_lo_), plot_.height / (y_hi_ - y_lo_));
    const double width = (x_hi_ - x_lo_) * scale;
    plot_.x += (plot_.width - width) / 2;
    plot_.width = width;
    plot_.height = (y_hi_ - y_lo_) * scale;
  }
}

std::vector<double> Panel::XTicks() const {
  return NiceTicks(x_lo_, x_hi_, std::max(2, static_cast<int>(plot_.width / 80)));
}

std::vector<double> Panel::YTicks() const {
  return options_.log_y ? LogTicks(y_lo_, y_hi_)
                        : NiceTicks(y_lo_, y_hi_, std::max(2, static_cast<int>(plot_.height / 45)));
}

std::vector<std::string> Panel::YLabels(const std::vector<double>& ticks) const {
  const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 1.0;
  std::vector<std::string> labels;
  for (const double y : ticks)
    labels.push_back(options_.log_y ? fmt::format("{:g}", std::pow(10.0, y)) : TickLabel(y, step));
  return labels;
}

double Panel::YValue(double y) const {
  return options_.log_y ? (y > 0.0 ? std::log10(y) : std::nan("")) : y;
}

Vec2 Panel::ToDevice(const Vec2& p) const {
  const double ty = (YValue(p.y()) - y_lo_) / (y_hi_ - y_lo_);
  return {plot_.x + (p.x() - x_lo_) / (x_hi_ - x_lo_) * plot_.width,
          plot_.y + (options_.invert_y ? ty : 1.0 - ty) * plot_.height};
}

void Panel::DrawFrame() const {
  cairo_t* c = cr_;
  cairo_save(c);
  SetColor(c, palette::kBlack);
  if (!options_.title.empty()) {
    DrawText(c, options_.title, plot_.x + plot_.width / 2, plot_.y - 24, kTitleFont, 0.5, 0.0,
             true);
  }
  const double bottom = plot_.y + plot_.height;
  const std::vector<double> xs = XTicks();
  const std::vector<double> ys = YTicks();
  const std::vector<std::string> y_labels = YLabels(ys);
  const double x_step = xs.size() > 1 ? xs[1] - xs[0] : 1.0;
  cairo_set_line_width(c, 1.0);
  cairo_set_dash(c, nullptr, 0, 0.0);
  for (double x : xs) {
    const double dx = plot_.x + (x - x_lo_) / (x_hi_ - x_lo_) * plot_.width;
    if (options_.grid) {
      SetColor(c, palette::kLightGray);
      cairo_move_to(c, dx, plot_.y);
      cairo_line_to(c, dx, bottom);
      cairo_stroke(c);
    }
    SetColor(c, palette::kBlack);
    cairo_move_to(c, dx, bottom);
    cairo_line_to(c, dx, bottom + 4);
    cairo_stroke(c);
    DrawText(c, TickLabel(x, x_step), dx, bottom + 7, kAxisFont, 0.5, 0.0);
  }
  for (std::size_t i = 0; i < ys.size(); ++i) {
    const double y = ys[i];
    const double ty = (y - y_lo_) / (y_hi_ - y_lo_);
    const double dy = plot_.y + (options_.invert_y ? ty : 1.0 - ty) * plot_.height;
    if (options_.grid) {
      SetColor(c, palette::kLightGray);
      cairo_move_to(c, plot_.x, dy);
      cairo_line_to(c, plot_.x + plot_.width, dy);
      cairo_stroke(c);
    }
    SetColor(c, palette::kBlack);
    cairo_move_to(c, plot_.x - 4, dy);
    cairo_line_to(c, plot_.x, dy);
    cairo_stroke(c);
    DrawText(c, y_labels[i], plot_.x - kYLabelGap, dy, kAxisFont, 1.0, 0.5);
  }
  DrawText(c, options_.x_label, plot_.x + plot_.width / 2, bottom + 25, kAxisFont, 0.5, 0.0);
  cairo_save(c);
  cairo_translate(c, plot_.x - y_title_, plot_.y + plot_.height / 2);
  cairo_rotate(c, -M_PI / 2);
  DrawText(c, options_.y_label, 0.0, 0.0, kAxisFont, 0.5, 0.5);
  cairo_restore(c);
  cairo_rectangle(c, plot_.x, plot_.y, plot_.width, plot_.height);
  cairo_stroke(c);
  cairo_restore(c);
}

void Panel::DrawNote(const std::string& note) const {
  cairo_t* c = cr_;
  cairo_save(c);
  SetColor(c, palette::kBlack);
  if (!options_.title.empty()) {
    DrawText(c, options_.title, plot_.x + plot_.width / 2, plot_.y - 24, kTitleFont, 0.5, 0.0,
             true);
  }
  SetColor(c, palette::kGray);
  cairo_set_line_width(c, 1.0);
  cairo_set_dash(c, nullptr, 0, 0.0);
  cairo_rectangle(c, plot_.x, plot_.y, plot_.width, plot_.height);
  cairo_stroke(c);
  const auto chars = static_cast<std::size_t>(std::max(20.0, plot_.width / 7.5));
  const std::vector<std::string> lines = WrapText(note, chars);
  const double line_height = 18;
  double y = plot_.y + plot_.height / 2 - line_height * (static_cast<double>(lines.size()) - 1) / 2;
  SetColor(c, palette::kBlack);
  for (const std::string& line : lines) {
    DrawText(c, line, plot_.x + plot_.width / 2, y, 12.0, 0.5, 0.5);
    y += line_height;
  }
  cairo_restore(c);
}

void Panel::Clip() const {
  cairo_rectangle(cr_, plot_.x, plot_.y, plot_.width, plot_.height);
  cairo_clip(cr_);
}

void Panel::Polyline(std::span<const Vec2> points, const Color& color, double width_px,
                     std::span<const double> dash_px) const {
  // Cairo refuses such dashes and then draws nothing more of the figure, with no word until saved.
  CheckDashes(dash_px);
  CheckPixels(width_px, "a panel line's width_px");
  cairo_save(cr_);
  Clip();
  cairo_new_path(cr_);
  std::vector<Vec2> device(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) device[i] = ToDevice(points[i]);
  // Clipped to the plot and as much again around it: Cairo's fixed-point coordinates wrap far
  // outside the figure. A lone point (between gaps) stays a move, as it was.
  const Box2 shown(Vec2(plot_.x - plot_.width, plot_.y - plot_.height),
                   Vec2(plot_.x + 2 * plot_.width, plot_.y + 2 * plot_.height));
  for (const std::vector<Vec2>& piece : ClipPolyline(device, false, shown).pieces) {
    cairo_move_to(cr_, piece[0].x(), piece[0].y());
    for (std::size_t i = 1; i < piece.size(); ++i) cairo_line_to(cr_, piece[i].x(), piece[i].y());
  }
  SetStroke(cr_, color, width_px, dash_px);
  cairo_stroke(cr_);
  cairo_restore(cr_);
}

void Panel::Dots(std::span<const Vec2> points, const Color& color, double radius_px) const {
  cairo_save(cr_);
  Clip();
  cairo_new_path(cr_);
  for (const Vec2& p : points) {
    const Vec2 d = ToDevice(p);
    if (!(d.cwiseAbs().maxCoeff() < kFarOutsidePx)) continue;  // NaN, or far beyond the plot
    cairo_new_sub_path(cr_);
    cairo_arc(cr_, d.x(), d.y(), radius_px, 0.0, 2 * M_PI);
  }
  SetColor(cr_, color);
  cairo_fill(cr_);
  cairo_restore(cr_);
}

void Panel::Crosses(std::span<const Vec2> points, const Color& color, double half_size_px) const {
  cairo_save(cr_);
  Clip();
  cairo_new_path(cr_);
  for (const Vec2& p : points) {
    const Vec2 d = ToDevice(p);
    if (d.cwiseAbs().maxCoeff() < kFarOutsidePx) CrossPath(cr_, d, half_size_px);  // not NaN
  }
  SetStroke(cr_, color, 1.5, {});
  cairo_stroke(cr_);
  cairo_restore(cr_);
}

void Panel::Segment(const Vec2& a, const Vec2& b, const Color& color, double width_px,
                    std::span<const double> dash_px) const {
  const Vec2 points[2] = {a, b};
  Polyline(points, color, width_px, dash_px);
}

void Panel::PoseMarker(const Vec2& p, double theta, const Color& color, double size_px) const {
  const Vec2 d = ToDevice(p);
  const Vec2 forward(std::cos(theta), -std::sin(theta));  // device y points down
  const Vec2 left(forward.y(), -forward.x());
  const Vec2 corners[3] = {d + size_px * forward, d - 0.5 * size_px * (forward - left),
                           d - 0.5 * size_px * (forward + left)};
  cairo_save(cr_);
  cairo_new_path(cr_);
  cairo_move_to(cr_, corners[0].x(), corners[0].y());
  for (const Vec2& corner : corners) cairo_line_to(cr_, corner.x(), corner.y());
  cairo_close_path(cr_);
  SetColor(cr_, color);
  cairo_fill_preserve(cr_);
  SetStroke(cr_, palette::kBlack, 1.0, {});
  cairo_stroke(cr_);
  cairo_restore(cr_);
}

void Panel::Image(const Eigen::MatrixXd& values, Colormap colormap, double vmin,
                  double vmax) const {
  PRIORMAP_CHECK(values.rows() > 0 && values.cols() > 0 && vmin < vmax,
                 "an image needs cells and vmin < vmax");
  // Image rows run top to bottom; values' rows run along y.
  const RasterImage image = ColormapImage(values, colormap, vmin, vmax, options_.invert_y);
  cairo_save(cr_);
  Clip();
  PaintRaster(cr_, image, plot_.x, plot_.y, plot_.width, plot_.height);
  cairo_restore(cr_);
}

void Panel::ColorBar(Colormap colormap, double vmin, double vmax, const std::string& label) const {
  PRIORMAP_CHECK(vmin < vmax, "a colour bar needs vmin < vmax");
  cairo_t* c = cr_;
  cairo_save(c);
  const double x = plot_.x + plot_.width + 16, width = 14, top = plot_.y, height = plot_.height;
  constexpr int kSteps = 128;
  for (int i = 0; i < kSteps; ++i) {
    SetColor(c, MapColor(colormap, (i + 0.5) / kSteps));
    cairo_rectangle(c, x, top + height * (1.0 - static_cast<double>(i + 1) / kSteps), width,
                    height / kSteps + 0.5);
    cairo_fill(c);
  }
  SetStroke(c, palette::kBlack, 1.0, {});
  cairo_rectangle(c, x, top, width, height);
  cairo_stroke(c);
  const std::vector<double> ticks = NiceTicks(vmin, vmax, 6);
  const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 1.0;
  double label_width = 0.0;
  for (double v : ticks) {
    const double y = top + height * (1.0 - (v - vmin) / (vmax - vmin));
    cairo_move_to(c, x + width, y);
    cairo_line_to(c, x + width + 4, y);
    cairo_stroke(c);
    const std::string text = TickLabel(v, step);
    DrawText(c, text, x + width + 6, y, kAxisFont, 0.0, 0.5);
    cairo_text_extents_t extents;
    cairo_text_extents(c, ValidUtf8(text).c_str(), &extents);
    label_width = std::max(label_width, extents.x_advance);
  }
  cairo_translate(c, x + width + 6 + label_width + 14, top + height / 2);
  cairo_rotate(c, -M_PI / 2);
  DrawText(c, label, 0.0, 0.0, kAxisFont, 0.5, 0.5);
  cairo_restore(c);
}

void Panel::LegendRow(const std::vector<LegendEntry>& entries) const {
  constexpr double kSwatch = 24.0, kGap = 5.0, kSpacing = 16.0, kRowHeight = 16.0;
  for (const LegendEntry& e : entries) {
    if (e.marker != Marker::kLine) continue;
    CheckDashes(e.dash_px);
    CheckPixels(e.width_px, "a legend line's width_px");
  }
  cairo_t* c = cr_;
  cairo_save(c);
  cairo_select_font_face(c, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(c, kLegendFont);
  // Entries fill rows as wide as the cell; two rows fit where one is planned.
  std::vector<std::vector<std::size_t>> rows(1);
  std::vector<double> widths, row_widths(1, 0.0);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    cairo_text_extents_t extents;
    cairo_text_extents(c, ValidUtf8(entries[i].label).c_str(), &extents);
    widths.push_back(kSwatch + kGap + extents.x_advance);
    const double added = widths.back() + (rows.back().empty() ? 0.0 : kSpacing);
    if (!rows.back().empty() && row_widths.back() + added > 0.88 * cell_.width) {
      rows.emplace_back();
      row_widths.push_back(0.0);
    }
    row_widths.back() += widths.back() + (rows.back().empty() ? 0.0 : kSpacing);
    rows.back().push_back(i);
  }
  const double centre = std::clamp(plot_.x + plot_.width / 2, cell_.x + row_widths[0] / 2 + 10,
                                   cell_.x + cell_.width - row_widths[0] / 2 - 10);
  double y = plot_.y + plot_.height + 56 - kRowHeight / 2 * static_cast<double>(rows.size() - 1);
  for (std::size_t r = 0; r < rows.size(); ++r, y += kRowHeight) {
    double x = centre - row_widths[r] / 2;
    for (const std::size_t i : rows[r]) {
      const LegendEntry& e = entries[i];
      cairo_new_path(c);
      switch (e.marker) {
        case Marker::kLine:
          cairo_move_to(c, x, y);
          cairo_line_to(c, x + kSwatch, y);
          SetStroke(c, e.color, e.width_px, e.dash_px);
          cairo_stroke(c);
          break;
        case Marker::kDot:
          cairo_arc(c, x + kSwatch / 2, y, 3.0, 0.0, 2 * M_PI);
          SetColor(c, e.color);
          cairo_fill(c);
          break;
        case Marker::kCross:
          CrossPath(c, {x + kSwatch / 2, y}, 4.0);
          SetStroke(c, e.color, 1.5, {});
          cairo_stroke(c);
          break;
      }
      SetColor(c, palette::kBlack);
      DrawText(c, e.label, x + kSwatch + kGap, y, kLegendFont, 0.0, 0.5);
      x += widths[i] + kSpacing;
    }
  }
  cairo_restore(c);
}

std::vector<std::string> WrapText(const std::string& text, std::size_t max_chars) {
  std::vector<std::string> lines;
  std::string line;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find_first_of(" \n", start);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(start, end - start);
    if (!line.empty() && line.size() + 1 + word.size() > max_chars) {
      lines.push_back(line);
      line.clear();
    }
    if (!word.empty()) line += (line.empty() ? "" : " ") + word;
    if (end < text.size() && text[end] == '\n') {
      lines.push_back(line);
      line.clear();
    }
    start = end + 1;
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

}  // namespace priormap::render::detail
