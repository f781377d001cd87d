#pragma once
// Constraints whose terms fold to constants hold, or fail, whatever the unknowns: a constraint
// that never holds makes every link of its block infeasible, one that always holds constrains
// nothing. Either is almost surely a mistake (a forgotten variable, a name typo'd into a constant),
// so lowering reports them at the constraint (docs/priorlet-language.md, "Constant constraints").

#include <optional>
#include <string>
#include <vector>

#include <priormap/dsl/ast.hpp>

#include "expression_graph.hpp"

namespace priormap::dsl::detail {

/// One comparison of a constraint as lowered: f = 0 (an equality) or g <= 0, one term per entry.
struct LoweredComparison {
  std::string source;  ///< the comparison as written
  bool equality = true;
  std::vector<NodeId> terms;
};

/// What a constraint says whatever the unknowns: an error when it can never hold, a warning when
/// it always holds or when one branch of a disjunction can never hold.
struct ConstantConstraintFinding {
  bool is_error = false;
  std::string message;
};

/// The finding for the constraint made of `branches` (more than one: a disjunction) in a block
/// of `kind`, or nullopt when whether it holds depends on the unknowns or the beam angles.
[[nodiscard]] std::optional<ConstantConstraintFinding> FindConstantConstraint(
    const ExpressionGraph& graph, const std::vector<LoweredComparison>& branches, BlockKind kind);

}  // namespace priormap::dsl::detail
