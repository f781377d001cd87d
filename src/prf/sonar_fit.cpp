#include <array>
#include <cmath>
#include <limits>
#include <nlopt.h>
#include <utility>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <priormap/core/check.hpp>
#include <priormap/core/scene_truth.hpp>
#include <priormap/prf/scene_coloring.hpp>
#include <priormap/prf/sonar_fit.hpp>
#include <priormap/prf/sonar_likelihood.hpp>

namespace priormap::prf {
namespace {

double Logit(double p) {
  return std::log(p / (1.0 - p));
}
double Logistic(double x) {
  return 1.0 / (1.0 + std::exp(-x));
}

// The free parameters as an unconstrained vector: probabilities by their logits, positive
// scales by their logs, mixture weights by their log-ratios to the max-range weight.
class Parameterization {
 public:
  Parameterization(const SonarModel& start, const SonarFitOptions& options)
      : start_(start), options_(options) {}

  [[nodiscard]] bool fits_clear_mixture() const { return options_.fit_clear_mixture; }

  [[nodiscard]] std::vector<double> Encode(const SonarModel& m) const {
    std::vector<double> x = {m.corner_bias,
                             m.corner_per_m,
                             m.face_bias,
                             m.face_per_m,
                             m.face_per_rad_projection,
                             m.face_per_rad_subtended,
                             Logit(m.max_return),
                             std::log(m.sigma_relative),
                             std::log(m.uniform_weight / m.max_weight),
                             LogRatio(m.exponential_weight, m.max_weight),
                             std::log(m.exponential_rate)};
    if (options_.fit_concave_corners) x.push_back(m.concave_corner_bias);
    if (options_.fit_clear_mixture) {
      x.push_back(std::log(m.clear_uniform_weight / m.clear_max_weight));
      x.push_back(LogRatio(m.clear_exponential_weight, m.clear_max_weight));
    }
    if (options_.fit_multipath) {
      // Off in the starting model (weight 0): start it at a guess inside the bounds.
      x.push_back(Logit(m.multipath_weight > 0.0 ? m.multipath_weight : 0.2));
      x.push_back(std::log(m.multipath_sigma_relative));
    }
    return x;
  }

  [[nodiscard]] SonarModel Decode(const double* x) const {
    SonarModel m = start_;
    m.corner_bias = x[0];
    m.corner_per_m = x[1];
    m.face_bias = x[2];
    m.face_per_m = x[3];
    m.face_per_rad_projection = x[4];
    m.face_per_rad_subtended = x[5];
    m.max_return = Logistic(x[6]);
    m.sigma_relative = std::exp(x[7]);
    Weights(x[8], x[9], &m.uniform_weight, &m.exponential_weight, &m.max_weight);
    m.exponential_rate = std::exp(x[10]);
    std::size_t k = 11;
    // Left out, a component is the paper's (whatever the starting model holds).
    m.concave_corner_bias = options_.fit_concave_corners ? x[k++] : 0.0;
    if (options_.fit_clear_mixture) {
      Weights(x[k], x[k + 1], &m.clear_uniform_weight, &m.clear_exponential_weight,
              &m.clear_max_weight);
      k += 2;
    } else {
      m.clear_uniform_weight = m.uniform_weight;
      m.clear_exponential_weight = m.exponential_weight;
      m.clear_max_weight = m.max_weight;
    }
    if (options_.fit_multipath) {
      m.multipath_weight = Logistic(x[k]);
      m.multipath_sigma_relative = std::exp(x[k + 1]);
    } else {
      m.multipath_weight = 0.0;
    }
    return m;
  }

