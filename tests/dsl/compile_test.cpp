// What a priorlet file compiles to: the terms of each block (kinds, signs, entries, disjunction
// branches), the block summaries, inheritance of header values, definitions and blocks, the
// simplification of the expression graph, the printed expressions and the evaluator's caching.
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/dsl/prior.hpp>
#include <priormap/dsl/prior_library.hpp>

#include "testing/diagnostic_matchers.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::dsl {
namespace {

using priormap::testing::DiagnosticAt;
using priormap::testing::TempDir;
using priormap::testing::WriteAll;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;

CompiledPrior Compile(const std::string& text, const std::string& path = "test.prior") {
  Result<CompiledPrior> prior = PriorLibrary().CompileText(text, path);
  if (!prior) ADD_FAILURE() << prior.error() << "\nin:\n" << text;
  return std::move(prior).value();
}

const CompiledBlock& SameRegion(const CompiledPrior& prior) {
  const CompiledBlock* block = prior.block(BlockKind::kSameRegion);
  if (!block) ADD_FAILURE() << "no same_region block";
  return *block;
}

// A prior of order 2 whose same_region block holds `body` (lines indented by the caller).
std::string OrderTwo(const std::string& body) {
  return "name: Test\norder: 2\npriorlet same_region:\n" + body;
}

std::vector<std::string> TermExpressions(const CompiledBlock& block) {
  std::vector<std::string> expressions;
  for (int t = 0; t < block.num_terms(); ++t) expressions.push_back(block.TermExpression(t));
  return expressions;
}

// Values of every term at x = (rho_1, rho_2, alpha_1, alpha_2) and phi.
std::vector<double> Values(const CompiledBlock& block, const std::vector<double>& x,
                           const std::vector<double>& phi) {
  std::vector<double> values(static_cast<std::size_t>(block.num_terms()));
  BlockEvaluator evaluator(block);
  evaluator.Evaluate(x, phi, values.data());
  return values;
}

// --- terms -------------------------------------------------------------------------------------

TEST(CompileTerms, VectorEqualityGivesOneTermPerEntry) {
  const CompiledPrior prior = Compile(OrderTwo("  [alpha_1; rho_1] == [alpha_2; rho_2]\n"));
  const CompiledBlock& block = SameRegion(prior);
  ASSERT_EQ(block.num_terms(), 2);
  EXPECT_THAT(TermExpressions(block), ElementsAre("alpha_1 - alpha_2", "rho_1 - rho_2"));
  for (int t = 0; t < 2; ++t) {
    const Term& term = block.terms()[static_cast<std::size_t>(t)];
    EXPECT_EQ(term.kind, TermKind::kEquality);
    EXPECT_EQ(term.entry, t);
    EXPECT_EQ(term.entries, 2);
    EXPECT_EQ(term.disjunction, -1);
    EXPECT_EQ(term.branch, -1);
    EXPECT_EQ(term.source, "[alpha_1; rho_1] == [alpha_2; rho_2]");
    EXPECT_EQ(term.loc.line, 4);
  }
  EXPECT_EQ(block.summary().equalities, 1);
  EXPECT_EQ(block.summary().scalar_terms, 2);
}

TEST(CompileTerms, MatrixEqualityWithAScalarComparesEveryEntryRowMajor) {
  const CompiledPrior prior = Compile(OrderTwo("  [alpha_1, rho_1; alpha_2, rho_2] == 1\n"));
  const CompiledBlock& block = SameRegion(prior);
  EXPECT_THAT(TermExpressions(block),
              ElementsAre("alpha_1 - 1", "rho_1 - 1", "alpha_2 - 1", "rho_2 - 1"));
  for (int t = 0; t < block.num_terms(); ++t) {
    EXPECT_EQ(block.terms()[static_cast<std::size_t>(t)].entry, t);
    EXPECT_EQ(block.terms()[static_cast<std::size_t>(t)].entries, 4);
  }
}

TEST(CompileTerms, ScalarEqualityIsLeftMinusRight) {
  const CompiledPrior prior = Compile(OrderTwo("  alpha_1 == alpha_2 + 1\n"));
  const CompiledBlock& block = SameRegion(prior);
  ASSERT_EQ(block.num_terms(), 1);
  EXPECT_EQ(block.terms()[0].kind, TermKind::kEquality);
  EXPECT_EQ(block.terms()[0].entries, 1);
  EXPECT_THAT(Values(block, {1.0, 2.0, 0.5, 0.25}, {0.0, 0.1}), ElementsAre(0.5 - 1.25));
}

TEST(CompileTerms, InequalitiesAreWrittenAsGLessOrEqualZero) {
  const CompiledPrior prior =
      Compile(OrderTwo("  rho_1 <= 2 * rho_2\n"
                       "  rho_1 >= 2 * rho_2\n"
                       "  rho_1 < 2 * rho_2\n"
                       "  rho_1 > 2 * rho_2\n"));
  const CompiledBlock& block = SameRegion(prior);
  ASSERT_EQ(block.num_terms(), 4);
  for (const Term& term : block.terms()) EXPECT_EQ(term.kind, TermKind::kInequality);
  // <= and < give lhs - rhs; >= and > give rhs - lhs.
  EXPECT_THAT(TermExpressions(block), ElementsAre("rho_1 - 2*rho_2", "2*rho_2 - rho_1",
                                                  "rho_1 - 2*rho_2", "2*rho_2 - rho_1"));
  EXPECT_THAT(Values(block, {3.0, 1.0, 0.0, 0.0}, {0.0, 0.1}), ElementsAre(1.0, -1.0, 1.0, -1.0));
  EXPECT_EQ(block.summary().inequalities, 4);
  EXPECT_EQ(block.summary().equalities, 0);
}

TEST(CompileTerms, DisjunctionBranchesShareAnIdAndAreNumberedInOrder) {
  const CompiledPrior prior =
      Compile(OrderTwo("  alpha_1 == 0 || alpha_1 == pi | alpha_2 <= 1\n"
                       "  rho_1 == rho_2\n"
                       "  [alpha_1; alpha_2] == 0 || rho_1 >= 1\n"));
  const CompiledBlock& block = SameRegion(prior);
  ASSERT_EQ(block.num_terms(), 7);
  const std::vector<Term>& terms = block.terms();
  const std::vector<std::array<int, 2>> expected = {{0, 0}, {0, 1}, {0, 2}, {-1, -1},
                                                    {1, 0}, {1, 0}, {1, 1}};
  for (std::size_t t = 0; t < terms.size(); ++t) {
    EXPECT_EQ(terms[t].disjunction, expected[t][0]) << "term " << t;
    EXPECT_EQ(terms[t].branch, expected[t][1]) << "term " << t;
  }
  EXPECT_EQ(terms[2].kind, TermKind::kInequality);
  EXPECT_EQ(terms[4].entry, 0);
  EXPECT_EQ(terms[5].entry, 1);
  EXPECT_EQ(terms[5].entries, 2);
  EXPECT_EQ(terms[0].source, "alpha_1 == 0 || alpha_1 == pi || alpha_2 <= 1");
  EXPECT_THAT(TermExpressions(block),
              ElementsAre("alpha_1", "alpha_1 - pi", "alpha_2 - 1", "rho_1 - rho_2", "alpha_1",
                          "alpha_2", "1 - rho_1"));
  EXPECT_EQ(block.num_disjunctions(), 2);
  // Constraints inside disjunctions are counted as disjunctions only.
  EXPECT_EQ(block.summary().disjunctions, 2);
  EXPECT_EQ(block.summary().equalities, 1);
  EXPECT_EQ(block.summary().inequalities, 0);
}

TEST(CompileTerms, EnergiesAreTheExpressionAsWrittenWithItsSign) {
  const CompiledPrior prior =
      Compile(OrderTwo("  model_likelihood -(alpha_2 - alpha_1)^2\n"
                       "  model_likelihood cos(alpha_2 - alpha_1)^2\n"));
  const CompiledBlock& block = SameRegion(prior);
  ASSERT_EQ(block.num_terms(), 2);
  for (const Term& term : block.terms()) EXPECT_EQ(term.kind, TermKind::kEnergy);
  EXPECT_EQ(block.terms()[0].source, "model_likelihood -(alpha_2 - alpha_1)^2");
  const std::vector<double> values = Values(block, {1.0, 1.0, 0.25, 1.0}, {0.0, 0.1});
  EXPECT_DOUBLE_EQ(values[0], -0.75 * 0.75);
  EXPECT_DOUBLE_EQ(values[1], std::pow(std::cos(0.75), 2));
  EXPECT_EQ(block.summary().energies, 2);
}

TEST(CompileTerms, SummaryCountsStatementsAndListsTheVariablesUsed) {
  const CompiledPrior prior = Compile(
      "name: Test\norder: 3\n"
      "priorlet same_region:\n"
      "  alpha_1 == alpha_3\n"
      "  [rho_2; alpha_1] == [1; 2]\n"
      "  rho_2 * cos(phi_1) <= 4\n"
      "  alpha_1 == 0 || alpha_1 == 1\n"
      "  model_likelihood alpha_3^2\n"
      "  model_likelihood 2 * alpha_3\n");
  const CompiledBlock& block = SameRegion(prior);
  const BlockSummary& s = block.summary();
  EXPECT_EQ(s.equalities, 2);
  EXPECT_EQ(s.inequalities, 1);
  EXPECT_EQ(s.disjunctions, 1);
  EXPECT_EQ(s.energies, 2);
  EXPECT_EQ(s.scalar_terms, 1 + 2 + 1 + 2 + 2);
  EXPECT_EQ(s.scalar_terms, block.num_terms());
  // rho before alpha before phi, each by index; rho_1, rho_3, alpha_2, phi_2, phi_3 are unused.
  EXPECT_THAT(s.variables, ElementsAre("rho_2", "alpha_1", "alpha_3", "phi_1"));
  EXPECT_EQ(block.num_variables(), 6);
  EXPECT_EQ(block.VariableName(0), "rho_1");
  EXPECT_EQ(block.VariableName(3), "alpha_1");
  EXPECT_EQ(block.VariableName(5), "alpha_3");
}

// norm of a scalar is abs; of a vector, sqrt of the sum of squares (guarded at 0 so that its
// derivative there is 0, not NaN; the guard does not change the value, and is not printed).
TEST(CompileTerms, NormPrintsAsAbsOfAScalarAndSqrtOfASumOfSquares) {
  const CompiledPrior prior = Compile(OrderTwo(
      "  model_likelihood norm(alpha_2 - alpha_1)\n  model_likelihood norm([rho_1; rho_2])\n"));
  const CompiledBlock& block = SameRegion(prior);
  EXPECT_THAT(TermExpressions(block),
              ElementsAre("abs(alpha_2 - alpha_1)", "sqrt(rho_1^2 + rho_2^2)"));
  EXPECT_THAT(Values(block, {3.0, 4.0, 0.5, 0.25}, {0.0, 0.1}), ElementsAre(0.25, 5.0));
}

// A product whose first factor is a negative constant prints with a sign in front: after an
// operator it is wrapped, or "a - -0.5*b" and "--0.5*b" (prior show --derivatives of the circular
// prior) read as typos.
TEST(CompileTerms, ASignedProductAfterAnOperatorIsWrapped) {
  const CompiledPrior prior = Compile(OrderTwo(
      "  model_likelihood alpha_1 - (-0.5 * alpha_2)\n  model_likelihood -(-0.5 * sin(alpha_2))\n"
      "  model_likelihood rho_1 * (-2 * rho_2)\n"));
  const CompiledBlock& block = SameRegion(prior);
  EXPECT_THAT(TermExpressions(block),
              ElementsAre("alpha_1 - (-0.5*alpha_2)", "-(-0.5*sin(alpha_2))", "rho_1*(-2*rho_2)"));
  EXPECT_THAT(Values(block, {3.0, 4.0, 0.5, 0.25}, {0.0, 0.1}),
              ElementsAre(0.5 + 0.125, 0.5 * std::sin(0.25), -24.0));
}

TEST(CompileTerms, MissingBlocksAreNull) {
  const CompiledPrior prior = Compile(OrderTwo("  alpha_1 == alpha_2\n"));
  EXPECT_NE(prior.block(BlockKind::kSameRegion), nullptr);
  EXPECT_EQ(prior.block(BlockKind::kDifferentRegion), nullptr);
  EXPECT_EQ(prior.block(BlockKind::kDifferentSurface), nullptr);
  EXPECT_EQ(prior.name(), "Test");
  EXPECT_EQ(prior.order(), 2);
  EXPECT_TRUE(std::isinf(prior.max_curvature()));  // none given
}

TEST(CompileTerms, DefinitionsAtFileScopeAreSharedByEveryBlock) {
  const CompiledPrior prior = Compile(
      "name: Test\norder: 2\n"
      "d = alpha_2 - alpha_1\n"
      "priorlet same_region:\n  d == 0\n"
      "priorlet different_region:\n  sin(2 * d) == 0\n"
      "priorlet different_surface:\n  model_likelihood d^2\n");
  EXPECT_EQ(prior.block(BlockKind::kSameRegion)->TermExpression(0), "alpha_2 - alpha_1");
  EXPECT_EQ(prior.block(BlockKind::kDifferentRegion)->TermExpression(0),
            "sin(2*(alpha_2 - alpha_1))");
  EXPECT_EQ(prior.block(BlockKind::kDifferentSurface)->TermExpression(0), "(alpha_2 - alpha_1)^2");
}

TEST(CompileTerms, BlockLocalDefinitionsAreNotVisibleInOtherBlocks) {
  const Result<CompiledPrior> prior = PriorLibrary().CompileText(
      "name: Test\norder: 2\n"
      "priorlet same_region:\n"
      "  d = alpha_2 - alpha_1\n"
      "  d == 0\n"
      "priorlet different_region:\n"
      "  d == 1\n",
      "test.prior");
  ASSERT_FALSE(prior.ok());
  EXPECT_THAT(prior.diagnostics().front(), DiagnosticAt("test.prior", 7, 3, "unknown name 'd'"));
}

// --- constraints that use no variable ----------------------------------------------------------

// The warnings of compiling `text` (which must compile).
std::vector<Diagnostic> Warnings(const std::string& text) {
  return Compile(text).warnings();
}

TEST(CompileConstantConstraints, ConstraintThatAlwaysHoldsIsKeptWithAWarningAtIt) {
  const CompiledPrior prior = Compile(OrderTwo("  rho_1 == rho_2\n  1 == 1\n"));
  EXPECT_THAT(prior.warnings(), ElementsAre(DiagnosticAt(
                                    "test.prior", 5, 3,
                                    "this constraint uses no variable and always holds ('1 == 1' "
                                    "simplifies to 0 == 0): it constrains nothing")));
  EXPECT_EQ(SameRegion(prior).num_terms(), 2);
}

TEST(CompileConstantConstraints, WhatTheGraphSimplifiesToAConstantIsCaught) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"sin(0) == 0", "'sin(0) == 0' simplifies to 0 == 0"},
      {"rho_1 - rho_1 == 0", "'rho_1 - rho_1 == 0' simplifies to 0 == 0"},
      {"0 * alpha_2 == 0", "'0 * alpha_2 == 0' simplifies to 0 == 0"},
      {"alpha_1 / alpha_1 <= 1", "'alpha_1 / alpha_1 <= 1' simplifies to 0 <= 0"},
      {"2 <= 3", "'2 <= 3' simplifies to -1 <= 0"},
      {"[1; 2] == [1; 2]", "every entry of '[1; 2] == [1; 2]' simplifies to 0 == 0"},
  };
  for (const auto& [constraint, why] : cases) {
    EXPECT_THAT(Warnings(OrderTwo("  " + constraint + "\n")),
                ElementsAre(DiagnosticAt("test.prior", 4, 3, "always holds (" + why + ")")))
        << constraint;
  }
}

