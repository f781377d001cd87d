// Uses the installed headers and libraries: simulate a scan, write it as JSON and draw it.
#include <cstdio>
#include <string>

#include <priormap/core/json_io.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/render/scene_drawing.hpp>

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : ".";
  const priormap::Scene scene = *priormap::BuiltinScene("square");
  priormap::Rng rng(1);
  const priormap::Scan scan =
      priormap::SimulateScan(priormap::SceneRayCaster(scene),
                             *priormap::RangeSensor::Preset("lms200"), *scene.default_pose, rng);
  priormap::WriteJsonScan(scan, out + "/consumer-scan.json");
  priormap::render::Figure figure(scene.Bounds());
  priormap::render::DrawScene(figure, scene);
  priormap::render::DrawScan(figure, scan);
  figure.Save(out + "/consumer-scan.png");
  std::printf("consumer: %zu beams, %zu valid\n", scan.size(), scan.NumValid());
  return scan.NumValid() > 0 ? 0 : 1;
}