  // Box bounds, wide but finite: a weight may fall to e^-25 of the max-range weight, a
  // probability's logit stays within ±15, a slope within ±500 per unit.
  struct Box {
    std::vector<double> lower, upper;
  };
  [[nodiscard]] Box Bounds(std::size_t n) const {
    constexpr double kLog1e4 = -9.210340371976184;  // log(1e-4)
    constexpr double kLog1e3 = 6.907755278982137;   // log(1e3)
    // In the order of Encode. The shape of the paper's independent-return model: an echo is
    // less likely as the distance grows, the projection angle falls or the subtended angle
    // shrinks.
    constexpr std::array<std::pair<double, double>, 11> kBounds = {{
        {-500.0, 500.0},      // corner_bias
        {-500.0, 0.0},        // corner_per_m
        {-500.0, 500.0},      // face_bias
        {-500.0, 0.0},        // face_per_m
        {0.0, 500.0},         // face_per_rad_projection
        {0.0, 500.0},         // face_per_rad_subtended
        {-15.0, 15.0},        // logit max_return
        {kLog1e4, 0.0},       // log sigma_relative: [1e-4, 1]
        {-25.0, 25.0},        // log uniform / max weight
        {-25.0, 25.0},        // log exponential / max weight
        {-kLog1e3, kLog1e3},  // log exponential_rate
    }};
    std::vector<std::pair<double, double>> bounds(kBounds.begin(), kBounds.end());
    if (options_.fit_concave_corners) bounds.emplace_back(-500.0, 500.0);
    if (options_.fit_clear_mixture) bounds.insert(bounds.end(), 2, {-25.0, 25.0});  // log-ratios
    if (options_.fit_multipath) {
      bounds.emplace_back(-15.0, 15.0);  // logit multipath_weight
      // log multipath_sigma_relative: [0.5 %, 20 %] of the path
      bounds.emplace_back(std::log(0.005), std::log(0.2));
    }
    PRIORMAP_CHECK(bounds.size() == n, "a bound for every fitted parameter");
    Box box;
    for (const auto& [lo, hi] : bounds) {
      box.lower.push_back(lo);
      box.upper.push_back(hi);
    }
    return box;
  }

 private:
  static double LogRatio(double a, double b) { return a > 0.0 ? std::log(a / b) : -25.0; }
  static void Weights(double log_u, double log_e, double* u, double* e, double* m) {
    const double total = std::exp(log_u) + std::exp(log_e) + 1.0;
    *u = std::exp(log_u) / total;
    *e = std::exp(log_e) / total;
    *m = 1.0 / total;
  }