// Rounding leaves sin(pi) at 1.2e-16: still 0 for this check, not an infeasible prior.
TEST(CompileConstantConstraints, RoundingOfAZeroConstantCountsAsHolding) {
  EXPECT_THAT(Warnings(OrderTwo("  sin(pi) == 0\n")),
              ElementsAre(DiagnosticAt("test.prior", 4, 3, "always holds")));
}

// The language documents < and > as meaning <= and >=, so 1 < 1 holds.
TEST(CompileConstantConstraints, StrictComparisonOfEqualConstantsHolds) {
  EXPECT_THAT(Warnings(OrderTwo("  1 < 1\n")),
              ElementsAre(DiagnosticAt("test.prior", 4, 3, "'1 < 1' simplifies to 0 <= 0")));
}

TEST(CompileConstantConstraints, DisjunctionWithABranchThatAlwaysHoldsConstrainsNothing) {
  EXPECT_THAT(Warnings(OrderTwo("  rho_1 == 0 || 1 == 1\n")),
              ElementsAre(DiagnosticAt(
                  "test.prior", 4, 3,
                  "branch 2 of this disjunction uses no variable and always holds ('1 == 1' "
                  "simplifies to 0 == 0): the disjunction constrains nothing")));
}

TEST(CompileConstantConstraints, DisjunctionBranchThatNeverHoldsIsAWarningWhenAnotherCan) {
  EXPECT_THAT(Warnings(OrderTwo("  1 == 2 || rho_1 == 0\n")),
              ElementsAre(DiagnosticAt(
                  "test.prior", 4, 3,
                  "branch 1 of this disjunction uses no variable and never holds ('1 == 2' "
                  "simplifies to -1 == 0): it can never be the branch that holds")));
}

