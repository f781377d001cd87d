#pragma once
/// A figure in world coordinates (metres, y up, equal aspect): maps, scans, normals, covariance
/// ellipses, heat-map grids. Drawn once, saved as PNG, SVG or PDF (chosen by the file extension).

#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include <priormap/core/circle.hpp>
#include <priormap/core/polygon.hpp>
#include <priormap/core/se2.hpp>
#include <priormap/render/color.hpp>
#include <priormap/render/figure_size.hpp>

namespace priormap::render {

struct LineStyle {
  Color color = palette::kBlack;
  double width_px = 1.5;  ///< finite, not negative (0 draws nothing)
  /// Lengths along the line, on and off by turns, repeated; empty: solid. Finite, not negative
  /// and not all 0. The figure's method given a style that is not as said here throws
  /// ContractError.
  std::vector<double> dash_px{};
};

/// Where the legend goes: in a row under the plot (covers nothing), or in a box inside a corner.
enum class LegendPlace { kBelow, kTopLeft, kTopRight, kBottomLeft, kBottomRight };

struct FigureOptions {
  /// Total width, including margins (grown when they leave no plot). Not negative, as
  /// max_height_px (else ContractError).
  int width_px = 800;
  int max_height_px = 800;  ///< the height follows the world's aspect ratio, up to this
  std::string title{};
  bool axes = true;         ///< metre ticks along the left and bottom edges
  bool colorbar = false;    ///< reserve room on the right for a heat map's colour bar
  double padding_m = 0.25;  ///< added around the world box; finite (below 1e-6 counts as 1e-6)
  LegendPlace legend = LegendPlace::kBelow;
};

class Figure {
 public:
  /// A figure showing `world` (plus padding). Preconditions (else ContractError): `world` is
  /// not empty, and it and its padded size are finite; the figure's size fits
  /// (figure_size.hpp), which is checked before anything is drawn.
  Figure(const Box2& world, FigureOptions options = {});
  ~Figure();
  Figure(Figure&&) noexcept;
  Figure& operator=(Figure&&) noexcept;

  /// Discs of `radius_px` (finite and not negative, else ContractError). More than 20,000 points (a
  /// log's) are drawn as one raster layer at twice the figure's resolution, so that their number
  /// does not set the memory, time and SVG/PDF size; a PNG looks the same either way.
  ///
  /// Whatever is drawn may reach beyond the world, and is clipped to the plot. Shapes with a
  /// non-finite coordinate are not drawn (points, ticks, markers, text, circles, arcs, filled
  /// polygons), except that a polyline is broken at such a point.
  void Points(std::span<const Vec2> points, const Color& color, double radius_px = 1.5);
  void Line(const Vec2& a, const Vec2& b, const LineStyle& style);
  void Polyline(std::span<const Vec2> points, bool closed, const LineStyle& style);
  /// Filled polygon with an optional outline (`stroke.width_px` 0 draws none).
  void FilledPolygon(const Polygon& polygon, const Color& fill,
                     const LineStyle& stroke = {{}, 0.0, {}});
  void CircleOutline(const Circle& circle, const LineStyle& style);
  /// The arc of the circle about `center` from world angle `from` counter-clockwise to `to` (at
  /// most one turn).
  void Arc(const Vec2& center, double radius, double from, double to, const LineStyle& style);
  void FilledCircle(const Circle& circle, const Color& fill);
  /// The ellipse {x : (x - mean)^T cov^-1 (x - mean) = n_sigma^2}. Precondition: cov SPD.
  void CovarianceEllipse(const Vec2& mean, const Mat2& covariance, double n_sigma,
                         const LineStyle& style);
  /// Short ticks of `length_px` from each point along the world angle `angles[i]` (normals).
  void Ticks(std::span<const Vec2> points, std::span<const double> angles, double length_px,
             const LineStyle& style);
  /// A pose marker: a triangle pointing along theta.
  void PoseMarker(const Se2& pose, const Color& color, double size_px = 10.0);
  /// Text with its left baseline at `position`. Precondition: size_px finite, from 0 to
  /// kMaxFigureSidePx.
  void Text(const Vec2& position, const std::string& text, double size_px = 12.0,
            const Color& color = palette::kBlack);
  /// A grid of cells over `extent`: values(iy, ix) covers the cell whose lower-left corner is
  /// extent.min() + (ix, iy) * cell size, so row 0 is at the bottom. NaN cells are left blank.
  /// With FigureOptions::colorbar, draws a colour bar labelled `label` (its ticks in units of a
  /// power of ten, named after the label, when plain ones would not fit beside it).
  /// `extent` may reach far beyond the world (a heat map 1e12 times its size): what is seen of
  /// it is drawn. Preconditions: vmin < vmax, both finite; `extent` not empty, finite, and its
  /// size in pixels below the largest double.
  void HeatMap(const Eigen::MatrixXd& values, const Box2& extent, Colormap colormap, double vmin,
               double vmax, const std::string& label = "");
  /// A legend entry (drawn where FigureOptions::legend says, when saving).
  void AddLegend(const std::string& label, const Color& color);

  /// Writes PNG, SVG or PDF according to the extension, atomically. Throws IoError.
  void Save(const std::filesystem::path& path) const;

  [[nodiscard]] int width_px() const;
  [[nodiscard]] int height_px() const;
  /// Device coordinates (pixels, y down) of a world point.
  [[nodiscard]] Vec2 ToDevice(const Vec2& world) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// ".png", ".svg", ".pdf".
[[nodiscard]] bool IsSupportedFigurePath(const std::filesystem::path& path);

/// The advance width, in pixels, of `text` as Figure::Text draws it at `size_px`: the figures
/// lay their labels out with it (bytes that are not UTF-8 count as U+FFFD). Thread-safe.
[[nodiscard]] double TextWidth(const std::string& text, double size_px = 12.0);

}  // namespace priormap::render
