#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/prf/coloring.hpp>

namespace priormap::prf {
namespace {

constexpr double kMinusInf = -std::numeric_limits<double>::infinity();

bool OnSegmentBox(const Vec2& a, const Vec2& b, const Vec2& p) {
  return p.x() >= std::min(a.x(), b.x()) && p.x() <= std::max(a.x(), b.x()) &&
         p.y() >= std::min(a.y(), b.y()) && p.y() <= std::max(a.y(), b.y());
}

int Sign(double x) {
  return (x > 0.0) - (x < 0.0);
}

// True when the open segments cross at one point interior to both.
bool ProperlyCross(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const int o1 = Sign(Cross(b - a, c - a));
  const int o2 = Sign(Cross(b - a, d - a));
  const int o3 = Sign(Cross(d - c, a - c));
  const int o4 = Sign(Cross(d - c, b - c));
  return o1 * o2 < 0 && o3 * o4 < 0;
}

// On side `side`'s line and strictly between its corners, by raw coordinates (perimeter
// coordinates round, and a vertex must never sit on a corner).
bool OnSideStrictly(const Window& w, const Vec2& p, int side) {
  switch (side) {
    case 0:
      return p.y() == w.min.y() && p.x() > w.min.x() && p.x() < w.max.x();
    case 1:
      return p.x() == w.max.x() && p.y() > w.min.y() && p.y() < w.max.y();
    case 2:
      return p.y() == w.max.y() && p.x() > w.min.x() && p.x() < w.max.x();
    case 3:
      return p.x() == w.min.x() && p.y() > w.min.y() && p.y() < w.max.y();
    default:
      return false;
  }
}

}  // namespace

bool SegmentsTouch(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const int o1 = Sign(Cross(b - a, c - a));
  const int o2 = Sign(Cross(b - a, d - a));
  const int o3 = Sign(Cross(d - c, a - c));
  const int o4 = Sign(Cross(d - c, b - c));
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  return (o1 == 0 && OnSegmentBox(a, b, c)) || (o2 == 0 && OnSegmentBox(a, b, d)) ||
         (o3 == 0 && OnSegmentBox(c, d, a)) || (o4 == 0 && OnSegmentBox(c, d, b));
}

Coloring::Coloring(const Window& window, double cell_size, Colour anchor)
    : window_(window),
      grid_(CellGrid::Covering(window.min, window.max, cell_size)),
      // Off-centre by irrational fractions, so that no structure placed on round coordinates
      // (in tests, in scenes) passes through it.
      anchor_(window.min + Vec2((0.5 + 0.01 * std::numbers::sqrt2) * window.Width(),
                                (0.5 + 0.01 * std::numbers::pi) * window.Height())),
      anchor_colour_(anchor),
      cells_(static_cast<std::size_t>(grid_.NumCells())) {}

int Coloring::CountCrossings(const Vec2& a, const Vec2& b) const {
  int crossings = 0;
  ForEachEdgeNear(a, b, [&](EdgeId e) {
    const Segment s = EdgeSegment(e);
    if (ProperlyCross(a, b, s.a, s.b)) ++crossings;
  });
  return crossings;
}

Colour Coloring::ColourAt(const Vec2& q) const {
  return CountCrossings(anchor_, q) % 2 == 0 ? anchor_colour_ : Flip(anchor_colour_);
}

std::optional<double> RaySegmentHit(const Vec2& origin, const Vec2& direction, const Vec2& a,
                                    const Vec2& b, double t_max) {
  const bool ordered = a.x() < b.x() || (a.x() == b.x() && a.y() <= b.y());
  const Vec2& first = ordered ? a : b;
  const Vec2 along = (ordered ? b : a) - first;
  const double denominator = Cross(direction, along);
  if (denominator == 0.0) return std::nullopt;
  const Vec2 offset = first - origin;
  const double t = Cross(offset, along) / denominator;
  const double u = Cross(offset, direction) / denominator;
  if (t > 0.0 && t <= t_max && u >= 0.0 && u <= 1.0) return t;
  return std::nullopt;
}

std::optional<RayHit> Coloring::FirstHit(const Vec2& origin, const Vec2& direction, double t_max,
                                         const Edit* ignoring) const {
  edge_marks_.NextRound();
  RayHit best{.t = std::numeric_limits<double>::infinity(), .edge = kNoEdge};
  WalkCells(grid_, origin, origin + t_max * direction, [&](int cell, double, double t_exit) {
    for (EdgeId e : cells_[cell]) {
      if (!edge_marks_.Mark(static_cast<std::size_t>(e))) continue;
      if (ignoring != nullptr && ignoring->Removes(e)) continue;
      const Segment s = EdgeSegment(e);
      const auto t = RaySegmentHit(origin, direction, s.a, s.b, t_max);
      if (t && *t < best.t) best = {.t = *t, .edge = e};
    }
    // Every hit in later cells is farther than this cell's exit.
    return best.t > t_exit * t_max;
  });
  if (best.edge != kNoEdge) return best;
  return std::nullopt;
}

double Coloring::VertexLogSin(const Vec2& position, int side, const Vec2& first,
                              const Vec2* second) const {
  const Vec2 u = first - position;
  double sine;
  if (side == kInterior) {
    const Vec2 w = *second - position;
    sine = std::abs(Cross(u, w)) / (u.norm() * w.norm());
  } else {
    sine = std::abs(Cross(u, window_.SideDirection(side))) / u.norm();
  }
  return sine > 0.0 ? std::log(sine) : kMinusInf;
}

// ---- storage ------------------------------------------------------------------------------

VertexId Coloring::AllocateVertex() {
  if (!free_vertices_.empty()) {
    const VertexId v = free_vertices_.back();
    free_vertices_.pop_back();
    return v;
  }
  vertices_.emplace_back();
  return static_cast<VertexId>(vertices_.size() - 1);
}

EdgeId Coloring::AllocateEdge() {
  if (!free_edges_.empty()) {
    const EdgeId e = free_edges_.back();
    free_edges_.pop_back();
    return e;
  }
  edges_.emplace_back();
  edge_marks_.resize(edges_.size());
  return static_cast<EdgeId>(edges_.size() - 1);
}

void Coloring::IndexEdge(EdgeId e) {
  const Segment s = EdgeSegment(e);
  WalkCells(grid_, s.a, s.b, [&](int cell, double, double) {
    cells_[cell].push_back(e);
    return true;
  });
}

void Coloring::UnindexEdge(EdgeId e) {
  const Segment s = EdgeSegment(e);
  WalkCells(grid_, s.a, s.b, [&](int cell, double, double) {
    auto& list = cells_[cell];
    const auto it = std::find(list.begin(), list.end(), e);
    PRIORMAP_DCHECK(it != list.end(), "edge missing from a cell of its walk");
    if (it != list.end()) {
      *it = list.back();
      list.pop_back();
    }
    return true;
  });
}

void Coloring::RemoveEdge(EdgeId e) {
  UnindexEdge(e);
  ColoringEdge& edge = edges_[e];
  for (VertexId v : edge.vertices)
    for (EdgeId& slot : vertices_[v].edges)
      if (slot == e) slot = kNoEdge;
  const std::int32_t slot = edge.slot;
  edge_list_[slot] = edge_list_.back();
  edges_[edge_list_[slot]].slot = slot;
  edge_list_.pop_back();
  edge = ColoringEdge{};
  free_edges_.push_back(e);
}

void Coloring::RemoveVertex(VertexId v) {
  ColoringVertex& vertex = vertices_[v];
  auto& list = vertex.side == kInterior ? interior_ : boundary_;
  const std::int32_t slot = vertex.slot;
  list[slot] = list.back();
  vertices_[list[slot]].slot = slot;
  list.pop_back();
  vertex = ColoringVertex{};
  free_vertices_.push_back(v);
}

// ---- edits --------------------------------------------------------------------------------

bool Coloring::CrossesAnything(const Vec2& a, const Vec2& b, VertexRef ra, VertexRef rb,
                               const Edit& edit) const {
  bool crosses = false;
  edge_marks_.NextRound();
  WalkCells(grid_, a, b, [&](int cell, double, double) {
    for (EdgeId e : cells_[cell]) {
      if (!edge_marks_.Mark(static_cast<std::size_t>(e))) continue;
      if (edit.Removes(e)) continue;
      const auto& ends = edges_[e].vertices;
      // Edges sharing an endpoint meet only there unless collinear, which the zero angle at
      // that vertex rejects.
      const auto shares = [&](VertexRef r) {
        return !r.is_new() && (r.id() == ends[0] || r.id() == ends[1]);
      };
      if (shares(ra) || shares(rb)) continue;
      const Segment s = EdgeSegment(e);
      if (SegmentsTouch(a, b, s.a, s.b)) {
        crosses = true;
        return false;
      }
    }
    return true;
  });
  return crosses;
}

bool Coloring::Evaluate(const Edit& edit, EditEffect* effect) const {
  *effect = EditEffect{};
  const Window& w = window_;
  SmallVector<Vec2, 3> new_positions;
  for (const NewVertex& nv : edit.new_vertices) {
    const Vec2& p = nv.position;
    if (nv.side == kInterior) {
      if (!w.ContainsInterior(p)) return false;
    } else {
      if (!OnSideStrictly(w, p, nv.side)) return false;
    }
    new_positions.push_back(p);
  }
  const auto position = [&](VertexRef r) -> const Vec2& {
    return r.is_new() ? new_positions[static_cast<std::size_t>(r.new_index())]
                      : vertices_[r.id()].position;
  };
  const auto side = [&](VertexRef r) {
    return r.is_new() ? edit.new_vertices[static_cast<std::size_t>(r.new_index())].side
                      : vertices_[r.id()].side;
  };

  // Added edges: proper, not along a side, not duplicated, crossing nothing.
  const std::size_t n_added = edit.added_edges.size();
  for (std::size_t i = 0; i < n_added; ++i) {
    const auto [ra, rb] = edit.added_edges[i];
    if (ra == rb) return false;
    const int sa = side(ra);
    if (sa != kInterior && sa == side(rb)) return false;
    const Vec2& a = position(ra);
    const Vec2& b = position(rb);
    if (a == b) return false;
    if (!ra.is_new() && !rb.is_new()) {
      for (EdgeId e : vertices_[ra.id()].edges)
        if (e != kNoEdge && !edit.Removes(e) && Other(e, ra.id()) == rb.id()) return false;
    }
    for (std::size_t j = 0; j < i; ++j) {
      const auto [rc, rd] = edit.added_edges[j];
      const bool same = (ra == rc && rb == rd) || (ra == rd && rb == rc);
      if (same) return false;
      if (ra == rc || ra == rd || rb == rc || rb == rd) continue;
      if (SegmentsTouch(a, b, position(rc), position(rd))) return false;
    }
    if (CrossesAnything(a, b, ra, rb, edit)) return false;
  }

  // Statistics of the edges.
  for (EdgeId e : edit.removed_edges) {
    const Segment s = EdgeSegment(e);
    effect->delta.AddEdge(s.b - s.a, -1.0);
  }
  for (const auto& [ra, rb] : edit.added_edges)
    effect->delta.AddEdge(position(rb) - position(ra), 1.0);

  // Angles: every vertex that loses or gains an edge, and the new ones.
  for (VertexId v : edit.removed_vertices) effect->delta.sum_log_sin -= vertices_[v].log_sin;
  SmallVector<VertexRef, 10> affected;
  const auto note = [&](VertexRef r) {
    if (!r.is_new() && std::find(edit.removed_vertices.begin(), edit.removed_vertices.end(),
                                 r.id()) != edit.removed_vertices.end())
      return;
    if (std::find(affected.begin(), affected.end(), r) == affected.end()) affected.push_back(r);
  };
  for (EdgeId e : edit.removed_edges)
    for (VertexId v : edges_[e].vertices) note(VertexRef::Existing(v));
  for (const auto& [ra, rb] : edit.added_edges) {
    note(ra);
    note(rb);
  }
  for (VertexRef r : affected) {
    SmallVector<Vec2, 3> neighbours;
    if (!r.is_new()) {
      for (EdgeId e : vertices_[r.id()].edges)
        if (e != kNoEdge && !edit.Removes(e))
          neighbours.push_back(vertices_[Other(e, r.id())].position);
    }
    for (const auto& [ra, rb] : edit.added_edges) {
      if (ra == r) neighbours.push_back(position(rb));
      if (rb == r) neighbours.push_back(position(ra));
    }
    const int s = side(r);
    const std::size_t degree = s == kInterior ? 2 : 1;
    PRIORMAP_DCHECK(neighbours.size() == degree, "an edit left a vertex with the wrong degree");
    if (neighbours.size() != degree) return false;
    const double log_sin =
        VertexLogSin(position(r), s, neighbours[0], degree == 2 ? &neighbours[1] : nullptr);
    if (!std::isfinite(log_sin)) return false;
    if (!r.is_new()) effect->delta.sum_log_sin -= vertices_[r.id()].log_sin;
    effect->delta.sum_log_sin += log_sin;
    effect->vertex_log_sin.push_back({r, log_sin});
  }
  effect->flips_anchor =
      RingContains({edit.flipped_region.begin(), edit.flipped_region.size()}, anchor_);
  return true;
}

SmallVector<EdgeId, 4> Coloring::Apply(const Edit& edit, const EditEffect& effect) {
  for (EdgeId e : edit.removed_edges) RemoveEdge(e);
  for (VertexId v : edit.removed_vertices) {
    PRIORMAP_DCHECK(vertices_[v].edges[0] == kNoEdge && vertices_[v].edges[1] == kNoEdge,
                    "a removed vertex kept an edge");
    RemoveVertex(v);
  }
  SmallVector<VertexId, 3> created;
  for (const NewVertex& nv : edit.new_vertices) {
    const VertexId v = AllocateVertex();
    ColoringVertex& vertex = vertices_[v];
    vertex.position = nv.position;
    vertex.side = nv.side;
    auto& list = nv.side == kInterior ? interior_ : boundary_;
    vertex.slot = static_cast<std::int32_t>(list.size());
    list.push_back(v);
    created.push_back(v);
  }
  const auto id = [&](VertexRef r) {
    return r.is_new() ? created[static_cast<std::size_t>(r.new_index())] : r.id();
  };
  SmallVector<EdgeId, 4> added;
  for (const auto& [ra, rb] : edit.added_edges) {
    const EdgeId e = AllocateEdge();
    added.push_back(e);
    ColoringEdge& edge = edges_[e];
    edge.vertices = {id(ra), id(rb)};
    edge.length =
        (vertices_[edge.vertices[0]].position - vertices_[edge.vertices[1]].position).norm();
    edge.slot = static_cast<std::int32_t>(edge_list_.size());
    edge_list_.push_back(e);
    for (VertexId v : edge.vertices) {
      auto& slots = vertices_[v].edges;
      const std::size_t degree = vertices_[v].side == kInterior ? 2 : 1;
      std::size_t k = 0;
      while (k < degree && slots[k] != kNoEdge) ++k;
      PRIORMAP_CHECK(k < degree, "an added edge exceeds a vertex's degree");
      slots[k] = e;
    }
    IndexEdge(e);
  }
  for (const auto& [r, log_sin] : effect.vertex_log_sin) vertices_[id(r)].log_sin = log_sin;
  stats_ += effect.delta;
  if (effect.flips_anchor) anchor_colour_ = Flip(anchor_colour_);
  return added;
}

// ---- checks -------------------------------------------------------------------------------

std::optional<std::string> Coloring::FindInvariantViolation(double tolerance) const {
  ColoringStats recomputed;
  for (std::size_t i = 0; i < edge_list_.size(); ++i) {
    const EdgeId e = edge_list_[i];
    if (edges_[e].slot != static_cast<std::int32_t>(i)) return fmt::format("edge {} slot", e);
    const Segment s = EdgeSegment(e);
    if (std::abs(s.Length() - edges_[e].length) > tolerance)
      return fmt::format("edge {} cached length", e);
    const auto [v0, v1] = edges_[e].vertices;
    for (VertexId v : {v0, v1})
      if (vertices_[v].edges[0] != e && vertices_[v].edges[1] != e)
        return fmt::format("edge {} is not listed by its vertex {}", e, v);
    if (vertices_[v0].side != kInterior && vertices_[v0].side == vertices_[v1].side)
      return fmt::format("edge {} runs along side {}", e, vertices_[v0].side);
    recomputed.AddEdge(s.b - s.a, 1.0);
    bool indexed = true;
    WalkCells(grid_, s.a, s.b, [&](int cell, double, double) {
      indexed =
          indexed && std::find(cells_[cell].begin(), cells_[cell].end(), e) != cells_[cell].end();
      return true;
    });
    if (!indexed) return fmt::format("edge {} missing from the grid", e);
    for (std::size_t j = 0; j < i; ++j) {
      const EdgeId f = edge_list_[j];
      const auto& a = edges_[e].vertices;
      const auto& b = edges_[f].vertices;
      if ((a[0] == b[0] && a[1] == b[1]) || (a[0] == b[1] && a[1] == b[0]))
        return fmt::format("edges {} and {} join the same vertices", e, f);
      if (a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1]) continue;
      const Segment t = EdgeSegment(f);
      if (SegmentsTouch(s.a, s.b, t.a, t.b)) return fmt::format("edges {} and {} cross", e, f);
    }
  }
  std::size_t cell_entries = 0;
  for (const auto& cell : cells_) cell_entries += cell.size();
  std::size_t walk_entries = 0;
  for (EdgeId e : edge_list_) {
    const Segment s = EdgeSegment(e);
    WalkCells(grid_, s.a, s.b, [&](int, double, double) {
      ++walk_entries;
      return true;
    });
  }
  if (cell_entries != walk_entries) return "the grid holds stale entries";

