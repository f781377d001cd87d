#pragma once
// One panel of a multi-panel figure: a rectangle of a Canvas with its own title, axes (linear,
// logarithmic or equal-aspect world coordinates), clipped data, legend row and colour bar.

#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <cairo.h>

#include <priormap/core/types.hpp>
#include <priormap/render/color.hpp>

namespace priormap::render::detail {

/// A rectangle in device pixels (y down).
struct Rect {
  double x = 0.0, y = 0.0, width = 0.0, height = 0.0;
};

enum class Marker { kLine, kDot, kCross };

struct LegendEntry {
  std::string label;
  Color color;
  Marker marker = Marker::kLine;
  std::vector<double> dash_px{};  ///< kLine: empty for solid
  double width_px = 2.0;
};

struct PanelOptions {
  std::string title{};
  std::string x_label{};
  std::string y_label{};
  bool log_y = false;         ///< y ticks at powers of ten; data <= 0 is not drawn
  bool equal_aspect = false;  ///< one unit is as long on both axes (maps in metres)
  bool invert_y = false;      ///< y grows downwards (matrix rows)
  bool grid = true;
  bool legend_row = false;      ///< room under the plot for a LegendRow
  double right_margin_px = 20;  ///< more for a colour bar
};

class Panel {
 public:
  /// A panel filling `cell` and showing [x_lo, x_hi] x [y_lo, y_hi] (with equal_aspect the
  /// plot area shrinks to keep the aspect, centred). The margins grow for tick labels that
  /// would run into the y label or out of the cell. Preconditions: x_lo < x_hi, y_lo < y_hi,
  /// and y_lo > 0 with log_y.
  Panel(cairo_t* cr, const Rect& cell, double x_lo, double x_hi, double y_lo, double y_hi,
        PanelOptions options);

  [[nodiscard]] Vec2 ToDevice(const Vec2& p) const;
  [[nodiscard]] const Rect& plot() const { return plot_; }

  /// Title, grid, ticks, tick labels, axis labels and the frame.
  void DrawFrame() const;
  /// Title and frame only, with `note` wrapped in the middle (a panel without data).
  void DrawNote(const std::string& note) const;

  // Data, clipped to the plot area. Points with a non-finite coordinate are skipped (and break
  // polylines); lines to points far beyond the plot are drawn to where they leave it. Lines throw
  // ContractError for dashes CheckDashes refuses, or a width CheckPixels refuses.
  void Polyline(std::span<const Vec2> points, const Color& color, double width_px,
                std::span<const double> dash_px = {}) const;
  void Dots(std::span<const Vec2> points, const Color& color, double radius_px) const;
  void Crosses(std::span<const Vec2> points, const Color& color, double half_size_px) const;
  void Segment(const Vec2& a, const Vec2& b, const Color& color, double width_px,
               std::span<const double> dash_px = {}) const;
  /// A triangle at `p` pointing along `theta` (world angle; equal-aspect panels).
  void PoseMarker(const Vec2& p, double theta, const Color& color, double size_px) const;
  /// values(r, c) fills the cell [c, c + 1] x [r, r + 1] scaled to the panel's range; NaN blank.
  void Image(const Eigen::MatrixXd& values, Colormap colormap, double vmin, double vmax) const;

  /// A colour bar right of the plot (room from right_margin_px). Precondition: vmin < vmax.
  void ColorBar(Colormap colormap, double vmin, double vmax, const std::string& label) const;
  /// One row of entries under the plot (legend_row). Throws ContractError, before drawing, for a
  /// kLine entry's dashes or width as Polyline does.
  void LegendRow(const std::vector<LegendEntry>& entries) const;

 private:
  void Clip() const;
  [[nodiscard]] double YValue(double y) const;  // log10 with log_y
  // The plot area within the cell for the margins (left, right).
  void LayOut(double left, double right);
  [[nodiscard]] std::vector<double> XTicks() const;
  [[nodiscard]] std::vector<double> YTicks() const;  // log10 with log_y
  [[nodiscard]] std::vector<std::string> YLabels(const std::vector<double>& ticks) const;

  cairo_t* cr_;
  Rect cell_;
  Rect plot_;
  double x_lo_, x_hi_, y_lo_, y_hi_;  // y in log10 with log_y
  double top_ = 0.0, bottom_ = 0.0;   // margins
  double y_title_ = 56.0;             // from the plot's left edge to the y label's middle
  PanelOptions options_;
};

/// Text wrapped at spaces into lines of at most `max_chars` characters.
[[nodiscard]] std::vector<std::string> WrapText(const std::string& text, std::size_t max_chars);

}  // namespace priormap::render::detail
