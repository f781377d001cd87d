#pragma once
/// An edit of a coloring's discontinuity graph, as every move of the sampler proposes it: remove
/// some edges (and vertices left without edges), add vertices and edges. Moving a vertex is
/// removing it and adding it elsewhere. The edit also names the region whose colour it reverses,
/// so the colour of the anchor point can follow.

#include <array>
#include <cstdint>
#include <utility>

#include <priormap/core/types.hpp>
#include <priormap/prf/arak.hpp>
#include <priormap/prf/small_vector.hpp>

namespace priormap::prf {

using VertexId = std::int32_t;
using EdgeId = std::int32_t;
inline constexpr VertexId kNoVertex = -1;
inline constexpr EdgeId kNoEdge = -1;
/// The side of an interior vertex.
inline constexpr int kInterior = -1;

/// An endpoint of an added edge: an existing vertex (id >= 0) or the k-th new vertex of the
/// edit (encoded as -1 - k).
struct VertexRef {
  std::int32_t value = 0;
  static VertexRef Existing(VertexId id) { return {id}; }
  static VertexRef New(int k) { return {-1 - k}; }
  [[nodiscard]] bool is_new() const { return value < 0; }
  [[nodiscard]] int new_index() const { return -1 - value; }
  [[nodiscard]] VertexId id() const { return value; }
  friend bool operator==(VertexRef a, VertexRef b) { return a.value == b.value; }
};

struct NewVertex {
  Vec2 position = Vec2::Zero();
  int side = kInterior;  ///< 0..3 for boundary vertices
};

struct Edit {
  SmallVector<EdgeId, 4> removed_edges;
  /// Vertices to delete; every edge of theirs must be in removed_edges.
  SmallVector<VertexId, 3> removed_vertices;
  SmallVector<NewVertex, 3> new_vertices;
  SmallVector<std::array<VertexRef, 2>, 4> added_edges;
  /// The closed polygon (even-odd rule) whose colour the edit reverses: bounded by the removed
  /// and added edges and, for boundary moves, the stretch of window boundary between them.
  SmallVector<Vec2, 8> flipped_region;

  [[nodiscard]] bool Removes(EdgeId e) const {
    for (EdgeId r : removed_edges)
      if (r == e) return true;
    return false;
  }

  void clear() {
    removed_edges.clear();
    removed_vertices.clear();
    new_vertices.clear();
    added_edges.clear();
    flipped_region.clear();
  }
};

/// What applying an edit changes in the statistics the Arak measure needs; computed by
/// Coloring::Evaluate and committed unchanged by Coloring::Apply.
struct EditEffect {
  ColoringStats delta;
  /// The new log sin φ of each vertex whose angle changes (existing or new).
  SmallVector<std::pair<VertexRef, double>, 10> vertex_log_sin;
  bool flips_anchor = false;
};

}  // namespace priormap::prf
