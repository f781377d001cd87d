#include <priormap/prf/moves.hpp>

namespace priormap::prf {
namespace {

constexpr std::array<std::string_view, kNumMoveTypes> kTypeNames{"triangle_birth",
                                                                 "triangle_death",
                                                                 "boundary_triangle_birth",
                                                                 "boundary_triangle_death",
                                                                 "corner_birth",
                                                                 "corner_death",
                                                                 "vertex_birth",
                                                                 "vertex_death",
                                                                 "interior_move",
                                                                 "boundary_move",
                                                                 "recolor",
                                                                 "local_recolor",
                                                                 "slide",
                                                                 "guided_triangle_birth",
                                                                 "guided_triangle_death",
                                                                 "edge_shift",
                                                                 "vertex_jump",
                                                                 "vertex_pair_birth",
                                                                 "vertex_pair_death"};
constexpr std::array<std::string_view, kNumMoveKinds> kKindNames{
    "triangle",      "boundary_triangle", "corner",        "vertex", "interior_move",
    "boundary_move", "recolor",           "local_recolor", "slide",  "guided_triangle",
    "edge_shift",    "vertex_jump",       "vertex_pair"};

}  // namespace

std::string_view MoveTypeName(MoveType type) {
  return kTypeNames[static_cast<std::size_t>(type)];
}

std::string_view MoveKindName(MoveKind kind) {
  return kKindNames[static_cast<std::size_t>(kind)];
}

std::optional<MoveKind> ParseMoveKind(std::string_view name) {
  for (int k = 0; k < kNumMoveKinds; ++k)
    if (kKindNames[static_cast<std::size_t>(k)] == name) return static_cast<MoveKind>(k);
  return std::nullopt;
}

}  // namespace priormap::prf