// A block of definitions only is not empty (an error) but constrains nothing, as a constraint
// that always holds: most likely its constraints were forgotten.
TEST(CompileConstantConstraints, BlockOfDefinitionsOnlyIsAWarningAtIt) {
  const CompiledPrior prior = Compile(
      "name: Test\norder: 2\nd = rho_1\npriorlet same_region:\n  d == rho_2\n"
      "priorlet different_region:\n  e = d - rho_2\n  f = e^2\n");
  EXPECT_THAT(prior.warnings(),
              ElementsAre(DiagnosticAt("test.prior", 6, 1,
                                       "'priorlet different_region' holds definitions only: it "
                                       "constrains nothing, as a missing block")));
  ASSERT_NE(prior.block(BlockKind::kDifferentRegion), nullptr);
  EXPECT_EQ(prior.block(BlockKind::kDifferentRegion)->num_terms(), 0);
}

// Beam angles differ from link to link, a constant entry beside variables can be structural,
// and a constant energy prices every link of its block in the topology search: none is constant.
TEST(CompileConstantConstraints, BeamAnglesConstantEntriesAndConstantEnergiesAreNotReported) {
  EXPECT_THAT(Warnings(OrderTwo("  phi_2 - phi_1 <= 0.1\n"
                                "  [rho_1; 0] == [rho_2; 0]\n"
                                "  model_likelihood 3\n")),
              ::testing::IsEmpty());
}

