#include <algorithm>
#include <cmath>
#include <numeric>

#include <priormap/core/check.hpp>
#include <priormap/prf/birth_guide.hpp>

namespace priormap::prf {
namespace {

double Chebyshev(const Vec2& a, const Vec2& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

// Half-width of the square around the midpoint of ab where the third vertex is drawn: the
// triangle's size follows its first edge, so that two hits on a chair leg give a small
// triangle and two hits on a wall a large one.
double ThirdVertexHalfWidth(const Vec2& a, const Vec2& b, double jitter, double pair_radius) {
  return std::clamp((a - b).norm(), 2.0 * jitter, pair_radius);
}

}  // namespace

BirthGuide::BirthGuide(std::vector<Vec2> points, double pair_radius, double jitter)
    : pair_radius_(pair_radius), jitter_(jitter) {
  PRIORMAP_CHECK(pair_radius > 0.0 && jitter > 0.0, "guide radii must be positive");
  PRIORMAP_CHECK(jitter <= pair_radius, "the jitter must not exceed the pair radius");
  for (const Vec2& p : points) PRIORMAP_CHECK(p.allFinite(), "guide points must be finite");
  if (points.empty()) return;
  Box2 box;
  for (const Vec2& p : points) box.extend(p);
  // Cells no smaller than the pair radius, so that a query of radius ≤ r looks at 3 × 3 cells.
  grid_.origin = box.min();
  grid_.cell = Vec2::Constant(pair_radius);
  grid_.nx = static_cast<int>(std::floor(box.sizes().x() / pair_radius)) + 1;
  grid_.ny = static_cast<int>(std::floor(box.sizes().y() / pair_radius)) + 1;
  PRIORMAP_CHECK(static_cast<double>(grid_.nx) * grid_.ny < 1e8, "guide grid too large");

  // Counting sort by cell; a stable order keeps Draw's choices reproducible.
  std::vector<int> cell_of(points.size());
  cell_start_.assign(static_cast<std::size_t>(grid_.NumCells()) + 1, 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    cell_of[i] = grid_.CellOf(points[i]);
    ++cell_start_[static_cast<std::size_t>(cell_of[i]) + 1];
  }
  std::partial_sum(cell_start_.begin(), cell_start_.end(), cell_start_.begin());
  points_.resize(points.size());
  std::vector<std::uint32_t> next(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t i = 0; i < points.size(); ++i)
    points_[next[static_cast<std::size_t>(cell_of[i])]++] = points[i];

  inverse_neighbours_.resize(points_.size());
  for (std::size_t i = 0; i < points_.size(); ++i) {
    int count = 0;
    ForEachPointNear(points_[i], pair_radius_, [&](std::size_t) { ++count; });
    inverse_neighbours_[i] = 1.0 / count;  // count ≥ 1: the point itself
  }
}

template <class Visit>
void BirthGuide::ForEachPointNear(const Vec2& q, double radius, Visit&& visit) const {
  if (points_.empty()) return;
  const int x0 = grid_.ClampX(q.x() - radius), x1 = grid_.ClampX(q.x() + radius);
  const int y0 = grid_.ClampY(q.y() - radius), y1 = grid_.ClampY(q.y() + radius);
  for (int iy = y0; iy <= y1; ++iy)
    for (int ix = x0; ix <= x1; ++ix) {
      const auto cell = static_cast<std::size_t>(iy * grid_.nx + ix);
      for (std::uint32_t i = cell_start_[cell]; i < cell_start_[cell + 1]; ++i)
        if (Chebyshev(points_[i], q) <= radius) visit(static_cast<std::size_t>(i));
    }
}

void BirthGuide::Draw(Rng& rng, Vec2* a, Vec2* b, Vec2* c) const {
  PRIORMAP_CHECK(!points_.empty(), "a birth guide without points cannot draw");
  const auto jittered = [&](const Vec2& p) -> Vec2 {
    return p + Vec2(rng.Uniform(-jitter_, jitter_), rng.Uniform(-jitter_, jitter_));
  };
  const std::size_t first = rng.UniformIndex(points_.size());
  // The second point uniformly among those within r of the first (the first included).
  const auto count = static_cast<std::uint64_t>(std::lround(1.0 / inverse_neighbours_[first]));
  std::uint64_t k = rng.UniformIndex(count);
  std::size_t second = first;
  ForEachPointNear(points_[first], pair_radius_, [&](std::size_t j) {
    if (k-- == 0) second = j;
  });
  *a = jittered(points_[first]);
  *b = jittered(points_[second]);
  const double h = ThirdVertexHalfWidth(*a, *b, jitter_, pair_radius_);
  *c = 0.5 * (*a + *b) + Vec2(rng.Uniform(-h, h), rng.Uniform(-h, h));
}

double BirthGuide::OrderedDensity(const Vec2& a, const Vec2& b, const Vec2& c) const {
  const double h = ThirdVertexHalfWidth(a, b, jitter_, pair_radius_);
  if (Chebyshev(c, 0.5 * (a + b)) > h) return 0.0;
  // Σ over the guide points i next to a and j next to b, j among i's neighbours, of
  // P(first = i) P(second = j | i) = 1/M · 1/#N(i).
  double pairs = 0.0;
  ForEachPointNear(a, jitter_, [&](std::size_t i) {
    ForEachPointNear(b, jitter_, [&](std::size_t j) {
      if (Chebyshev(points_[i], points_[j]) <= pair_radius_) pairs += inverse_neighbours_[i];
    });
  });
  if (pairs == 0.0) return 0.0;
  const double square_jitter = 4.0 * jitter_ * jitter_;
  return pairs / static_cast<double>(points_.size()) / (square_jitter * square_jitter) /
         (4.0 * h * h);
}

double BirthGuide::Density(const Vec2& a, const Vec2& b, const Vec2& c) const {
  return OrderedDensity(a, b, c) + OrderedDensity(b, a, c) + OrderedDensity(a, c, b) +
         OrderedDensity(c, a, b) + OrderedDensity(b, c, a) + OrderedDensity(c, b, a);
}

}  // namespace priormap::prf
