#include <cmath>
#include <limits>
#include <variant>

#include <priormap/render/figure.hpp>
#include <priormap/render/prf_study_figures.hpp>

namespace priormap::render {
namespace {

constexpr Color kUnknown{0.80, 0.85, 0.90};
constexpr Color kTrueWall = palette::kVermillion;

Figure StudyFigure(const Box2& extent, const std::string& title) {
  return Figure(extent, {.width_px = 900,
                         .max_height_px = 900,
                         .title = title,
                         .axes = true,
                         .colorbar = false,
                         .padding_m = 0.0,
                         .legend = LegendPlace::kBelow});
}

void FillExtent(Figure& figure, const Box2& extent, const Color& color) {
  figure.FilledPolygon(Polygon{{extent.corner(Box2::BottomLeft), extent.corner(Box2::BottomRight),
                                extent.corner(Box2::TopRight), extent.corner(Box2::TopLeft)}},
                       color);
}

}  // namespace

void SaveTruthFigure(const std::filesystem::path& path, const prf::EvaluationRaster& raster,
                     std::span<const Se2> poses, const std::string& title) {
  const prf::CellGrid& grid = raster.grid;
  const Box2 extent(grid.origin,
                    grid.origin + Vec2(grid.nx * grid.cell.x(), grid.ny * grid.cell.y()));
  Eigen::MatrixXd values(grid.ny, grid.nx);
  for (int iy = 0; iy < grid.ny; ++iy)
    for (int ix = 0; ix < grid.nx; ++ix) {
      const auto i = static_cast<std::size_t>(iy * grid.nx + ix);
      const bool black = raster.truth_black[i] != 0;
      // Sparse cells a shade off their colour, so that the figure shows where no beam went.
      values(iy, ix) = !raster.Observed(i) ? std::numeric_limits<double>::quiet_NaN()
                       : raster.Sparse(i)  ? (black ? 0.7 : 0.2)
                                           : (black ? 1.0 : 0.0);
    }
  Figure figure = StudyFigure(extent, title);
  FillExtent(figure, extent, kUnknown);
  figure.HeatMap(values, extent, Colormap::kOccupancy, 0.0, 1.0);
  for (const Se2& pose : poses) figure.PoseMarker(pose, palette::kOrange, 12.0);
  figure.AddLegend("observed, free / occupied", palette::kBlack);
  figure.AddLegend("sparse: no beam crossed or ended in the cell", palette::kGray);
  figure.AddLegend("not observed", kUnknown);
  figure.Save(path);
}

void SaveErrorFigure(const std::filesystem::path& path, const prf::EvaluationRaster& raster,
                     std::span<const double> probability, const std::string& title) {
  const prf::CellGrid& grid = raster.grid;
  const Box2 extent(grid.origin,
                    grid.origin + Vec2(grid.nx * grid.cell.x(), grid.ny * grid.cell.y()));
  enum Kind {
    kNotScored,
    kRightFree,
    kRightOccupied,
    kFreeCalledOccupied,
    kOccupiedCalledFree,
    kUndecided
  };
  const Color colours[] = {kUnknown,           {0.93, 0.93, 0.93},
                           {0.45, 0.45, 0.45}, palette::kVermillion,
                           palette::kBlue,     palette::kYellow};
  const auto kind = [&](std::size_t i) {
    if (!raster.Observed(i)) return kNotScored;
    const double p = probability[i];
    const bool black = raster.truth_black[i] != 0;
    if (!(p > 0.5) && !(p < 0.5)) return kUndecided;
    if ((p > 0.5) == black) return black ? kRightOccupied : kRightFree;
    return black ? kOccupiedCalledFree : kFreeCalledOccupied;
  };
  Figure figure = StudyFigure(extent, title);
  // One rectangle per run of equal cells along a row: a figure of tens, not thousands, of
  // thousands of shapes.
  for (int iy = 0; iy < grid.ny; ++iy) {
    int from = 0;
    for (int ix = 1; ix <= grid.nx; ++ix) {
      const auto at = [&](int x) { return kind(static_cast<std::size_t>(iy * grid.nx + x)); };
      if (ix < grid.nx && at(ix) == at(from)) continue;
      const Vec2 lo = grid.origin + Vec2(from * grid.cell.x(), iy * grid.cell.y());
      const Vec2 hi = grid.origin + Vec2(ix * grid.cell.x(), (iy + 1) * grid.cell.y());
      figure.FilledPolygon(Polygon{{lo, Vec2(hi.x(), lo.y()), hi, Vec2(lo.x(), hi.y())}},
                           colours[at(from)]);
      from = ix;
    }
  }
  figure.AddLegend("right: free / occupied", colours[kRightOccupied]);
  figure.AddLegend("free called occupied", colours[kFreeCalledOccupied]);
  figure.AddLegend("occupied called free", colours[kOccupiedCalledFree]);
  figure.AddLegend("undecided", colours[kUndecided]);
  figure.AddLegend("not scored", kUnknown);
  figure.Save(path);
}

void SaveMapAndWallsFigure(const std::filesystem::path& path,
                           const std::vector<prf::MapFace>& faces, const prf::Window& window,
                           const Scene& scene, const std::string& title) {
  const Box2 extent(window.min, window.max);
  Figure figure = StudyFigure(extent, title);
  // Largest first: each nested face paints over the face that holds it.
  for (const prf::MapFace& face : faces)
    figure.FilledPolygon(
        Polygon{face.outer},
        face.colour == prf::Colour::kBlack ? Color{0.15, 0.15, 0.15} : palette::kWhite,
        {palette::kBlue, 0.8, {}});
  for (const ScenePrimitive& wall : scene.Primitives()) {
    if (const auto* segment = std::get_if<Segment>(&wall.shape))
      figure.Line(segment->a, segment->b, {kTrueWall, 1.2, {4.0, 3.0}});
    else
      figure.CircleOutline(std::get<Circle>(wall.shape), {kTrueWall, 1.2, {4.0, 3.0}});
  }
  figure.AddLegend("MAP map (occupied dark, edges blue)", palette::kBlue);
  figure.AddLegend("true walls", kTrueWall);
  figure.Save(path);
}

}  // namespace priormap::render