TEST(CompileConstantConstraints, WarningsComeInBlockThenLineOrder) {
  const std::vector<Diagnostic> warnings = Warnings(
      "name: Test\norder: 2\npriorlet different_region:\n  2 <= 3\n"
      "priorlet same_region:\n  1 == 1\n  rho_1 == 0\n  0 >= 0\n");
  EXPECT_THAT(warnings, ElementsAre(DiagnosticAt("test.prior", 6, 3, "'1 == 1'"),
                                    DiagnosticAt("test.prior", 8, 3, "'0 >= 0'"),
                                    DiagnosticAt("test.prior", 4, 3, "'2 <= 3'")));
}

// --- inheritance -------------------------------------------------------------------------------

// A parent prior of order 2 in a directory, for children to specialize.
class Inheritance : public ::testing::Test {
 protected:
  Inheritance() {
    WriteAll(dir_ / "parent.prior",
             "# A parent prior.\n"              // 1
             "name: Parent\n"                   // 2
             "order: 2\n"                       // 3
             "max_curvature: 5\n"               // 4
             "n = alpha_2 - alpha_1\n"          // 5
             "priorlet same_region:\n"          // 6
             "  d = rho_2 - rho_1\n"            // 7
             "  d == 0\n"                       // 8
             "priorlet different_region:\n"     // 9
             "  model_likelihood cos(n)^2\n");  // 10
  }

  Result<CompiledPrior> CompileChild(const std::string& text) const {
    return PriorLibrary().CompileText(text, ChildPath());
  }
  [[nodiscard]] std::string ChildPath() const { return (dir_ / "child.prior").string(); }
  [[nodiscard]] std::string ParentPath() const { return (dir_ / "parent.prior").string(); }
  [[nodiscard]] const TempDir& dir() const { return dir_; }

