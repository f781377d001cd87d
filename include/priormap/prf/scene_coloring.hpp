#pragma once
/// The true map of a simulated scene as a polygonal coloring (Paskin & Thrun, Sec. 1.3.1): what
/// the PRF would ideally find. Its log-posterior under a data model, set against the chains',
/// tells a model that prefers another map from a sampler that has not found this one yet; its
/// views are the ground truth a sonar model is fitted on.

#include <string>
#include <variant>

#include <priormap/core/scene.hpp>
#include <priormap/core/scene_truth.hpp>
#include <priormap/prf/coloring.hpp>

namespace priormap::prf {

/// The scene's closed wall polylines clipped to `window` as a discontinuity graph (a polyline
/// leaving the window ends on its side), coloured by `truth` at the anchor. Only closed
/// polylines bound regions: a scene with open polylines or circles is refused, as is one whose
/// walls cross, touch each other or pass through a corner of the window.
[[nodiscard]] std::variant<Coloring, std::string> SceneColoring(const Scene& scene,
                                                                const SceneTruth& truth,
                                                                const Window& window,
                                                                double cell_size);

}  // namespace priormap::prf
