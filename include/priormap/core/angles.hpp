#pragma once
/// Angles in radians, counter-clockwise. Canonical range is (-pi, pi].

#include <numbers>
#include <span>
#include <vector>

namespace priormap {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// Maps any finite angle to (-pi, pi]; NaN and infinities give NaN.
[[nodiscard]] double WrapAngle(double angle);

/// The signed smallest rotation taking `from` to `to`, in (-pi, pi].
[[nodiscard]] double AngleDifference(double to, double from);

/// Adds multiples of 2*pi so that consecutive elements differ by at most pi; the first element
/// is kept as is. Non-finite elements are copied and skipped (the next finite element is
/// unwrapped against the last finite one).
[[nodiscard]] std::vector<double> UnwrapAngles(std::span<const double> angles);

[[nodiscard]] constexpr double DegToRad(double degrees) {
  return degrees * kPi / 180.0;
}
[[nodiscard]] constexpr double RadToDeg(double radians) {
  return radians * 180.0 / kPi;
}

}  // namespace priormap