 private:
  TempDir dir_;
};

TEST_F(Inheritance, ChildInheritsHeaderValuesDefinitionsAndBlocks) {
  const Result<CompiledPrior> prior = CompileChild("name: Child\nspecializes: Parent\n");
  ASSERT_TRUE(prior.ok()) << prior.error();
  const CompiledPrior& p = prior.value();
  EXPECT_EQ(p.name(), "Child");
  EXPECT_EQ(p.order(), 2);
  EXPECT_EQ(p.max_curvature(), 5.0);
  ASSERT_EQ(p.chain().size(), 2u);
  EXPECT_EQ(p.chain()[0].name, "Child");
  EXPECT_EQ(p.chain()[0].path, ChildPath());
  EXPECT_EQ(p.chain()[1].name, "Parent");
  EXPECT_EQ(p.chain()[1].path, ParentPath());
  ASSERT_NE(p.block(BlockKind::kSameRegion), nullptr);
  EXPECT_THAT(TermExpressions(*p.block(BlockKind::kSameRegion)), ElementsAre("rho_2 - rho_1"));
  ASSERT_NE(p.block(BlockKind::kDifferentRegion), nullptr);
  EXPECT_THAT(TermExpressions(*p.block(BlockKind::kDifferentRegion)),
              ElementsAre("cos(alpha_2 - alpha_1)^2"));
  EXPECT_EQ(p.block(BlockKind::kDifferentSurface), nullptr);
  // The inherited term points to the parent's file.
  const Term& inherited = p.block(BlockKind::kSameRegion)->terms()[0];
  EXPECT_EQ(inherited.loc.file_name(), ParentPath());
  EXPECT_EQ(inherited.loc.line, 8);
}

TEST_F(Inheritance, ChildBlockStatementsComeAfterTheParentsAndSeeItsLocalDefinitions) {
  const Result<CompiledPrior> prior = CompileChild(
      "name: Child\nspecializes: Parent\n"
      "priorlet same_region:\n"
      "  e = 2 * d\n"
      "  alpha_1 == e + n\n"
      "priorlet different_surface:\n"
      "  alpha_1 == alpha_2\n");
  ASSERT_TRUE(prior.ok()) << prior.error();
  const CompiledBlock& same = *prior.value().block(BlockKind::kSameRegion);
  ASSERT_EQ(same.num_terms(), 2);
  EXPECT_EQ(same.TermExpression(0), "rho_2 - rho_1");
  // alpha_1 - (e + n) with e = 2 d = 2 (rho_2 - rho_1) and n = alpha_2 - alpha_1.
  const double rho_1 = 1.0, rho_2 = 1.5, alpha_1 = 0.25, alpha_2 = 1.0;
  EXPECT_THAT(Values(same, {rho_1, rho_2, alpha_1, alpha_2}, {0.0, 0.1}),
              ElementsAre(rho_2 - rho_1, alpha_1 - (2 * (rho_2 - rho_1) + alpha_2 - alpha_1)));
  EXPECT_EQ(same.terms()[0].loc.file_name(), ParentPath());
  EXPECT_EQ(same.terms()[1].loc.file_name(), ChildPath());
  EXPECT_EQ(same.terms()[1].loc.line, 5);
  EXPECT_EQ(same.summary().equalities, 2);
  EXPECT_THAT(TermExpressions(*prior.value().block(BlockKind::kDifferentSurface)),
              ElementsAre("alpha_1 - alpha_2"));
}

TEST_F(Inheritance, ChildCannotRedefineAParentsName) {
  const Result<CompiledPrior> prior = CompileChild(
      "name: Child\nspecializes: Parent\n"
      "priorlet same_region:\n"
      "  d = 1\n");
  ASSERT_FALSE(prior.ok());
  EXPECT_THAT(prior.diagnostics().front(),
              DiagnosticAt(ChildPath(), 4, 3, "'d' is already defined"));
}

TEST_F(Inheritance, ChildOverridesOrderAndParentConstraintsStillCompile) {
  const Result<CompiledPrior> prior = CompileChild(
      "name: Child\nspecializes: Parent\norder: 3\n"
      "max_curvature: 0.5\n"
      "priorlet same_region:\n"
      "  rho_3 == rho_2\n");
  ASSERT_TRUE(prior.ok()) << prior.error();
  EXPECT_EQ(prior.value().order(), 3);
  EXPECT_EQ(prior.value().max_curvature(), 0.5);
  const CompiledBlock& same = *prior.value().block(BlockKind::kSameRegion);
  EXPECT_EQ(same.num_variables(), 6);
  EXPECT_THAT(TermExpressions(same), ElementsAre("rho_2 - rho_1", "rho_3 - rho_2"));
  // In the order-3 block the parent's alpha_1, alpha_2 are variables 3 and 4.
  const CompiledBlock& different = *prior.value().block(BlockKind::kDifferentRegion);
  EXPECT_EQ(different.num_variables(), 6);
  EXPECT_EQ(different.VariableName(4), "alpha_2");
  EXPECT_NE(different.DerivativeExpression(0, 3), "0");
  EXPECT_NE(different.DerivativeExpression(0, 4), "0");
  EXPECT_EQ(different.DerivativeExpression(0, 2), "0");
  EXPECT_EQ(different.DerivativeExpression(0, 5), "0");
}

