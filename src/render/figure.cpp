#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/segment.hpp>
#include <priormap/render/figure.hpp>
#include <priormap/render/ticks.hpp>

#include "axis_labels.hpp"
#include "canvas.hpp"
#include "clip.hpp"
#include "raster_image.hpp"

namespace priormap::render {
namespace {

constexpr double kAxisFont = 11.0;
constexpr double kTitleFont = 14.0;
// Device coordinates beyond this are far outside any figure, and near where Cairo's 24.8
// fixed-point coordinates wrap.
constexpr double kFarOutsidePx = 1e6;
// Above this many points, Figure::Points draws a raster layer instead of one arc per point.
constexpr std::size_t kMaxVectorPoints = 20000;
constexpr double kMaskScale = 2.0;
constexpr double kMaxMaskPixels = 16e6;

constexpr int kAxisTicks = 8;
// Left of the y tick labels: the gap to the axis and the rotated "y (m)" beyond them.
constexpr double kYLabelGap = 8.0, kYTitleRoom = 22.0;
// Between a tick label and the figure's edge, at least.
constexpr double kEdgeGap = 2.0;
// A plot is at least this wide and tall, the figure grown if need be.
constexpr double kMinPlotPx = 10.0;
// Right of the plot with a colour bar: the bar, its tick labels and its label (rotated).
constexpr double kColorbarGap = 18.0, kColorbarWidth = 16.0, kColorbarTitleOffset = 52.0;
// Tick labels of the colour bar at most this wide leave room for its label at its place.
constexpr double kColorbarLabelRoom = 36.0;

// The width of the widest label of the ticks NiceTicks puts on [lo, hi].
double WidestTickLabel(double lo, double hi) {
  const std::vector<double> ticks = NiceTicks(lo, hi, kAxisTicks);
  const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 1.0;
  double widest = 0.0;
  for (double t : ticks)
    widest = std::max(widest, detail::TextWidth(TickLabel(t, step), kAxisFont));
  return widest;
}

struct Margins {
  double left, right, top, bottom;
};

// A disc this large covers the whole figure from any centre Drawable admits; Cairo spends minutes
// on one of 1e300 pixels.
constexpr double kLargestRadiusPx = 2 * kFarOutsidePx;

// Refuses, where the style is given, a style Cairo would not draw as asked.
void CheckLineStyle(const LineStyle& style) {
  detail::CheckDashes(style.dash_px);
  detail::CheckPixels(style.width_px, "a line style's width_px");
  detail::CheckColor(style.color, "a line style's color");
}

// The stroke of `style`: its colour, width and dashes.
void SetLineStyle(cairo_t* cr, const LineStyle& style) {
  detail::SetColor(cr, style.color);
  cairo_set_line_width(cr, style.width_px);
  cairo_set_dash(cr, style.dash_px.data(), static_cast<int>(style.dash_px.size()), 0.0);
}

// Adds the path through the device points `device` (not empty) to the current one.
void AddPath(cairo_t* cr, std::span<const Vec2> device, bool closed) {
  cairo_move_to(cr, device[0].x(), device[0].y());
  for (std::size_t i = 1; i < device.size(); ++i) cairo_line_to(cr, device[i].x(), device[i].y());
  if (closed) cairo_close_path(cr);
}

void StrokePath(cairo_t* cr, std::span<const Vec2> device, bool closed, const LineStyle& style) {
  if (device.empty() || style.width_px <= 0.0) return;
  cairo_new_path(cr);
  AddPath(cr, device, closed);
  SetLineStyle(cr, style);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_stroke(cr);
}

// "×10⁵", "×10⁻⁴": the unit of ticks written in powers of ten.
std::string PowerOfTen(int exponent) {
  static const std::array<const char*, 10> kDigits = {"⁰", "¹", "²", "³", "⁴",
                                                      "⁵", "⁶", "⁷", "⁸", "⁹"};
  std::string out = exponent < 0 ? "×10⁻" : "×10";
  for (const char digit : std::to_string(std::abs(exponent)))
    out += kDigits[static_cast<std::size_t>(digit - '0')];
  return out;
}

}  // namespace

struct Figure::Impl {
  FigureOptions options;
  Box2 world;  // padded
  Margins margins{};
  double scale = 1.0;  // pixels per metre
  double plot_width = 0.0, plot_height = 0.0;
  double x_label_spacing = 0.0;  // the least distance between x ticks, in pixels
  std::unique_ptr<detail::Canvas> canvas;
  std::vector<std::pair<std::string, Color>> legend;

