// Malformed priorlet files: each gives exactly one error `file:line:col: message` that names the
// problem, through the whole pipeline (parse, inheritance, checks, compilation), and none throws,
// crashes or hangs. Purely syntactic problems are already reported by ParsePrior, with the same
// diagnostic; the others parse and fail when the prior is compiled.
#include <cstddef>
#include <ostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>

#include <priormap/dsl/parse.hpp>
#include <priormap/dsl/prior_library.hpp>

#include "testing/diagnostic_matchers.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::dsl {
namespace {

using ::priormap::testing::DiagnosticAt;
using ::priormap::testing::Lines;
using ::priormap::testing::TempDir;
using ::priormap::testing::WriteAll;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr const char* kPath = "bad.prior";

// The header every case below starts with, unless it is about the header: lines 1 and 2.
const std::string kHead = "name: T\norder: 2\n";

enum class Stage {
  kParse,    // ParsePrior already rejects the text
  kCompile,  // the text parses; compiling it fails
};

struct MalformedCase {
  std::string name;  // test name suffix
  std::string text;
  int line;
  int col;
  std::string message;  // a part of the message
  Stage stage;
};

void PrintTo(const MalformedCase& c, std::ostream* os) {
  *os << c.name;
}

std::vector<MalformedCase> Cases() {
  const std::string block = kHead + "priorlet same_region:\n";  // statements start on line 4
  const std::string points =
      kHead + "p_1 = [cos(phi_1); sin(phi_1)] * rho_1\npriorlet same_region:\n";  // line 5
  // Limits that keep a small hostile file from exhausting memory, time or the stack.
  std::ostringstream doubling;  // v_i has 2^(i+1) entries
  doubling << kHead << "v0 = [rho_1 rho_2]\n";
  for (int i = 1; i <= 10; ++i) doubling << "v" << i << " = [v" << i - 1 << " v" << i - 1 << "]\n";
  std::ostringstream outer;
  outer << kHead << "v0 = [rho_1 rho_2]\n";
  for (int i = 1; i <= 5; ++i) outer << "v" << i << " = [v" << i - 1 << " v" << i - 1 << "]\n";
  outer << "m = v5' * v5\n";  // 64x64
  std::ostringstream column;
  column << kHead << "v0 = [rho_1; rho_2]\n";
  for (int i = 1; i <= 9; ++i) column << "v" << i << " = [v" << i - 1 << "; v" << i - 1 << "]\n";
  column << "priorlet same_region:\n  v9 == 0\n  rho_1 == 0\n";  // 1024 terms, then one more
  std::ostringstream deep;                                       // each line two operations deeper
  deep << kHead << "a0 = sin(rho_1)\n";
  for (int i = 1; i <= 1100; ++i) deep << "a" << i << " = sin(a" << i - 1 << ") * rho_2\n";
  std::ostringstream products;  // 32x32 matrix products
  products << "name: T\norder: 16\nr = [";
  for (int i = 1; i <= 16; ++i) products << " rho_" << i << " alpha_" << i;
  products << "]\nM0 = r' * r\nM1 = M0 * M0 + 1\nM2 = M1 * M0 + 2\nM3 = M2 * M0 + 3\n";
  std::ostringstream derivatives;
  derivatives << "name: T\norder: 16\na0 = sin(rho_1 * alpha_2 + phi_3)\n";
  for (int i = 1; i < 200; ++i)
    derivatives << "a" << i << " = sin(a" << i - 1 << ") * rho_" << i % 16 + 1 << "\n";
  derivatives << "priorlet same_region:\n  model_likelihood a199\n";  // block at line 203

  const Stage kParse = Stage::kParse;
  const Stage kCompile = Stage::kCompile;
  return {
      // Names and indices.
      {"UnknownVariable", block + "  alpha_1 == beta_2\n", 4, 14, "unknown name 'beta_2'",
       kCompile},
      {"LeftmostOfTwoUnknownNames", kHead + "x = sin(foo) / norm(bar - baz)\n", 3, 9,
       "unknown name 'foo'", kCompile},
      {"IndexAboveOrder", block + "  rho_3 == 1\n", 4, 3,
       "'rho_3': index 3 is above the prior's order 2", kCompile},
      {"HugeIndexIsAboveOrder", block + "  alpha_99999999999999999999 == 1\n", 4, 3,
       "index 99999999999999999999 is above the prior's order 2", kCompile},
      {"IndexZero", block + "  rho_2 == rho_0\n", 4, 12, "'rho_0': indices start at 1", kCompile},
      // alpha_01 is not a second name of alpha_1.
      {"IndexWithALeadingZero", block + "  alpha_2 == alpha_01\n", 4, 14,
       "'alpha_01': indices are written without leading zeros (alpha_1)", kCompile},
      {"SubscriptIndexWithALeadingZero", block + "  \xCF\x81\xE2\x82\x80\xE2\x82\x82 == 1\n", 4, 3,
       "'rho_02': indices are written without leading zeros (rho_2)", kCompile},
      {"DefiningAnIndexWithALeadingZero", kHead + "phi_001 = 3\n", 3, 1,
       "'phi_001': indices are written without leading zeros (phi_1)", kCompile},
      {"IndexOfZerosOnly", block + "  rho_00 == 1\n", 4, 3, "'rho_00': indices start at 1",
       kCompile},
      {"RhoWithoutIndex", block + "  rho == 1\n", 4, 3, "'rho' needs an index: rho_1 ... rho_2",
       kCompile},
      {"LocalDefinitionOfAnotherBlock",
       block + "  q = 1\n  rho_1 == q\npriorlet different_region:\n  rho_1 == q\n", 7, 12,
       "unknown name 'q'", kCompile},
      {"FunctionWithoutArguments", block + "  sin == 0\n", 4, 3,
       "'sin' is a function: call it as sin(...)", kCompile},
      {"IndexingADefinition", points + "  p_1(1) == 0\n", 5, 3,
       "'p_1' is a definition, not a function: indexing with () is not supported", kCompile},
      {"CallingAVariable", block + "  phi_1(2) == 0\n", 4, 3,
       "'phi_1' is a variable, not a function", kCompile},
      // Shapes.
      {"AddingAColumnAndARow", block + "  [rho_1; rho_2] + [rho_1, rho_2] == 0\n", 4, 18,
       "'+': the operands are 2x1 and 1x2", kCompile},
      {"MatrixProductInnerSizes", points + "  p_1 * p_1 == 0\n", 5, 7,
       "matrix product of 2x1 and 2x1: the inner sizes differ", kCompile},
      {"EqualityOfDifferentSizes", block + "  [rho_1; rho_2] == [rho_1, rho_2]\n", 4, 18,
       "'==' compares values of the same size (or one scalar), got 2x1 and 1x2", kCompile},
      {"DivisionByAVector", block + "  1 / [rho_1; rho_2] == 0\n", 4, 5,
       "'/' divides by a scalar only", kCompile},
      {"PowerOfAVector", points + "  p_1 ^ 2 == 0\n", 5, 7, "'^' needs scalars, got 2x1 ^ 1x1",
       kCompile},
      {"HorizontalConcatenationOfDifferentHeights", block + "  [[rho_1; rho_2], rho_1] == 0\n", 4,
       20, "horizontal concatenation of 2x1 and 1x1: the row counts differ", kCompile},
      {"VerticalConcatenationOfDifferentWidths", block + "  [[rho_1, rho_2]; rho_1] == 0\n", 4, 20,
       "vertical concatenation of 1x2 and 1x1: the column counts differ", kCompile},
      {"MatrixRowsOfDifferentLengths", block + "  [rho_1, rho_2; rho_1] == 0\n", 4, 3,
       "matrix rows must have the same length: row 1 has 2, row 2 has 1", kParse},
      // Functions.
      {"UnknownFunction", block + "  foo(rho_1) == 0\n", 4, 3,
       "unknown function 'foo' (available: abs, acos", kCompile},
      {"Atan2WithOneArgument", block + "  atan2(rho_1) == 0\n", 4, 3,
       "'atan2' takes 2 arguments, got 1", kCompile},
      {"SinWithoutArguments", block + "  sin() == 0\n", 4, 3, "'sin' takes 1 argument, got 0",
       kCompile},
      {"MinWithThreeArguments", block + "  min(rho_1, rho_2, 3) == 0\n", 4, 3,
       "'min' takes 1 or 2 arguments, got 3", kCompile},
      // Definitions.
      {"DefinitionCycle", kHead + "a = b\nb = a\n", 3, 5,
       "definition cycle: 'a' uses 'b' (line 4), which depends on 'a' (line 3)", kCompile},
      {"DefinitionCycleInABlock", block + "  a = b + 1\n  b = 2 * a\n  a == 0\n", 4, 7,
       "definition cycle: 'a' uses 'b' (line 5)", kCompile},
      {"SelfReference", kHead + "a = a + 1\n", 3, 5, "'a' is used in its own definition", kCompile},
      {"UseBeforeDefinition", kHead + "a = b + 1\nb = 2\n", 3, 5,
       "'b' is used before its definition at line 4", kCompile},
      {"Redefinition", kHead + "a = 1\na = 2\n", 4, 1, "'a' is already defined at bad.prior:3",
       kCompile},
      {"BlockRedefinesItsOwnName",
       kHead + "priorlet same_region:\n  a = 1\n  a == rho_1\n  a = 2\n", 6, 3,
       "'a' is already defined at bad.prior:4", kCompile},
      {"BlockRedefinesAFileScopeName",
       kHead + "a = 1\npriorlet same_region:\n  a = 2\n  a == rho_1\n", 5, 3,
       "'a' is already defined at bad.prior:3", kCompile},
      {"RedefiningPi", kHead + "pi = 3\n", 3, 1, "'pi' is a constant and cannot be redefined",
       kCompile},
      {"RedefiningRho1", block + "  rho_1 = rho_2\n", 4, 3,
       "'rho_1' is predefined (rho_i, alpha_i, phi_i) and cannot be redefined (to constrain it, "
       "compare with "
       "'==')",
       kCompile},
      {"RedefiningAFunction", kHead + "sin = 3\n", 3, 1,
       "'sin' is a function and cannot be redefined", kCompile},
      {"DefiningModelLikelihood", kHead + "model_likelihood = 3\n", 3, 1,
       "'model_likelihood' is a keyword and cannot be defined", kParse},
      {"DefiningPriorlet", kHead + "priorlet = 3\n", 3, 1,
       "'priorlet' is a keyword and cannot be defined", kParse},
      {"KeywordInAnExpression", block + "  +model_likelihood - 1 == 0\n", 4, 4,
       "'model_likelihood' starts an energy statement ('model_likelihood expression'); it cannot "
       "be used in an "
       "expression",
       kParse},
      {"DefinitionWithoutExpression", kHead + "x =\n", 3, 4, "expected an expression after 'x ='",
       kParse},
      // Header.
      {"MissingName", "order: 2\n", 1, 1, "missing 'name:' (every prior file needs one)", kCompile},
      {"MissingOrderWithoutParent", "name: T\n", 1, 1, "missing 'order:'", kCompile},
      {"OrderNotAnInteger", "name: T\norder: 2.5\n", 2, 8,
       "order must be a whole number from 1 to 16, got '2.5'", kCompile},
      {"OrderZero", "name: T\norder: 0\n", 2, 8,
       "order must be a whole number from 1 to 16, got '0'", kCompile},
      {"OrderTooLarge", "name: T\norder: 17\n", 2, 8,
       "order must be a whole number from 1 to 16, got '17'", kCompile},
      {"NegativeMaxCurvature", kHead + "max_curvature: -1\n", 3, 16,
       "max_curvature must be a non-negative number (1/m) or inf, got '-1'", kCompile},
      {"NegativeMaxCurvatureOverflows", kHead + "max_curvature: -1e400\n", 3, 16,
       "must be a non-negative number (1/m) or inf, got '-1e400'", kCompile},
      {"NegativeMaxCurvatureUnderflows", kHead + "max_curvature: -1e-400\n", 3, 16,
       "must be a non-negative number (1/m) or inf, got '-1e-400'", kCompile},
      {"NegativeZeroMaxCurvature", kHead + "max_curvature: -0\n", 3, 16,
       "must be a non-negative number (1/m) or inf, got '-0'", kCompile},
      {"MaxCurvatureNotANumber", kHead + "max_curvature: ten\n", 3, 16,
       "max_curvature must be a non-negative number (1/m) or inf, got 'ten'", kCompile},
      {"MaxCurvatureNaN", kHead + "max_curvature: nan\n", 3, 16, "got 'nan'", kCompile},
      {"MaxCurvatureOverflows", kHead + "max_curvature: 1e400\n", 3, 16,
       "max_curvature '1e400' is above the largest number", kCompile},
      {"MaxCurvatureUnderflows", kHead + "max_curvature: 1e-400\n", 3, 16,
       "max_curvature '1e-400' is below the smallest normal magnitude", kCompile},
      {"MaxCurvatureSubnormal", kHead + "max_curvature: 1e-310\n", 3, 16,
       "(it underflows; write 0 for straight surfaces only)", kCompile},
      // A header value is the rest of its line: "..." neither continues it nor is dropped.
      {"ContinuedNameLine", "name: Long ...\n  name\norder: 2\n", 1, 12,
       "a header line cannot be continued: 'name:' takes the rest of its line, without a '...' "
       "at its end",
       kParse},
      {"ContinuedOrderLine", "name: T\norder: 2 ...# two\n", 2, 10,
       "a header line cannot be continued: 'order:'", kParse},
      // A header value is printed and matched by `specializes:` as written: characters that
      // garble a terminal or make two names that look alike differ are refused.
      {"NulInAName", std::string("name: T") + '\0' + "X\norder: 2\n", 1, 8,
       "unexpected control character U+0000 in a header value", kParse},
      {"InvalidUtf8InAName", "name: T\xFF\norder: 2\n", 1, 8,
       "unexpected byte 0xFF (prior files are UTF-8 text)", kParse},
      // The first problem in reading order (found by the fuzzer: the "..." was reported first,
      // at a column counted over the bytes before it).
      {"InvalidUtf8BeforeAContinuation", "name: \x81\x81T ...\norder: 2\n", 1, 7,
       "unexpected byte 0x81 (prior files are UTF-8 text)", kParse},
      {"NoBreakSpaceInAParentsName", "name: T\nspecializes: Polygonal\xC2\xA0prior\n", 2, 23,
       "unexpected character U+00A0 in a header value (a non-ASCII space", kParse},
      {"HeaderKeyWithoutValue", "name: T\norder:\n", 2, 7, "expected a value after 'order:'",
       kParse},
      {"DuplicateHeaderKey", "name: T\nname: again\norder: 2\n", 2, 1,
       "duplicate 'name:' (already given at line 1)", kParse},
      {"HeaderAfterABlock", block + "  rho_1 == 0\nmax_curvature: 3\n", 5, 1,
       "'max_curvature:' must come before the first priorlet block", kParse},
      {"UnknownHeaderKey", kHead + "foo: 3\n", 3, 1,
       "unknown header key 'foo:' (the keys are name, order, max_curvature and specializes)",
       kParse},
      {"HeaderLineInsideABlock", block + "  name: other\n", 4, 3,
       "'name:' is a header line and must start at column 1", kParse},
      {"UnknownParent", "name: T\nspecializes: Nope\n", 2, 14, "unknown prior 'Nope'", kCompile},
      {"SpecializingItself", "name: T\nspecializes: T\n", 2, 14,
       "inheritance cycle: 'T' specializes 'T'", kCompile},
      // Indentation and blocks.
      {"IndentedLineOutsideABlock", kHead + "  a = 1\n", 3, 3,
       "unexpected indentation: only the lines of a priorlet block are indented", kParse},
      {"InconsistentIndentationInABlock", block + "  rho_1 == rho_2\n   rho_1 == 0\n", 5, 4,
       "inconsistent indentation: the lines of this block start at column 3", kParse},
      {"TabsAfterSpaces", block + "        rho_1 == rho_2\n\trho_1 == 0\n", 5, 2,
       "this line is indented with 1 tab, the block's first line with 8 spaces (do not mix tabs "
       "and spaces)",
       kParse},
      {"SpacesAfterTabs", block + "\trho_1 == rho_2\n  \trho_1 == 0\n", 5, 4,
       "this line is indented with 1 tab and 2 spaces, the block's first line with 1 tab", kParse},
      {"EmptyBlockAtTheEnd", block, 3, 1, "empty block 'priorlet same_region'", kParse},
      {"EmptyBlockBeforeAnother", block + "priorlet different_region:\n  rho_1 == 0\n", 3, 1,
       "empty block 'priorlet same_region'", kParse},
      {"DuplicateBlock", block + "  rho_1 == 0\npriorlet same_region:\n  rho_2 == 0\n", 5, 1,
       "duplicate 'priorlet same_region' block (the first is at line 3)", kParse},
      {"UnknownBlockKind", kHead + "priorlet other_region:\n  rho_1 == 0\n", 3, 10,
       "unknown block kind 'other_region' (expected same_region, different_region or "
       "different_surface)",
       kParse},
      {"BlockWithoutKind", kHead + "priorlet\n", 3, 9, "expected a block kind", kParse},
      {"BlockWithoutColon", kHead + "priorlet same_region\n  rho_1 == 0\n", 3, 21,
       "expected ':' after 'priorlet same_region', got the end of the line", kParse},
      {"BodyAfterTheColon", kHead + "priorlet same_region: rho_1 == 0\n", 3, 23,
       "a priorlet block's body goes on the following, indented lines", kParse},
      {"NestedBlock", block + "  priorlet different_region:\n", 4, 3,
       "'priorlet' starts a block and must be at column 1", kParse},
      {"ConstraintAtFileScope", kHead + "rho_1 == 0\n", 3, 1,
       "a constraint must be inside a priorlet block", kParse},
      {"ModelLikelihoodAtFileScope", kHead + "model_likelihood rho_1^2\n", 3, 1,
       "'model_likelihood' must be inside a priorlet block", kParse},
      // Statements.
      {"NonScalarInequality", block + "  [rho_1; rho_2] <= 0\n", 4, 18,
       "an inequality compares scalars, got 2x1 and 1x1", kCompile},
      {"NonScalarModelLikelihood", block + "  model_likelihood [rho_1; rho_2]\n", 4, 3,
       "model_likelihood needs a scalar, got 2x1", kCompile},
      {"ModelLikelihoodWithoutExpression", block + "  model_likelihood\n", 4, 19,
       "expected an expression after 'model_likelihood'", kParse},
      {"PlainExpressionAsAConstraint", block + "  rho_1 - rho_2\n", 4, 3,
       "expected a constraint: a comparison with '==', '<=' or '>='", kCompile},
      {"PlainExpressionInADisjunction", block + "  (rho_1 == 0) || rho_2 * 2\n", 4, 19,
       "expected a constraint: a comparison", kCompile},
      {"ComparisonAsAValue", block + "  a = (rho_1 == rho_2)\n  a == 0\n", 4, 14,
       "a comparison is not a value", kCompile},
      {"ComparisonInArithmetic", block + "  (rho_1 == rho_2) + 1 == 0\n", 4, 10,
       "a comparison is not a value", kCompile},
      // Constants that fold to NaN or an infinity: a term never finite.
      {"ConstantThatIsNotANumber", block + "  rho_1 == log(-1)\n", 4, 12,
       "this is not a number whatever the unknowns: a constant must be a finite number", kCompile},
      {"InfiniteConstant", block + "  rho_1 <= 2 * (1 / 0)\n", 4, 19,
       "this is infinite whatever the unknowns", kCompile},
      // Constants that underflow: the value written is lost (to 0, or to a subnormal whose
      // reciprocal overflows), as in a literal below the normal range.
      {"ConstantProductThatUnderflowsToZero", block + "  rho_1 == 1e-200 * 1e-200\n", 4, 19,
       "this underflows whatever the unknowns: an operation on constants falls below the "
       "smallest normal magnitude, 2.2250738585072014e-308 (write 0 for zero)",
       kCompile},
      {"SubnormalConstantQuotientAsADivisor", block + "  rho_1 <= alpha_1 / (1e-300 / 1e20)\n", 4,
       30, "this underflows whatever the unknowns", kCompile},
      {"SubnormalConstantProductAsADivisor",
       block + "  model_likelihood alpha_1 / (1e-300 * 1e-20)\n", 4, 38,
       "this underflows whatever the unknowns", kCompile},
      {"ConstantFunctionThatUnderflows", block + "  rho_1 == exp(-1000) * rho_2\n", 4, 12,
       "this underflows whatever the unknowns", kCompile},
      {"UnknownDividedByZero", block + "  rho_1 <= alpha_1 / 0\n", 4, 20,
       "division by zero (the divisor is the constant 0)", kCompile},
      {"UnknownsDividedElementwiseByZero", block + "  [rho_1; rho_2] ./ [1; 0] == 0\n", 4, 18,
       "division by zero", kCompile},
      // Constraints that use no variable and can never hold: every link of their block infeasible.
      {"ConstantEqualityThatNeverHolds", block + "  1 == 2\n", 4, 3,
       "this constraint uses no variable and never holds ('1 == 2' simplifies to -1 == 0): every "
       "link it governs (priorlet same_region) would be infeasible",
       kCompile},
      {"ConstantInequalityThatNeverHolds", block + "  2 >= 3\n", 4, 3,
       "this constraint uses no variable and never holds ('2 >= 3' simplifies to 1 <= 0)",
       kCompile},
      {"VariableMinusItselfThatNeverHolds", block + "  rho_1 - rho_1 == 1\n", 4, 3,
       "this constraint uses no variable and never holds ('rho_1 - rho_1 == 1' simplifies to -1 "
       "== 0)",
       kCompile},
      {"ConstantEntryOfAVectorEqualityThatNeverHolds", block + "  [rho_1; 1] == [rho_2; 2]\n", 4, 3,
       "an entry of this constraint uses no variable and never holds (entry 2 of '[rho_1; 1] == "
       "[rho_2; 2]' simplifies to -1 == 0)",
       kCompile},
      {"DisjunctionNoBranchOfWhichCanHold", block + "  1 == 2 || 3 <= 2\n", 4, 3,
       "no branch of this disjunction can hold, whatever the unknowns (branch 1: '1 == 2' "
       "simplifies to -1 == 0; branch 2: '3 <= 2' simplifies to 1 <= 0)",
       kCompile},
      {"ConstantThatNeverHoldsNamesItsBlock", kHead + "priorlet different_surface:\n  0 >= 1\n", 4,
       3, "every link it governs (priorlet different_surface) would be infeasible", kCompile},
      {"ConstantThatNeverHoldsAfterASemicolon", block + "  rho_1 == rho_2; 1 == 2\n", 4, 19,
       "this constraint uses no variable and never holds", kCompile},
      {"DisjunctionAsAValue", block + "  model_likelihood (rho_1 == 0 || rho_2 == 0)\n", 4, 32,
       "'||' joins constraints; it cannot be used inside an expression", kCompile},
      {"ChainedComparison", block + "  0 <= rho_1 <= 1\n", 4, 14, "comparisons cannot be chained",
       kParse},
      {"ChainedEquality", block + "  rho_1 == rho_2 == 0\n", 4, 18, "comparisons cannot be chained",
       kParse},
      {"AssignmentInAConstraint", block + "  rho_1 + 1 = 0\n", 4, 13,
       "'=' defines a name; a constraint compares with '==', '<=' or '>='", kParse},
      {"AndAnd", block + "  rho_1 == 0 && rho_2 == 0\n", 4, 14,
       "'&&' is not supported: every constraint of a priorlet must hold, so write them on separate "
       "lines",
       kParse},
      {"NotEqual", block + "  rho_1 ~= 0\n", 4, 9, "'~=' / '!=' constraints are not supported",
       kParse},
      {"EmptyStatement", block + "  rho_1 == 0;;\n", 4, 14, "expected an expression, got ';'",
       kParse},
      // Brackets.
      {"UnterminatedParenthesis", block + "  (rho_1 == 0\n", 4, 3,
       "unterminated '(': expected ')' before the end of the line", kParse},
      {"UnterminatedCall", block + "  sin(rho_1\n", 4, 6,
       "unterminated '(': expected ')' before the end of the line", kParse},
      {"UnterminatedBracket", block + "  [rho_1; rho_2\n", 4, 3,
       "unterminated '[': expected ']' before the end of the line", kParse},
      {"UnclosedBracketBeforeAComparison", block + "  [rho_1; rho_2 == 0\n", 4, 17,
       "expected ',', ';' or ']' in the matrix opened at column 3, got '=='", kParse},
      {"UnclosedCallBeforeAComparison", block + "  sin(rho_1 == 0\n", 4, 13,
       "expected ',' or ')' in the arguments of 'sin', got '=='", kParse},
      {"UnmatchedParenthesis", block + "  rho_1 == 0)\n", 4, 13, "unmatched ')'", kParse},
      {"UnmatchedBracket", block + "  rho_1 == 0]\n", 4, 13, "unmatched ']'", kParse},
      {"EmptyMatrix", block + "  [] == 0\n", 4, 3, "empty matrix '[]'", kParse},
      {"MatrixStartingWithAComma", block + "  [, rho_1] == 0\n", 4, 4,
       "expected a matrix element before ','", kParse},
      {"MatrixEndingWithAComma", block + "  [rho_1,] == 0\n", 4, 10,
       "expected a matrix element after ','", kParse},
      {"MatrixStartingWithAnOperator", block + "  [* rho_1] == 0\n", 4, 4,
       "expected a matrix element or ']', got '*'", kParse},
      {"NestedTooDeeply",
       block + "  " + std::string(150, '(') + "rho_1" + std::string(150, ')') + " == 0\n", 4, 103,
       "expression nested too deeply", kParse},
      {"TooManySigns", block + "  rho_1 == " + std::string(150, '-') + "1\n", 4, 112,
       "expression nested too deeply", kParse},
      // Numbers and characters.
      {"NumberWithTwoDots", block + "  rho_1 == 1.2.3\n", 4, 12, "bad number '1.2.3'", kParse},
      {"NumberRunningIntoALetter", block + "  rho_1 == 3x\n", 4, 12, "bad number '3x'", kParse},
      {"ExponentWithoutDigits", block + "  rho_1 == 1e\n", 4, 12,
       "bad number '1e': an exponent needs digits", kParse},
      // Beyond the doubles: an overflow, and (as no quantity of a prior is that small) an
      // underflow to 0 or to a subnormal number, which keeps only some of the digits written.
      {"NumberThatOverflows", block + "  rho_1 == 1e999\n", 4, 12,
       "bad number '1e999': above the largest number, 1.7976931348623157e+308 (it overflows)",
       kParse},
      {"LongIntegerThatOverflows", block + "  rho_1 == 1" + std::string(400, '0') + "\n", 4, 12,
       "(it overflows)", kParse},
      {"NumberThatUnderflowsToZero", block + "  rho_1 == 1e-400\n", 4, 12,
       "bad number '1e-400': below the smallest normal magnitude, 2.2250738585072014e-308 (it "
       "underflows; write 0 for zero)",
       kParse},
      {"SubnormalNumber", block + "  rho_1 == 1e-310\n", 4, 12,
       "bad number '1e-310': below the smallest normal magnitude", kParse},
      {"LongFractionThatUnderflows", block + "  rho_1 == 0." + std::string(400, '0') + "1\n", 4, 12,
       "(it underflows; write 0 for zero)", kParse},
      {"HugeExponentThatUnderflows", block + "  rho_1 == 5e-99999999999999999999\n", 4, 12,
       "(it underflows; write 0 for zero)", kParse},
      {"StrayQuote", block + "  rho_1 == 'a'\n", 4, 12,
       "unexpected ' (transpose must follow an operand directly; strings are not supported)",
       kParse},
      {"QuoteAfterABlank", block + "  rho_1 == rho_2 '\n", 4, 18, "unexpected '", kParse},
      {"GreekLetterBeta", block + "  rho_1 == \xCE\xB2\n", 4, 12,
       "unexpected character '\xCE\xB2' (U+03B2); only \xCF\x81, \xCE\xB1, \xCF\x86 and \xCF\x95 "
       "may be written "
       "in Greek",
       kParse},
      {"GreekLetterInAName", block + "  rho_1 == x\xCE\xB2\n", 4, 13,
       "unexpected character U+03B2 in a name", kParse},
      // After Greek letters columns still count characters: α₁ is two.
      {"ColumnAfterGreekLetters", block + "  \xCE\xB1\xE2\x82\x81 == \xCF\x81_2 @\n", 4, 13,
       "unexpected character '@'", kParse},
      {"UnknownCharacter", block + "  rho_1 == 0 $\n", 4, 14, "unexpected character '$'", kParse},
      // "\r", "\n" and "\r\n" each end one line, mixed or not.
      {"LineAfterCrEndings", "name: T\rorder: 2\rpriorlet same_region:\r  rho_1 == 0 $\r", 4, 14,
       "unexpected character '$'", kParse},
      {"LineAfterMixedEndings", "name: T\r\norder: 2\r\rpriorlet same_region:\n\r  rho_1 == $\r\n",
       6, 12, "unexpected character '$'", kParse},
      {"CompileErrorAfterCrEndings", "name: T\rorder: 2\rpriorlet same_region:\r\r  rho_3 == 0\r",
       5, 3, "'rho_3': index 3 is above the prior's order 2", kCompile},
      {"InvalidUtf8", block + "  rho_1 == \xFF\n", 4, 12,
       "unexpected byte 0xFF (prior files are UTF-8 text)", kParse},
      {"NulByte", block + std::string("  rho_1 == \0\n", 13), 4, 12, "unexpected character U+0000",
       kParse},
      // Characters the editor shows as a blank or not at all are named, and others shown.
      {"NoBreakSpace",
       block + "  rho_1 ==\xC2\xA0"
               "0\n",
       4, 11, "unexpected character U+00A0 (a non-ASCII space: use a plain space or a tab)",
       kParse},
      {"NoBreakSpaceIndentation", block + "\xC2\xA0\xC2\xA0rho_1 == 0\n", 4, 1,
       "unexpected character U+00A0 (a non-ASCII space", kParse},
      {"ZeroWidthSpace", block + "  rho_1 == 0\xE2\x80\x8B\n", 4, 13,
       "unexpected character U+200B (an invisible zero-width character: delete it)", kParse},
      {"RightToLeftOverride",
       block + "  rho_1 == \xE2\x80\xAE"
               "0\n",
       4, 12, "unexpected character U+202E (an invisible zero-width character: delete it)", kParse},
      {"ByteOrderMarkInsideTheFile", block + "\xEF\xBB\xBF  rho_1 == 0\n", 4, 1,
       "unexpected character U+FEFF (an invisible zero-width character", kParse},
      {"LatinLetterInAName", block + "  caf\xC3\xA9 == 0\n", 4, 6,
       "unexpected character '\xC3\xA9' (U+00E9)", kParse},
      // Limits.
      {"MatrixOfMoreThan1024Entries", doubling.str(), 13, 7,
       "a 1x2048 matrix: more than 1024 entries", kCompile},
      {"OuterProductOfMoreThan1024Entries", outer.str(), 9, 9,
       "a 64x64 matrix: more than 1024 entries", kCompile},
      {"MoreThan1024Terms", column.str(), 15, 3,
       "more than 1024 scalar terms in 'priorlet same_region'", kCompile},
      {"OperationsNestedMoreThan2000Deep", deep.str(), 1003, 1,
       "'a1000' is too large to compile: operations nested more than 2000 deep", kCompile},
      {"MoreThan131072Subexpressions", products.str(), 7, 1,
       "'M3' is too large to compile: more than 131072 distinct subexpressions", kCompile},
      {"DerivativesTooLarge", derivatives.str(), 203, 1,
       "the derivatives of 'priorlet same_region' are too large to compile", kCompile},
      {"ExpressionMoreThan500Deep", block + "  rho_1 == rho_2" + std::string(600, '\'') + "\n", 4,
       117, "expression too deep: more than 500 operations inside one another", kParse},
      {"ContinuationAtTheEndOfTheFile", block + "  rho_1 == ...\n", 4, 11,
       "expected an expression, got the end", kParse},
  };
}

class MalformedPriorTest : public ::testing::TestWithParam<MalformedCase> {};

TEST_P(MalformedPriorTest, CompilingGivesOneErrorAtItsLocation) {
  const MalformedCase& c = GetParam();
  const PriorLibrary library;
  Result<CompiledPrior> compiled = Diagnostic{};
  ASSERT_NO_THROW(compiled = library.CompileText(c.text, kPath));
  ASSERT_FALSE(compiled.ok());
  EXPECT_THAT(compiled.diagnostics(), ElementsAre(DiagnosticAt(kPath, c.line, c.col, c.message)));
}

TEST_P(MalformedPriorTest, ParsingFailsAlikeExactlyWhenTheErrorIsSyntactic) {
  const MalformedCase& c = GetParam();
  Result<PriorFile> parsed = Diagnostic{};
  ASSERT_NO_THROW(parsed = ParsePrior(c.text, kPath));
  if (c.stage == Stage::kParse) {
    ASSERT_FALSE(parsed.ok());
    EXPECT_THAT(parsed.diagnostics(), ElementsAre(DiagnosticAt(kPath, c.line, c.col, c.message)));
  } else {
    EXPECT_TRUE(parsed.ok()) << parsed.error();
  }
}

TEST_P(MalformedPriorTest, ErrorTextIsFileLineColMessage) {
  const MalformedCase& c = GetParam();
  const Result<CompiledPrior> compiled = PriorLibrary().CompileText(c.text, kPath);
  ASSERT_FALSE(compiled.ok());
  EXPECT_THAT(compiled.error(),
              ::testing::StartsWith(std::string(kPath) + ":" + std::to_string(c.line) + ":" +
                                    std::to_string(c.col) + ": "));
  EXPECT_THAT(compiled.error(), HasSubstr(c.message));
}

INSTANTIATE_TEST_SUITE_P(Malformed, MalformedPriorTest, ::testing::ValuesIn(Cases()),
                         [](const ::testing::TestParamInfo<MalformedCase>& test) {
                           return test.param.name;
                         });

TEST(MalformedPriorCases, AreAtLeastThirtyAndNamedUniquely) {
  const std::vector<MalformedCase> cases = Cases();
  EXPECT_GE(cases.size(), 30u);
  std::vector<std::string> names;
  for (const MalformedCase& c : cases) names.push_back(c.name);
  std::sort(names.begin(), names.end());
  EXPECT_EQ(std::adjacent_find(names.begin(), names.end()), names.end());
}

// ---------------------------------------------------------------------------------------------
// Errors that involve other files: inheritance resolved in the directory of the file.

TEST(MalformedInheritance, CycleOfTwoFilesIsReportedWhereItCloses) {
  const TempDir dir;
  WriteAll(dir / "a.prior", "name: A\nspecializes: B\n");
  WriteAll(dir / "b.prior", "name: B\norder: 2\nspecializes: A\n");
  const std::string a = (dir / "a.prior").string();
  const std::string b = (dir / "b.prior").string();
  const PriorLibrary library;

  const Result<CompiledPrior> compiled = library.CompileText("name: A\nspecializes: B\n", a);
  ASSERT_FALSE(compiled.ok());
  EXPECT_THAT(compiled.diagnostics(),
              ElementsAre(DiagnosticAt(b, 3, 14,
                                       "inheritance cycle: 'A' specializes 'B' specializes 'A'")));

  const Result<CompiledPrior> loaded = library.Load(b);
  ASSERT_FALSE(loaded.ok());
  EXPECT_THAT(loaded.diagnostics(),
              ElementsAre(DiagnosticAt(a, 2, 14,
                                       "inheritance cycle: 'B' specializes 'A' specializes 'B'")));
}

TEST(MalformedInheritance, UnknownParentNamesTheDirectoriesSearched) {
  const TempDir dir;
  const std::string child = (dir / "child.prior").string();
  const Result<CompiledPrior> compiled =
      PriorLibrary().CompileText("name: C\nspecializes: Nope\n", child);
  ASSERT_FALSE(compiled.ok());
  EXPECT_THAT(compiled.diagnostics(),
              ElementsAre(DiagnosticAt(child, 2, 14, "unknown prior 'Nope'")));
  EXPECT_THAT(compiled.error(), HasSubstr(dir.path().string()));
  EXPECT_THAT(compiled.error(), HasSubstr("the built-in library"));
}

TEST(MalformedInheritance, ErrorInAParentIsReportedInTheParentsFile) {
  const TempDir dir;
  WriteAll(dir / "parent.prior", "name: P\norder: 2\nq = rho_3 + 1\n");
  const std::string child = (dir / "child.prior").string();
  const Result<CompiledPrior> compiled =
      PriorLibrary().CompileText("name: C\nspecializes: P\n", child);
  ASSERT_FALSE(compiled.ok());
  EXPECT_THAT(compiled.diagnostics(),
              ElementsAre(DiagnosticAt((dir / "parent.prior").string(), 3, 5,
                                       "'rho_3': index 3 is above the prior's order 2")));
}

TEST(MalformedInheritance, ChildLoweringTheOrderBreaksTheParentsIndices) {
  const TempDir dir;
  WriteAll(dir / "parent.prior",
           "name: P\norder: 2\npriorlet same_region:\n  alpha_1 == alpha_2\n");
  const std::string child = (dir / "child.prior").string();
  const Result<CompiledPrior> compiled =
      PriorLibrary().CompileText("name: C\norder: 1\nspecializes: P\n", child);
  ASSERT_FALSE(compiled.ok());
  EXPECT_THAT(compiled.diagnostics(),
              ElementsAre(DiagnosticAt((dir / "parent.prior").string(), 4, 14,
                                       "index 2 is above the prior's order 1")));
}

TEST(MalformedInheritance, ChildRedefiningAParentsNameIsAnError) {
  const TempDir dir;
  WriteAll(dir / "parent.prior", "name: P\norder: 2\nd = rho_2 - rho_1\n");
  const std::string child = (dir / "child.prior").string();
  const Result<CompiledPrior> compiled =
      PriorLibrary().CompileText("name: C\nspecializes: P\nd = 1\n", child);
  ASSERT_FALSE(compiled.ok());
  EXPECT_THAT(
      compiled.diagnostics(),
      ElementsAre(DiagnosticAt(
          child, 3, 1, "'d' is already defined at " + (dir / "parent.prior").string() + ":3")));
}

TEST(MalformedInheritance, TwoParentsOfOneNameInADirectoryAreAmbiguous) {
  const TempDir dir;
  WriteAll(dir / "p1.prior", "name: P\norder: 2\n");
  WriteAll(dir / "p2.prior", "name: P\norder: 3\n");
  const std::string child = (dir / "child.prior").string();
  const Result<CompiledPrior> compiled =
      PriorLibrary().CompileText("name: C\nspecializes: P\n", child);
  ASSERT_FALSE(compiled.ok());
  EXPECT_THAT(compiled.diagnostics(),
              ElementsAre(DiagnosticAt(child, 2, 14, "ambiguous prior name 'P'")));
}

// ---------------------------------------------------------------------------------------------
// Robustness: whatever the text, one diagnostic that points into it, or a compiled prior.

// Where `d` points is inside `text`: a line it has, a column of that line (or just after it).
::testing::AssertionResult PointsInto(const Diagnostic& d, const std::string& text) {
  const std::vector<std::string> lines = Lines(text);
  if (d.line < 1 || d.line > static_cast<int>(lines.size())) {
    return ::testing::AssertionFailure() << d.ToString() << ": no such line";
  }
  int characters = 0;  // UTF-8 continuation bytes do not start characters
  for (const char c : lines[static_cast<std::size_t>(d.line - 1)]) {
    if ((static_cast<unsigned char>(c) & 0xC0) != 0x80) ++characters;
  }
  if (d.col < 1 || d.col > characters + 1) {
    return ::testing::AssertionFailure()
           << d.ToString() << ": the line has " << characters << " characters";
  }
  return ::testing::AssertionSuccess();
}

// Nesting is bounded (parentheses, brackets, calls, signs), and so is the length of a line, which
// bounds operator chains: the trees stay shallow enough for the recursive passes over them.
TEST(MalformedRobustness, HugeNestingAndChainsAreRejectedWithoutExhaustingTheStack) {
  struct Repeat {
    std::string text;
    int times;
    std::string message;
  };
  const std::vector<Repeat> repeats = {{"(", 3000, "nested too deeply"},
                                       {"[", 3000, "nested too deeply"},
                                       {"sin(", 3000, "nested too deeply"},
                                       {"-", 3000, "nested too deeply"},
                                       {"2^-(", 2000, "nested too deeply"},
                                       {"rho_2 + ", 2000, "expression too deep"},
                                       {"rho_2^", 2000, "expression too deep"},
                                       {"(", 100000, "tokens in one logical line"},
                                       {"rho_2 + ", 100000, "tokens in one logical line"},
                                       {"2^", 100000, "tokens in one logical line"},
                                       {"rho_2' * ...\n", 100000, "tokens in one logical line"}};
  for (const Repeat& r : repeats) {
    std::string deep;
    for (int i = 0; i < r.times; ++i) deep += r.text;
    const std::string text = kHead + "priorlet same_region:\n  rho_1 == " + deep + "1\n";
    Result<CompiledPrior> compiled = Diagnostic{};
    ASSERT_NO_THROW(compiled = PriorLibrary().CompileText(text, kPath)) << r.text;
    ASSERT_FALSE(compiled.ok()) << r.text;
    ASSERT_EQ(compiled.diagnostics().size(), 1u) << r.text;
    EXPECT_THAT(compiled.diagnostics()[0].message, HasSubstr(r.message)) << r.text;
    EXPECT_TRUE(PointsInto(compiled.diagnostics()[0], text)) << r.text;
  }
}

TEST(MalformedRobustness, NestingAndChainsWithinTheLimitsCompile) {
  std::string chain;
  for (int i = 0; i < 200; ++i) chain += "rho_2^2 - ";
  for (const std::string& rhs :
       {std::string(90, '(') + "rho_2" + std::string(90, ')'), chain + "1"}) {
    const std::string text = kHead + "priorlet same_region:\n  rho_1 == " + rhs + "\n";
    const Result<CompiledPrior> compiled = PriorLibrary().CompileText(text, kPath);
    EXPECT_TRUE(compiled.ok()) << compiled.error();
  }
}

// Edits of the built-in priors: random characters and tokens inserted, text deleted, lines
// duplicated. Each result either compiles or gives exactly one diagnostic that points into the
// edited text (or into a built-in parent), and nothing throws.
RC_GTEST_PROP(MalformedRobustness, EditedBuiltinPriorsGiveOneLocatedErrorOrCompile, ()) {
  const auto& builtins = BuiltinPriorTexts();
  RC_PRE(!builtins.empty());
  const auto& [file, original] = *rc::gen::elementOf(builtins);
  std::string text = original;
  const std::vector<std::string> pieces = {"(",
                                           ")",
                                           "[",
                                           "]",
                                           ";",
                                           ",",
                                           "'",
                                           ".'",
                                           "==",
                                           "<=",
                                           "||",
                                           "|",
                                           "=",
                                           "-",
                                           "+",
                                           "*",
                                           "^",
                                           ".^",
                                           "./",
                                           "...",
                                           "\n",
                                           "\n  ",
                                           "\t",
                                           "  ",
                                           "#",
                                           "%",
                                           ":",
                                           "1e",
                                           "2.5",
                                           "0",
                                           "rho_3",
                                           "alpha_1",
                                           "\xCE\xB1\xE2\x82\x81",
                                           "\xCE\xB2",
                                           "\xFF",
                                           "pi",
                                           "p_1",
                                           "norm(",
                                           "atan2(",
                                           "model_likelihood ",
                                           "priorlet same_region:\n",
                                           "priorlet different_region:\n",
                                           "order: 3\n",
                                           "name: X\n",
                                           "specializes: Polygonal prior\n",
                                           "x = "};
  const int edits = *rc::gen::inRange(1, 6);
  for (int e = 0; e < edits; ++e) {
    const std::size_t at = *rc::gen::inRange<std::size_t>(0, text.size() + 1);
    switch (*rc::gen::inRange(0, 3)) {
      case 0:
        text.insert(at, *rc::gen::elementOf(pieces));
        break;
      case 1:
        text.erase(at, *rc::gen::inRange<std::size_t>(1, 12));
        break;
      default: {
        const std::size_t start = text.rfind('\n', at == 0 ? 0 : at - 1);
        const std::size_t line_start = start == std::string::npos ? 0 : start + 1;
        const std::size_t end = text.find('\n', at);
        const std::string line = text.substr(
            line_start, end == std::string::npos ? std::string::npos : end - line_start + 1);
        text.insert(line_start, line);
      }
    }
  }
  Result<CompiledPrior> compiled = Diagnostic{};
  try {
    compiled = PriorLibrary().CompileText(text, kPath);
  } catch (...) {
    RC_FAIL("CompileText threw");
  }
  if (compiled.ok()) return;
  RC_ASSERT(compiled.diagnostics().size() == 1u);
  const Diagnostic& d = compiled.diagnostics()[0];
  RC_ASSERT(!d.message.empty());
  if (d.file == kPath) {
    const ::testing::AssertionResult inside = PointsInto(d, text);
    RC_ASSERT_FALSE(!inside);  // (text of the failure: inside.message())
  } else {
    // A problem in a built-in parent (e.g. the edit lowered the order): located in that file.
    RC_ASSERT(d.file.rfind("<builtin>/", 0) == 0u);
    RC_ASSERT(d.line >= 1);
    RC_ASSERT(d.col >= 1);
  }
}

}  // namespace
}  // namespace priormap::dsl
