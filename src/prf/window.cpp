#include <algorithm>
#include <cmath>
#include <limits>

#include <priormap/prf/window.hpp>

namespace priormap::prf {

Vec2 Window::Corner(int k) const {
  switch (((k % kNumSides) + kNumSides) % kNumSides) {
    case 0:
      return min;
    case 1:
      return {max.x(), min.y()};
    case 2:
      return max;
    default:
      return {min.x(), max.y()};
  }
}

Vec2 Window::SideDirection(int side) const {
  switch (side) {
    case 0:
      return {1.0, 0.0};
    case 1:
      return {0.0, 1.0};
    case 2:
      return {-1.0, 0.0};
    default:
      return {0.0, -1.0};
  }
}

double Window::DistanceToSide(const Vec2& origin, const Vec2& direction) const {
  double t = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 2; ++axis) {
    const double d = direction[axis];
    if (d > 0.0) t = std::min(t, (max[axis] - origin[axis]) / d);
    if (d < 0.0) t = std::min(t, (min[axis] - origin[axis]) / d);
  }
  return t;
}

double Window::CornerCoordinate(int k) const {
  k = ((k % kNumSides) + kNumSides) % kNumSides;
  const double w = Width();
  const double h = Height();
  const double starts[kNumSides] = {0.0, w, w + h, 2.0 * w + h};
  return starts[k];
}

double Window::Wrap(double s) const {
  const double perimeter = Perimeter();
  s = std::fmod(s, perimeter);
  if (s < 0.0) s += perimeter;
  return s >= perimeter ? 0.0 : s;
}

int Window::SideAt(double s) const {
  s = Wrap(s);
  for (int side = kNumSides - 1; side >= 0; --side) {
    const double start = CornerCoordinate(side);
    if (s == start) return -1;
    if (s > start) return side;
  }
  return -1;
}

Vec2 Window::PointAt(double s) const {
  s = Wrap(s);
  const int side = SideAt(s);
  if (side < 0) {
    for (int k = 0; k < kNumSides; ++k)
      if (s == CornerCoordinate(k)) return Corner(k);
  }
  const double along = s - CornerCoordinate(side);
  switch (side) {
    case 0:
      return {min.x() + along, min.y()};
    case 1:
      return {max.x(), min.y() + along};
    case 2:
      return {max.x() - along, max.y()};
    default:
      return {min.x(), max.y() - along};
  }
}

double Window::CoordinateOf(const Vec2& p, int side) const {
  switch (side) {
    case 0:
      return p.x() - min.x();
    case 1:
      return CornerCoordinate(1) + (p.y() - min.y());
    case 2:
      return CornerCoordinate(2) + (max.x() - p.x());
    default:
      return CornerCoordinate(3) + (max.y() - p.y());
  }
}

}  // namespace priormap::prf
