#include <cmath>

#include <priormap/core/angles.hpp>

namespace priormap {

double WrapAngle(double angle) {
  // std::remainder gives [-pi, pi]; the canonical range is (-pi, pi].
  const double wrapped = std::remainder(angle, kTwoPi);
  return wrapped <= -kPi ? wrapped + kTwoPi : wrapped;
}

double AngleDifference(double to, double from) {
  return WrapAngle(to - from);
}

std::vector<double> UnwrapAngles(std::span<const double> angles) {
  std::vector<double> out(angles.begin(), angles.end());
  bool have_previous = false;
  double previous = 0.0;
  for (double& a : out) {
    if (!std::isfinite(a)) continue;
    if (have_previous) a = previous + AngleDifference(a, previous);
    previous = a;
    have_previous = true;
  }
  return out;
}

}  // namespace priormap