  for (int kind = 0; kind < 2; ++kind) {
    const auto& list = kind == 0 ? interior_ : boundary_;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const VertexId v = list[i];
      const ColoringVertex& vertex = vertices_[v];
      if (vertex.slot != static_cast<std::int32_t>(i)) return fmt::format("vertex {} slot", v);
      if ((kind == 0) != (vertex.side == kInterior)) return fmt::format("vertex {} list", v);
      const std::size_t degree = vertex.side == kInterior ? 2 : 1;
      SmallVector<Vec2, 2> neighbours;
      for (std::size_t k = 0; k < 2; ++k) {
        const EdgeId e = vertex.edges[k];
        if (k >= degree) {
          if (e != kNoEdge) return fmt::format("vertex {} has an extra edge", v);
          continue;
        }
        if (e == kNoEdge || edges_[e].slot < 0)
          return fmt::format("vertex {} has degree < {}", v, degree);
        if (edges_[e].vertices[0] != v && edges_[e].vertices[1] != v)
          return fmt::format("vertex {} lists edge {} that does not end at it", v, e);
        neighbours.push_back(vertices_[Other(e, v)].position);
      }
      if (vertex.side == kInterior) {
        if (!window_.ContainsInterior(vertex.position))
          return fmt::format("interior vertex {} outside the window", v);
      } else {
        if (!OnSideStrictly(window_, vertex.position, vertex.side))
          return fmt::format("boundary vertex {} off its side", v);
      }
      const double log_sin = VertexLogSin(vertex.position, vertex.side, neighbours[0],
                                          degree == 2 ? &neighbours[1] : nullptr);
      if (std::abs(log_sin - vertex.log_sin) > tolerance)
        return fmt::format("vertex {} cached angle", v);
      recomputed.sum_log_sin += log_sin;
    }
  }
  if (recomputed.edges != stats_.edges ||
      std::abs(recomputed.total_length - stats_.total_length) > tolerance ||
      std::abs(recomputed.sum_log_length - stats_.sum_log_length) > tolerance ||
      std::abs(recomputed.sum_log_sin - stats_.sum_log_sin) > tolerance ||
      std::abs(recomputed.sum_cos4 - stats_.sum_cos4) > tolerance ||
      std::abs(recomputed.sum_sin4 - stats_.sum_sin4) > tolerance)
    return "cached statistics differ from recomputation";
  return std::nullopt;
}