  SonarModel start_;
  SonarFitOptions options_;
};

struct Objective {
  std::span<const SonarFitReading> readings;
  const Parameterization* parameters;
  int evaluations = 0;
};

// A Dirichlet(2, 2, 2) prior on each outlier mixture's weights: one pseudo-reading per
// component, so that a component the data never saw gets a small weight, not zero (a weight of
// zero would make one later reading of that kind cost tens of nats).
double MixtureLogPrior(const SonarModel& m, bool clear_mixture) {
  double log_prior =
      std::log(m.uniform_weight) + std::log(m.exponential_weight) + std::log(m.max_weight);
  if (clear_mixture)
    log_prior += std::log(m.clear_uniform_weight) + std::log(m.clear_exponential_weight) +
                 std::log(m.clear_max_weight);
  return log_prior;
}

// NLopt minimizes: the negative log-likelihood, +inf for a model that is not usable.
double NegativeLogLikelihood(unsigned, const double* x, double*, void* data) {
  auto* objective = static_cast<Objective*>(data);
  ++objective->evaluations;
  const SonarModel model = objective->parameters->Decode(x);
  if (!model.Problem().empty()) return std::numeric_limits<double>::infinity();
  const double log_posterior = FitLogLikelihood(objective->readings, model) +
                               MixtureLogPrior(model, objective->parameters->fits_clear_mixture());
  return std::isfinite(log_posterior) ? -log_posterior : std::numeric_limits<double>::infinity();
}

}  // namespace

std::vector<SonarFitReading> ViewsOf(std::shared_ptr<const SonarData> data, const Coloring& truth) {
  SonarLikelihood likelihood(data, SonarModel{});
  const auto problem = likelihood.Reset(truth);
  PRIORMAP_CHECK(!problem, problem.value_or(""));
  std::vector<SonarFitReading> readings;
  readings.reserve(data->readings.size());
  for (std::size_t i = 0; i < data->readings.size(); ++i) {
    const SonarReading& r = data->readings[i];
    SonarView view = likelihood.View(truth, i);
    readings.push_back({.range = r.range,
                        .max_reading = r.max_reading,
                        .max_range = data->max_range,
                        .features = std::move(view.features),
                        .seen_fraction = view.seen_fraction,
                        .multipath = likelihood.MultipathLength(truth, i)});
  }
  return readings;
}

std::variant<std::vector<SonarFitReading>, std::string> ViewsOfScene(
    const Log& log, const Scene& scene, double max_range, double margin, double cell_size) {
  auto selected =
      SelectSonarReadings(log, {.first_scan = 0, .end_scan = std::nullopt, .max_range = max_range});
  if (!selected) return selected.diagnostics().front().message;
  auto data = std::make_shared<const SonarData>(std::move(selected).value());
  std::vector<Vec2> seeds = scene.waypoints;
  for (const Scan& scan : log.scans)
    if (scan.sonar && scan.pose.translation().allFinite()) seeds.push_back(scan.pose.translation());
  for (const Vec2& sensor : data->sensors) seeds.push_back(sensor);
  if (std::string problem = PointOnASurface(scene, seeds); !problem.empty())
    return problem + ": the log was not recorded in this scene, or its poses are off";
  const SceneTruth truth(scene, seeds);
  auto coloring = SceneColoring(scene, truth, WindowAround(*data, margin), cell_size);
  if (auto* problem = std::get_if<std::string>(&coloring))
    return "scene " + scene.name + ": " + *problem;
  const Coloring& true_map = std::get<Coloring>(coloring);
  // A transducer inside a wall has no view: a message, not ViewsOf's contract failure.
  for (std::size_t s = 0; s < data->sensors.size(); ++s) {
    const Vec2& sensor = data->sensors[s];
    if (true_map.ColourAt(sensor) == Colour::kBlack)
      return fmt::format(
          "transducer position {} of the log, ({}, {}), lies inside the walls of scene {}: the "
          "log was not recorded in this scene, its poses are off, or its path runs closer to a "
          "wall than the transducers sit from the robot's centre",
          s, sensor.x(), sensor.y(), scene.name);
  }
  return ViewsOf(data, true_map);
}

double FitLogLikelihood(std::span<const SonarFitReading> readings, const SonarModel& model) {
  // Each reading's term in parallel, summed in order: the same total for any thread count.
  std::vector<double> terms(readings.size());
  tbb::parallel_for(std::size_t{0}, readings.size(), [&](std::size_t i) {
    const SonarFitReading& r = readings[i];
    terms[i] = model.LogLikelihood(r.range, r.max_reading, r.features, r.max_range, r.seen_fraction,
                                   r.multipath);
  });
  double total = 0.0;
  for (const double t : terms) total += t;
  return total;
}

SonarFitResult FitSonarModel(std::span<const SonarFitReading> readings, const SonarModel& start,
                             const SonarFitOptions& options) {
  PRIORMAP_CHECK(!readings.empty(), "no readings to fit the sonar model to");
  PRIORMAP_CHECK(start.Problem().empty(), "the starting sonar model: " + start.Problem());
  PRIORMAP_CHECK(options.rounds >= 1 && options.max_evaluations >= 1, "at least one evaluation");
  const Parameterization parameters(start, options);
  std::vector<double> x = parameters.Encode(start);
  const auto n = static_cast<unsigned>(x.size());
  const auto [lower, upper] = parameters.Bounds(n);
  for (unsigned i = 0; i < n; ++i) x[i] = std::clamp(x[i], lower[i], upper[i]);

  SonarFitResult result;
  result.readings = readings.size();
  result.initial_log_likelihood = FitLogLikelihood(readings, start);
  Objective objective{.readings = readings, .parameters = &parameters};
  double minimum = NegativeLogLikelihood(n, x.data(), nullptr, &objective);
  for (int round = 0; round < options.rounds; ++round) {
    nlopt_opt opt = nlopt_create(NLOPT_LN_SBPLX, n);
    PRIORMAP_CHECK(opt != nullptr, "NLopt could not create its optimizer");
    nlopt_set_lower_bounds(opt, lower.data());
    nlopt_set_upper_bounds(opt, upper.data());
    nlopt_set_min_objective(opt, NegativeLogLikelihood, &objective);
    nlopt_set_ftol_abs(opt, options.tolerance);
    nlopt_set_maxeval(opt, options.max_evaluations);
    // Initial steps of about a tenth of each parameter's scale.
    std::vector<double> steps(n, 0.5);
    steps[4] = 5.0;  // the projection slope, per radian
    nlopt_set_initial_step(opt, steps.data());
    double value = minimum;
    const nlopt_result status = nlopt_optimize(opt, x.data(), &value);
    nlopt_destroy(opt);
    PRIORMAP_CHECK(status > 0 || status == NLOPT_ROUNDOFF_LIMITED,
                   "NLopt failed while fitting the sonar model (status " +
                       std::to_string(static_cast<int>(status)) + ")");
    const bool improved = value < minimum - options.tolerance;
    minimum = std::min(minimum, value);
    if (!improved && round > 0) break;
  }
  result.model = parameters.Decode(x.data());
  result.log_likelihood = FitLogLikelihood(readings, result.model);
  result.evaluations = objective.evaluations;
  return result;
}

}  // namespace priormap::prf
