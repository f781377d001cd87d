// Running posterior estimates: the flip-time counts equal, sample for sample, what inspecting
// every state of the chain gives (each cell's centre colour by crossing parity against all
// edges, and "completely white" by testing every edge against the cell).
#include <gtest/gtest.h>

#include <priormap/prf/estimates.hpp>
#include <priormap/prf/sampler.hpp>

#include "prf/brute_force.hpp"

namespace priormap::prf {
namespace {

bool SegmentMeetsBox(const Segment& s, const Vec2& lo, const Vec2& hi) {
  const Box2 box(lo, hi);
  if (box.contains(s.a) || box.contains(s.b)) return true;
  const Vec2 corners[4] = {lo, Vec2(hi.x(), lo.y()), hi, Vec2(lo.x(), hi.y())};
  for (int k = 0; k < 4; ++k)
    if (SegmentsTouch(s.a, s.b, corners[k], corners[(k + 1) % 4])) return true;
  return false;
}

TEST(PosteriorEstimates, CountWhatInspectingEveryStateCounts) {
  const Window window{Vec2::Zero(), Vec2(2.0, 1.5)};
  SamplerOptions options;
  options.p = 2.0;
  options.birth_scale = 0.5;
  PrfSampler sampler(Coloring(window, 0.25), options, 11);
  sampler.Run(2000);  // burn-in, not counted

  PosteriorEstimates estimates(window, 0.3);
  sampler.RecordInto(&estimates);
  const CellGrid& grid = estimates.grid();
  const auto cells = static_cast<std::size_t>(grid.NumCells());
  std::vector<std::uint64_t> black(cells, 0), white(cells, 0);
  const int samples = 3000;
  for (int n = 0; n < samples; ++n) {
    sampler.Step();
    const std::vector<Segment> edges = AllEdges(sampler.coloring());
    for (int index = 0; index < grid.NumCells(); ++index) {
      const Vec2 centre = grid.Centre(index);
      const int parity =
          CrossingsByBruteForce(sampler.coloring(), sampler.coloring().anchor(), centre) % 2;
      const Colour anchor = sampler.coloring().anchor_colour();
      const bool is_black = (parity == 0 ? anchor : Flip(anchor)) == Colour::kBlack;
      const Vec2 lo =
          grid.origin + Vec2((index % grid.nx) * grid.cell.x(), (index / grid.nx) * grid.cell.y());
      bool crossed = false;
      for (const Segment& s : edges) crossed = crossed || SegmentMeetsBox(s, lo, lo + grid.cell);
      black[static_cast<std::size_t>(index)] += is_black ? 1 : 0;
      white[static_cast<std::size_t>(index)] += (!is_black && !crossed) ? 1 : 0;
    }
  }
  const std::uint64_t last = sampler.steps();
  ASSERT_EQ(estimates.Samples(last), static_cast<std::uint64_t>(samples));
  const Eigen::MatrixXd black_fraction = estimates.BlackFraction(last);
  const Eigen::MatrixXd white_fraction = estimates.WhiteFraction(last);
  double mixed = 0.0;
  for (int index = 0; index < grid.NumCells(); ++index) {
    const int iy = index / grid.nx, ix = index % grid.nx;
    EXPECT_NEAR(black_fraction(iy, ix) * samples, static_cast<double>(black[index]), 1e-6) << index;
    EXPECT_NEAR(white_fraction(iy, ix) * samples, static_cast<double>(white[index]), 1e-6) << index;
    mixed += black_fraction(iy, ix) > 0.0 && black_fraction(iy, ix) < 1.0 ? 1 : 0;
  }
  EXPECT_GT(mixed, grid.NumCells() / 4);      // the chain moved over the cells
  EXPECT_GT(white_fraction.maxCoeff(), 0.2);  // and cells were completely white at times
}

}  // namespace
}  // namespace priormap::prf