void Coloring::Save(BinaryWriter& out) const {
  out.Put(window_.min.x());
  out.Put(window_.min.y());
  out.Put(window_.max.x());
  out.Put(window_.max.y());
  out.Put(grid_.cell.x());
  out.Put(grid_.cell.y());
  out.Put(anchor_colour_);
  out.Put<std::uint64_t>(vertices_.size());
  for (const ColoringVertex& v : vertices_) {
    out.Put(v.position.x());
    out.Put(v.position.y());
    out.Put<std::int32_t>(v.side);
    out.Put(v.edges[0]);
    out.Put(v.edges[1]);
    out.Put(v.log_sin);
    out.Put(v.slot);
  }
  out.Put<std::uint64_t>(edges_.size());
  for (const ColoringEdge& e : edges_) {
    out.Put(e.vertices[0]);
    out.Put(e.vertices[1]);
    out.Put(e.length);
    out.Put(e.slot);
  }
  out.PutVector(free_vertices_);
  out.PutVector(free_edges_);
  out.PutVector(interior_);
  out.PutVector(boundary_);
  out.PutVector(edge_list_);
  for (const auto& cell : cells_) out.PutVector(cell);
  out.Put<std::int32_t>(stats_.edges);
  out.Put(stats_.total_length);
  out.Put(stats_.sum_log_length);
  out.Put(stats_.sum_log_sin);
  out.Put(stats_.sum_cos4);
  out.Put(stats_.sum_sin4);
}

