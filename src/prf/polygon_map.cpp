#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include <nlohmann/json.hpp>

#include <priormap/core/check.hpp>
#include <priormap/prf/polygon_map.hpp>

namespace priormap::prf {
namespace {

// The planar graph of the discontinuities and the window's sides, as half-edges. Sides are
// walked counter-clockwise only, so the outside of the window is never a face.
struct HalfEdgeGraph {
  std::vector<Vec2> nodes;
  std::vector<int> from, to;          // per half-edge
  std::vector<std::vector<int>> out;  // per node: outgoing half-edges
  std::vector<int> twin;              // -1 for side pieces
  std::vector<int> component;         // per node: its connected component's root
};

HalfEdgeGraph BuildGraph(const Coloring& coloring) {
  HalfEdgeGraph g;
  std::map<VertexId, int> node_of;
  const auto node = [&](VertexId v) {
    auto [it, inserted] = node_of.try_emplace(v, static_cast<int>(g.nodes.size()));
    if (inserted) g.nodes.push_back(coloring.vertex(v).position);
    return it->second;
  };
  const auto add = [&](int a, int b) {
    g.from.push_back(a);
    g.to.push_back(b);
    g.twin.push_back(-1);
    return static_cast<int>(g.from.size()) - 1;
  };
  for (EdgeId e : coloring.edge_ids()) {
    const auto [v0, v1] = coloring.edge(e).vertices;
    const int a = add(node(v0), node(v1));
    const int b = add(node(v1), node(v0));
    g.twin[static_cast<std::size_t>(a)] = b;
    g.twin[static_cast<std::size_t>(b)] = a;
  }
  // The window's perimeter: corners and boundary vertices in counter-clockwise order.
  const Window& w = coloring.window();
  std::vector<std::pair<double, int>> perimeter;
  for (int k = 0; k < kNumSides; ++k) {
    g.nodes.push_back(w.Corner(k));
    perimeter.emplace_back(w.CornerCoordinate(k), static_cast<int>(g.nodes.size()) - 1);
  }
  for (VertexId v : coloring.boundary_vertices())
    perimeter.emplace_back(w.CoordinateOf(coloring.vertex(v).position, coloring.vertex(v).side),
                           node(v));
  std::sort(perimeter.begin(), perimeter.end());
  for (std::size_t i = 0; i < perimeter.size(); ++i)
    add(perimeter[i].second, perimeter[(i + 1) % perimeter.size()].second);

  g.out.assign(g.nodes.size(), {});
  for (std::size_t h = 0; h < g.from.size(); ++h)
    g.out[static_cast<std::size_t>(g.from[h])].push_back(static_cast<int>(h));

  // Components (union-find over nodes), so that a hole is never matched with its own face.
  std::vector<int> parent(g.nodes.size());
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](int x) {
    while (parent[static_cast<std::size_t>(x)] != x)
      x = parent[static_cast<std::size_t>(x)] =
          parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
    return x;
  };
  for (std::size_t h = 0; h < g.from.size(); ++h)
    parent[static_cast<std::size_t>(find(g.from[h]))] = find(g.to[h]);
  for (std::size_t n = 0; n < g.nodes.size(); ++n) g.component.push_back(find(static_cast<int>(n)));
  return g;
}

// The half-edge that follows h around the face on h's left: at h's head, the first outgoing
// half-edge clockwise from the way back.
int NextAroundFace(const HalfEdgeGraph& g, int h) {
  const int v = g.to[static_cast<std::size_t>(h)];
  const Vec2& here = g.nodes[static_cast<std::size_t>(v)];
  const Vec2 back = g.nodes[static_cast<std::size_t>(g.from[static_cast<std::size_t>(h)])] - here;
  const double back_angle = std::atan2(back.y(), back.x());
  int best = -1;
  double best_turn = 0.0;
  for (int candidate : g.out[static_cast<std::size_t>(v)]) {
    if (candidate == g.twin[static_cast<std::size_t>(h)]) continue;
    const Vec2 d =
        g.nodes[static_cast<std::size_t>(g.to[static_cast<std::size_t>(candidate)])] - here;
    // Clockwise angle from `back` to d, in (0, 2π].
    double turn = back_angle - std::atan2(d.y(), d.x());
    while (turn <= 0.0) turn += 2.0 * std::numbers::pi;
    while (turn > 2.0 * std::numbers::pi) turn -= 2.0 * std::numbers::pi;
    if (best < 0 || turn < best_turn) {
      best = candidate;
      best_turn = turn;
    }
  }
  PRIORMAP_CHECK(best >= 0, "a face walk reached a dead end");
  return best;
}

}  // namespace

