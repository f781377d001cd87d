// Simulate one laser scan of a built-in room, compare it with its ground truth, and draw it.
//   example_01_simulate_scan [scene] [out.png]   (or .svg, .pdf)
#include <cmath>
#include <cstdio>
#include <exception>
#include <optional>
#include <string>

#include <priormap/core/simulate.hpp>
#include <priormap/render/scene_drawing.hpp>

// Arguments it cannot use get the usage line and exit 2. The library throws what it cannot do
// (here: a figure it cannot write, as to a missing directory or with an extension other than .png,
// .svg or .pdf); say what, and exit 1.
int main(int argc, char** argv) try {
  const std::string scene_name = argc > 1 ? argv[1] : "l-room";
  const std::string figure_path = argc > 2 ? argv[2] : "simulated-scan.png";

  const std::optional<priormap::Scene> scene = priormap::BuiltinScene(scene_name);
  if (!scene || argc > 3) {
    std::fprintf(stderr, "usage: %s [scene] [out.png|.svg|.pdf]\n", argv[0]);
    if (!scene) {
      std::string known;
      for (const std::string& name : priormap::BuiltinSceneNames()) known += " " + name;
      std::fprintf(stderr, "unknown scene %s (built-in:%s)\n", scene_name.c_str(), known.c_str());
    }
    return 2;
  }
  const priormap::RangeSensor sensor = *priormap::RangeSensor::Preset("utm30");
  priormap::Rng rng(/*seed=*/1);
  const priormap::Scan scan =
      priormap::SimulateScan(priormap::SceneRayCaster(*scene), sensor, *scene->default_pose, rng);

  // Every simulated scan carries its ground truth: here, the empirical noise level.
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan.IsValid(i)) sum_sq += std::pow(scan.ranges[i] - scan.truth->range[i], 2);
  }
  std::printf("%zu beams, %zu valid, empirical sigma %.4f m (sensor sigma %.4f m)\n", scan.size(),
              scan.NumValid(), std::sqrt(sum_sq / static_cast<double>(scan.NumValid())),
              sensor.sigma);

  priormap::render::Figure figure(scene->Bounds(), {.title = scene_name});
  priormap::render::DrawScene(figure, *scene);
  priormap::render::DrawScan(figure, scan);
  figure.Save(figure_path);
  std::printf("wrote %s\n", figure_path.c_str());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "error: %s\n", e.what());
  return 1;
}