Coloring Coloring::Load(BinaryReader& in, const Window& window, double cell_size) {
  Coloring c(window, cell_size);
  const std::array<double, 6> frame{window.min.x(), window.min.y(),   window.max.x(),
                                    window.max.y(), c.grid_.cell.x(), c.grid_.cell.y()};
  for (const double expected : frame)
    if (std::bit_cast<std::uint64_t>(in.Get<double>()) != std::bit_cast<std::uint64_t>(expected))
      in.Fail("a coloring of another window or cell size");
  c.anchor_colour_ = in.Get<Colour>();
  if (c.anchor_colour_ != Colour::kBlack && c.anchor_colour_ != Colour::kWhite)
    in.Fail("an anchor colour that is neither black nor white");
  // The bytes each element takes bound the counts by what is left, before anything is allocated.
  constexpr std::size_t kVertexBytes = 2 * 8 + 3 * 4 + 8 + 4;
  constexpr std::size_t kEdgeBytes = 2 * 4 + 8 + 4;
  // And a cap far above any map (the validity check below is quadratic in the edges).
  constexpr std::uint64_t kMaxElements = std::uint64_t{1} << 17;
  c.vertices_.resize(in.GetCount(
      std::min<std::uint64_t>(kMaxElements, in.remaining() / kVertexBytes), "vertices"));
  for (ColoringVertex& v : c.vertices_) {
    const double x = in.Get<double>();
    v.position = Vec2(x, in.Get<double>());
    v.side = in.Get<std::int32_t>();
    v.edges[0] = in.Get<EdgeId>();
    v.edges[1] = in.Get<EdgeId>();
    v.log_sin = in.Get<double>();
    v.slot = in.Get<std::int32_t>();
  }
  c.edges_.resize(
      in.GetCount(std::min<std::uint64_t>(kMaxElements, in.remaining() / kEdgeBytes), "edges"));
  for (ColoringEdge& e : c.edges_) {
    e.vertices[0] = in.Get<VertexId>();
    e.vertices[1] = in.Get<VertexId>();
    e.length = in.Get<double>();
    e.slot = in.Get<std::int32_t>();
  }
  c.free_vertices_ = in.GetVector<VertexId>();
  c.free_edges_ = in.GetVector<EdgeId>();
  c.interior_ = in.GetVector<VertexId>();
  c.boundary_ = in.GetVector<VertexId>();
  c.edge_list_ = in.GetVector<EdgeId>();
  for (auto& cell : c.cells_) cell = in.GetVector<EdgeId>();
  c.stats_.edges = in.Get<std::int32_t>();
  c.stats_.total_length = in.Get<double>();
  c.stats_.sum_log_length = in.Get<double>();
  c.stats_.sum_log_sin = in.Get<double>();
  c.stats_.sum_cos4 = in.Get<double>();
  c.stats_.sum_sin4 = in.Get<double>();
  c.edge_marks_.resize(c.edges_.size());
  bool finite = std::isfinite(c.stats_.total_length) && std::isfinite(c.stats_.sum_log_length) &&
                std::isfinite(c.stats_.sum_log_sin) && std::isfinite(c.stats_.sum_cos4) &&
                std::isfinite(c.stats_.sum_sin4);
  for (const ColoringVertex& v : c.vertices_)
    finite = finite && v.position.allFinite() && std::isfinite(v.log_sin);
  for (const ColoringEdge& e : c.edges_) finite = finite && std::isfinite(e.length);
  if (!finite) in.Fail("a number that is not finite");

  // Ids in range and every pooled element either listed once or free, before the brute-force
  // check below (which trusts the ids) looks at the geometry.
  const auto n_vertices = static_cast<std::int64_t>(c.vertices_.size());
  const auto n_edges = static_cast<std::int64_t>(c.edges_.size());
  const auto valid_edge = [&](EdgeId e) { return e >= 0 && e < n_edges; };
  const auto valid_vertex = [&](VertexId v) { return v >= 0 && v < n_vertices; };
  std::vector<std::uint8_t> seen_vertex(c.vertices_.size(), 0);
  std::vector<std::uint8_t> seen_edge(c.edges_.size(), 0);
  for (const auto* list : {&c.interior_, &c.boundary_, &c.free_vertices_})
    for (const VertexId v : *list)
      if (!valid_vertex(v) || seen_vertex[static_cast<std::size_t>(v)]++)
        in.Fail("a vertex list with an unknown or repeated vertex");
  for (const auto* list : {&c.edge_list_, &c.free_edges_})
    for (const EdgeId e : *list)
      if (!valid_edge(e) || seen_edge[static_cast<std::size_t>(e)]++)
        in.Fail("an edge list with an unknown or repeated edge");
  if (c.interior_.size() + c.boundary_.size() + c.free_vertices_.size() != c.vertices_.size() ||
      c.edge_list_.size() + c.free_edges_.size() != c.edges_.size())
    in.Fail("vertices or edges neither in use nor free");
  for (const VertexId v : c.free_vertices_)
    if (c.vertices_[static_cast<std::size_t>(v)].slot != -1) in.Fail("a free vertex in use");
  for (const EdgeId e : c.free_edges_)
    if (c.edges_[static_cast<std::size_t>(e)].slot != -1) in.Fail("a free edge in use");
  for (const auto* list : {&c.interior_, &c.boundary_}) {
    for (const VertexId v : *list) {
      const ColoringVertex& vertex = c.vertices_[static_cast<std::size_t>(v)];
      if (vertex.side < kInterior || vertex.side > 3) in.Fail("a vertex on no side");
      if (!(vertex.position.x() >= window.min.x() && vertex.position.x() <= window.max.x() &&
            vertex.position.y() >= window.min.y() && vertex.position.y() <= window.max.y()))
        in.Fail("a vertex outside the window");
      for (const EdgeId e : vertex.edges)
        if (e != kNoEdge && (!valid_edge(e) || c.edges_[static_cast<std::size_t>(e)].slot < 0))
          in.Fail("a vertex with an unknown edge");
    }
  }
  for (const EdgeId e : c.edge_list_)
    for (const VertexId v : c.edges_[static_cast<std::size_t>(e)].vertices)
      if (!valid_vertex(v) || c.vertices_[static_cast<std::size_t>(v)].slot < 0)
        in.Fail("an edge with an unknown vertex");
  for (const auto& cell : c.cells_)
    for (const EdgeId e : cell)
      if (!valid_edge(e)) in.Fail("a grid cell with an unknown edge");
  if (const auto violation = c.FindInvariantViolation(1e-6))
    in.Fail("an invalid coloring (" + *violation + ")");
  return c;
}