TEST_F(Inheritance, InfiniteMaxCurvatureOverridesAParentsValue) {
  const Result<CompiledPrior> prior =
      CompileChild("name: Child\nspecializes: Parent\nmax_curvature: inf\n");
  ASSERT_TRUE(prior.ok()) << prior.error();
  EXPECT_TRUE(std::isinf(prior.value().max_curvature()));
}

TEST_F(Inheritance, LoweringTheOrderBelowAParentsIndexIsAnErrorInTheParentsFile) {
  WriteAll(dir() / "three.prior",
           "name: Three\n"            // 1
           "order: 3\n"               // 2
           "priorlet same_region:\n"  // 3
           "  rho_1 == rho_3\n");     // 4
  const Result<CompiledPrior> prior = CompileChild("name: Child\nspecializes: Three\norder: 2\n");
  ASSERT_FALSE(prior.ok());
  ASSERT_EQ(prior.diagnostics().size(), 1u);
  // The order that rules the parent's text out is the child's, and is named.
  EXPECT_THAT(prior.diagnostics().front(),
              DiagnosticAt((dir() / "three.prior").string(), 4, 12,
                           fmt::format("index 3 is above the prior's order 2 (order: 2 at {}:3)",
                                       ChildPath())));
}

TEST_F(Inheritance, AConstantConstraintOfTheParentIsReportedInTheParentsFile) {
  WriteAll(dir() / "constant.prior",
           "name: Constant\nspecializes: Parent\npriorlet same_region:\n  1 == 1\n");
  const Result<CompiledPrior> prior =
      CompileChild("name: Child\nspecializes: Constant\npriorlet same_region:\n  rho_1 >= 1\n");
  ASSERT_TRUE(prior.ok()) << prior.error();
  EXPECT_THAT(prior.value().warnings(),
              ElementsAre(DiagnosticAt((dir() / "constant.prior").string(), 4, 3,
                                       "this constraint uses no variable and always holds")));
}

TEST_F(Inheritance, GrandchildInheritsThroughTheChain) {
  WriteAll(dir() / "middle.prior",
           "name: Middle\nspecializes: Parent\npriorlet same_region:\n  alpha_1 == alpha_2\n");
  const Result<CompiledPrior> prior = CompileChild(
      "name: Child\nspecializes: Middle\n"
      "priorlet same_region:\n  model_likelihood n^2\n");
  ASSERT_TRUE(prior.ok()) << prior.error();
  ASSERT_EQ(prior.value().chain().size(), 3u);
  EXPECT_EQ(prior.value().chain()[1].name, "Middle");
  EXPECT_EQ(prior.value().chain()[2].name, "Parent");
  EXPECT_THAT(TermExpressions(*prior.value().block(BlockKind::kSameRegion)),
              ElementsAre("rho_2 - rho_1", "alpha_1 - alpha_2", "(alpha_2 - alpha_1)^2"));
}

// --- simplification ----------------------------------------------------------------------------

TEST(CompileSimplification, ConstantsAreFolded) {
  const CompiledPrior prior = Compile(OrderTwo("  x = 2*3; alpha_1*x == alpha_2*6\n"));
  const CompiledBlock& block = SameRegion(prior);
  ASSERT_EQ(block.num_terms(), 1);
  EXPECT_EQ(block.TermExpression(0), "6*alpha_1 - 6*alpha_2");
  EXPECT_THAT(block.TermExpression(0), Not(HasSubstr("2*3")));
  EXPECT_EQ(block.DerivativeExpression(0, 2), "6");
}

// Only an operation on nonzero normal constants that loses its value underflows (an error): zero
// operands, exact zeros (a cancellation, log 1, acos 1) and tiny normal results compile.
TEST(CompileSimplification, ZeroOperandsExactZerosAndTinyNormalConstantsFold) {
  const CompiledPrior prior = Compile(OrderTwo(
      "  rho_1 == 0 * 1e-300 + 0^2 + 1e-300 * 0 + log(1) + acos(1) + (1 - 1) + rho_2 * 0^alpha_1\n"
      "  rho_1 == 1e-150 * 1e-150 + 2.2250738585072014e-308 * 1 + 8e-308 / 2\n"));
  const CompiledBlock& block = SameRegion(prior);
  ASSERT_EQ(block.num_terms(), 2);
  const std::vector<double> values = Values(block, {1.0, 2.0, 0.5, 1.0}, {0.0, 0.1});
  EXPECT_DOUBLE_EQ(values[0], 1.0);
  EXPECT_DOUBLE_EQ(values[1], 1.0 - (1e-300 + 2.2250738585072014e-308 + 4e-308));
}

TEST(CompileSimplification, ConstantSubexpressionsCostNoInstructions) {
  // The relaxed rectangular bound, deg2rad and all, against the number it stands for.
  const CompiledPrior folded =
      Compile(OrderTwo("  tolerance = 3\n"
                       "  cos(alpha_2 - alpha_1) <= cos(deg2rad(90 - tolerance))\n"));
  const CompiledPrior plain = Compile(OrderTwo("  cos(alpha_2 - alpha_1) <= 0.05\n"));
  EXPECT_EQ(SameRegion(folded).TapeLengths(), SameRegion(plain).TapeLengths());
  EXPECT_THAT(SameRegion(folded).TermExpression(0), Not(HasSubstr("deg2rad")));
  const std::vector<double> values = Values(SameRegion(folded), {1.0, 1.0, 0.0, 1.0}, {0.0, 0.1});
  EXPECT_NEAR(values[0], std::cos(1.0) - std::cos(87.0 * kPi / 180.0), 1e-15);
}

