#pragma once
/// A polygonal coloring of a rectangular window (Paskin & Thrun, Sec. 1.3.1): the discontinuity
/// graph (interior vertices of degree 2, boundary vertices of degree 1 on the window's sides,
/// no crossing edges) and the colour of one anchor point. The colour of any point is the anchor's
/// flipped once per edge crossed on the way there.
///
/// The graph keeps a uniform grid index over its edges (each cell lists the edges crossing it),
/// which makes crossing tests, colour queries and line walks cost the cells they visit, and the
/// statistics the Arak measure needs (edge count, Σ|e|, Σ log|e|, Σ log sin φ_v), updated by each
/// edit in O(1).

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include <priormap/core/binary_io.hpp>
#include <priormap/core/polygon.hpp>
#include <priormap/core/segment.hpp>
#include <priormap/core/types.hpp>
#include <priormap/prf/arak.hpp>
#include <priormap/prf/cell_grid.hpp>
#include <priormap/prf/edit.hpp>
#include <priormap/prf/visit_marks.hpp>
#include <priormap/prf/window.hpp>

namespace priormap::prf {

enum class Colour : std::uint8_t { kWhite = 0, kBlack = 1 };
[[nodiscard]] inline Colour Flip(Colour c) {
  return c == Colour::kWhite ? Colour::kBlack : Colour::kWhite;
}

struct ColoringVertex {
  Vec2 position = Vec2::Zero();
  int side = kInterior;
  std::array<EdgeId, 2> edges{kNoEdge, kNoEdge};  // interior: both; boundary: edges[0]
  double log_sin = 0.0;                           ///< log sin φ_v, cached
  std::int32_t slot = -1;  ///< position in the interior or boundary list; -1 when free
};

/// Where a ray first meets an edge: origin + t·direction lies on `edge`.
struct RayHit {
  double t = 0.0;
  EdgeId edge = kNoEdge;
};

/// The t in (0, t_max] at which origin + t·direction meets the closed segment ab, if any. The
/// result does not depend on the order of a and b, so a hit computed on an edit's added edge
/// equals, bit for bit, the one computed on the edge once applied.
[[nodiscard]] std::optional<double> RaySegmentHit(const Vec2& origin, const Vec2& direction,
                                                  const Vec2& a, const Vec2& b, double t_max);

struct ColoringEdge {
  std::array<VertexId, 2> vertices{kNoVertex, kNoVertex};
  double length = 0.0;
  std::int32_t slot = -1;  ///< position in the edge list; -1 when free
};

/// Queries (CountCrossings, ColourAt, FirstHit, ForEachEdgeNear) are const but share a mutable
/// visit mark per edge: one Coloring must not be queried from several threads at once (each
/// chain owns its coloring).
class Coloring {
 public:
  /// The empty graph with the anchor (by default near the window's centre) of colour `anchor`.
  Coloring(const Window& window, double cell_size, Colour anchor = Colour::kWhite);

  [[nodiscard]] const Window& window() const { return window_; }
  [[nodiscard]] const CellGrid& grid() const { return grid_; }
  [[nodiscard]] const ColoringVertex& vertex(VertexId v) const { return vertices_[v]; }
  [[nodiscard]] const ColoringEdge& edge(EdgeId e) const { return edges_[e]; }
  [[nodiscard]] std::span<const VertexId> interior_vertices() const { return interior_; }
  [[nodiscard]] std::span<const VertexId> boundary_vertices() const { return boundary_; }
  [[nodiscard]] std::span<const EdgeId> edge_ids() const { return edge_list_; }
  [[nodiscard]] std::span<const EdgeId> cell_edges(int cell) const { return cells_[cell]; }
  [[nodiscard]] const ColoringStats& stats() const { return stats_; }
  [[nodiscard]] Vec2 anchor() const { return anchor_; }
  [[nodiscard]] Colour anchor_colour() const { return anchor_colour_; }

  /// The vertex at the other end of edge e from v.
  [[nodiscard]] VertexId Other(EdgeId e, VertexId v) const {
    const auto& ends = edges_[e].vertices;
    return ends[0] == v ? ends[1] : ends[0];
  }
  [[nodiscard]] Segment EdgeSegment(EdgeId e) const {
    return {vertices_[edges_[e].vertices[0]].position, vertices_[edges_[e].vertices[1]].position};
  }
  /// The k-th added edge of `edit`, with its ends where the edit puts them.
  [[nodiscard]] Segment AddedSegment(const Edit& edit, std::size_t k) const {
    const auto position = [&](VertexRef r) -> const Vec2& {
      return r.is_new() ? edit.new_vertices[static_cast<std::size_t>(r.new_index())].position
                        : vertices_[r.id()].position;
    };
    return {position(edit.added_edges[k][0]), position(edit.added_edges[k][1])};
  }

