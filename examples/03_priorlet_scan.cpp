// Correct one noisy laser scan with an environment prior (priorlets, de la Puente & Censi): the
// MAP ranges against the truth, the regions and surfaces, the outliers, the degrees of freedom.
//   example_03_priorlet_scan [prior] [scene] [out.png]   (prior: a name or a .prior file;
//   the figure may be .svg or .pdf too)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <priormap/core/simulate.hpp>
#include <priormap/dsl/prior_library.hpp>
#include <priormap/priorlets/engine.hpp>
#include <priormap/priorlets/posterior.hpp>
#include <priormap/render/map_scan_figure.hpp>

// Arguments it cannot use get the usage line and exit 2; a prior that does not load, exit 1. What
// the library cannot do throws (a figure it cannot write; std::domain_error when a prior of your
// own leaves its domain at the estimate): say what, and exit 1.
int main(int argc, char** argv) try {
  const std::string prior_name = argc > 1 ? argv[1] : "rectangular";
  const std::string scene_name = argc > 2 ? argv[2] : "square";
  const std::string figure_path = argc > 3 ? argv[3] : "priorlet-scan.png";

  // As the app resolves --prior: a .prior file, else a name searched in PRIORMAP_PRIOR_PATH,
  // then in the built-in library (the files of priors/, compiled in).
  const priormap::Result<priormap::dsl::CompiledPrior> prior =
      priormap::dsl::PriorLibrary::WithEnvironment({}).Load(prior_name);
  if (!prior) {
    std::fprintf(stderr, "%s\n", prior.error().c_str());
    return 1;
  }
  const std::optional<priormap::Scene> scene = priormap::BuiltinScene(scene_name);
  if (!scene || argc > 4) {
    std::fprintf(stderr, "usage: %s [prior] [scene] [out.png|.svg|.pdf]\n", argv[0]);
    if (!scene) {
      std::string known;
      for (const std::string& name : priormap::BuiltinSceneNames()) known += " " + name;
      std::fprintf(stderr, "unknown scene %s (built-in:%s)\n", scene_name.c_str(), known.c_str());
    }
    return 2;
  }
  // 2 % spurious short readings, so that the engine has outliers to find.
  priormap::RangeSensor sensor = *priormap::RangeSensor::Preset("utm30");
  sensor.outlier_probability = 0.02;
  priormap::Rng rng(/*seed=*/2);
  const priormap::Scan scan =
      priormap::SimulateScan(priormap::SceneRayCaster(*scene), sensor, *scene->default_pose, rng);

  const priormap::priorlets::MapScan map =
      priormap::priorlets::EstimateMapScan(scan, prior.value());
  // The in-model range covariance only feeds the figure's heat map.
  const priormap::priorlets::Posterior posterior = priormap::priorlets::AnalysePosterior(
      scan, prior.value(), map, {.keep_range_covariance = true});

  // Range errors over the readings both the truth and the engine call walls: a reading the
  // simulator made up has no true range to be corrected to.
  double raw_sq = 0.0, map_sq = 0.0;
  std::size_t scored = 0, true_outliers = 0, outliers_found = 0, outliers = 0;
  std::set<int> true_regions;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (!scan.IsValid(i)) continue;
    const bool made_up = scan.truth->outlier[i] != 0;
    true_outliers += made_up;
    outliers += !map.inmodel[i];
    outliers_found += made_up && !map.inmodel[i];
    if (made_up) continue;
    true_regions.insert(scan.truth->region[i]);
    if (!map.inmodel[i]) continue;
    raw_sq += std::pow(scan.ranges[i] - scan.truth->range[i], 2);
    map_sq += std::pow(map.rho[i] - scan.truth->range[i], 2);
    ++scored;
  }
  const double raw_rms = std::sqrt(raw_sq / static_cast<double>(scored));
  const double map_rms = std::sqrt(map_sq / static_cast<double>(scored));

  std::printf("%s, %s scene: %zu beams, %zu valid, MAP %s in %.2f s\n",
              prior.value().name().c_str(), scene_name.c_str(), scan.size(), scan.NumValid(),
              map.feasible ? "feasible" : "INFEASIBLE", map.stats.seconds_total);
  std::printf("range error (RMS over %zu readings): %.2f mm measured, %.2f mm MAP\n", scored,
              1e3 * raw_rms, 1e3 * map_rms);
  std::printf("regions: %zu (true: %zu), surfaces: %zu\n", map.regions.size(), true_regions.size(),
              map.surfaces.size());
  std::printf("%zu outliers; %zu of the simulator's %zu spurious readings among them\n", outliers,
              outliers_found, true_outliers);
  const priormap::priorlets::DegreesOfFreedom& dof = posterior.dof;
  std::printf("degrees of freedom: %zu free = %zu extrinsic (pose) + %zu intrinsic (map)\n",
              dof.free, dof.extrinsic, dof.intrinsic);
  // The constraints shrink each range's uncertainty well below the sensor's noise.
  std::vector<double> std_rho;
  for (const double s : posterior.posterior_std_rho)
    if (std::isfinite(s)) std_rho.push_back(s);
  if (!std_rho.empty()) {
    std::nth_element(std_rho.begin(), std_rho.begin() + std_rho.size() / 2, std_rho.end());
    std::printf("posterior range std: %.2f mm (median; sensor %.0f mm)\n",
                1e3 * std_rho[std_rho.size() / 2], 1e3 * sensor.sigma);
  }
  // How the corrected map may still vary, largest first. v mixes ranges and normal angles, so
  // its sigma is not a length: what it does to the ranges is sigma times v's range entries.
  for (const priormap::priorlets::Eigenvariation& v : posterior.intrinsic_eigenvariations) {
    double largest = 0.0;
    for (const double rho : v.rho)
      if (std::isfinite(rho)) largest = std::max(largest, std::abs(v.sigma * rho));
    std::printf("  intrinsic eigenvariation: moves a range by up to %.2f mm (1 sigma)\n",
                1e3 * largest);
  }

  priormap::render::MapScanFigure(scan, map, posterior,
                                  {.title = prior.value().name() + ", " + scene_name})
      .Save(figure_path);
  std::printf("wrote %s\n", figure_path.c_str());

  // What the example claims: the prior pulls the ranges towards the truth, and the readings the
  // simulator made up do not pass for walls (but for the odd one that fell within the noise).
  const bool ok = map.feasible && map_rms < raw_rms && 10 * outliers_found >= 9 * true_outliers;
  if (!ok) std::fprintf(stderr, "unexpected result: see the numbers above\n");
  return ok ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "error: %s\n", e.what());
  return 1;
}
