#include <cmath>
#include <utility>

#include <priormap/core/check.hpp>
#include <priormap/core/scene_ray_caster.hpp>
#include <priormap/prf/sonar_observed_area.hpp>

namespace priormap::prf {
namespace {

EvaluationRaster UnseenRaster(const CellGrid& grid, const SceneTruth& truth) {
  EvaluationRaster raster;
  raster.grid = grid;
  const auto n = static_cast<std::size_t>(grid.NumCells());
  raster.truth_black.resize(n);
  raster.observation.assign(n, Observation::kUnseen);
  raster.covered.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i)
    raster.truth_black[i] = truth.Occupied(grid.Centre(static_cast<int>(i))) ? 1 : 0;
  return raster;
}

ConeWallHits MarkConeFans(const SonarData& data, const Scene& scene, const ConeFanOptions& options,
                          EvaluationRaster* raster) {
  const SceneRayCaster caster(scene);
  ConeWallHits hits;
  const CellGrid& grid = raster->grid;
  // Half a cell apart, so that a ray marks about every cell it crosses.
  const double step = options.mark_step > 0.0 ? options.mark_step : 0.5 * grid.cell.minCoeff();
  const Box2 box(grid.origin, grid.origin + Vec2(grid.nx * grid.cell.x(), grid.ny * grid.cell.y()));
  const auto mark = [&](const Vec2& p, Observation what, bool covered) {
    if (!box.contains(p)) return;
    const auto i = static_cast<std::size_t>(grid.CellOf(p));
    if (what == Observation::kVisible ||
        (what == Observation::kBehindSurface && raster->observation[i] == Observation::kUnseen))
      raster->observation[i] = what;
    if (covered) raster->covered[i] = 1;
  };
  const int rays = options.rays_per_cone;
  for (const SonarReading& r : data.readings) {
    const double axis = std::atan2(r.cone.axis.y(), r.cone.axis.x());
    const double reach = r.max_reading ? r.cone.max_range : r.range;
    for (int k = 0; k < rays; ++k) {
      const double angle = axis + r.cone.half_spread * (2.0 * k / (rays - 1) - 1.0);
      const Vec2 u(std::cos(angle), std::sin(angle));
      const auto hit = caster.Cast({.origin = r.cone.origin, .angle = angle}, r.cone.max_range);
      const double seen = hit ? hit->range : r.cone.max_range;
      for (double t = 0.0; t <= seen; t += step)
        mark(r.cone.origin + t * u, Observation::kVisible, t <= reach);
      if (!hit) continue;
      for (double t = seen + step; t <= seen + options.band; t += step)
        mark(r.cone.origin + t * u, Observation::kBehindSurface, false);
      hits[hit->region].push_back(r.cone.origin + seen * u);
    }
  }
  return hits;
}

}  // namespace

EvaluationRaster MakeSonarEvaluationRaster(const CellGrid& grid, const SceneTruth& truth,
                                           const Scene& scene, const SonarData& data,
                                           const ConeFanOptions& options, ConeWallHits* wall_hits) {
  // A step below a micrometre would mark each ray millions of times (a subnormal one forever).
  PRIORMAP_CHECK(options.rays_per_cone >= 2 && options.band >= 0.0 && std::isfinite(options.band) &&
                     (options.mark_step == 0.0 ||
                      (options.mark_step >= 1e-6 && std::isfinite(options.mark_step))),
                 "a cone's fan needs at least two rays, a finite band that is not negative, and a "
                 "mark step of 0 or at least 1e-6 m");
  EvaluationRaster raster = UnseenRaster(grid, truth);
  ConeWallHits hits = MarkConeFans(data, scene, options, &raster);
  if (wall_hits) *wall_hits = std::move(hits);
  return raster;
}

}  // namespace priormap::prf
