#pragma once
/// Parsing priorlet files into syntax trees. Only syntax is checked here; names, shapes and
/// inheritance are checked when a prior is compiled (PriorLibrary::Compile, prior_library.hpp).

#include <filesystem>
#include <string>
#include <string_view>

#include <priormap/core/diagnostic.hpp>
#include <priormap/dsl/ast.hpp>

namespace priormap::dsl {

/// Parses prior text; `path` names it in diagnostics and locates `specializes` parents.
/// On error, the first problem as `path:line:col: message`.
[[nodiscard]] Result<PriorFile> ParsePrior(std::string_view text, const std::string& path);

/// The expression / statement printed back as priorlet source (normalised spacing, minimal
/// parentheses); parsing the result gives the same tree.
[[nodiscard]] std::string ToSource(const Expr& expr);
[[nodiscard]] std::string ToSource(const Statement& statement);

/// Reads and parses a prior file.
[[nodiscard]] Result<PriorFile> ReadPriorFile(const std::filesystem::path& path);

}  // namespace priormap::dsl
