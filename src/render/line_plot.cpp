#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/core/types.hpp>
#include <priormap/render/line_plot.hpp>
#include <priormap/render/ticks.hpp>

#include "axis_labels.hpp"
#include "canvas.hpp"
#include "clip.hpp"

namespace priormap::render {
namespace {

constexpr double kFont = 11.0;
constexpr int kXTicks = 8, kYTicks = 6;
constexpr double kMinWidth = 200, kMinHeight = 150;
// Left of the plot: the y tick labels end kYLabelGap before it, and the rotated y label, centred
// kYTitleX from the figure's edge, needs kYTitleRoom of the margin.
constexpr double kLeft = 72, kYLabelGap = 6, kYTitleX = 16, kYTitleRoom = 26;
constexpr double kRight = 20;
// Between a tick label and the figure's edge, at least.
constexpr double kEdgeGap = 2;
// A plot is at least this wide, the figure grown if need be.
constexpr double kMinPlotWidth = 50;
// A marker this large covers the whole plot from any point drawn (within a plot of it); Cairo
// spends minutes on a disc of 1e300 pixels.
constexpr double kLargestMarkerPx = 1e6;

std::pair<double, double> DataRange(const std::vector<Series>& series, bool use_x,
                                    const std::vector<std::pair<double, Color>>& extra) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Series& s : series) {
    for (double v : use_x ? s.x : s.y) {
      if (std::isfinite(v)) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
    }
  }
  if (!use_x) {
    // A line at infinity (a bound that diverged) is not drawn, and cannot set the axis.
    for (const auto& [y, color] : extra) {
      if (std::isfinite(y)) {
        lo = std::min(lo, y);
        hi = std::max(hi, y);
      }
    }
  }
  if (!std::isfinite(lo)) return {0.0, 1.0};
  // The padded ends stay finite: data near the largest double would pad out to infinity.
  constexpr double kLargest = std::numeric_limits<double>::max();
  if (lo == hi) {
    return {std::max(lo - std::max(0.5, std::abs(lo) * 0.1), -kLargest),
            std::min(hi + std::max(0.5, std::abs(hi) * 0.1), kLargest)};
  }
  if (!use_x) {
    const double pad = 0.05 * hi - 0.05 * lo;
    return {std::max(lo - pad, -kLargest), std::min(hi + pad, kLargest)};
  }
  return {lo, hi};
}

}  // namespace

void LinePlot::AddHorizontalLine(double y, const Color& color, std::string label) {
  detail::CheckColor(color, "a horizontal line's color");
  Series s;
  s.label = std::move(label);
  s.color = color;
  s.dash_px = {6.0, 4.0};
  s.y = {y, y};  // x filled in at drawing time with the axis range
  horizontal_lines_.push_back(std::move(s));
}

void LinePlot::Add(Series series) {
  detail::CheckDashes(series.dash_px);
  detail::CheckPixels(series.width_px, "a series' width_px");
  if (series.color) detail::CheckColor(*series.color, "a series' color");
  series_.push_back(std::move(series));
}

LinePlot::LinePlot(LinePlotOptions options) : options_(std::move(options)) {
  // Sizes below the least grow to it; a negative one is a caller's mistake.
  detail::CheckPixels(options_.width_px, "a line plot's width_px");
  detail::CheckPixels(options_.height_px, "a line plot's height_px");
  detail::CheckFigureSize(std::max<double>(options_.width_px, kMinWidth),
                          std::max<double>(options_.height_px, kMinHeight));
}

