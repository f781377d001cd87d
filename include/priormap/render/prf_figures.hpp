#pragma once
/// Figures of polygonal random fields and occupancy grids (after Paskin & Thrun's Figs. 4–5):
/// a probability raster (P(black), or an occupancy grid) as a grey image, and a polygonal map
/// with its occupied faces filled. PNG, SVG or PDF by the file's extension.

#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include <priormap/core/map_server.hpp>
#include <priormap/prf/polygon_map.hpp>

namespace priormap::render {

/// The raster white (0) to black (1), unknown (NaN) cells light blue-grey, the sensor positions
/// as small dots when given; `scale_label` names the colour bar.
void SaveProbabilityFigure(const std::filesystem::path& path, const OccupancyRaster& raster,
                           const std::string& title, std::span<const Vec2> sensors = {},
                           const std::string& scale_label = "P(occupied)");

/// The faces of a polygonal map: occupied ones filled dark, the discontinuities drawn.
void SaveFacesFigure(const std::filesystem::path& path, const std::vector<prf::MapFace>& faces,
                     const prf::Window& window, const std::string& title);

}  // namespace priormap::render