  Vec2 ToDevice(const Vec2& p) const {
    return {margins.left + (p.x() - world.min().x()) * scale,
            margins.top + (world.max().y() - p.y()) * scale};
  }
  std::vector<Vec2> ToDevice(std::span<const Vec2> points) const {
    std::vector<Vec2> device(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) device[i] = ToDevice(points[i]);
    return device;
  }
  cairo_t* cr() const { return canvas->cr(); }

  // The plot's scale and size for the margins; returns the figure's width.
  double LayOut() {
    const Vec2 size = world.sizes();
    // A size smaller than the margins grows to leave a plot: a negative room would flip the world.
    const double width = std::ceil(
        std::max(std::max(options.width_px, 100) * 1.0, margins.left + margins.right + kMinPlotPx));
    const double max_plot_height =
        std::max(std::max(options.max_height_px, 100) - margins.top - margins.bottom, kMinPlotPx);
    scale = (width - margins.left - margins.right) / size.x();
    if (size.y() * scale > max_plot_height) scale = max_plot_height / size.y();
    plot_width = size.x() * scale;
    plot_height = size.y() * scale;
    return width;
  }

  // The x ticks and their labels: labels side by side need their width apart.
  detail::TickLabels XTicks() const {
    return detail::LabelTicks(
        SpacedNiceTicks(world.min().x(), world.max().x(), kAxisTicks, plot_width, x_label_spacing),
        kAxisFont);
  }

  // What may be drawn: the world and as much again on each side, at least 64 pixels, so that
  // lines and outlines clipped to it end out of sight (the plot shows the world). Cairo's
  // fixed-point coordinates wrap far outside the figure, which turned long lines round.
  Box2 Shown() const {
    const Vec2 reach = world.sizes().cwiseMax(Vec2::Constant(64.0 / scale));
    return {world.min() - reach, world.max() + reach};
  }

  // A polyline clipped to what is shown, broken at non-finite points.
  void StrokeClipped(std::span<const Vec2> points, bool closed, const LineStyle& style) const {
    const detail::ClippedPolyline clipped = detail::ClipPolyline(points, closed, Shown());
    for (const std::vector<Vec2>& piece : clipped.pieces)
      StrokePath(cr(), ToDevice(piece), clipped.closed, style);
  }

  // Whether a device point is near enough the figure to draw a mark of a few pixels at.
  static bool Drawable(const Vec2& device) {
    return device.cwiseAbs().maxCoeff() < kFarOutsidePx;  // also false for NaN
  }

  // Whether Cairo can draw the circle of device centre `d` and radius `radius_px` as it is.
  static bool CairoCircle(const Vec2& d, double radius_px) {
    return Drawable(d) && std::abs(radius_px) < kFarOutsidePx;
  }

  // Where a circle too large for Cairo (a radius of a million pixels and more) can be seen: the
  // angles [centre - half, centre + half] (world) that hold every point of it within what is
  // shown, seen from the circle's centre; nullopt when the circle passes by or encloses it all.
  struct Cone {
    double centre, half;
  };
  std::optional<Cone> ConeOnShown(const Circle& circle, bool* encloses = nullptr) const {
    const Box2 shown = Shown();
    const Vec2 towards = shown.center() - circle.center;
    const double reach = shown.sizes().norm() / 2, distance = towards.norm();
    const double radius = std::abs(circle.radius);
    if (encloses != nullptr) *encloses = distance + reach <= radius;
    if (distance > radius + reach || distance + reach <= radius) return std::nullopt;
    return Cone{std::atan2(towards.y(), towards.x()),
                distance > reach ? std::asin(reach / distance) : M_PI};
  }

  // Points of the circle at angles [from, to] (to >= from), close enough that the chords stay
  // within a tenth of a pixel of it.
  std::vector<Vec2> SampleArc(const Circle& circle, double from, double to) const {
    const double radius = std::abs(circle.radius);
    const double step = std::sqrt(8.0 * 0.1 / (radius * scale));
    const double steps = std::ceil((to - from) / step);  // NaN only for a radius of 1e308
    const auto n = static_cast<std::size_t>(!(steps > 8.0) ? 8.0 : std::min(steps, 1e5));
    std::vector<Vec2> points(n + 1);
    for (std::size_t i = 0; i <= n; ++i) {
      const double angle = from + (to - from) * static_cast<double>(i) / static_cast<double>(n);
      points[i] = circle.center + radius * Vec2(std::cos(angle), std::sin(angle));
    }
    return points;
  }

