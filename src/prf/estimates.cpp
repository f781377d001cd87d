#include <priormap/core/check.hpp>
#include <priormap/prf/estimates.hpp>
#include <priormap/prf/polygon_map.hpp>

namespace priormap::prf {

PosteriorEstimates::PosteriorEstimates(const Window& window, double cell_size)
    : grid_(CellGrid::Covering(window.min, window.max, cell_size)),
      cells_(static_cast<std::size_t>(grid_.NumCells())) {}

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

void PosteriorEstimates::WhiteMayHaveChanged(CellState& cell, bool was_white,
                                             std::uint64_t sample) {
  if (was_white == White(cell)) return;
  if (was_white) cell.white_samples += sample - cell.white_since;
  cell.white_since = sample;
}

void PosteriorEstimates::FlipColour(CellState& cell, std::uint64_t sample) {
  const bool was_white = White(cell);
  if (cell.black) cell.black_samples += sample - cell.black_since;
  cell.black_since = sample;
  cell.black = !cell.black;
  WhiteMayHaveChanged(cell, was_white, sample);
}

void PosteriorEstimates::CountEdge(const Segment& edge, int change, std::uint64_t sample) {
  WalkCells(grid_, edge.a, edge.b, [&](int index, double, double) {
    CellState& cell = cells_[static_cast<std::size_t>(index)];
    const bool was_white = White(cell);
    PRIORMAP_DCHECK(change > 0 || cell.edges > 0, "an edge removed from a cell without edges");
    cell.edges = static_cast<std::uint32_t>(static_cast<int>(cell.edges) + change);
    WhiteMayHaveChanged(cell, was_white, sample);
    return true;
  });
}

void PosteriorEstimates::Record(const Coloring& coloring, const Edit& edit, std::uint64_t sample) {
  for (EdgeId e : edit.removed_edges) CountEdge(coloring.EdgeSegment(e), -1, sample);
  for (std::size_t k = 0; k < edit.added_edges.size(); ++k)
    CountEdge(coloring.AddedSegment(edit, k), +1, sample);

  const std::span<const Vec2> region{edit.flipped_region.begin(), edit.flipped_region.size()};
  ForEachCellUnder(grid_, region, [&](int index) {
    if (RingContains(region, grid_.Centre(index)))
      FlipColour(cells_[static_cast<std::size_t>(index)], sample);
  });
}

template <class Count>
Eigen::MatrixXd PosteriorEstimates::Fraction(std::uint64_t last_sample, Count&& count) const {
  Eigen::MatrixXd fraction(grid_.ny, grid_.nx);
  const double samples = static_cast<double>(Samples(last_sample));
  for (int index = 0; index < grid_.NumCells(); ++index)
    fraction(index / grid_.nx, index % grid_.nx) =
        static_cast<double>(count(cells_[static_cast<std::size_t>(index)])) / samples;
  return fraction;
}

Eigen::MatrixXd PosteriorEstimates::BlackFraction(std::uint64_t last_sample) const {
  return Fraction(last_sample, [&](const CellState& cell) {
    return cell.black_samples + (cell.black ? last_sample + 1 - cell.black_since : 0);
  });
}

Eigen::MatrixXd PosteriorEstimates::WhiteFraction(std::uint64_t last_sample) const {
  return Fraction(last_sample, [&](const CellState& cell) {
    return cell.white_samples + (White(cell) ? last_sample + 1 - cell.white_since : 0);
  });
}

void PosteriorEstimates::Save(BinaryWriter& out) const {
  out.Put(start_);
  out.Put<std::uint64_t>(cells_.size());
  for (const CellState& cell : cells_) {
    out.Put(cell.black_since);
    out.Put(cell.white_since);
    out.Put(cell.black_samples);
    out.Put(cell.white_samples);
    out.Put(cell.edges);
    out.Put<std::uint8_t>(cell.black ? 1 : 0);
  }
}

void PosteriorEstimates::Load(BinaryReader& in) {
  start_ = in.Get<std::uint64_t>();
  if (in.Get<std::uint64_t>() != cells_.size()) in.Fail("estimates of another raster");
  for (CellState& cell : cells_) {
    cell.black_since = in.Get<std::uint64_t>();
    cell.white_since = in.Get<std::uint64_t>();
    cell.black_samples = in.Get<std::uint64_t>();
    cell.white_samples = in.Get<std::uint64_t>();
    cell.edges = in.Get<std::uint32_t>();
    cell.black = in.Get<std::uint8_t>() != 0;
  }
}

}  // namespace priormap::prf