void LinePlot::Save(const std::filesystem::path& path) const {
  for (const Series& s : series_) {
    PRIORMAP_CHECK(s.x.size() == s.y.size(), "a series needs as many x as y values");
  }
  std::vector<std::pair<double, Color>> lines;
  for (const Series& s : horizontal_lines_) lines.emplace_back(s.y[0], *s.color);
  // Plain variables rather than structured bindings: lambdas below capture them (clang 14 cannot).
  const std::pair<double, double> x_range =
      options_.x_range.value_or(DataRange(series_, true, lines));
  const std::pair<double, double> y_range =
      options_.y_range.value_or(DataRange(series_, false, lines));
  const double x_lo = x_range.first, x_hi = x_range.second, y_lo = y_range.first,
               y_hi = y_range.second;
  PRIORMAP_CHECK(std::isfinite(x_lo) && std::isfinite(x_hi) && std::isfinite(y_lo) &&
                     std::isfinite(y_hi) && x_lo < x_hi && y_lo < y_hi,
                 fmt::format("a line plot's ranges must be finite and not empty (got x [{}, {}], "
                             "y [{}, {}])",
                             x_lo, x_hi, y_lo, y_hi));

  // The layout: margins that hold the tick labels, and ticks no closer than their labels need.
  double width = std::max<double>(options_.width_px, kMinWidth);
  const double height = std::max<double>(options_.height_px, kMinHeight);
  const double top = options_.title.empty() ? 16 : 38, bottom = 52;
  const double plot_h = height - top - bottom;
  const detail::TickLabels ys =
      detail::LabelTicks(SpacedNiceTicks(y_lo, y_hi, kYTicks, plot_h, kFont + 3), kFont);
  // Wide y labels (values in the millions) ran into the y label: the margin grows.
  double left = std::max(kLeft, ys.Widest() + kYLabelGap + kYTitleRoom), right = kRight;
  const double x_spacing =
      detail::LabelTicks(NiceTicks(x_lo, x_hi, kXTicks), kFont).Widest() + kFont;
  double plot_w = 0.0;
  detail::TickLabels xs;
  // The x labels are centred on their ticks, and the last was cut at the figure's edge when
  // wider than twice the margin ("1000000"): the margins grow until the labels fit, each round
  // leaving at most the part of the shortfall beyond the end tick.
  detail::GrowMarginsForEndLabels(left, right, [&](double l, double r) {
    width = std::ceil(std::max(width, l + r + kMinPlotWidth));
    plot_w = width - l - r;
    xs = detail::LabelTicks(SpacedNiceTicks(x_lo, x_hi, kXTicks, plot_w, x_spacing), kFont);
    const auto [before, after] = detail::LabelOverhang(xs, x_lo, x_hi, plot_w);
    return std::pair{before + kEdgeGap - l, after + kEdgeGap - r};
  });
  // Where a point falls across the plot: 0 to 1 from its left (top) edge, in halves so that a
  // range wider than the largest double does not overflow.
  const auto across = [&](double x, double y) {
    return Vec2((x / 2 - x_lo / 2) / (x_hi / 2 - x_lo / 2),
                (y_hi / 2 - y / 2) / (y_hi / 2 - y_lo / 2));
  };
  const auto to_device = [&](const Vec2& a) {
    return Vec2(left + a.x() * plot_w, top + a.y() * plot_h);
  };
  // Data is clipped to the plot and as much again around it before Cairo sees it: its
  // fixed-point coordinates wrap beyond about 8 million pixels, which drew a line to a point far
  // beyond an explicit range short, or elsewhere.
  const Box2 shown(Vec2(-1.0, -1.0), Vec2(2.0, 2.0));

  detail::Canvas canvas(width, height);
  cairo_t* c = canvas.cr();
  detail::SetColor(c, palette::kBlack);
  if (!options_.title.empty())
    detail::DrawText(c, options_.title, left + plot_w / 2, 12, 14.0, 0.5, 0.0, true);

  // Grid and tick labels.
  cairo_set_line_width(c, 1.0);
  for (std::size_t i = 0; i < xs.ticks.size(); ++i) {
    const double dx = to_device(across(xs.ticks[i], y_lo)).x();
    detail::SetColor(c, palette::kLightGray);
    cairo_move_to(c, dx, top);
    cairo_line_to(c, dx, top + plot_h);
    cairo_stroke(c);
    detail::SetColor(c, palette::kBlack);
    detail::DrawText(c, xs.labels[i], dx, top + plot_h + 6, kFont, 0.5, 0.0);
  }
  for (std::size_t i = 0; i < ys.ticks.size(); ++i) {
    const double dy = to_device(across(x_lo, ys.ticks[i])).y();
    detail::SetColor(c, palette::kLightGray);
    cairo_move_to(c, left, dy);
    cairo_line_to(c, left + plot_w, dy);
    cairo_stroke(c);
    detail::SetColor(c, palette::kBlack);
    detail::DrawText(c, ys.labels[i], left - kYLabelGap, dy, kFont, 1.0, 0.5);
  }
  detail::DrawText(c, options_.x_label, left + plot_w / 2, height - 18, kFont, 0.5, 0.0);
  cairo_save(c);
  cairo_translate(c, kYTitleX, top + plot_h / 2);
  cairo_rotate(c, -M_PI / 2);
  detail::DrawText(c, options_.y_label, 0, 0, kFont, 0.5, 0.5);
  cairo_restore(c);

  // Data, clipped to the plot area.
  cairo_save(c);
  cairo_rectangle(c, left, top, plot_w, plot_h);
  cairo_clip(c);
  std::vector<std::pair<std::string, Color>> legend;
  const auto draw = [&](const Series& s, const Color& color) {
    detail::SetColor(c, color);
    if (s.markers) {
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        const Vec2 a = across(s.x[i], s.y[i]);
        if (!shown.contains(a)) continue;  // also leaves out NaN
        const Vec2 d = to_device(a);
        cairo_new_sub_path(c);
        cairo_arc(c, d.x(), d.y(), std::clamp(s.width_px, 1.5, kLargestMarkerPx), 0, 2 * M_PI);
      }
      cairo_fill(c);
    } else {
      cairo_new_path(c);
      // Each run of finite points, clipped; a point between gaps is a segment of no length,
      // which the round cap draws as a dot.
      std::vector<Vec2> run;
      const auto end_run = [&] {
        if (run.size() == 1 && shown.contains(run[0])) {
          const Vec2 d = to_device(run[0]);
          cairo_move_to(c, d.x(), d.y());
          cairo_line_to(c, d.x(), d.y());
        } else if (run.size() > 1) {
          for (const std::vector<Vec2>& piece : detail::ClipPolyline(run, false, shown).pieces) {
            const Vec2 first = to_device(piece[0]);
            cairo_move_to(c, first.x(), first.y());
            for (std::size_t k = 1; k < piece.size(); ++k) {
              const Vec2 d = to_device(piece[k]);
              cairo_line_to(c, d.x(), d.y());
            }
          }
        }
        run.clear();
      };
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
          run.push_back(across(s.x[i], s.y[i]));
        } else {
          end_run();
        }
      }
      end_run();
      cairo_set_line_width(c, s.width_px);
      cairo_set_dash(c, s.dash_px.data(), static_cast<int>(s.dash_px.size()), 0.0);
      cairo_set_line_join(c, CAIRO_LINE_JOIN_ROUND);
      cairo_set_line_cap(c, CAIRO_LINE_CAP_ROUND);
      cairo_stroke(c);
    }
    if (!s.label.empty()) legend.emplace_back(s.label, color);
  };
  for (std::size_t k = 0; k < series_.size(); ++k) {
    draw(series_[k], series_[k].color.value_or(palette::Categorical(static_cast<int>(k))));
  }
  for (Series s : horizontal_lines_) {
    if (!std::isfinite(s.y[0])) continue;
    s.x = {x_lo, x_hi};
    draw(s, *s.color);
  }
  cairo_restore(c);

  detail::SetColor(c, palette::kBlack);
  cairo_set_line_width(c, 1.0);
  cairo_set_dash(c, nullptr, 0, 0.0);
  cairo_rectangle(c, left, top, plot_w, plot_h);
  cairo_stroke(c);

  detail::DrawLegend(c, legend, left + plot_w - 8, top + 8, true);
  canvas.Save(path);
}

}  // namespace priormap::render
