#pragma once
/// The beam model of the PRF laser likelihood (Paskin & Thrun, Sec. 2.2): given the distance d to
/// the first edge along the beam (none within R: d = ∞), a reading is
///   - with weight w_hit, Gaussian around d (truncated to r ≥ 0; its mass beyond R is a max
///     reading, and with no edge within R the whole component is a max reading),
///   - with weight w_outlier, uniform on [0, R),
///   - with weight w_max, a max reading whatever the map (glass, black surfaces).
/// The observation space is [0, R) plus the max-reading atom; the density integrates to one over
/// it for every d (tests/prf/laser_likelihood_test.cpp). The sensor standing in black has
/// likelihood zero; that is the data term's business, not the beam model's.

#include <string>

namespace priormap::prf {

struct LaserModel {
  double sigma = 0.05;  ///< m
  double hit_weight = 0.8;
  double outlier_weight = 0.15;
  double max_weight = 0.05;

  /// Empty when valid, else what is wrong (weights positive and summing to one, σ > 0).
  [[nodiscard]] std::string Problem() const;

  /// log p(reading | d) for a reading r < R, or of a max reading when `max_reading`.
  [[nodiscard]] double LogLikelihood(double reading, bool max_reading, double d,
                                     double max_range) const;
};

}  // namespace priormap::prf
