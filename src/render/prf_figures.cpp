#include <cmath>

#include <priormap/render/figure.hpp>
#include <priormap/render/prf_figures.hpp>

namespace priormap::render {
namespace {

constexpr Color kUnknown{0.80, 0.85, 0.90};

// A map figure: the extent without padding, axes in metres.
Figure MapFigure(const Box2& extent, const std::string& title, bool colorbar) {
  return Figure(extent, {.width_px = 900,
                         .max_height_px = 900,
                         .title = title,
                         .axes = true,
                         .colorbar = colorbar,
                         .padding_m = 0.0,
                         .legend = LegendPlace::kBelow});
}

}  // namespace

void SaveProbabilityFigure(const std::filesystem::path& path, const OccupancyRaster& raster,
                           const std::string& title, std::span<const Vec2> sensors,
                           const std::string& scale_label) {
  const Eigen::MatrixXd& p = raster.probability;
  const Box2 extent(raster.origin,
                    raster.origin + raster.resolution * Vec2(static_cast<double>(p.cols()),
                                                             static_cast<double>(p.rows())));
  Figure figure = MapFigure(extent, title, true);
  figure.FilledPolygon(Polygon{{extent.corner(Box2::BottomLeft), extent.corner(Box2::BottomRight),
                                extent.corner(Box2::TopRight), extent.corner(Box2::TopLeft)}},
                       kUnknown);
  figure.HeatMap(p, extent, Colormap::kOccupancy, 0.0, 1.0, scale_label);
  if (!sensors.empty()) figure.Points(sensors, palette::kOrange, 1.2);
  figure.Save(path);
}

void SaveFacesFigure(const std::filesystem::path& path, const std::vector<prf::MapFace>& faces,
                     const prf::Window& window, const std::string& title) {
  const Box2 extent(window.min, window.max);
  Figure figure = MapFigure(extent, title, false);
  // Largest first: each nested face paints over the face that holds it.
  for (const prf::MapFace& face : faces)
    figure.FilledPolygon(
        Polygon{face.outer},
        face.colour == prf::Colour::kBlack ? Color{0.15, 0.15, 0.15} : palette::kWhite,
        {palette::kBlue, 0.8, {}});
  figure.Save(path);
}

}  // namespace priormap::render
