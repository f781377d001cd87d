#include <algorithm>
#include <cmath>
#include <limits>

#include <priormap/core/check.hpp>
#include <priormap/core/types.hpp>
#include <priormap/render/line_plot.hpp>
#include <priormap/render/ticks.hpp>

#include "canvas.hpp"

namespace priormap::render {
namespace {

constexpr double kFont = 11.0;

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
  Series s;
  s.label = std::move(label);
  s.color = color;
  s.dash_px = {6.0, 4.0};
  s.y = {y, y};  // x filled in at drawing time with the axis range
  horizontal_lines_.push_back(std::move(s));
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
  PRIORMAP_CHECK(x_lo < x_hi && y_lo < y_hi, "plot ranges must not be empty");

  const double width = std::max(options_.width_px, 200), height = std::max(options_.height_px, 150);
  const double left = 72, right = 20, top = options_.title.empty() ? 16 : 38, bottom = 52;
  const double plot_w = width - left - right, plot_h = height - top - bottom;
  // Halves, so that a range wider than the largest double does not overflow.
  const auto to_device = [&](double x, double y) {
    return Vec2(left + (x / 2 - x_lo / 2) / (x_hi / 2 - x_lo / 2) * plot_w,
                top + (y_hi / 2 - y / 2) / (y_hi / 2 - y_lo / 2) * plot_h);
  };

  detail::Canvas canvas(width, height);
  cairo_t* c = canvas.cr();
  detail::SetColor(c, palette::kBlack);
  if (!options_.title.empty())
    detail::DrawText(c, options_.title, left + plot_w / 2, 12, 14.0, 0.5, 0.0, true);

  // Grid and tick labels.
  const std::vector<double> xs = NiceTicks(x_lo, x_hi, 8), ys = NiceTicks(y_lo, y_hi, 6);
  const double x_step = xs.size() > 1 ? xs[1] - xs[0] : 1.0,
               y_step = ys.size() > 1 ? ys[1] - ys[0] : 1.0;
  cairo_set_line_width(c, 1.0);
  for (double x : xs) {
    const double dx = to_device(x, y_lo).x();
    detail::SetColor(c, palette::kLightGray);
    cairo_move_to(c, dx, top);
    cairo_line_to(c, dx, top + plot_h);
    cairo_stroke(c);
    detail::SetColor(c, palette::kBlack);
    detail::DrawText(c, TickLabel(x, x_step), dx, top + plot_h + 6, kFont, 0.5, 0.0);
  }
  for (double y : ys) {
    const double dy = to_device(x_lo, y).y();
    detail::SetColor(c, palette::kLightGray);
    cairo_move_to(c, left, dy);
    cairo_line_to(c, left + plot_w, dy);
    cairo_stroke(c);
    detail::SetColor(c, palette::kBlack);
    detail::DrawText(c, TickLabel(y, y_step), left - 6, dy, kFont, 1.0, 0.5);
  }
  detail::DrawText(c, options_.x_label, left + plot_w / 2, height - 18, kFont, 0.5, 0.0);
  cairo_save(c);
  cairo_translate(c, 16, top + plot_h / 2);
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
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
        const Vec2 d = to_device(s.x[i], s.y[i]);
        cairo_new_sub_path(c);
        cairo_arc(c, d.x(), d.y(), std::max(1.5, s.width_px), 0, 2 * M_PI);
      }
      cairo_fill(c);
    } else {
      cairo_new_path(c);
      bool pen_down = false;
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
          pen_down = false;
          continue;
        }
        const Vec2 d = to_device(s.x[i], s.y[i]);
        if (pen_down) {
          cairo_line_to(c, d.x(), d.y());
        } else {
          cairo_move_to(c, d.x(), d.y());
          const bool isolated =
              i + 1 == s.x.size() || !std::isfinite(s.x[i + 1]) || !std::isfinite(s.y[i + 1]);
          // A point between gaps: a segment of no length, which the round cap draws as a dot.
          if (isolated) cairo_line_to(c, d.x(), d.y());
        }
        pen_down = true;
      }
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
