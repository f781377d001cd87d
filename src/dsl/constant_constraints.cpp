#include "constant_constraints.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include <fmt/format.h>

#include <priormap/core/diagnostic.hpp>

namespace priormap::dsl::detail {
namespace {

// Folding leaves rounding in constants that are 0 in exact arithmetic (sin(pi) is 1.2e-16), far
// below anything a constraint on ranges in metres and angles in radians could mean.
constexpr double kRoundingTolerance = 1e-9;
// A constraint's text in a message: enough to recognise it, not a flood (the location has it all).
constexpr std::size_t kQuotedSourceLength = 80;

enum class Truth { kDepends, kAlways, kNever };

// How a comparison fares whatever the unknowns, and why, in terms the user can check.
struct Verdict {
  Truth truth = Truth::kDepends;
  std::string why;
};

bool Holds(bool equality, double value) {
  return equality ? std::abs(value) <= kRoundingTolerance : value <= kRoundingTolerance;
}

std::string Quoted(const LoweredComparison& c) {
  return QuoteForMessage(c.source, kQuotedSourceLength);
}

std::string Simplified(bool equality, double value) {
  return fmt::format("{} {} 0", value, equality ? "==" : "<=");
}

std::string EntryOf(const LoweredComparison& c, std::size_t entry) {
  return c.terms.size() == 1 ? Quoted(c) : fmt::format("entry {} of {}", entry + 1, Quoted(c));
}

// One entry that is a failing constant makes the whole comparison fail; the comparison holds
// whatever the unknowns only when every entry is a constant that holds.
Verdict Judge(const ExpressionGraph& graph, const LoweredComparison& c) {
  bool every_entry_holds = true;
  for (std::size_t i = 0; i < c.terms.size(); ++i) {
    if (!graph.IsConst(c.terms[i])) {
      every_entry_holds = false;
      continue;
    }
    const double value = graph.node(c.terms[i]).value;
    if (!Holds(c.equality, value)) {
      return {Truth::kNever,
              fmt::format("{} simplifies to {}", EntryOf(c, i), Simplified(c.equality, value))};
    }
  }
  if (!every_entry_holds) return {};
  if (c.terms.size() > 1)
    return {Truth::kAlways, fmt::format("every entry of {} simplifies to 0 == 0", Quoted(c))};
  return {Truth::kAlways, fmt::format("{} simplifies to {}", Quoted(c),
                                      Simplified(c.equality, graph.node(c.terms[0]).value))};
}

std::string Infeasible(BlockKind kind) {
  return fmt::format("every link it governs (priorlet {}) would be infeasible", ToString(kind));
}

std::optional<ConstantConstraintFinding> ComparisonFinding(const LoweredComparison& c,
                                                           const Verdict& verdict, BlockKind kind) {
  switch (verdict.truth) {
    case Truth::kDepends:
      return std::nullopt;
    case Truth::kNever:
      return ConstantConstraintFinding{
          true, fmt::format("{} uses no variable and never holds ({}): {}",
                            c.terms.size() == 1 ? "this constraint" : "an entry of this constraint",
                            verdict.why, Infeasible(kind))};
    case Truth::kAlways:
      return ConstantConstraintFinding{
          false, fmt::format("this constraint uses no variable and always holds ({}): it "
                             "constrains nothing",
                             verdict.why)};
  }
  return std::nullopt;
}

// A branch that always holds makes the whole disjunction hold; one that never holds only makes
// it fail when every other branch does too, and is otherwise a dead alternative.
std::optional<ConstantConstraintFinding> DisjunctionFinding(const std::vector<Verdict>& verdicts,
                                                            BlockKind kind) {
  const auto first = [&](Truth truth) {
    return std::find_if(verdicts.begin(), verdicts.end(),
                        [&](const Verdict& v) { return v.truth == truth; });
  };
  if (const auto always = first(Truth::kAlways); always != verdicts.end()) {
    return ConstantConstraintFinding{
        false, fmt::format("branch {} of this disjunction uses no variable and always holds ({}): "
                           "the disjunction constrains nothing",
                           always - verdicts.begin() + 1, always->why)};
  }
  const auto never = first(Truth::kNever);
  if (never == verdicts.end()) return std::nullopt;
  const bool every_branch_fails = std::all_of(
      verdicts.begin(), verdicts.end(), [](const Verdict& v) { return v.truth == Truth::kNever; });
  if (!every_branch_fails) {
    return ConstantConstraintFinding{
        false, fmt::format("branch {} of this disjunction uses no variable and never holds ({}): "
                           "it can never be the branch that holds",
                           never - verdicts.begin() + 1, never->why)};
  }
  std::string whys;
  for (std::size_t b = 0; b < verdicts.size(); ++b)
    whys += fmt::format("{}branch {}: {}", b == 0 ? "" : "; ", b + 1, verdicts[b].why);
  return ConstantConstraintFinding{
      true, fmt::format("no branch of this disjunction can hold, whatever the unknowns ({}): {}",
                        whys, Infeasible(kind))};
}

}  // namespace

std::optional<ConstantConstraintFinding> FindConstantConstraint(
    const ExpressionGraph& graph, const std::vector<LoweredComparison>& branches, BlockKind kind) {
  std::vector<Verdict> verdicts;
  for (const LoweredComparison& branch : branches) verdicts.push_back(Judge(graph, branch));
  if (branches.size() == 1) return ComparisonFinding(branches[0], verdicts[0], kind);
  return DisjunctionFinding(verdicts, kind);
}

}  // namespace priormap::dsl::detail