  // The parts of the arc [from, to] (to >= from, at most a turn apart) of a circle too large for
  // Cairo that lie near what is shown, as polylines.
  std::vector<std::vector<Vec2>> VisibleArcs(const Circle& circle, double from, double to) const {
    std::vector<std::vector<Vec2>> arcs;
    const std::optional<Cone> cone = ConeOnShown(circle);
    if (!cone) return arcs;
    // From within [-pi, pi), as the cone's centre is: the arc then ends below 3 pi.
    const double turns = std::floor((from + M_PI) / (2 * M_PI));
    from -= 2 * M_PI * turns;
    to -= 2 * M_PI * turns;
    for (int turn = -1; turn <= 2; ++turn) {
      const double lo = std::max(from, cone->centre - cone->half + 2 * M_PI * turn);
      const double hi = std::min(to, cone->centre + cone->half + 2 * M_PI * turn);
      if (lo < hi) arcs.push_back(SampleArc(circle, lo, hi));
    }
    return arcs;
  }

  // The disc of a circle too large for Cairo within what is shown, as a polygon (empty: none).
  // What is shown lies in the cone, so the disc there is the sector of the cone, clipped.
  std::vector<Vec2> VisibleDisc(const Circle& circle) const {
    const Box2 shown = Shown();
    bool encloses = false;
    const std::optional<Cone> cone = ConeOnShown(circle, &encloses);
    if (encloses) {
      return {shown.corner(Box2::BottomLeft), shown.corner(Box2::BottomRight),
              shown.corner(Box2::TopRight), shown.corner(Box2::TopLeft)};
    }
    if (!cone) return {};
    std::vector<Vec2> sector =
        SampleArc(circle, cone->centre - cone->half, cone->centre + cone->half);
    if (cone->half < M_PI) sector.push_back(circle.center);
    return detail::ClipPolygon(sector, shown);
  }

  // A log's millions of points, each kept as an arc, cost the recorded drawing half a gigabyte
  // and an SVG tens of megabytes. Drawn into one coverage mask of the figure at up to kMaskScale
  // times its resolution they cost at most kMaxMaskPixels bytes, and twice that for the record of
  // where points fell, whatever their number, and look the same in a PNG. False (nothing drawn) for
  // a figure larger than kMaxMaskPixels or one Cairo cannot make a mask of: its points stay
  // vectors.
  bool PointsAsMask(std::span<const Vec2> points, const Color& color, double radius_px) const {
    const double figure_pixels = canvas->width() * canvas->height();
    if (!(figure_pixels <= kMaxMaskPixels)) return false;
    // Twice the figure's resolution, so that a zoomed SVG or PDF stays sharp, where the cap allows.
    const double mask_scale = std::min(kMaskScale, std::sqrt(kMaxMaskPixels / figure_pixels));
    const int width = static_cast<int>(std::ceil(canvas->width() * mask_scale));
    const int height = static_cast<int>(std::ceil(canvas->height() * mask_scale));
    cairo_surface_t* mask = cairo_image_surface_create(CAIRO_FORMAT_A8, width, height);
    if (cairo_surface_status(mask) != CAIRO_STATUS_SUCCESS) {  // a side over Cairo's 32767 px
      cairo_surface_destroy(mask);
      return false;
    }
    cairo_t* m = cairo_create(mask);
    // Points within a quarter of a mask pixel of one drawn look the same: drawing each again
    // would only cost time (a log's points mostly fall on walls already drawn).
    constexpr double cells_per_pixel = 4.0;  // along each axis
    const auto row = static_cast<std::size_t>(cells_per_pixel * width);
    std::vector<bool> drawn(row * static_cast<std::size_t>(cells_per_pixel * height));
    // Filled in batches: one path of millions of arcs would itself take gigabytes.
    constexpr std::size_t kBatch = 4096;
    std::size_t pending = 0;
    const double radius = radius_px * mask_scale;
    for (const Vec2& p : points) {
      const Vec2 d = ToDevice(p) * mask_scale;
      if (!(d.x() >= 0.0 && d.y() >= 0.0 && d.x() < width && d.y() < height))
        continue;  // also leaves out NaN; a point's disc beyond the figure's edge is not seen
      const std::size_t cell = static_cast<std::size_t>(cells_per_pixel * d.y()) * row +
                               static_cast<std::size_t>(cells_per_pixel * d.x());
      if (drawn[cell]) continue;
      drawn[cell] = true;
      cairo_new_sub_path(m);
      cairo_arc(m, d.x(), d.y(), radius, 0.0, 2 * M_PI);
      if (++pending == kBatch) {
        cairo_fill(m);
        pending = 0;
      }
    }
    cairo_fill(m);
    cairo_destroy(m);
    cairo_surface_flush(mask);
    cairo_t* c = cr();
    cairo_save(c);
    detail::SetColor(c, color);
    cairo_scale(c, 1.0 / mask_scale, 1.0 / mask_scale);
    cairo_mask_surface(c, mask, 0.0, 0.0);
    cairo_restore(c);
    cairo_surface_destroy(mask);  // the recording keeps its own reference
    return true;
  }

