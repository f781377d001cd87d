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
/// One extension, off by default (multipath_weight = 0): when the cone's axis meets a face, the
/// outlier component gives weight multipath_weight to a Gaussian around the length of the axis's
/// path mirrored at that face and followed to the next edge (the multipath reading a specular
/// miss gives; sonar_multipath.hpp finds that path), its mass beyond R a max reading.
/// The observation space is [0, R) plus the max-reading atom; the density integrates to one
/// over it for every set of features (tests/prf/sonar_model_test.cpp).

#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <priormap/core/rng.hpp>
#include <priormap/prf/sonar_visibility.hpp>

namespace priormap::prf {

struct SonarModel {
  // Corners: q = max_return · logistic(corner_bias + corner_per_m · d
  //              + concave_corner_bias · [seen from inside]).
  double corner_bias = 1.0;
  double corner_per_m = -0.5;
  /// A corner seen from inside is a corner reflector; one seen from outside (a tip, a door
  /// frame) only diffracts. 0 gives the paper's model, where a corner's echo depends on its
  /// distance alone.
  double concave_corner_bias = 0.0;
  // Faces: q = max_return · logistic(face_bias + face_per_m · d
  //            + face_per_rad_projection · (projection − π/2) + face_per_rad_subtended ·
  //            subtended).
  double face_bias = -1.0;
  double face_per_m = -0.3;
  double face_per_rad_projection = 15.0;  ///< about 0.26 per degree off normal incidence
  double face_per_rad_subtended = 12.0;   ///< a whole 20° cone: +4.2
  /// Caps every q, so that a reading always keeps some outlier weight.
  double max_return = 0.95;

  double sigma_relative = 0.01;  ///< range noise relative to the distance
  double sigma_min = 0.01;       ///< m

  // The outlier component, given no feature echoed: a mixture of a uniform, an exponential and
  // a max-range atom, its weights summing to one, for the sound that met a surface and was
  // reflected away (a specular miss, possibly heard back after several bounces)...
  double uniform_weight = 0.3;
  double exponential_weight = 0.1;
  double max_weight = 0.6;
  double exponential_rate = 2.0;  ///< 1/m
  // ... and for the sound that met nothing within R, which has no surface to bounce off: a
  // second mixture. The outlier density is the two weighted by the share of the cone's angle
  // that sees a face (SonarView::seen_fraction) and the rest. Equal to the first (the
  // defaults), it gives the paper's single outlier mixture.
  double clear_uniform_weight = 0.3;
  double clear_exponential_weight = 0.1;
  double clear_max_weight = 0.6;
  // Multipath: given a specular miss whose axis meets a face, the share of the outlier
  // component that is heard back along the mirrored path (0: the paper's model), and that
  // reading's spread relative to the path's length (wider than a direct echo's, as the map's
  // faces are never exactly where the sound bounced).
  double multipath_weight = 0.0;
  double multipath_sigma_relative = 0.02;

  /// Empty when valid, else what is wrong.
  [[nodiscard]] std::string Problem() const;

  /// q_f, the independent return probability of a feature.
  [[nodiscard]] double IndependentReturn(const SonarFeature& feature) const;
  /// r_f for each feature (in depth order) into `returns`; returns the outlier weight
  /// Π (1 − q_f), which with the r_f sums to one.
  double ReturnProbabilities(std::span<const SonarFeature> features,
                             std::vector<double>* returns) const;
  /// A reading drawn from the model (the generative story of LogLikelihood): each feature in
  /// depth order echoes with its q until one does, its range Gaussian around the feature's
  /// distance (truncated to r >= 0; at or beyond R a max reading); when none does, an outlier
  /// from the specular mixture with probability `seen_fraction`, else from the clear one; with
  /// a mirrored path (`multipath`: its length, +inf when not heard within R), first the
  /// multipath reading with probability multipath_weight.
  struct Draw {
    double range = 0.0;  // when not max_reading
    bool max_reading = false;
  };
  [[nodiscard]] Draw Sample(std::span<const SonarFeature> features, double seen_fraction,
                            double max_range, Rng& rng,
                            std::optional<double> multipath = std::nullopt) const;

  /// log p(reading | features) for a reading r < R, or of a max reading when `max_reading`;
  /// `seen_fraction` is the share of the cone that meets a surface (SonarView); `multipath` the
  /// length of the axis's mirrored path (+inf when it is not heard within R), nullopt when the
  /// axis meets no face within R.
  [[nodiscard]] double LogLikelihood(double reading, bool max_reading,
                                     std::span<const SonarFeature> features, double max_range,
                                     double seen_fraction = 1.0,
                                     std::optional<double> multipath = std::nullopt) const;
  /// Whether the multipath extension is on (views then need their mirrored paths).
  [[nodiscard]] bool models_multipath() const { return multipath_weight > 0.0; }
};

/// A parameter of SonarModel and its name (in model files, sonar_model_io.hpp).
struct SonarModelParameter {
  const char* name;
  double SonarModel::*member;
};
/// Every parameter of SonarModel, in a fixed order (that of the files and of fingerprints).
inline constexpr std::array<SonarModelParameter, 19> kSonarModelParameters = {{
    {"corner_bias", &SonarModel::corner_bias},
    {"corner_per_m", &SonarModel::corner_per_m},
    {"concave_corner_bias", &SonarModel::concave_corner_bias},
    {"face_bias", &SonarModel::face_bias},
    {"face_per_m", &SonarModel::face_per_m},
    {"face_per_rad_projection", &SonarModel::face_per_rad_projection},
    {"face_per_rad_subtended", &SonarModel::face_per_rad_subtended},
    {"max_return", &SonarModel::max_return},
    {"sigma_relative", &SonarModel::sigma_relative},
    {"sigma_min", &SonarModel::sigma_min},
    {"uniform_weight", &SonarModel::uniform_weight},
    {"exponential_weight", &SonarModel::exponential_weight},
    {"max_weight", &SonarModel::max_weight},
    {"exponential_rate", &SonarModel::exponential_rate},
    {"clear_uniform_weight", &SonarModel::clear_uniform_weight},
    {"clear_exponential_weight", &SonarModel::clear_exponential_weight},
    {"clear_max_weight", &SonarModel::clear_max_weight},
    {"multipath_weight", &SonarModel::multipath_weight},
    {"multipath_sigma_relative", &SonarModel::multipath_sigma_relative},
}};

}  // namespace priormap::prf
