#pragma once
/// Figures of the PRF accuracy study (prf/map_study.hpp): the ground truth as scored (the
/// observed area's true colours, its sparse part shaded, the rest unknown) and the MAP polygon
/// map with the true walls drawn over it. The grid and the posterior use prf_figures.hpp.

#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <priormap/core/scene.hpp>
#include <priormap/prf/map_scores.hpp>
#include <priormap/prf/polygon_map.hpp>

namespace priormap::render {

/// Observed cells in their true colour (white free, black occupied), the sparse ones in light
/// and dark grey, unobserved cells in the unknown colour; the sensor poses as markers.
void SaveTruthFigure(const std::filesystem::path& path, const prf::EvaluationRaster& raster,
                     std::span<const Se2> poses, const std::string& title);

/// Where a map is right and wrong over the scored cells: right ones light (free) or dark grey
/// (occupied), free cells called occupied in vermillion, occupied cells called free in blue,
/// undecided ones (P = 0.5 or unknown) in yellow; `probability` is P(occupied) at each cell of
/// the raster's grid.
void SaveErrorFigure(const std::filesystem::path& path, const prf::EvaluationRaster& raster,
                     std::span<const double> probability, const std::string& title);

/// The map's faces (occupied filled dark) with the scene's true walls over them.
void SaveMapAndWallsFigure(const std::filesystem::path& path,
                           const std::vector<prf::MapFace>& faces, const prf::Window& window,
                           const Scene& scene, const std::string& title);

}  // namespace priormap::render
