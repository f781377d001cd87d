#include <priormap/core/check.hpp>
#include <priormap/prf/estimates.hpp>
#include <priormap/prf/polygon_map.hpp>

namespace priormap::prf {

PosteriorEstimates::PosteriorEstimates(const Window& window, double cell_size)
    : grid_(CellGrid::Covering(window.min, window.max, cell_size)),
      cells_(static_cast<std::size_t>(grid_.NumCells())) {}

Vec2 PosteriorEstimates::Centre(int cell) const {
  const int ix = cell % grid_.nx;
  const int iy = cell / grid_.nx;
  return grid_.origin + Vec2((ix + 0.5) * grid_.cell.x(), (iy + 0.5) * grid_.cell.y());
}

void PosteriorEstimates::Start(const Coloring& coloring, std::uint64_t sample) {
  start_ = sample;
  for (CellState& cell : cells_)
    cell = {.black_since = sample,
            .white_since = sample,
            .black_samples = 0,
            .white_samples = 0,
            .edges = 0,
            .black = false};
  const Eigen::MatrixXd black = ColourRaster(coloring, grid_);
  for (int index = 0; index < grid_.NumCells(); ++index)
    cells_[static_cast<std::size_t>(index)].black = black(index / grid_.nx, index % grid_.nx) > 0.5;
  for (EdgeId e : coloring.edge_ids()) {
    const Segment s = coloring.EdgeSegment(e);
    WalkCells(grid_, s.a, s.b, [&](int cell, double, double) {
      ++cells_[static_cast<std::size_t>(cell)].edges;
      return true;
    });
  }
}

void PosteriorEstimates::SetBlack(CellState& cell, bool black, std::uint64_t sample) {
  const bool was_white = White(cell);
  if (cell.black) cell.black_samples += sample - cell.black_since;
  cell.black_since = sample;
  cell.black = black;
  if (was_white != White(cell)) {
    if (was_white) cell.white_samples += sample - cell.white_since;
    cell.white_since = sample;
  }
}

void PosteriorEstimates::CountEdge(const Vec2& a, const Vec2& b, int change, std::uint64_t sample) {
  WalkCells(grid_, a, b, [&](int index, double, double) {
    CellState& cell = cells_[static_cast<std::size_t>(index)];
    const bool was_white = White(cell);
    PRIORMAP_DCHECK(change > 0 || cell.edges > 0, "an edge removed from a cell without edges");
    cell.edges = static_cast<std::uint32_t>(static_cast<int>(cell.edges) + change);
    if (was_white != White(cell)) {
      if (was_white) cell.white_samples += sample - cell.white_since;
      cell.white_since = sample;
    }
    return true;
  });
}

void PosteriorEstimates::Record(const Coloring& coloring, const Edit& edit, std::uint64_t sample) {
  for (EdgeId e : edit.removed_edges) {
    const Segment s = coloring.EdgeSegment(e);
    CountEdge(s.a, s.b, -1, sample);
  }
  const auto position = [&](VertexRef r) {
    return r.is_new() ? edit.new_vertices[static_cast<std::size_t>(r.new_index())].position
                      : coloring.vertex(r.id()).position;
  };
  for (const auto& [ra, rb] : edit.added_edges) CountEdge(position(ra), position(rb), +1, sample);

  const std::span<const Vec2> region{edit.flipped_region.begin(), edit.flipped_region.size()};
  ForEachCellUnder(grid_, region, [&](int index) {
    if (!InsidePolygon(region, Centre(index))) return;
    CellState& cell = cells_[static_cast<std::size_t>(index)];
    SetBlack(cell, !cell.black, sample);
  });
}

Eigen::MatrixXd PosteriorEstimates::BlackFraction(std::uint64_t last_sample) const {
  Eigen::MatrixXd fraction(grid_.ny, grid_.nx);
  const double samples = static_cast<double>(Samples(last_sample));
  for (int index = 0; index < grid_.NumCells(); ++index) {
    const CellState& cell = cells_[static_cast<std::size_t>(index)];
    const std::uint64_t black =
        cell.black_samples + (cell.black ? last_sample + 1 - cell.black_since : 0);
    fraction(index / grid_.nx, index % grid_.nx) = static_cast<double>(black) / samples;
  }
  return fraction;
}

Eigen::MatrixXd PosteriorEstimates::WhiteFraction(std::uint64_t last_sample) const {
  Eigen::MatrixXd fraction(grid_.ny, grid_.nx);
  const double samples = static_cast<double>(Samples(last_sample));
  for (int index = 0; index < grid_.NumCells(); ++index) {
    const CellState& cell = cells_[static_cast<std::size_t>(index)];
    const std::uint64_t white =
        cell.white_samples + (White(cell) ? last_sample + 1 - cell.white_since : 0);
    fraction(index / grid_.nx, index % grid_.nx) = static_cast<double>(white) / samples;
  }
  return fraction;
}

}  // namespace priormap::prf