  void ClipToPlot() const {
    cairo_reset_clip(cr());
    cairo_rectangle(cr(), margins.left, margins.top, plot_width, plot_height);
    cairo_clip(cr());
  }

  void DrawTitleAndAxes() const {
    cairo_t* c = cr();
    detail::SetColor(c, palette::kBlack);
    if (!options.title.empty()) {
      detail::DrawText(c, options.title, margins.left + plot_width / 2, 10.0, kTitleFont, 0.5, 0.0,
                       true);
    }
    if (!options.axes) return;
    detail::SetColor(c, palette::kBlack);
    cairo_set_line_width(c, 1.0);
    // Labels side by side need their width apart, labels one above the other their height.
    const detail::TickLabels xs = XTicks();
    const std::vector<double> ys =
        SpacedNiceTicks(world.min().y(), world.max().y(), kAxisTicks, plot_height, kAxisFont + 3);
    const double y_step = ys.size() > 1 ? ys[1] - ys[0] : 1.0;
    const double bottom = margins.top + plot_height;
    for (std::size_t i = 0; i < xs.ticks.size(); ++i) {
      const double dx = ToDevice({xs.ticks[i], 0.0}).x();
      cairo_move_to(c, dx, bottom);
      cairo_line_to(c, dx, bottom + 5);
      cairo_stroke(c);
      detail::DrawText(c, xs.labels[i], dx, bottom + 8, kAxisFont, 0.5, 0.0);
    }
    for (double y : ys) {
      const double dy = ToDevice({0.0, y}).y();
      cairo_move_to(c, margins.left - 5, dy);
      cairo_line_to(c, margins.left, dy);
      cairo_stroke(c);
      detail::DrawText(c, TickLabel(y, y_step), margins.left - kYLabelGap, dy, kAxisFont, 1.0, 0.5);
    }
    detail::DrawText(c, "x (m)", margins.left + plot_width / 2, bottom + 24, kAxisFont, 0.5, 0.0);
    cairo_save(c);
    cairo_translate(c, 12.0, margins.top + plot_height / 2);
    cairo_rotate(c, -M_PI / 2);
    detail::DrawText(c, "y (m)", 0.0, 0.0, kAxisFont, 0.5, 0.5);
    cairo_restore(c);
  }

  void DrawColorbar(Colormap colormap, double vmin, double vmax, const std::string& label) const {
    cairo_t* c = cr();
    cairo_save(c);
    cairo_reset_clip(c);
    const double x = margins.left + plot_width + kColorbarGap, width = kColorbarWidth,
                 top = margins.top, height = plot_height;
    constexpr int kSteps = 96;
    for (int i = 0; i < kSteps; ++i) {
      const double t = (i + 0.5) / kSteps;
      detail::SetColor(c, MapColor(colormap, t));
      cairo_rectangle(c, x, top + height * (1.0 - static_cast<double>(i + 1) / kSteps), width,
                      height / kSteps + 0.5);
      cairo_fill(c);
    }
    detail::SetColor(c, palette::kBlack);
    cairo_set_line_width(c, 1.0);
    cairo_rectangle(c, x, top, width, height);
    cairo_stroke(c);
    // The margin has room for tick labels kColorbarLabelRoom wide, then the bar's label. Wider
    // ones (values in the millions, or of 1e-5) overlapped the label and ran off the figure: they
    // are written in units of a power of ten instead, which the label names.
    std::string title = label;
    const std::vector<double> ticks = NiceTicks(vmin, vmax, 5);
    detail::TickLabels labels = detail::LabelTicks(ticks, kAxisFont);
    if (labels.Widest() > kColorbarLabelRoom) {
      const int exponent =
          static_cast<int>(std::floor(std::log10(std::max(std::abs(vmin), std::abs(vmax)))));
      const double unit = std::pow(10.0, exponent);
      std::vector<double> scaled;
      for (const double v : ticks) scaled.push_back(v / unit);
      labels = detail::LabelTicks(std::move(scaled), kAxisFont);
      title = label.empty() ? PowerOfTen(exponent) : label + " (" + PowerOfTen(exponent) + ")";
    }
    for (std::size_t i = 0; i < ticks.size(); ++i) {
      const double y = top + height * (1.0 - (ticks[i] / 2 - vmin / 2) / (vmax / 2 - vmin / 2));
      cairo_move_to(c, x + width, y);
      cairo_line_to(c, x + width + 4, y);
      cairo_stroke(c);
      detail::DrawText(c, labels.labels[i], x + width + 6, y, kAxisFont, 0.0, 0.5);
    }
    if (!title.empty()) {
      const double offset = std::max(kColorbarTitleOffset, 6 + labels.Widest() + 14);
      cairo_translate(c, x + width + offset, top + height / 2);
      cairo_rotate(c, -M_PI / 2);
      detail::DrawText(c, title, 0.0, 0.0, kAxisFont, 0.5, 0.5);
    }
    cairo_restore(c);
  }

