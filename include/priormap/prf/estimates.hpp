#pragma once
/// Running posterior estimates over a raster of the window (Paskin & Thrun, Sec. 1.3.3): the
/// fraction of samples in which each cell's centre is black (P(black), the image of Fig. 4c/f),
/// and the fraction in which each cell is completely white (no edge through it and its centre
/// white: the occupancy-grid-like estimate).
///
/// Every step of the chain is a sample, yet an accepted edit costs only the cells it touches:
/// each cell keeps the sample index since which its state holds and adds the elapsed count to
/// its totals when the state changes (flip times), and the totals are closed when read.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include <priormap/prf/coloring.hpp>

namespace priormap::prf {

class PosteriorEstimates {
 public:
  /// A raster of cells of about `cell_size` covering `window`.
  PosteriorEstimates(const Window& window, double cell_size);

  /// Starts counting with `coloring` as the state of sample `sample` onwards.
  void Start(const Coloring& coloring, std::uint64_t sample);
  /// Before coloring.Apply(edit): the edit's result is the state from sample `sample` onwards.
  void Record(const Coloring& coloring, const Edit& edit, std::uint64_t sample);

  [[nodiscard]] const CellGrid& grid() const { return grid_; }

  /// The counts and flip times (checkpoints); Load expects estimates of the same raster.
  void Save(BinaryWriter& out) const;
  void Load(BinaryReader& in);
  /// Samples counted up to and including `last_sample`.
  [[nodiscard]] std::uint64_t Samples(std::uint64_t last_sample) const {
    return last_sample + 1 - start_;
  }
  /// P(black) at each cell centre, over samples [start, last_sample]; row 0 at the bottom.
  [[nodiscard]] Eigen::MatrixXd BlackFraction(std::uint64_t last_sample) const;
  /// Fraction of those samples in which each cell was completely white.
  [[nodiscard]] Eigen::MatrixXd WhiteFraction(std::uint64_t last_sample) const;

 private:
  struct CellState {
    std::uint64_t black_since = 0;  // sample from which the centre's colour holds
    std::uint64_t white_since = 0;  // sample from which the "completely white" state holds
    std::uint64_t black_samples = 0;
    std::uint64_t white_samples = 0;
    std::uint32_t edges = 0;  // edges through the cell
    bool black = false;
  };
  [[nodiscard]] bool White(const CellState& cell) const { return !cell.black && cell.edges == 0; }
  /// Closes the "completely white" count when the state differs from `was_white`.
  void WhiteMayHaveChanged(CellState& cell, bool was_white, std::uint64_t sample);
  void FlipColour(CellState& cell, std::uint64_t sample);
  void CountEdge(const Segment& edge, int change, std::uint64_t sample);
  template <class Count>
  [[nodiscard]] Eigen::MatrixXd Fraction(std::uint64_t last_sample, Count&& count) const;

  CellGrid grid_;
  std::vector<CellState> cells_;
  std::uint64_t start_ = 0;
};

}  // namespace priormap::prf
