#pragma once
/// A coloring as a vector map: its faces (the regions between discontinuities and the window's
/// sides), each one colour, with its outer ring and holes. Neighbouring faces always differ in
/// colour (each edge is a discontinuity), so the black faces are exactly the occupied regions.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include <priormap/prf/coloring.hpp>

namespace priormap::prf {

struct MapFace {
  std::vector<Vec2> outer;               ///< counter-clockwise
  std::vector<std::vector<Vec2>> holes;  ///< clockwise
  Colour colour = Colour::kWhite;
  double area = 0.0;  ///< of the outer ring, holes not subtracted
};

/// The faces of the coloring, largest outer ring first (drawing them in this order paints every
/// nested face over the one that holds it).
[[nodiscard]] std::vector<MapFace> ExtractFaces(const Coloring& coloring);

/// GeoJSON (RFC 7946) FeatureCollection: one Polygon feature per black face (property
/// "occupied": true), the window as a property, coordinates in metres of the log's frame.
[[nodiscard]] std::string FacesToGeoJson(const std::vector<MapFace>& faces, const Window& window);

/// Bytes of the map stored compactly: float32 coordinates per vertex, two 16-bit indices per
/// edge, the anchor's position and colour (the paper's storage comparison).
[[nodiscard]] std::size_t CompactMapBytes(const Coloring& coloring);

/// 1 where the cell centre of `grid` is black, 0 where white; row 0 at the bottom. Walks each
/// row from its first centre, by the parity of crossings between neighbouring centres.
[[nodiscard]] Eigen::MatrixXd ColourRaster(const Coloring& coloring, const CellGrid& grid);

}  // namespace priormap::prf