  void DrawOverlay(cairo_t* c) const {
    if (options.axes) {
      detail::SetColor(c, palette::kBlack);
      cairo_set_line_width(c, 1.0);
      cairo_rectangle(c, margins.left, margins.top, plot_width, plot_height);
      cairo_stroke(c);
    }
    if (legend.empty()) return;
    if (options.legend == LegendPlace::kBelow) {
      detail::DrawLegendRow(c, legend, margins.left + plot_width / 2,
                            margins.top + plot_height + margins.bottom - 14);
      return;
    }
    const bool right =
        options.legend == LegendPlace::kTopRight || options.legend == LegendPlace::kBottomRight;
    const bool bottom =
        options.legend == LegendPlace::kBottomLeft || options.legend == LegendPlace::kBottomRight;
    const double x = right ? margins.left + plot_width - 10 : margins.left + 10;
    const double y = bottom ? margins.top + plot_height - 10 - detail::LegendHeight(legend.size())
                            : margins.top + 10;
    detail::DrawLegend(c, legend, x, y, right);
  }
};

Figure::Figure(const Box2& world, FigureOptions options) : impl_(std::make_unique<Impl>()) {
  PRIORMAP_CHECK(
      !world.isEmpty() && world.min().allFinite() && world.max().allFinite(),
      fmt::format("a figure needs a non-empty, finite world box (got [{}, {}] x [{}, {}])",
                  world.min().x(), world.max().x(), world.min().y(), world.max().y()));
  PRIORMAP_CHECK(std::isfinite(options.padding_m), "a figure's padding must be finite");
  // Sizes below the margins grow to leave a plot; a negative one is a caller's mistake.
  detail::CheckPixels(options.width_px, "a figure's width_px");
  detail::CheckPixels(options.max_height_px, "a figure's max_height_px");
  Impl& f = *impl_;
  f.options = std::move(options);
  const Vec2 pad = Vec2::Constant(std::max(f.options.padding_m, 1e-6));
  f.world = Box2(world.min() - pad, world.max() + pad);
  PRIORMAP_CHECK(
      f.world.sizes().allFinite(),
      "a figure's world box, with its padding, must be narrower than the largest double");
  // The bottom margin always has room for a legend row: entries arrive after the layout is fixed.
  f.margins = {
      f.options.axes ? 60.0 : 10.0, f.options.colorbar ? 100.0 : 16.0,
      f.options.title.empty() ? 12.0 : 36.0,
      (f.options.axes ? 44.0 : 10.0) + (f.options.legend == LegendPlace::kBelow ? 24.0 : 0.0)};
  // Coordinates in the millions (UTM, or near the world's bound) have y labels wider than the
  // margin, which would cut them at the figure's edge.
  if (f.options.axes) {
    f.margins.left =
        std::max(f.margins.left,
                 WidestTickLabel(f.world.min().y(), f.world.max().y()) + kYLabelGap + kYTitleRoom);
    f.x_label_spacing = WidestTickLabel(f.world.min().x(), f.world.max().x()) + kAxisFont;
  }
  double width = 0.0;
  if (f.options.axes) {
    // The x labels are centred on their ticks: one at an end of the axis reaches half its width
    // beyond the plot, and was cut at the figure's edge where that is wider than the margin
    // ("1000000" at the right). Each round leaves at most half of the shortfall (the part of the
    // plot beyond the end tick shrinks with the plot, and centring gives each side half a gain).
    detail::GrowMarginsForEndLabels(
        f.margins.left, f.margins.right, [&](double left, double right) {
          width = f.LayOut();
          const auto [before, after] =
              detail::LabelOverhang(f.XTicks(), f.world.min().x(), f.world.max().x(), f.plot_width);
          const double centring = (width - left - right - f.plot_width) / 2;
          return std::pair{before + kEdgeGap - (left + centring),
                           after + kEdgeGap - (right + centring)};
        });
  } else {
    width = f.LayOut();
  }
  const double height = std::ceil(f.margins.top + f.plot_height + f.margins.bottom);
  // Centre the plot horizontally when the height limit made it narrower than the figure.
  f.margins.left += (width - f.margins.left - f.margins.right - f.plot_width) / 2;
  f.canvas = std::make_unique<detail::Canvas>(width, height);  // checks the size first
  f.DrawTitleAndAxes();
  f.ClipToPlot();
}

Figure::~Figure() = default;
Figure::Figure(Figure&&) noexcept = default;
Figure& Figure::operator=(Figure&&) noexcept = default;

int Figure::width_px() const {
  return static_cast<int>(impl_->canvas->width());
}
int Figure::height_px() const {
  return static_cast<int>(impl_->canvas->height());
}
Vec2 Figure::ToDevice(const Vec2& world) const {
  return impl_->ToDevice(world);
}

void Figure::Points(std::span<const Vec2> points, const Color& color, double radius_px) {
  detail::CheckPixels(radius_px, "a point's radius_px");
  detail::CheckColor(color, "a point's color");
  radius_px = std::min(radius_px, kLargestRadiusPx);
  if (points.size() > kMaxVectorPoints && impl_->PointsAsMask(points, color, radius_px)) return;
  cairo_t* c = impl_->cr();
  detail::SetColor(c, color);
  for (const Vec2& p : points) {
    const Vec2 d = impl_->ToDevice(p);
    if (!Impl::Drawable(d)) continue;  // also leaves out NaN
    cairo_new_sub_path(c);
    cairo_arc(c, d.x(), d.y(), radius_px, 0.0, 2 * M_PI);
  }
  cairo_fill(c);
}

void Figure::Line(const Vec2& a, const Vec2& b, const LineStyle& style) {
  CheckLineStyle(style);  // here, whether or not the line is seen
  // Clipped first to what is shown: Cairo's fixed-point coordinates wrap far outside the figure,
  // which turned a long ray round.
  if (!a.allFinite() || !b.allFinite()) return;
  const std::optional<Segment> clipped = ClipSegmentToBox({a, b}, impl_->Shown());
  if (!clipped) return;
  const Vec2 device[2] = {impl_->ToDevice(clipped->a), impl_->ToDevice(clipped->b)};
  StrokePath(impl_->cr(), device, false, style);
}

void Figure::Arc(const Vec2& center, double radius, double from, double to,
                 const LineStyle& style) {
  CheckLineStyle(style);
  // Cairo asserts, and aborts the program, on a NaN angle.
  if (!center.allFinite() || !std::isfinite(radius) || !std::isfinite(from) || !std::isfinite(to))
    return;
  // Cairo draws every turn of a longer arc (up to 65536 of them): minutes, and an SVG of
  // megabytes, for what looks like one circle.
  // From an angle of 1e17 a turn is below its resolution: reduced first, the turn stays one.
  if (to - from > 2 * M_PI) {
    from = std::remainder(from, 2 * M_PI);
    to = from + 2 * M_PI;
  }
  const Vec2 d = impl_->ToDevice(center);
  if (!impl_->CairoCircle(d, radius * impl_->scale)) {
    // Cairo's arc runs counter-clockwise from `from` to `to` less whole turns, up to one below.
    if (to < from) to += 2 * M_PI * std::ceil((from - to) / (2 * M_PI));
    for (const std::vector<Vec2>& piece : impl_->VisibleArcs({center, radius}, from, to))
      impl_->StrokeClipped(piece, false, style);
    return;
  }
  cairo_t* c = impl_->cr();
  cairo_new_path(c);
  // Device y points down, so a counter-clockwise world arc is a negative device one.
  cairo_arc_negative(c, d.x(), d.y(), radius * impl_->scale, -from, -to);
  SetLineStyle(c, style);
  cairo_set_line_cap(c, CAIRO_LINE_CAP_ROUND);
  cairo_stroke(c);
}

void Figure::Polyline(std::span<const Vec2> points, bool closed, const LineStyle& style) {
  CheckLineStyle(style);
  impl_->StrokeClipped(points, closed, style);
}

void Figure::FilledPolygon(const Polygon& polygon, const Color& fill, const LineStyle& stroke) {
  CheckLineStyle(stroke);
  detail::CheckColor(fill, "a polygon's fill");
  const std::vector<Vec2>& vertices = polygon.vertices;
  // A vertex that is not finite leaves no shape to fill (Cairo drew one to some other point).
  if (vertices.empty() ||
      !std::all_of(vertices.begin(), vertices.end(), [](const Vec2& v) { return v.allFinite(); }))
    return;
  const Box2 shown = impl_->Shown();
  const bool inside = std::all_of(vertices.begin(), vertices.end(),
                                  [&](const Vec2& v) { return shown.contains(v); });
  const std::vector<Vec2> device =
      impl_->ToDevice(inside ? vertices : detail::ClipPolygon(vertices, shown));
  cairo_t* c = impl_->cr();
  if (!device.empty()) {
    cairo_new_path(c);
    AddPath(c, device, true);
    detail::SetColor(c, fill);
    cairo_fill(c);
  }
  if (inside) {
    StrokePath(c, device, true, stroke);
  } else if (stroke.width_px > 0.0) {
    impl_->StrokeClipped(vertices, true, stroke);
  }
}

void Figure::CircleOutline(const Circle& circle, const LineStyle& style) {
  CheckLineStyle(style);
  if (!circle.center.allFinite() || !std::isfinite(circle.radius)) return;
  const Vec2 d = impl_->ToDevice(circle.center);
  if (!impl_->CairoCircle(d, circle.radius * impl_->scale)) {
    for (const std::vector<Vec2>& piece : impl_->VisibleArcs(circle, 0.0, 2 * M_PI))
      impl_->StrokeClipped(piece, false, style);
    return;
  }
  cairo_t* c = impl_->cr();
  cairo_new_path(c);
  cairo_arc(c, d.x(), d.y(), circle.radius * impl_->scale, 0.0, 2 * M_PI);
  SetLineStyle(c, style);
  cairo_stroke(c);
}

void Figure::FilledCircle(const Circle& circle, const Color& fill) {
  detail::CheckColor(fill, "a circle's fill");
  if (!circle.center.allFinite() || !std::isfinite(circle.radius)) return;
  const Vec2 d = impl_->ToDevice(circle.center);
  cairo_t* c = impl_->cr();
  cairo_new_path(c);
  if (impl_->CairoCircle(d, circle.radius * impl_->scale)) {
    cairo_arc(c, d.x(), d.y(), circle.radius * impl_->scale, 0.0, 2 * M_PI);
  } else {
    const std::vector<Vec2> device = impl_->ToDevice(impl_->VisibleDisc(circle));
    if (device.empty()) return;
    AddPath(c, device, true);
  }
  detail::SetColor(c, fill);
  cairo_fill(c);
}

void Figure::CovarianceEllipse(const Vec2& mean, const Mat2& covariance, double n_sigma,
                               const LineStyle& style) {
  const Eigen::SelfAdjointEigenSolver<Mat2> eigen(covariance);
  PRIORMAP_CHECK(eigen.info() == Eigen::Success && eigen.eigenvalues().minCoeff() >= 0.0,
                 "covariance ellipse needs a positive semi-definite matrix");
  const Mat2 axes = eigen.eigenvectors() * eigen.eigenvalues().cwiseSqrt().asDiagonal() * n_sigma;
  constexpr int kPoints = 72;
  std::vector<Vec2> points(kPoints);
  for (int i = 0; i < kPoints; ++i) {
    const double t = 2 * M_PI * i / kPoints;
    points[static_cast<std::size_t>(i)] = mean + axes * Vec2(std::cos(t), std::sin(t));
  }
  Polyline(points, true, style);
}

void Figure::Ticks(std::span<const Vec2> points, std::span<const double> angles, double length_px,
                   const LineStyle& style) {
  PRIORMAP_CHECK(points.size() == angles.size(), "one angle per tick");
  CheckLineStyle(style);
  cairo_t* c = impl_->cr();
  cairo_new_path(c);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!std::isfinite(angles[i])) continue;
    const Vec2 d = impl_->ToDevice(points[i]);
    const Vec2 end(d.x() + length_px * std::cos(angles[i]),
                   d.y() - length_px * std::sin(angles[i]));
    if (!Impl::Drawable(d) || !Impl::Drawable(end)) continue;  // also NaN
    cairo_move_to(c, d.x(), d.y());
    cairo_line_to(c, end.x(), end.y());
  }
  SetLineStyle(c, style);
  cairo_stroke(c);
}