  /// log of the Arak measure's density with its potential (ArakLogDensity of stats()).
  [[nodiscard]] double LogArakDensity(double p) const { return ArakLogDensity(stats_, p); }

  /// Number of edges crossing the open segment (a, b).
  [[nodiscard]] int CountCrossings(const Vec2& a, const Vec2& b) const;
  [[nodiscard]] Colour ColourAt(const Vec2& q) const;
  /// The first edge that origin + t·direction meets for t in (0, t_max], if any; edges that
  /// `ignoring` removes are passed over (the walk of a beam in the state an edit would leave,
  /// whose added edges the caller tests itself).
  [[nodiscard]] std::optional<RayHit> FirstHit(const Vec2& origin, const Vec2& direction,
                                               double t_max, const Edit* ignoring = nullptr) const;

  /// Calls visit(edge) once for each edge indexed in a cell that segment ab passes through.
  template <class Visit>
  void ForEachEdgeNear(const Vec2& a, const Vec2& b, Visit&& visit) const {
    edge_marks_.NextRound();
    WalkCells(grid_, a, b, [&](int cell, double, double) {
      for (EdgeId e : cells_[cell]) {
        if (!edge_marks_.Mark(static_cast<std::size_t>(e))) continue;
        visit(e);
      }
      return true;
    });
  }

  /// Checks an edit against the rules of a valid coloring (vertices inside the window or on a
  /// side, degrees, no crossing, no duplicate or boundary-hugging edge, no zero angle) and
  /// computes its effect on the statistics. Returns false when the result would be invalid.
  [[nodiscard]] bool Evaluate(const Edit& edit, EditEffect* effect) const;
  /// Applies an edit that Evaluate accepted, with the effect it computed. Returns the ids the
  /// added edges received, in the order of edit.added_edges.
  SmallVector<EdgeId, 4> Apply(const Edit& edit, const EditEffect& effect);

  /// Rebuilds every invariant by brute force (degrees, crossings of all edge pairs, grid
  /// contents, statistics to `tolerance`); returns the first violation found. For tests and
  /// debug runs.
  [[nodiscard]] std::optional<std::string> FindInvariantViolation(double tolerance = 1e-9) const;

  /// The whole state, pools and free lists and the grid's lists in their order included, so
  /// that a loaded coloring behaves exactly as the saved one under the same moves (checkpoints).
  void Save(BinaryWriter& out) const;
  /// A coloring saved by Save for this window and cell size; BinaryFormatError when the data
  /// are not a valid coloring of it.
  [[nodiscard]] static Coloring Load(BinaryReader& in, const Window& window, double cell_size);

  /// A coloring given its discontinuity graph outright (a known map, the truth of a simulated
  /// scene): vertices with their sides (kInterior or the side they lie on), edges as pairs of
  /// vertex indices, and the colour at the anchor. Returns what is wrong when the graph is not a
  /// valid coloring of the window (degrees, crossings, vertices off the window or its sides).
  [[nodiscard]] static std::variant<Coloring, std::string> FromGraph(
      const Window& window, double cell_size, std::span<const NewVertex> vertices,
      std::span<const std::array<int, 2>> edges, Colour anchor);

  /// log sin φ of a vertex at `position` on `side` with the given neighbours (one for boundary
  /// vertices, two for interior ones); −inf for a zero angle.
  [[nodiscard]] double VertexLogSin(const Vec2& position, int side, const Vec2& first,
                                    const Vec2* second) const;

 private:
  VertexId AllocateVertex();
  EdgeId AllocateEdge();
  void IndexEdge(EdgeId e);
  void UnindexEdge(EdgeId e);
  void RemoveEdge(EdgeId e);
  void RemoveVertex(VertexId v);
  [[nodiscard]] bool CrossesAnything(const Vec2& a, const Vec2& b, VertexRef ra, VertexRef rb,
                                     const Edit& edit) const;

  Window window_;
  CellGrid grid_;
  Vec2 anchor_;
  Colour anchor_colour_;
  std::vector<ColoringVertex> vertices_;
  std::vector<ColoringEdge> edges_;
  std::vector<VertexId> free_vertices_;
  std::vector<EdgeId> free_edges_;
  std::vector<VertexId> interior_;
  std::vector<VertexId> boundary_;
  std::vector<EdgeId> edge_list_;
  std::vector<std::vector<EdgeId>> cells_;
  ColoringStats stats_;
  mutable VisitMarks edge_marks_;
};

/// True when closed segments ab and cd share a point (touching counts).
[[nodiscard]] bool SegmentsTouch(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d);

}  // namespace priormap::prf
