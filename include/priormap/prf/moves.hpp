#pragma once
/// The move types of the sampler (Paskin & Thrun, Fig. 2; Clifford & Nicholls 1994) and their
/// counters. A move *kind* is chosen by weight; births and deaths of a kind then split evenly.
/// docs/prf-moves.md derives each proposal density and Hastings ratio.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace priormap::prf {

enum class MoveKind : int {
  kTriangle,          // interior triangle birth/death (Fig. 2a)
  kBoundaryTriangle,  // boundary triangle birth/death: a bend attached to one side (Fig. 2b)
  kCorner,            // corner edge birth/death: an edge cutting off a window corner (Fig. 2c)
  kVertex,            // vertex birth/death on an edge (Fig. 2d)
  kInteriorMove,      // interior vertex moves (Fig. 2e)
  kBoundaryMove,      // boundary vertex moves along the boundary (Fig. 2f)
  kRecolor,           // recolor quadrilateral, two edges drawn uniformly (Fig. 2h)
  kLocalRecolor,      // recolor with the second edge from the first's grid cells (Fig. 2i)
  kSlide,             // slide a vertex along one of its edges (Fig. 2j)
  kGuidedTriangle,    // triangle birth/death with a data-guided birth (birth_guide.hpp)
  kEdgeShift,         // both ends of an edge between interior vertices moved by one step
  kVertexJump,        // an interior vertex moved next to a neighbour's other neighbour, or far
  kVertexPair,        // two adjacent vertices born on an edge, or cut off along a new edge
};
inline constexpr int kNumMoveKinds = 13;
/// The kinds there were before vertex jumps: what a checkpoint of a run without them holds.
inline constexpr int kNumMoveKindsBeforeJumps = 11;

enum class MoveType : int {
  kTriangleBirth,
  kTriangleDeath,
  kBoundaryTriangleBirth,
  kBoundaryTriangleDeath,
  kCornerBirth,
  kCornerDeath,
  kVertexBirth,
  kVertexDeath,
  kInteriorMove,
  kBoundaryMove,
  kRecolor,
  kLocalRecolor,
  kSlide,
  kGuidedTriangleBirth,
  kGuidedTriangleDeath,
  kEdgeShift,
  kVertexJump,
  kVertexPairBirth,
  kVertexPairDeath,
};
inline constexpr int kNumMoveTypes = 19;
/// The types there were before vertex jumps: what a checkpoint of a run without them holds.
inline constexpr int kNumMoveTypesBeforeJumps = 16;
/// The types there were before vertex pairs.
inline constexpr int kNumMoveTypesBeforePairs = 17;

/// snake_case names, as in summary.json and on the command line ("triangle_birth", ...).
[[nodiscard]] std::string_view MoveTypeName(MoveType type);
[[nodiscard]] std::string_view MoveKindName(MoveKind kind);
[[nodiscard]] std::optional<MoveKind> ParseMoveKind(std::string_view name);

struct MoveCounter {
  std::uint64_t proposed = 0;
  std::uint64_t invalid = 0;  ///< the proposal left the space of valid colorings (or had density 0)
  std::uint64_t accepted = 0;
  /// Rejected by the delayed acceptance's first stage, on the screening data alone
  /// (SamplerOptions::screen_stride), before the full data were evaluated.
  std::uint64_t screened_out = 0;

  MoveCounter& operator+=(const MoveCounter& other) {
    proposed += other.proposed;
    invalid += other.invalid;
    accepted += other.accepted;
    screened_out += other.screened_out;
    return *this;
  }
  /// accepted / proposed, 0 before any proposal.
  [[nodiscard]] double AcceptanceRate() const {
    return proposed ? static_cast<double>(accepted) / static_cast<double>(proposed) : 0.0;
  }
};
using MoveCounters = std::array<MoveCounter, kNumMoveTypes>;

/// Adds `more`'s counts to `total`, move type by move type (several chains' counters together).
inline void AddCounters(MoveCounters* total, const MoveCounters& more) {
  for (std::size_t t = 0; t < total->size(); ++t) (*total)[t] += more[t];
}

/// The counts of all move types together.
[[nodiscard]] inline MoveCounter Total(const MoveCounters& counters) {
  MoveCounter total;
  for (const MoveCounter& c : counters) total += c;
  return total;
}

/// Relative weight of each move kind; zero switches a kind off. Guided triangles need a guide
/// (SamplerOptions::guide); without one, or with one that has no points, their weight counts as
/// zero.
struct MoveWeights {
  /// Edge shifts, vertex jumps and vertex pairs are off by default: they are not among the
  /// paper's moves, and chains with the default weights keep the course they had before the kinds
  /// existed.
  std::array<double, kNumMoveKinds> weight{1.0, 1.0, 1.0, 2.0, 2.0, 1.0, 0.5,
                                           1.0, 1.0, 3.0, 0.0, 0.0, 0.0};

  [[nodiscard]] double& operator[](MoveKind kind) { return weight[static_cast<int>(kind)]; }
  [[nodiscard]] double operator[](MoveKind kind) const { return weight[static_cast<int>(kind)]; }
};

}  // namespace priormap::prf
