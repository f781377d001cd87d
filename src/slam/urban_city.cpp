// The city of the urban scenario (Parsley & Julier, Sec. VI, Fig. 3): square blocks on a street
// grid, each holding 1-4 rectangular buildings, and point beacons on the buildings' walls.
#include <array>
#include <cmath>
#include <numeric>

#include <priormap/core/check.hpp>

#include "urban_detail.hpp"

namespace priormap::slam::detail {
namespace {

// A block or a part of one; street[s] says whether side s (0 bottom, 1 right, 2 top, 3 left,
// the edge order of a counter-clockwise rectangle from its lower-left corner) is on a street.
struct Cell {
  Box2 box;
  std::array<bool, 4> street{true, true, true, true};
};

// Cuts `cell` across `axis` (0: a cut at constant x) at `fraction` of its extent; the new
// sides face each other, not a street.
std::array<Cell, 2> Split(const Cell& cell, int axis, double fraction) {
  Cell lo = cell;
  Cell hi = cell;
  const double cut = cell.box.min()(axis) + fraction * cell.box.sizes()(axis);
  lo.box.max()(axis) = cut;
  hi.box.min()(axis) = cut;
  lo.street[axis == 0 ? 1 : 2] = false;
  hi.street[axis == 0 ? 3 : 0] = false;
  return {lo, hi};
}

// 1-4 cells, equally likely: one building filling the block, two side by side, three (one
// half split again the other way) or four (both halves split, each at its own fraction).
std::vector<Cell> LayOutBlock(const Box2& block, Rng& rng) {
  const int count = 1 + static_cast<int>(rng.UniformIndex(4));
  const Cell whole{block};
  if (count == 1) return {whole};
  const int axis = static_cast<int>(rng.UniformIndex(2));
  const auto [a, b] = Split(whole, axis, rng.Uniform(0.35, 0.65));
  if (count == 2) return {a, b};
  const auto [a0, a1] = Split(a, 1 - axis, rng.Uniform(0.35, 0.65));
  if (count == 3) return {a0, a1, b};
  const auto [b0, b1] = Split(b, 1 - axis, rng.Uniform(0.35, 0.65));
  return {a0, a1, b0, b1};
}

// The building of a cell: set back from the street on street sides; on the other sides half a
// gap from its neighbour, and now and then a yard behind it, so sizes vary.
Polygon BuildingIn(const Cell& cell, const UrbanScenarioOptions& options, Rng& rng) {
  std::array<double, 4> inset{};
  for (int side = 0; side < 4; ++side) {
    if (cell.street[side]) {
      inset[side] = rng.Uniform(options.setback_min, options.setback_max);
    } else {
      const double depth = cell.box.sizes()(side % 2 == 0 ? 1 : 0);
      inset[side] = 0.5 * rng.Uniform(options.building_gap_min, options.building_gap_max);
      if (rng.Bernoulli(0.3)) inset[side] += rng.Uniform(0.0, 0.25 * depth);
    }
  }
  const double x0 = cell.box.min().x() + inset[3];
  const double x1 = cell.box.max().x() - inset[1];
  const double y0 = cell.box.min().y() + inset[0];
  const double y1 = cell.box.max().y() - inset[2];
  PRIORMAP_CHECK(x1 - x0 > 1.0 && y1 - y0 > 1.0, "a building of the urban scenario degenerated");
  return Polygon{{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}};
}

bool NearRoute(const Segment& wall, const std::vector<Se2>& poses, double distance) {
  // Every 4th pose (1.4 m apart at the default speed) is dense enough for a 30 m test.
  for (std::size_t k = 0; k < poses.size(); k += 4) {
    if (PointSegmentDistance(poses[k].translation(), wall) <= distance) return true;
  }
  return false;
}

bool InsideAnyBuilding(const std::vector<Polygon>& buildings, const Vec2& p) {
  for (const Polygon& building : buildings) {
    if (building.Contains(p)) return true;
  }
  return false;
}

}  // namespace

City BuildCity(const UrbanScenarioOptions& options, Rng& rng) {
  const double pitch = options.block_size + options.street_width;
  const double kerb = 0.5 * options.street_width;
  City city;
  for (int j = kCityStreetMinY; j < kCityStreetMaxY; ++j) {
    for (int i = kCityStreetMinX; i < kCityStreetMaxX; ++i) {
      const Box2 block(Vec2(i * pitch + kerb, j * pitch + kerb),
                       Vec2((i + 1) * pitch - kerb, (j + 1) * pitch - kerb));
      for (const Cell& cell : LayOutBlock(block, rng)) {
        const int b = static_cast<int>(city.buildings.size());
        city.buildings.push_back(BuildingIn(cell, options, rng));
        for (int side = 0; side < 4; ++side) {
          city.walls.push_back(city.buildings.back().Edge(side));
          city.wall_building.push_back(b);
          city.street_facing.push_back(cell.street[side]);
        }
      }
    }
  }
  return city;
}

std::vector<Beacon> PlaceBeacons(const City& city, const std::vector<Se2>& poses,
                                 const std::vector<int>& frame_steps,
                                 const UrbanScenarioOptions& options, Rng& rng) {
  // Candidates on the street-facing walls near the route: one 0.5 m from each end (building
  // corners are the landmarks one sees first coming up to and into a crossing, which keeps
  // every frame seeing some), random spacing in between.
  constexpr double kCornerMargin = 0.5;  // so that no beacon is on two walls at once
  std::vector<Beacon> candidates;
  for (std::size_t w = 0; w < city.walls.size(); ++w) {
    const Segment& wall = city.walls[w];
    if (!city.street_facing[w] || !NearRoute(wall, poses, options.max_range)) continue;
    const double length = wall.Length();
    if (length <= 2.0 * kCornerMargin) continue;
    const double last = length - kCornerMargin;
    std::vector<double> along{kCornerMargin};
    for (double s =
             kCornerMargin + rng.Uniform(options.beacon_spacing_min, options.beacon_spacing_max);
         s < last - options.beacon_spacing_min;
         s += rng.Uniform(options.beacon_spacing_min, options.beacon_spacing_max)) {
      along.push_back(s);
    }
    if (last - along.back() >= options.beacon_spacing_min) along.push_back(last);
    for (const double s : along) {
      candidates.push_back({wall.PointAt(s / length), static_cast<int>(w), true});
    }
  }
  // Kept where the route sees them at least once, as Bailey & Nieto's landmarks line the path:
  // the others would never enter the filter.
  std::vector<char> seen(candidates.size(), 0);
  for (const auto& frame : Visibility(city, poses, frame_steps, candidates, options)) {
    for (const VisibleBeacon& v : frame) seen[v.beacon] = 1;
  }
  std::vector<Beacon> beacons;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (seen[i]) beacons.push_back(candidates[i]);
  }
  // Exactly round(fraction n) beacons, chosen at random, move out into the street (lamp posts,
  // signs, bollards): near their wall but not on it. Street-facing walls look onto at least the
  // setback plus half a street, so the retry is only a guard.
  std::vector<int> order(beacons.size());
  std::iota(order.begin(), order.end(), 0);
  for (std::size_t k = order.size(); k > 1; --k) {
    std::swap(order[k - 1], order[rng.UniformIndex(k)]);
  }
  const auto off_wall = static_cast<std::size_t>(
      std::lround(options.off_wall_fraction * static_cast<double>(beacons.size())));
  for (std::size_t k = 0; k < off_wall; ++k) {
    Beacon& beacon = beacons[order[k]];
    const Vec2 normal = OutwardNormal(city.walls[beacon.wall]);
    bool placed = false;
    for (int attempt = 0; attempt < 20 && !placed; ++attempt) {
      const Vec2 p =
          beacon.position + rng.Uniform(options.off_wall_min, options.off_wall_max) * normal;
      placed = !InsideAnyBuilding(city.buildings, p);
      if (placed) beacon.position = p;
    }
    PRIORMAP_CHECK(placed, "no room for an off-wall beacon in front of its wall");
    beacon.on_wall = false;
  }
  return beacons;
}

}  // namespace priormap::slam::detail
