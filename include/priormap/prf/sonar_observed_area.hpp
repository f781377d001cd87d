#pragma once
/// What sonar cones could see of a scene, to score a sonar map where its readings could say
/// something, as the sonar study does (sonar_study.hpp): the sonar counterpart of ObservedArea
/// (core/observed_area.hpp) with MarkCoverage (map_scores.hpp). A ring's cones do not see all
/// round: between and beyond them lies area no reading could tell anything about, which a
/// laser's ObservedArea from the same poses would score.
///
/// A fan of rays across each cone, each followed to the first true surface within R, marks the
/// cells it crosses as visible and those up to `band` behind that surface as behind it; the
/// cells inside the cone up to its reading (R for a max reading) are its covered cells. Points
/// are marked every half cell along a ray (ConeFanOptions::mark_step).

#include <map>
#include <vector>

#include <priormap/core/scene.hpp>
#include <priormap/core/scene_truth.hpp>
#include <priormap/prf/cell_grid.hpp>
#include <priormap/prf/map_scores.hpp>
#include <priormap/prf/sonar_data.hpp>

namespace priormap::prf {

struct ConeFanOptions {
  int rays_per_cone = 21;  ///< across each cone's spread, its edges included; at least 2
  double band = 0.1;       ///< depth behind a seen surface that counts as observed, m
  double mark_step = 0.0;  ///< between marks along a ray, m; 0: half the raster's smaller cell side
};

/// Where the fans' rays met the scene's surfaces, by the region of the primitive met
/// (Scene::Primitives): the seen parts of the true walls.
using ConeWallHits = std::map<int, std::vector<Vec2>>;

/// The truth at each centre of `grid` and what the cones of `data` could see of `scene` there:
/// observation (visible wins over behind a surface) and coverage. `wall_hits`, when given,
/// receives where the rays met surfaces. Throws ContractError for fewer than two rays per cone,
/// a band that is negative or infinite, or a mark step other than 0 below 1e-6 m.
[[nodiscard]] EvaluationRaster MakeSonarEvaluationRaster(const CellGrid& grid,
                                                         const SceneTruth& truth,
                                                         const Scene& scene, const SonarData& data,
                                                         const ConeFanOptions& options = {},
                                                         ConeWallHits* wall_hits = nullptr);

}  // namespace priormap::prf