std::variant<Coloring, std::string> Coloring::FromGraph(const Window& window, double cell_size,
                                                        std::span<const NewVertex> vertices,
                                                        std::span<const std::array<int, 2>> edges,
                                                        Colour anchor) {
  Coloring c(window, cell_size, anchor);
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const NewVertex& nv = vertices[i];
    const bool on_side = nv.side >= 0 && nv.side < kNumSides;
    if (nv.side != kInterior && !on_side)
      return fmt::format("vertex {} has side {}, not -1 (interior) or 0..3", i, nv.side);
    if (!nv.position.allFinite() || (nv.side == kInterior && !window.ContainsInterior(nv.position)))
      return fmt::format("interior vertex {} at ({}, {}) is not inside the window", i,
                         nv.position.x(), nv.position.y());
    const VertexId v = c.AllocateVertex();
    ColoringVertex& vertex = c.vertices_[v];
    vertex.position = nv.position;
    vertex.side = nv.side;
    auto& list = nv.side == kInterior ? c.interior_ : c.boundary_;
    vertex.slot = static_cast<std::int32_t>(list.size());
    list.push_back(v);
  }
  const auto n = static_cast<int>(vertices.size());
  for (const auto& [a, b] : edges) {
    if (a < 0 || b < 0 || a >= n || b >= n || a == b)
      return fmt::format("edge ({}, {}) does not join two of the {} vertices", a, b, n);
    const EdgeId e = c.AllocateEdge();
    ColoringEdge& edge = c.edges_[e];
    edge.vertices = {a, b};
    edge.length = (vertices[static_cast<std::size_t>(a)].position -
                   vertices[static_cast<std::size_t>(b)].position)
                      .norm();
    edge.slot = static_cast<std::int32_t>(c.edge_list_.size());
    c.edge_list_.push_back(e);
    for (const VertexId v : edge.vertices) {
      auto& slots = c.vertices_[v].edges;
      const std::size_t degree = c.vertices_[v].side == kInterior ? 2 : 1;
      std::size_t k = 0;
      while (k < degree && slots[k] != kNoEdge) ++k;
      if (k == degree)
        return fmt::format("vertex {} has more than {} edge{}", v, degree, degree > 1 ? "s" : "");
      slots[k] = e;
    }
    c.IndexEdge(e);
    const Segment segment = c.EdgeSegment(e);
    c.stats_.AddEdge(segment.b - segment.a, 1.0);
    // The anchor's colour says which side of the edges through it is which: on an edge it would
    // say nothing.
    if (PointSegmentDistance(c.anchor_, segment) <= 1e-9)
      return fmt::format(
          "edge ({}, {}) passes through the anchor at ({}, {}), whose colour would "
          "then be undefined",
          a, b, c.anchor_.x(), c.anchor_.y());
  }
  for (const VertexId v : c.interior_) {
    ColoringVertex& vertex = c.vertices_[v];
    if (vertex.edges[1] == kNoEdge)
      return fmt::format("interior vertex {} has fewer than two edges", v);
    const Vec2 first = c.vertices_[c.Other(vertex.edges[0], v)].position;
    const Vec2 second = c.vertices_[c.Other(vertex.edges[1], v)].position;
    vertex.log_sin = c.VertexLogSin(vertex.position, kInterior, first, &second);
  }
  for (const VertexId v : c.boundary_) {
    ColoringVertex& vertex = c.vertices_[v];
    if (vertex.edges[0] == kNoEdge) return fmt::format("boundary vertex {} has no edge", v);
    const Vec2 first = c.vertices_[c.Other(vertex.edges[0], v)].position;
    vertex.log_sin = c.VertexLogSin(vertex.position, vertex.side, first, nullptr);
  }
  for (const std::span<const VertexId> list : {c.interior_, c.boundary_})
    for (const VertexId v : list) {
      if (!std::isfinite(c.vertices_[v].log_sin))
        return fmt::format("vertex {} has a zero angle", v);
      c.stats_.sum_log_sin += c.vertices_[v].log_sin;
    }
  if (const auto violation = c.FindInvariantViolation(1e-6)) return *violation;
  return c;
}

}  // namespace priormap::prf