TEST(CompileSimplification, IdenticalSubexpressionsAreComputedOnce) {
  const std::array<std::array<std::size_t, 3>, 3> lengths = {
      SameRegion(
          Compile(OrderTwo(
              "  model_likelihood (sin(alpha_1 - alpha_2) + rho_1) * (sin(alpha_1 - alpha_2) + "
              "rho_1)\n")))
          .TapeLengths(),
      SameRegion(
          Compile(OrderTwo("  s = sin(alpha_1 - alpha_2) + rho_1\n  model_likelihood s * s\n")))
          .TapeLengths(),
      SameRegion(Compile(OrderTwo("  model_likelihood sin(alpha_1 - alpha_2) + rho_1\n")))
          .TapeLengths()};
  EXPECT_EQ(lengths[0], lengths[1]);
  // Squaring adds one instruction to the values: the repeated operand is not computed twice.
  EXPECT_EQ(lengths[0][0], lengths[2][0] + 1);
}

TEST(CompileSimplification, TermsSharingSubexpressionsShareInstructions) {
  const auto values_length = [](const std::string& body) {
    return SameRegion(Compile(OrderTwo(body))).TapeLengths()[0];
  };
  const std::size_t one = values_length("  model_likelihood exp(rho_1 * rho_2)\n");
  const std::size_t two = values_length(
      "  model_likelihood exp(rho_1 * rho_2)\n  model_likelihood exp(rho_1 * rho_2)\n");
  EXPECT_EQ(one, two);
}

TEST(CompileSimplification, ParameterOnlyPartsAreOutsideThePerCallTapes) {
  // cos(phi_1) runs when phi changes; per call only the product remains, and the derivative by
  // rho_1 is cos(phi_1) itself.
  const CompiledPrior prior =
      Compile("name: Test\norder: 1\npriorlet same_region:\n  rho_1 * cos(phi_1) == 0\n");
  const CompiledBlock& block = SameRegion(prior);
  EXPECT_EQ(block.TapeLengths(), (std::array<std::size_t, 3>{1, 1, 1}));
  EXPECT_EQ(block.DerivativeExpression(0, 0), "cos(phi_1)");
  EXPECT_EQ(block.DerivativeExpression(0, 1), "0");
}

TEST(CompileSimplification, DerivativesOfUnusedVariablesAreZero) {
  const CompiledPrior prior = Compile(OrderTwo("  model_likelihood (alpha_2 - alpha_1)^2\n"));
  const CompiledBlock& block = SameRegion(prior);
  EXPECT_EQ(block.TermExpression(0), "(alpha_2 - alpha_1)^2");
  EXPECT_EQ(block.DerivativeExpression(0, 0), "0");
  EXPECT_EQ(block.DerivativeExpression(0, 1), "0");
  EXPECT_EQ(block.DerivativeExpression(0, 2), "2*(alpha_1 - alpha_2)");
  EXPECT_EQ(block.DerivativeExpression(0, 3), "2*(alpha_2 - alpha_1)");
}

// Golden text of the polygonal prior (Fig. 2a), as `priormap prior show --derivatives` prints it.
TEST(CompileSimplification, PolygonalSameRegionExpressionsAndDerivatives) {
  const Result<CompiledPrior> prior = PriorLibrary().Load("Polygonal prior");
  ASSERT_TRUE(prior.ok()) << prior.error();
  const CompiledBlock& block = *prior.value().block(BlockKind::kSameRegion);
  ASSERT_EQ(block.num_terms(), 2);
  EXPECT_EQ(block.TermExpression(0), "alpha_1 - alpha_2");
  EXPECT_EQ(block.DerivativeExpression(0, 0), "0");
  EXPECT_EQ(block.DerivativeExpression(0, 2), "1");
  EXPECT_EQ(block.DerivativeExpression(0, 3), "-1");
  EXPECT_EQ(block.TermExpression(1),
            "(cos(phi_2)*rho_2 - cos(phi_1)*rho_1)*cos(alpha_1) + (sin(phi_2)*rho_2 - "
            "sin(phi_1)*rho_1)*sin(alpha_1)");
  EXPECT_EQ(block.DerivativeExpression(1, 0), "-cos(phi_1)*cos(alpha_1) - sin(phi_1)*sin(alpha_1)");
  EXPECT_EQ(block.DerivativeExpression(1, 1), "sin(phi_2)*sin(alpha_1) + cos(phi_2)*cos(alpha_1)");
  EXPECT_EQ(block.DerivativeExpression(1, 2),
            "(sin(phi_2)*rho_2 - sin(phi_1)*rho_1)*cos(alpha_1) - (cos(phi_2)*rho_2 - "
            "cos(phi_1)*rho_1)*sin(alpha_1)");
  EXPECT_EQ(block.DerivativeExpression(1, 3), "0");
}

// --- the evaluator -----------------------------------------------------------------------------

struct Outputs {
  std::vector<double> values, gradients, hessians;
  bool operator==(const Outputs&) const = default;
};

