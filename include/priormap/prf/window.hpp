#pragma once
/// The rectangular window through which a polygonal coloring is seen (Paskin & Thrun, Sec. 1.3.1).
/// Boundary vertices live on its sides; a point on the boundary is addressed by its side and by
/// its perimeter coordinate s in [0, Perimeter()), counter-clockwise from the lower-left corner.

#include <priormap/core/types.hpp>

namespace priormap::prf {

/// Side k runs counter-clockwise from Corner(k) to Corner(k + 1): 0 bottom, 1 right, 2 top, 3 left.
inline constexpr int kNumSides = 4;

struct Window {
  Vec2 min = Vec2::Zero();
  Vec2 max = Vec2::Ones();

  [[nodiscard]] double Width() const { return max.x() - min.x(); }
  [[nodiscard]] double Height() const { return max.y() - min.y(); }
  [[nodiscard]] double Area() const { return Width() * Height(); }
  [[nodiscard]] double Perimeter() const { return 2.0 * (Width() + Height()); }
  [[nodiscard]] Vec2 Center() const { return 0.5 * (min + max); }

  /// Corner k (k mod 4): lower-left, lower-right, upper-right, upper-left.
  [[nodiscard]] Vec2 Corner(int k) const;
  /// Unit direction of side k, counter-clockwise.
  [[nodiscard]] Vec2 SideDirection(int side) const;
  [[nodiscard]] double SideLength(int side) const { return side % 2 == 0 ? Width() : Height(); }
  /// Perimeter coordinate of Corner(k).
  [[nodiscard]] double CornerCoordinate(int k) const;

  /// True for points strictly inside (not on the boundary).
  [[nodiscard]] bool ContainsInterior(const Vec2& p) const {
    return p.x() > min.x() && p.x() < max.x() && p.y() > min.y() && p.y() < max.y();
  }

  /// The distance from a point inside to the boundary along a unit direction.
  [[nodiscard]] double DistanceToSide(const Vec2& origin, const Vec2& direction) const;

  /// The side holding perimeter coordinate s (wrapped into [0, Perimeter())), or -1 when s is
  /// exactly a corner: boundary vertices never sit on corners.
  [[nodiscard]] int SideAt(double s) const;
  /// The boundary point at perimeter coordinate s (wrapped). Points on a side are exact: their
  /// coordinate across the side equals the side's.
  [[nodiscard]] Vec2 PointAt(double s) const;
  /// Perimeter coordinate of a point on side `side`.
  [[nodiscard]] double CoordinateOf(const Vec2& p, int side) const;
  /// s wrapped into [0, Perimeter()).
  [[nodiscard]] double Wrap(double s) const;
};

}  // namespace priormap::prf
