#pragma once
/// Data-guided triangle births: where the data say a surface is, propose one. The chain of the
/// Clifford–Nicholls moves finds a wall only when a blind birth happens to put an edge within a
/// few centimetres of it at the right angle; on the Intel lab's 5,550 beams the chains were still
/// discovering walls after 15 million steps. A guided birth draws two vertices next to two nearby
/// guide points (the beams' end points) and the third in a square around their midpoint, as
/// large as the first edge is long, so the new triangle's first edge runs along the hits. Its
/// proposal density is computed exactly (docs/prf-moves.md, "Guided triangle"), so the chain still
/// targets the same posterior; the guide only changes how fast it gets there.

#include <cstdint>
#include <span>
#include <vector>

#include <priormap/core/rng.hpp>
#include <priormap/core/types.hpp>
#include <priormap/prf/cell_grid.hpp>

namespace priormap::prf {

class BirthGuide {
 public:
  /// `points`: where surfaces are likely (finite). `pair_radius` r: the second point is drawn
  /// among those within Chebyshev distance r of the first. `jitter` δ: each of the first two
  /// vertices a, b is uniform in the square of half-width δ around its guide point. The third
  /// is uniform in the square of half-width h = clamp(|ab|, 2δ, r) around the midpoint of ab.
  BirthGuide(std::vector<Vec2> points, double pair_radius, double jitter);

  [[nodiscard]] std::size_t size() const { return points_.size(); }
  [[nodiscard]] std::span<const Vec2> points() const { return points_; }
  [[nodiscard]] double pair_radius() const { return pair_radius_; }
  [[nodiscard]] double jitter() const { return jitter_; }

  /// Draws the vertices of a triangle in order (a, b next to guide points, c around their
  /// midpoint). Precondition: size() > 0.
  void Draw(Rng& rng, Vec2* a, Vec2* b, Vec2* c) const;

  /// The density of the unordered triangle {a, b, c} against Lebesgue measure on the three
  /// positions divided by their 3! orders: the sum of the ordered densities over the six orders.
  [[nodiscard]] double Density(const Vec2& a, const Vec2& b, const Vec2& c) const;

 private:
  /// Density of Draw giving exactly (a, b, c) in this order.
  [[nodiscard]] double OrderedDensity(const Vec2& a, const Vec2& b, const Vec2& c) const;
  /// Calls visit(i) for each point within Chebyshev distance `radius` of q (radius ≤ the
  /// index's cell).
  template <class Visit>
  void ForEachPointNear(const Vec2& q, double radius, Visit&& visit) const;

  std::vector<Vec2> points_;  ///< sorted by index cell
  double pair_radius_;
  double jitter_;
  CellGrid grid_;                           ///< cells of pair_radius_
  std::vector<std::uint32_t> cell_start_;   ///< points_ of cell k: [cell_start_[k], [k + 1])
  std::vector<double> inverse_neighbours_;  ///< 1 / #points within r, per point
};

}  // namespace priormap::prf
