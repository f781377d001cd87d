#pragma once
// Lowering a resolved prior (a file and its ancestors) to scalar terms of an expression graph:
// names, indices, shapes and constraint structure are checked here, with file:line:col errors.

#include <array>
#include <memory>
#include <vector>

#include <priormap/core/diagnostic.hpp>
#include <priormap/dsl/prior.hpp>

namespace priormap::dsl::detail {

/// A prior with its inheritance resolved: `files` from the prior itself to its root ancestor.
struct ResolvedPrior {
  std::vector<std::shared_ptr<const PriorFile>> files;
};

/// Checks the prior and compiles every block. The first problem is the error.
[[nodiscard]] Result<CompiledPrior> LowerAndCompile(const ResolvedPrior& prior);

}  // namespace priormap::dsl::detail
