#pragma once
/// The sonar measurement model of the PRF (Paskin & Thrun, Sec. 2.3, Fig. 3), given the features
/// a cone sees (SonarView::features, in depth order):
///   - each feature f would echo on its own with probability q_f, a logistic function of its
///     distance (corners), or of the distance to its closest point, the projection angle and the
///     angle its visible part subtends (faces): the independent return model;
///   - the return probability of f is r_f = q_f Π_{g<f} (1 − q_g): f echoes only if no closer
///     feature did (the paper prints (1 − r_g), which does not sum to one with the outlier
///     weight; its words, "only if none of the closer features did", are the product above);
///   - a reading is, with weight r_f, Gaussian around f's distance (σ = max(σ_min, σ_rel d),
///     truncated to r ≥ 0, its mass beyond R a max reading), and with the outlier weight
///     Π_f (1 − q_f) drawn from a mixture of a uniform on [0, R), an exponential truncated to
///     [0, R) and a max-range point mass.
/// The observation space is [0, R) plus the max-reading atom; the density integrates to one
/// over it for every set of features (tests/prf/sonar_model_test.cpp).

#include <span>
#include <string>
#include <vector>

#include <priormap/prf/sonar_visibility.hpp>

namespace priormap::prf {

struct SonarModel {
  // Corners: q = max_return · logistic(corner_bias + corner_per_m · d).
  double corner_bias = 1.0;
  double corner_per_m = -0.5;
  // Faces: q = max_return · logistic(face_bias + face_per_m · d
  //            + face_per_rad_projection · (projection − π/2) + face_per_rad_subtended ·
  //            subtended).
  double face_bias = -1.0;
  double face_per_m = -0.3;
  double face_per_rad_projection = 15.0;  // about 0.26 per degree off normal incidence
  double face_per_rad_subtended = 12.0;   // a whole 20° cone: +4.2
  /// Caps every q, so that a reading always keeps some outlier weight.
  double max_return = 0.95;

  double sigma_relative = 0.01;  // range noise relative to the distance
  double sigma_min = 0.01;       // m

  // The outlier component, given no feature echoed: weights summing to one.
  double uniform_weight = 0.3;
  double exponential_weight = 0.1;
  double max_weight = 0.6;
  double exponential_rate = 2.0;  // 1/m

  /// Empty when valid, else what is wrong.
  [[nodiscard]] std::string Problem() const;

  /// q_f, the independent return probability of a feature.
  [[nodiscard]] double IndependentReturn(const SonarFeature& feature) const;
  /// r_f for each feature (in depth order) into `returns`; returns the outlier weight
  /// Π (1 − q_f), which with the r_f sums to one.
  double ReturnProbabilities(std::span<const SonarFeature> features,
                             std::vector<double>* returns) const;
  /// log p(reading | features) for a reading r < R, or of a max reading when `max_reading`.
  [[nodiscard]] double LogLikelihood(double reading, bool max_reading,
                                     std::span<const SonarFeature> features,
                                     double max_range) const;
};

}  // namespace priormap::prf
