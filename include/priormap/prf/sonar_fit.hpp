#pragma once
/// Fitting the sonar model (sonar_model.hpp) to readings whose true map is known: each reading
/// is paired with what the true map shows its cone (features, seen fraction), and the model's
/// parameters maximize the log-likelihood of the readings. Paskin & Thrun's logistic
/// independent-return model has coefficients to be set; fitted on simulated or surveyed data,
/// the PRF's sonar likelihood says what the sensor actually does (docs/sonar.md).

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include <priormap/core/log.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/prf/coloring.hpp>
#include <priormap/prf/sonar_data.hpp>
#include <priormap/prf/sonar_model.hpp>

namespace priormap::prf {

/// One reading and what the true map shows its cone.
struct SonarFitReading {
  double range = 0.0;  ///< when not max_reading
  bool max_reading = false;
  double max_range = 0.0;
  std::vector<SonarFeature> features;  ///< in depth order
  double seen_fraction = 0.0;
  /// The length of its multipath path in the true map (+inf: not heard within R), nullopt when
  /// its axis meets no face (SonarLikelihood::MultipathLength).
  std::optional<double> multipath;
};

/// The readings of `data` with their views of `truth` (a coloring whose window holds the
/// sensors). Throws ContractError when a sensor lies in black.
[[nodiscard]] std::vector<SonarFitReading> ViewsOf(std::shared_ptr<const SonarData> data,
                                                   const Coloring& truth);

/// The sonar readings of a localized log of `scene` (its rings up to `max_range`) with their
/// views of the scene's true map (SceneColoring), in the window a mapping run would use
/// (`margin` around the readings, `cell_size`). A message when the log has no sonar reading,
/// the scene has no true coloring, or a transducer lies on a wall or inside one.
[[nodiscard]] std::variant<std::vector<SonarFitReading>, std::string> ViewsOfScene(
    const Log& log, const Scene& scene, double max_range, double margin = 1.0,
    double cell_size = 0.5);

/// Σ log p(reading | its view) under `model`, in a fixed order (the same for any thread count).
[[nodiscard]] double FitLogLikelihood(std::span<const SonarFitReading> readings,
                                      const SonarModel& model);

struct SonarFitOptions {
  /// Objective evaluations allowed per round of the optimizer (NLopt's Subplex).
  int max_evaluations = 20000;
  /// Rounds, each restarted from the last one's optimum (a direct-search method can stall on
  /// a ridge; a restart resets its simplex).
  int rounds = 3;
  /// Stop a round when a step changes the log-likelihood by less than this (nats).
  double tolerance = 1e-6;
  /// Also fit the parameters of the second outlier mixture (for cones that see nothing); when
  /// false they stay equal to the first's, the paper's single mixture.
  bool fit_clear_mixture = true;
  /// Also fit concave_corner_bias; when false it is 0, the paper's distance-only corners (even
  /// when the starting model has another value).
  bool fit_concave_corners = true;
  /// Also fit the multipath component (multipath_weight, multipath_sigma_relative); when false
  /// its weight is 0, the paper's model (even when the starting model has another).
  bool fit_multipath = true;
};

struct SonarFitResult {
  SonarModel model;
  double log_likelihood = 0.0;          ///< of the fitted model (without the weights' prior)
  double initial_log_likelihood = 0.0;  ///< of the starting model
  int evaluations = 0;
  std::size_t readings = 0;
};

/// The model of greatest likelihood, starting from `start`, within the paper's shape (an echo
/// no likelier with distance, no less likely with the projection and subtended angles) and
/// with a weak Dirichlet prior (one pseudo-reading per component) on the outlier mixtures'
/// weights. sigma_min and every parameter the options leave out keep `start`'s values.
/// Precondition: readings not empty, start valid.
[[nodiscard]] SonarFitResult FitSonarModel(std::span<const SonarFitReading> readings,
                                           const SonarModel& start,
                                           const SonarFitOptions& options = {});

}  // namespace priormap::prf