void Figure::PoseMarker(const Se2& pose, const Color& color, double size_px) {
  detail::CheckColor(color, "a pose marker's color");
  cairo_t* c = impl_->cr();
  const Vec2 d = impl_->ToDevice(pose.translation());
  if (!Impl::Drawable(d) || !std::isfinite(pose.theta()) || !(std::abs(size_px) < kFarOutsidePx))
    return;
  const Vec2 forward(std::cos(pose.theta()), -std::sin(pose.theta()));  // device y points down
  const Vec2 left(forward.y(), -forward.x());
  const Vec2 tip = d + size_px * forward;
  const Vec2 back_left = d - 0.5 * size_px * forward + 0.5 * size_px * left;
  const Vec2 back_right = d - 0.5 * size_px * forward - 0.5 * size_px * left;
  cairo_new_path(c);
  cairo_move_to(c, tip.x(), tip.y());
  cairo_line_to(c, back_left.x(), back_left.y());
  cairo_line_to(c, back_right.x(), back_right.y());
  cairo_close_path(c);
  detail::SetColor(c, color);
  cairo_fill_preserve(c);
  detail::SetColor(c, palette::kBlack);
  cairo_set_line_width(c, 1.0);
  cairo_set_dash(c, nullptr, 0, 0.0);
  cairo_stroke(c);
}