std::vector<MapFace> ExtractFaces(const Coloring& coloring) {
  const HalfEdgeGraph g = BuildGraph(coloring);
  std::vector<char> used(g.from.size(), 0);
  struct Cycle {
    std::vector<Vec2> ring;
    int component;
    Vec2 inside;  // a point just left of the first half-edge
  };
  std::vector<Cycle> faces, holes;
  for (std::size_t start = 0; start < g.from.size(); ++start) {
    if (used[start]) continue;
    Cycle cycle;
    cycle.component = g.component[static_cast<std::size_t>(g.from[start])];
    int h = static_cast<int>(start);
    do {
      used[static_cast<std::size_t>(h)] = 1;
      cycle.ring.push_back(g.nodes[static_cast<std::size_t>(g.from[static_cast<std::size_t>(h)])]);
      h = NextAroundFace(g, h);
    } while (h != static_cast<int>(start));
    const Vec2 a = cycle.ring[0];
    const Vec2 b = cycle.ring.size() > 1 ? cycle.ring[1] : a;
    cycle.inside = 0.5 * (a + b) + 1e-7 * Perp(b - a);
    (RingSignedArea(cycle.ring) > 0.0 ? faces : holes).push_back(std::move(cycle));
  }
  std::vector<MapFace> result(faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f) {
    result[f].outer = faces[f].ring;
    result[f].area = RingSignedArea(faces[f].ring);
    result[f].colour = coloring.ColourAt(faces[f].inside);
  }
  // Each hole (the outside of a closed polygon) belongs to the smallest face of another
  // component that holds it.
  for (Cycle& hole : holes) {
    int owner = -1;
    for (std::size_t f = 0; f < faces.size(); ++f) {
      if (faces[f].component == hole.component) continue;
      if (!RingContains(faces[f].ring, hole.ring[0])) continue;
      if (owner < 0 || result[f].area < result[static_cast<std::size_t>(owner)].area)
        owner = static_cast<int>(f);
    }
    PRIORMAP_CHECK(owner >= 0, "a closed polygon lies in no face");
    result[static_cast<std::size_t>(owner)].holes.push_back(std::move(hole.ring));
  }
  std::sort(result.begin(), result.end(),
            [](const MapFace& x, const MapFace& y) { return x.area > y.area; });
  return result;
}

std::string FacesToGeoJson(const std::vector<MapFace>& faces, const Window& window) {
  const auto ring = [](const std::vector<Vec2>& points) {
    nlohmann::json coordinates = nlohmann::json::array();
    for (const Vec2& p : points) coordinates.push_back({p.x(), p.y()});
    coordinates.push_back({points.front().x(), points.front().y()});  // closed, per RFC 7946
    return coordinates;
  };
  nlohmann::json features = nlohmann::json::array();
  for (const MapFace& face : faces) {
    if (face.colour != Colour::kBlack) continue;
    nlohmann::json rings = nlohmann::json::array();
    rings.push_back(ring(face.outer));
    for (const auto& hole : face.holes) rings.push_back(ring(hole));
    features.push_back({{"type", "Feature"},
                        {"properties", {{"occupied", true}}},
                        {"geometry", {{"type", "Polygon"}, {"coordinates", rings}}}});
  }
  const nlohmann::json collection = {
      {"type", "FeatureCollection"},
      {"properties",
       {{"window", {window.min.x(), window.min.y(), window.max.x(), window.max.y()}}}},
      {"features", features}};
  return collection.dump() + "\n";
}

std::size_t CompactMapBytes(const Coloring& coloring) {
  const std::size_t vertices =
      coloring.interior_vertices().size() + coloring.boundary_vertices().size();
  return 8 * vertices + 4 * coloring.edge_ids().size() + 8 + 1;
}

Eigen::MatrixXd ColourRaster(const Coloring& coloring, const CellGrid& grid) {
  Eigen::MatrixXd raster(grid.ny, grid.nx);
  const auto centre = [&](int ix, int iy) { return grid.Centre(iy * grid.nx + ix); };
  for (int iy = 0; iy < grid.ny; ++iy) {
    bool black = coloring.ColourAt(centre(0, iy)) == Colour::kBlack;
    raster(iy, 0) = black ? 1.0 : 0.0;
    for (int ix = 1; ix < grid.nx; ++ix) {
      if (coloring.CountCrossings(centre(ix - 1, iy), centre(ix, iy)) % 2 == 1) black = !black;
      raster(iy, ix) = black ? 1.0 : 0.0;
    }
  }
  return raster;
}

}  // namespace priormap::prf
