#include <cmath>
#include <numbers>

#include <priormap/prf/arak.hpp>

namespace priormap::prf {

double ExpectedEdges(double p, const Window& window) {
  return p * window.Perimeter() + 4.0 * std::numbers::pi * p * p * window.Area();
}

double ExpectedCrossings(double p, double d) {
  return 2.0 * p * d;
}

double SameColourProbability(double p, double d) {
  return 0.5 * (1.0 + std::exp(-4.0 * p * d));
}

}  // namespace priormap::prf