void Figure::Text(const Vec2& position, const std::string& text, double size_px,
                  const Color& color) {
  // Cairo refuses a NaN size, and then draws nothing more of the figure.
  // Freetype fails beyond some 30,000 px (only when the figure is saved), larger than any figure.
  PRIORMAP_CHECK(
      std::isfinite(size_px) && size_px >= 0.0 && size_px <= kMaxFigureSidePx,
      fmt::format("text's size_px must be a finite number of pixels from 0 to {} (got {})",
                  kMaxFigureSidePx, size_px));
  detail::CheckColor(color, "text's color");
  const Vec2 d = impl_->ToDevice(position);
  if (!Impl::Drawable(d)) return;  // NaN was drawn at some point
  detail::SetColor(impl_->cr(), color);
  detail::DrawText(impl_->cr(), text, d.x(), d.y(), size_px, 0.0, 1.0);
}

void Figure::HeatMap(const Eigen::MatrixXd& values, const Box2& extent, Colormap colormap,
                     double vmin, double vmax, const std::string& label) {
  PRIORMAP_CHECK(
      values.rows() > 0 && values.cols() > 0,
      fmt::format("a heat map needs cells (got {} x {} values)", values.rows(), values.cols()));
  PRIORMAP_CHECK(std::isfinite(vmin) && std::isfinite(vmax) && vmax > vmin,
                 fmt::format("a heat map needs finite vmin < vmax (got {} and {})", vmin, vmax));
  // Else Cairo refuses the image's scale, and then draws nothing more of the figure.
  PRIORMAP_CHECK(extent.min().allFinite() && extent.max().allFinite() &&
                     (extent.max() - extent.min()).minCoeff() > 0.0,
                 "heat map needs a finite extent of some width and height");
  const Vec2 top_left = impl_->ToDevice({extent.min().x(), extent.max().y()});
  const Vec2 bottom_right = impl_->ToDevice({extent.max().x(), extent.min().y()});
  // Only the visible part is drawn, however far the rest reaches, but its place must be a number.
  PRIORMAP_CHECK((bottom_right - top_left).allFinite(),
                 "heat map extent too large to place: its size in pixels overflows a double");
  const detail::RasterImage image = detail::ColormapImage(values, colormap, vmin, vmax, false);
  detail::PaintRaster(impl_->cr(), image, top_left.x(), top_left.y(),
                      bottom_right.x() - top_left.x(), bottom_right.y() - top_left.y());
  if (impl_->options.colorbar) impl_->DrawColorbar(colormap, vmin, vmax, label);
}

void Figure::AddLegend(const std::string& label, const Color& color) {
  detail::CheckColor(color, "a legend entry's color");  // here, not when saving
  impl_->legend.emplace_back(label, color);
}

void Figure::Save(const std::filesystem::path& path) const {
  impl_->canvas->Save(path, [this](cairo_t* c) { impl_->DrawOverlay(c); });
}

bool IsSupportedFigurePath(const std::filesystem::path& path) {
  const std::string e = path.extension().string();
  return e == ".png" || e == ".svg" || e == ".pdf";
}

}  // namespace priormap::render