Outputs EvaluateWith(BlockEvaluator& evaluator, const CompiledBlock& block,
                     const std::vector<double>& x, const std::vector<double>& phi) {
  const std::size_t nt = static_cast<std::size_t>(block.num_terms());
  const std::size_t nv = static_cast<std::size_t>(block.num_variables());
  Outputs out{std::vector<double>(nt), std::vector<double>(nt * nv),
              std::vector<double>(nt * nv * nv)};
  evaluator.Evaluate(x, phi, out.values.data(), out.gradients.data(), out.hessians.data());
  return out;
}

Outputs EvaluateFresh(const CompiledBlock& block, const std::vector<double>& x,
                      const std::vector<double>& phi) {
  BlockEvaluator evaluator(block);
  return EvaluateWith(evaluator, block, x, phi);
}

TEST(BlockEvaluatorCache, ChangingPhiBackAndForthGivesWhatFreshEvaluatorsGive) {
  // The circular prior's points depend on phi (cached) and on rho (per call).
  const Result<CompiledPrior> prior = PriorLibrary().Load("circular");
  ASSERT_TRUE(prior.ok()) << prior.error();
  const CompiledBlock& block = *prior.value().block(BlockKind::kSameRegion);
  const std::vector<double> x = {2.0, 2.5, 3.0, 0.1, 0.5, 1.2};
  const std::vector<double> phi_a = {-0.3, 0.0, 0.4}, phi_b = {-0.2, 0.3, 0.9};
  const Outputs fresh_a = EvaluateFresh(block, x, phi_a), fresh_b = EvaluateFresh(block, x, phi_b);
  ASSERT_NE(fresh_a.values, fresh_b.values);

  BlockEvaluator evaluator(block);
  EXPECT_EQ(EvaluateWith(evaluator, block, x, phi_a), fresh_a);
  EXPECT_EQ(EvaluateWith(evaluator, block, x, phi_b), fresh_b);
  EXPECT_EQ(EvaluateWith(evaluator, block, x, phi_a), fresh_a);
  // Only one beam angle changing is a change too.
  const std::vector<double> phi_c = {-0.3, 0.0, 0.5};
  EXPECT_EQ(EvaluateWith(evaluator, block, x, phi_c), EvaluateFresh(block, x, phi_c));
}

TEST(BlockEvaluatorCache, ChangingXWithTheSamePhiGivesWhatFreshEvaluatorsGive) {
  const Result<CompiledPrior> prior = PriorLibrary().Load("polygonal");
  ASSERT_TRUE(prior.ok()) << prior.error();
  const CompiledBlock& block = *prior.value().block(BlockKind::kSameRegion);
  const std::vector<double> phi = {0.1, 0.2};
  BlockEvaluator evaluator(block);
  for (const std::vector<double>& x :
       {std::vector<double>{1.0, 2.0, 0.3, 0.4}, std::vector<double>{1.5, 0.5, -1.0, 2.0}}) {
    EXPECT_EQ(EvaluateWith(evaluator, block, x, phi), EvaluateFresh(block, x, phi));
  }
}

TEST(BlockEvaluatorCache, EvaluatorsOfOneBlockAreIndependent) {
  const Result<CompiledPrior> prior = PriorLibrary().Load("circular");
  ASSERT_TRUE(prior.ok()) << prior.error();
  const CompiledBlock& block = *prior.value().block(BlockKind::kSameRegion);
  const std::vector<double> x = {2.0, 2.5, 3.0, 0.1, 0.5, 1.2};
  const std::vector<double> phi_a = {-0.3, 0.0, 0.4}, phi_b = {-0.2, 0.3, 0.9};
  BlockEvaluator first(block), second(block);
  const Outputs a = EvaluateWith(first, block, x, phi_a);
  EvaluateWith(second, block, x, phi_b);
  EXPECT_EQ(EvaluateWith(first, block, x, phi_a), a);
}

// Definitions used twice per line double the written-out text at each line: 30 lines would
// print some 1e15 characters (prior show ran out of memory). The graph shares them; the text
// describes the term instead.
TEST(Compile, ATermTooLongToWriteOutIsDescribedNotPrinted) {
  std::string text = "name: Chain\norder: 2\nx0 = alpha_1 + alpha_2\n";
  for (int i = 1; i <= 30; ++i) text += fmt::format("x{0} = x{1} * x{1} + sin(x{1})\n", i, i - 1);
  text += "priorlet same_region:\n  x30 == 0\n";
  const CompiledPrior prior = Compile(text);
  EXPECT_THAT(SameRegion(prior).TermExpression(0), ::testing::StartsWith("<not printed: "));
  EXPECT_THAT(SameRegion(prior).DerivativeExpression(0, 2), HasSubstr("characters>"));
  // A short chain is still printed in full.
  const CompiledPrior short_chain = Compile(
      "name: Short\norder: 2\nx0 = alpha_1 + alpha_2\nx1 = x0 * x0 + sin(x0)\n"
      "priorlet same_region:\n  x1 == 0\n");
  EXPECT_EQ(SameRegion(short_chain).TermExpression(0),
            "(alpha_1 + alpha_2)^2 + sin(alpha_1 + alpha_2)");
}

}  // namespace
}  // namespace priormap::dsl
