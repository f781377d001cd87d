// Parsing well-formed priorlet files: the seven files of the paper's Fig. 2 as printed, the
// lexical conveniences (Unicode names, ';', comments, continuation lines), MATLAB's rules for
// matrices, precedence and associativity, and printing statements back (ToSource), which must
// give text that parses to the same tree.
#include <array>
#include <cstddef>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>

#include <priormap/dsl/parse.hpp>
#include <priormap/dsl/prior.hpp>
#include <priormap/dsl/prior_library.hpp>

#include "testing/diagnostic_matchers.hpp"

namespace priormap::dsl {
namespace {

using ::priormap::testing::DiagnosticAt;
using ::testing::ElementsAre;
using ::testing::IsEmpty;

constexpr const char* kPath = "test.prior";

// ---------------------------------------------------------------------------------------------
// Views of a parse: a line per header entry, definition, block and statement; a tree as an
// S-expression.

std::string NumberText(double value) {
  std::ostringstream out;
  out.precision(17);
  out << value;
  return out.str();
}

std::string Tree(const Expr& e) {
  const auto children = [&] {
    std::string out;
    for (const ExprPtr& child : e.children) {
      out += ' ';
      out += Tree(*child);
    }
    return out;
  };
  switch (e.kind) {
    case Expr::Kind::kNumber:
      return NumberText(e.number);
    case Expr::Kind::kName:
      return e.name;
    case Expr::Kind::kNegate:
      return "(neg" + children() + ")";
    case Expr::Kind::kTranspose:
      return "('" + children() + ")";
    case Expr::Kind::kCall:
      return "(call " + e.name + children() + ")";
    case Expr::Kind::kMatrix: {
      const std::size_t per_row =
          e.rows > 0 ? e.children.size() / static_cast<std::size_t>(e.rows) : 0;
      return "(matrix " + std::to_string(e.rows) + "x" + std::to_string(per_row) + children() + ")";
    }
    case Expr::Kind::kOr:
      return "(||" + children() + ")";
    case Expr::Kind::kCompare: {
      static constexpr std::array<const char*, 5> kOps = {"==", "<=", ">=", "<", ">"};
      return std::string("(") + kOps[static_cast<std::size_t>(e.compare)] + children() + ")";
    }
    case Expr::Kind::kBinary: {
      static constexpr std::array<const char*, 8> kOps = {"+",  "-",  "*",  "/",
                                                          ".*", "./", ".^", "^"};
      return std::string("(") + kOps[static_cast<std::size_t>(e.binary)] + children() + ")";
    }
  }
  return "?";
}

std::string Tree(const Statement& s) {
  switch (s.kind) {
    case Statement::Kind::kDefinition:
      return "(= " + s.name + " " + Tree(*s.expr) + ")";
    case Statement::Kind::kEnergy:
      return "(energy " + Tree(*s.expr) + ")";
    case Statement::Kind::kConstraint:
      return Tree(*s.expr);
  }
  return "?";
}

std::string Describe(const Statement& s) {
  const char* kind = s.kind == Statement::Kind::kDefinition ? "definition"
                     : s.kind == Statement::Kind::kEnergy   ? "energy"
                                                            : "constraint";
  return std::string(kind) + " " + std::to_string(s.loc.line) + ":" + std::to_string(s.loc.col) +
         " " + ToSource(s);
}

std::vector<std::string> Outline(const PriorFile& file) {
  std::vector<std::string> out;
  for (const HeaderEntry& h : file.header) {
    out.push_back(h.key + " " + std::to_string(h.value_loc.line) + ":" +
                  std::to_string(h.value_loc.col) + " " + h.value);
  }
  for (const Statement& s : file.definitions) out.push_back(Describe(s));
  for (const Block& b : file.blocks) {
    out.push_back(std::string("block ") + ToString(b.kind) + " " + std::to_string(b.loc.line) +
                  ":" + std::to_string(b.loc.col));
    for (const Statement& s : b.statements) out.push_back("  " + Describe(s));
  }
  return out;
}

// The outline of `text`, or the parse error as the only line.
std::vector<std::string> OutlineOf(const std::string& text) {
  const Result<PriorFile> parsed = ParsePrior(text, kPath);
  if (!parsed) return {"error: " + parsed.error()};
  return Outline(parsed.value());
}

// The statements of a same_region block whose body is `body` (lines 4 on).
std::vector<Statement> BlockStatements(const std::string& body) {
  const Result<PriorFile> parsed =
      ParsePrior("name: T\norder: 2\npriorlet same_region:\n" + body + "\n", kPath);
  if (!parsed) {
    ADD_FAILURE() << parsed.error();
    return {};
  }
  if (parsed.value().blocks.size() != 1) {
    ADD_FAILURE() << "expected one block";
    return {};
  }
  return parsed.value().blocks[0].statements;
}

// The tree of the single statement `statement` in a block.
std::string TreeOf(const std::string& statement) {
  const std::vector<Statement> statements = BlockStatements("  " + statement);
  if (statements.size() != 1) return std::to_string(statements.size()) + " statements";
  return Tree(statements[0]);
}

// ---------------------------------------------------------------------------------------------
// Fig. 2 of the paper, verbatim.

const char* const kFig2a = R"(name: Polygonal prior
order: 2
max_curvature: 0
p_1 = [cos( phi_1 ); sin( phi_1 )] * rho_1; # define cartesian coords
p_2 = [cos( phi_2 ); sin( phi_2 )] * rho_2; # as shortcuts
priorlet same_region:
  alpha_1 == alpha_2
  (p_2 - p_1)' * [cos( alpha_1 ); sin( alpha_1 )] == 0
)";

const char* const kFig2b = R"(name: Rectangular prior
specializes: Polygonal prior
priorlet different_region:
  ( alpha_2 == alpha_1 - pi/2 ) || ( alpha_2 == alpha_1 + pi/2 )
)";

const char* const kFig2c = R"(name: Rectangular prior (relaxed)
specializes: Polygonal prior
priorlet different_region:
  tolerance = 3; # 3deg tolerance
  cos( alpha_2 - alpha_1 ) <= cos(deg2rad(90+tolerance))
  -cos( alpha_2 - alpha_1 ) <= -cos(deg2rad(90-tolerance))
)";

const char* const kFig2d = R"(name: Rectangular prior (relaxed - alternative)
specializes: Polygonal prior
priorlet different_region:
  model_likelihood cos( alpha_2 - alpha_1 )^2
)";

const char* const kFig2e = R"(name: Circular prior
order: 3
max_curvature: 10 # min radius = 0.1 m
# two oriented points define a circle. This is the radius.
r12 = sin(( alpha_2 - alpha_1 )/2) / norm(p_1 - p_2);
r23 = sin(( alpha_3 - alpha_2 )/2) / norm(p_3 - p_2);
r13 = sin(( alpha_3 - alpha_1 )/2) / norm(p_3 - p_1);
priorlet same_region:
  r12 == r23 # the three oriented points
  r23 == r13 # lie on the same circle
)";

const char* const kFig2f = R"(name: Circular prior (with prior on radius)
specializes: Circular prior
priorlet same_region: # it is likely that the radius is around 2.0
  model_likelihood (r13 - 2.0)^2
)";

const char* const kFig2g = R"(name: Splines prior
order: 2
max_curvature: 10
priorlet same_region:
  model_likelihood ( alpha_2 - alpha_1 )^2
)";

TEST(PaperFigure2, PolygonalPriorParsesToTwoDefinitionsAndTwoEqualities) {
  EXPECT_THAT(OutlineOf(kFig2a),
              ElementsAre("name 1:7 Polygonal prior", "order 2:8 2", "max_curvature 3:16 0",
                          "definition 4:1 p_1 = [cos(phi_1); sin(phi_1)] * rho_1",
                          "definition 5:1 p_2 = [cos(phi_2); sin(phi_2)] * rho_2",
                          "block same_region 6:1", "  constraint 7:3 alpha_1 == alpha_2",
                          "  constraint 8:3 (p_2 - p_1)' * [cos(alpha_1); sin(alpha_1)] == 0"));
}

TEST(PaperFigure2, RectangularPriorIsOneDisjunctionOfTwoEqualities) {
  EXPECT_THAT(
      OutlineOf(kFig2b),
      ElementsAre("name 1:7 Rectangular prior", "specializes 2:14 Polygonal prior",
                  "block different_region 3:1",
                  "  constraint 4:3 alpha_2 == alpha_1 - pi / 2 || alpha_2 == alpha_1 + pi / 2"));
  EXPECT_EQ(TreeOf("( alpha_2 == alpha_1 - pi/2 ) || ( alpha_2 == alpha_1 + pi/2 )"),
            "(|| (== alpha_2 (- alpha_1 (/ pi 2))) (== alpha_2 (+ alpha_1 (/ pi 2))))");
}

TEST(PaperFigure2, RelaxedRectangularPriorParsesWithItsSwappedBounds) {
  // The paper's lines as printed (90+tolerance in the first, 90-tolerance in the second).
  EXPECT_THAT(
      OutlineOf(kFig2c),
      ElementsAre("name 1:7 Rectangular prior (relaxed)", "specializes 2:14 Polygonal prior",
                  "block different_region 3:1", "  definition 4:3 tolerance = 3",
                  "  constraint 5:3 cos(alpha_2 - alpha_1) <= cos(deg2rad(90 + tolerance))",
                  "  constraint 6:3 -cos(alpha_2 - alpha_1) <= -cos(deg2rad(90 - tolerance))"));
}

TEST(PaperFigure2, AlternativeRelaxedRectangularPriorIsAnEnergy) {
  EXPECT_THAT(OutlineOf(kFig2d),
              ElementsAre("name 1:7 Rectangular prior (relaxed - alternative)",
                          "specializes 2:14 Polygonal prior", "block different_region 3:1",
                          "  energy 4:3 model_likelihood cos(alpha_2 - alpha_1)^2"));
  EXPECT_EQ(TreeOf("model_likelihood cos( alpha_2 - alpha_1 )^2"),
            "(energy (^ (call cos (- alpha_2 alpha_1)) 2))");
}

TEST(PaperFigure2, CircularPriorParsesWithCommentsStripped) {
  EXPECT_THAT(OutlineOf(kFig2e),
              ElementsAre("name 1:7 Circular prior", "order 2:8 3", "max_curvature 3:16 10",
                          "definition 5:1 r12 = sin((alpha_2 - alpha_1) / 2) / norm(p_1 - p_2)",
                          "definition 6:1 r23 = sin((alpha_3 - alpha_2) / 2) / norm(p_3 - p_2)",
                          "definition 7:1 r13 = sin((alpha_3 - alpha_1) / 2) / norm(p_3 - p_1)",
                          "block same_region 8:1", "  constraint 9:3 r12 == r23",
                          "  constraint 10:3 r23 == r13"));
}

TEST(PaperFigure2, CircularPriorWithRadiusParsesWithACommentAfterTheColon) {
  EXPECT_THAT(OutlineOf(kFig2f),
              ElementsAre("name 1:7 Circular prior (with prior on radius)",
                          "specializes 2:14 Circular prior", "block same_region 3:1",
                          "  energy 4:3 model_likelihood (r13 - 2)^2"));
}

TEST(PaperFigure2, SplinesPriorParsesToOneEnergy) {
  EXPECT_THAT(
      OutlineOf(kFig2g),
      ElementsAre("name 1:7 Splines prior", "order 2:8 2", "max_curvature 3:16 10",
                  "block same_region 4:1", "  energy 5:3 model_likelihood (alpha_2 - alpha_1)^2"));
}

// The printed files also compile (parents from the built-in library), except the circular prior,
// which uses the points p_1..p_3 that the paper leaves out of the figure.
TEST(PaperFigure2, PrintedFilesCompileExceptTheCircularPriorsOmittedPoints) {
  const PriorLibrary library;
  for (const char* text : {kFig2a, kFig2b, kFig2c, kFig2d, kFig2f, kFig2g}) {
    const Result<CompiledPrior> compiled = library.CompileText(text, kPath);
    EXPECT_TRUE(compiled.ok()) << compiled.error();
  }
  const Result<CompiledPrior> circular = library.CompileText(kFig2e, kPath);
  ASSERT_FALSE(circular.ok());
  const int col =
      static_cast<int>(
          std::string("r12 = sin(( alpha_2 - alpha_1 )/2) / norm(p_1 - p_2);").find("p_1")) +
      1;
  EXPECT_THAT(circular.diagnostics(),
              ElementsAre(DiagnosticAt(kPath, 5, col, "unknown name 'p_1'")));
}

// ---------------------------------------------------------------------------------------------
// Lexical conveniences.

TEST(ParserUnicode, GreekLettersAndSubscriptsAreTheAsciiNames) {
  // ρ_1, α₁, φ₂, ϕ_1, α₁₂ and α_₁.
  EXPECT_EQ(TreeOf("\xCF\x81_1 + \xCE\xB1\xE2\x82\x81 + \xCF\x86\xE2\x82\x82 + \xCF\x95_1 == "
                   "\xCE\xB1\xE2\x82\x81\xE2\x82\x82 + \xCE\xB1_\xE2\x82\x81"),
            "(== (+ (+ (+ rho_1 alpha_1) phi_2) phi_1) (+ alpha_12 alpha_1))");
}

TEST(ParserUnicode, GreekNamesCompileToThePredefinedVariables) {
  const Result<CompiledPrior> compiled = PriorLibrary().CompileText(
      "name: T\norder: 2\npriorlet same_region:\n  \xCF\x81_1 == \xCE\xB1\xE2\x82\x82 * "
      "\xCF\x95\xE2\x82\x81\n",
      kPath);
  ASSERT_TRUE(compiled.ok()) << compiled.error();
  const CompiledBlock* block = compiled.value().block(BlockKind::kSameRegion);
  ASSERT_NE(block, nullptr);
  EXPECT_THAT(block->summary().variables, ElementsAre("rho_1", "alpha_2", "phi_1"));
}

TEST(ParserUnicode, ColumnsCountCharactersNotBytes) {
  // α₁ takes 5 bytes and 2 columns: '==' is at column 6.
  const std::vector<Statement> statements = BlockStatements("  \xCE\xB1\xE2\x82\x81 == \xCF\x81_2");
  ASSERT_EQ(statements.size(), 1u);
  EXPECT_EQ(statements[0].expr->loc.col, 6);
  EXPECT_EQ(statements[0].expr->children[1]->loc.col, 9);
}

TEST(ParserStatements, SemicolonAtTheEndOfALineIsOptional) {
  EXPECT_EQ(OutlineOf("name: T\norder: 2\nx = rho_1;\ny = rho_2\n"),
            OutlineOf("name: T\norder: 2\nx = rho_1\ny = rho_2;\n"));
  EXPECT_THAT(OutlineOf("name: T\norder: 2\nx = rho_1;\n"),
              ElementsAre("name 1:7 T", "order 2:8 2", "definition 3:1 x = rho_1"));
}

TEST(ParserStatements, SemicolonsSeparateStatementsOnOneLine) {
  std::vector<std::string> described;
  for (const Statement& s :
       BlockStatements("  a = 1; b = a + rho_1;rho_1 == b; model_likelihood b^2;")) {
    described.push_back(Describe(s));
  }
  EXPECT_THAT(described,
              ElementsAre("definition 4:3 a = 1", "definition 4:10 b = a + rho_1",
                          "constraint 4:24 rho_1 == b", "energy 4:36 model_likelihood b^2"));
}

TEST(ParserStatements, CommentsStartWithHashOrPercent) {
  EXPECT_THAT(OutlineOf("# a prior\n"
                        "name: Commented # not part of the name\n"
                        "% a MATLAB comment\n"
                        "order: 2 % two points\n"
                        "   # an indented comment line is not a block line\n"
                        "x = rho_1 # the first\n"
                        "priorlet same_region: % the block\n"
                        "  # a comment in the block\n"
                        "  x == rho_2 % x is rho_1 # still the comment\n"),
              ElementsAre("name 2:7 Commented", "order 4:8 2", "definition 6:1 x = rho_1",
                          "block same_region 7:1", "  constraint 9:3 x == rho_2"));
}

TEST(ParserStatements, ContinuationLinesJoinIntoOneStatement) {
  EXPECT_THAT(
      OutlineOf("name: T\n"
                "order: 2\n"
                "p = [cos(phi_1); ...  # a comment after the dots\n"
                "sin(phi_1)] * ...\n"
                "    rho_1\n"
                "priorlet same_region:\n"
                "  rho_1 + ...\n"
                "rho_2 == ...\n"
                "      2\n"
                "  rho_2 == 1\n"),
      ElementsAre("name 1:7 T", "order 2:8 2",
                  "definition 3:1 p = [cos(phi_1); sin(phi_1)] * rho_1", "block same_region 6:1",
                  "  constraint 7:3 rho_1 + rho_2 == 2", "  constraint 10:3 rho_2 == 1"));
}

TEST(ParserStatements, BlankLinesCrlfAndAMissingFinalNewlineAreFine) {
  EXPECT_THAT(
      OutlineOf(
          "name: T\r\n\r\norder : 2\r\n   \r\npriorlet same_region:\r\n\r\n  rho_1 == 0\r\n\r\n"
          "  rho_2 == 0"),
      ElementsAre("name 1:7 T", "order 3:9 2", "block same_region 5:1",
                  "  constraint 7:3 rho_1 == 0", "  constraint 9:3 rho_2 == 0"));
}

// Classic Mac OS ends lines with a lone CR: each "\r", "\n" and "\r\n" ends one line (a "\r\n"
// one, not two), so line numbers are the ones an editor shows, whatever the endings and their mix.
TEST(ParserStatements, CrLfAndCrlfEachEndOneLine) {
  const auto expected = ElementsAre("name 1:7 T", "order 2:8 2", "block same_region 3:1",
                                    "  constraint 4:3 rho_1 == 0", "  constraint 6:3 rho_2 == 0");
  EXPECT_THAT(OutlineOf("name: T\rorder: 2\rpriorlet same_region:\r  rho_1 == 0\r\r  rho_2 == 0\r"),
              expected);
  EXPECT_THAT(OutlineOf("name: T\r\norder: 2\rpriorlet same_region:\n  rho_1 == 0\n\r  rho_2 == 0"),
              expected);
  // A continuation joins across a lone CR too.
  EXPECT_THAT(OutlineOf("name: T\rorder: 2\rx = 1 + ...\r  2\r"),
              ElementsAre("name 1:7 T", "order 2:8 2", "definition 3:1 x = 1 + 2"));
}

// "\r\r\n" (CRLF passed twice through a text-mode layer) ends one line, as does any run of CRs
// before an LF; CRs that no LF follows each end one, so "\r\r" in a CR-only file is a blank line.
TEST(ParserStatements, CrsBeforeAnLfEndOneLine) {
  EXPECT_THAT(
      OutlineOf("name: T\r\r\norder: 2\r\r\npriorlet same_region:\r\r\n  alpha_1 == ...\r\r\n"
                "    alpha_2\r\r\r\n  rho_1 == 0\r\r  rho_2 == 0\r\r\r  phi_1 == 0\r\r\n"),
      ElementsAre("name 1:7 T", "order 2:8 2", "block same_region 3:1",
                  "  constraint 4:3 alpha_1 == alpha_2", "  constraint 6:3 rho_1 == 0",
                  "  constraint 8:3 rho_2 == 0", "  constraint 11:3 phi_1 == 0"));
  // A later error names the line an editor shows.
  const Result<PriorFile> parsed = ParsePrior(
      "name: T\r\r\norder: 2\r\r\npriorlet same_region:\r\r\n  alpha_1 == ...\r\r\n    "
      "alpha_2\r\r\n"
      "\r\r\n  rho_1 == 0 $\r\r\n",
      kPath);
  ASSERT_FALSE(parsed.ok());
  EXPECT_THAT(parsed.diagnostics(),
              ElementsAre(DiagnosticAt(kPath, 7, 14, "unexpected character '$'")));
}

// A header value may hold any printable text, tabs and non-ASCII letters included; columns count
// characters.
TEST(ParserStatements, HeaderValuesHoldAnyPrintableText) {
  EXPECT_THAT(OutlineOf("name: R\xC3\xA4ume \xE2\x80\x94 \xCF\x81\tand more\norder:\t2\n"),
              ElementsAre("name 1:7 R\xC3\xA4ume \xE2\x80\x94 \xCF\x81\tand more", "order 2:8 2"));
}

// A diagnostic after lone-CR line endings names the line an editor shows.
TEST(ParserStatements, ErrorsAfterCrLineEndingsNameTheirLine) {
  const Result<PriorFile> parsed =
      ParsePrior("name: T\rorder: 2\rpriorlet same_region:\r  rho_1 == 0 $\r", kPath);
  ASSERT_FALSE(parsed.ok());
  EXPECT_THAT(parsed.diagnostics(),
              ElementsAre(DiagnosticAt(kPath, 4, 14, "unexpected character '$'")));
}

// Windows Notepad starts UTF-8 files with a byte order mark, which editors do not show: it is
// not a character of line 1, so the header parses and columns count from the first visible one.
TEST(ParserStatements, AByteOrderMarkAtTheStartIsIgnored) {
  EXPECT_THAT(OutlineOf("\xEF\xBB\xBFname: T\norder: 2\npriorlet same_region:\n  rho_1 == 0\n"),
              ElementsAre("name 1:7 T", "order 2:8 2", "block same_region 3:1",
                          "  constraint 4:3 rho_1 == 0"));
  const Result<PriorFile> definition_first = ParsePrior("\xEF\xBB\xBFx = 1 +\n", kPath);
  ASSERT_FALSE(definition_first.ok());
  EXPECT_THAT(
      definition_first.diagnostics(),
      ElementsAre(DiagnosticAt(kPath, 1, 8, "expected an expression, got the end of the line")));
}

TEST(ParserStatements, EmptyTextParsesToAnEmptyFile) {
  const Result<PriorFile> parsed = ParsePrior("", kPath);
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_THAT(parsed.value().header, IsEmpty());
  EXPECT_THAT(parsed.value().definitions, IsEmpty());
  EXPECT_THAT(parsed.value().blocks, IsEmpty());
}

TEST(ParserStatements, BlocksEndAtTheNextLineAtColumnOne) {
  EXPECT_THAT(OutlineOf("name: T\norder: 2\n"
                        "priorlet different_surface:\n\trho_1 <= rho_2\n\trho_1 >= 0\n"
                        "d = rho_2 - rho_1\n"
                        "priorlet same_region:\n    model_likelihood d^2\n"),
              ElementsAre("name 1:7 T", "order 2:8 2", "definition 6:1 d = rho_2 - rho_1",
                          "block different_surface 3:1", "  constraint 4:2 rho_1 <= rho_2",
                          "  constraint 5:2 rho_1 >= 0", "block same_region 7:1",
                          "  energy 8:5 model_likelihood d^2"));
}

// ---------------------------------------------------------------------------------------------
// Expressions: MATLAB's rules.

TEST(ParserExpressions, TransposeIsQuoteOrDotQuote) {
  EXPECT_EQ(TreeOf("x = (p_2 - p_1)'"), "(= x (' (- p_2 p_1)))");
  EXPECT_EQ(TreeOf("x = p_1.'"), "(= x (' p_1))");
  EXPECT_EQ(TreeOf("x = p_1''"), "(= x (' (' p_1)))");
  EXPECT_EQ(TreeOf("x = [1 2]'"), "(= x (' (matrix 1x2 1 2)))");
  EXPECT_EQ(TreeOf("x = 2'"), "(= x (' 2))");
  EXPECT_EQ(TreeOf("x = 2.'"), "(= x (' 2))");
}

TEST(ParserExpressions, BlanksInBracketsSeparateElementsAsInMatlab) {
  EXPECT_EQ(TreeOf("x = [a b]"), "(= x (matrix 1x2 a b))");
  EXPECT_EQ(TreeOf("x = [a -b]"), "(= x (matrix 1x2 a (neg b)))");
  EXPECT_EQ(TreeOf("x = [a +b]"), "(= x (matrix 1x2 a b))");
  EXPECT_EQ(TreeOf("x = [a - b]"), "(= x (matrix 1x1 (- a b)))");
  EXPECT_EQ(TreeOf("x = [a-b]"), "(= x (matrix 1x1 (- a b)))");
  EXPECT_EQ(TreeOf("x = [a- b]"), "(= x (matrix 1x1 (- a b)))");
  EXPECT_EQ(TreeOf("x = [a - -b]"), "(= x (matrix 1x1 (- a (neg b))))");
  EXPECT_EQ(TreeOf("x = [a' b']"), "(= x (matrix 1x2 (' a) (' b)))");
  EXPECT_EQ(TreeOf("x = [sin(a)]"), "(= x (matrix 1x1 (call sin a)))");
  EXPECT_EQ(TreeOf("x = [sin (a)]"), "(= x (matrix 1x2 sin a))");
  EXPECT_EQ(TreeOf("x = [2 .5]"), "(= x (matrix 1x2 2 0.5))");
  // Outside brackets blanks do not matter.
  EXPECT_EQ(TreeOf("x = a -b"), "(= x (- a b))");
  EXPECT_EQ(TreeOf("x = sin (a)"), "(= x (call sin a))");
}

TEST(ParserExpressions, SemicolonsStackRowsAndCommasSeparateColumns) {
  EXPECT_EQ(TreeOf("x = [a; b]"), "(= x (matrix 2x1 a b))");
  EXPECT_EQ(TreeOf("x = [a, b]"), "(= x (matrix 1x2 a b))");
  EXPECT_EQ(TreeOf("x = [a,b;c d]"), "(= x (matrix 2x2 a b c d))");
  EXPECT_EQ(TreeOf("x = [a; b;]"), "(= x (matrix 2x1 a b))");
  EXPECT_EQ(TreeOf("x = [[a; b], [c; d]]"), "(= x (matrix 1x2 (matrix 2x1 a b) (matrix 2x1 c d)))");
}

TEST(ParserExpressions, ElementwiseOperatorsTakeTheirMatrixCounterpartsPrecedence) {
  EXPECT_EQ(TreeOf("x = a .* b ./ c .^ d"), "(= x (./ (.* a b) (.^ c d)))");
  // A dot after a number belongs to the operator that follows: 1.*x is 1 .* x.
  EXPECT_EQ(TreeOf("x = 1.*a + 2./b + 3.^c"), "(= x (+ (+ (.* 1 a) (./ 2 b)) (.^ 3 c)))");
  EXPECT_EQ(TreeOf("x = 1..*a"), "(= x (.* 1 a))");
}

TEST(ParserExpressions, UnaryMinusBindsLooserThanPower) {
  EXPECT_EQ(TreeOf("x = -2^2"), "(= x (neg (^ 2 2)))");
  EXPECT_EQ(TreeOf("x = -a'"), "(= x (neg (' a)))");
  EXPECT_EQ(TreeOf("x = 2^-1"), "(= x (^ 2 (neg 1)))");
  EXPECT_EQ(TreeOf("x = 2^-a^b"), "(= x (^ (^ 2 (neg a)) b))");
  EXPECT_EQ(TreeOf("x = a*-b"), "(= x (* a (neg b)))");
  EXPECT_EQ(TreeOf("x = -a*b"), "(= x (* (neg a) b))");
  EXPECT_EQ(TreeOf("x = --a"), "(= x (neg (neg a)))");
  EXPECT_EQ(TreeOf("x = +a"), "(= x a)");
}

TEST(ParserExpressions, PowersAssociateToTheLeft) {
  EXPECT_EQ(TreeOf("x = 2^3^2"), "(= x (^ (^ 2 3) 2))");
  EXPECT_EQ(TreeOf("x = a.^b^c"), "(= x (^ (.^ a b) c))");
  EXPECT_EQ(TreeOf("x = a^b'"), "(= x (^ a (' b)))");
}

TEST(ParserExpressions, ArithmeticPrecedenceAndLeftAssociativity) {
  EXPECT_EQ(TreeOf("a + b * c == d - e - f"), "(== (+ a (* b c)) (- (- d e) f))");
  EXPECT_EQ(TreeOf("a / b * c <= (a + b) * c"), "(<= (* (/ a b) c) (* (+ a b) c))");
  EXPECT_EQ(TreeOf("a >= b"), "(>= a b)");
  EXPECT_EQ(TreeOf("a < b"), "(< a b)");
  EXPECT_EQ(TreeOf("a > b"), "(> a b)");
  EXPECT_EQ(TreeOf("atan2(a, b + c) == max(a)"), "(== (call atan2 a (+ b c)) (call max a))");
}

// Evaluated, the precedence rules give MATLAB's numbers: -2^2 = -4 and 2^3^2 = 64.
TEST(ParserExpressions, CompiledPrecedenceGivesMatlabsValues) {
  const Result<CompiledPrior> compiled = PriorLibrary().CompileText(
      "name: T\norder: 1\npriorlet same_region:\n  model_likelihood rho_1 * -2^2\n"
      "  model_likelihood rho_1 * 2^3^2\n  model_likelihood rho_1 * 2^-1\n  model_likelihood 8 / 4 "
      "/ 2 * rho_1\n",
      kPath);
  ASSERT_TRUE(compiled.ok()) << compiled.error();
  const CompiledBlock* block = compiled.value().block(BlockKind::kSameRegion);
  ASSERT_NE(block, nullptr);
  ASSERT_EQ(block->num_terms(), 4);
  BlockEvaluator evaluator(*block);
  const std::array<double, 2> x = {1.0, 0.0};
  const std::array<double, 1> phi = {0.0};
  std::array<double, 4> values{};
  evaluator.Evaluate(x, phi, values.data());
  EXPECT_THAT(values, ElementsAre(-4.0, 64.0, 0.5, 1.0));
}

TEST(ParserExpressions, OrIsWrittenDoubleOrSingle) {
  EXPECT_EQ(TreeOf("a == 1 || b == 2"), "(|| (== a 1) (== b 2))");
  EXPECT_EQ(TreeOf("a == 1 | b == 2"), "(|| (== a 1) (== b 2))");
  EXPECT_EQ(TreeOf("a == 1 | b == 2 || c <= 3"), "(|| (|| (== a 1) (== b 2)) (<= c 3))");
}

TEST(ParserExpressions, ParenthesesMayHoldComparisonsAndDisjunctions) {
  EXPECT_EQ(TreeOf("(a == b)"), "(== a b)");
  EXPECT_EQ(TreeOf("((a <= b)) || (c == d)"), "(|| (<= a b) (== c d))");
  EXPECT_EQ(TreeOf("(a == b || c == d) || e == f"), "(|| (|| (== a b) (== c d)) (== e f))");
  // As values they parse (and are rejected when compiled: see malformed_test.cpp).
  EXPECT_EQ(TreeOf("x = (a == b)"), "(= x (== a b))");
}

TEST(ParserExpressions, NumbersAreDecimalWithOptionalExponent) {
  EXPECT_EQ(TreeOf("x = 3 + 2.5 + .5 + 1e-3 + 1E+2 + 7."),
            "(= x (+ (+ (+ (+ (+ 3 2.5) 0.5) 0.001) 100) 7))");
}

// The ends of the double range: the largest number and the smallest normal one are numbers, and
// so is a zero written with any exponent (it neither overflows nor underflows).
TEST(ParserExpressions, NumbersUpToTheEndsOfTheNormalRangeAreAccepted) {
  EXPECT_EQ(TreeOf("x = 1.7976931348623157e308 + 2.2250738585072014e-308"),
            "(= x (+ 1.7976931348623157e+308 2.2250738585072014e-308))");
  EXPECT_EQ(TreeOf("x = 0e-400 + 0.000e999"), "(= x (+ 0 0))");
}

// ---------------------------------------------------------------------------------------------
// Printing back.

TEST(ParserToSource, NormalisesSpacingAndKeepsOnlyNeededParentheses) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"(p_2 - p_1)' * [cos( alpha_1 ); sin( alpha_1 )] == 0",
       "(p_2 - p_1)' * [cos(alpha_1); sin(alpha_1)] == 0"},
      {"( alpha_2 == alpha_1 - pi/2 ) || ( alpha_2 == alpha_1 + pi/2 )",
       "alpha_2 == alpha_1 - pi / 2 || alpha_2 == alpha_1 + pi / 2"},
      {"x = ((a + b)) * (c)", "x = (a + b) * c"},
      {"x = a - (b - c)", "x = a - (b - c)"},
      {"x = (a - b) - c", "x = a - b - c"},
      {"x = a / (b * c)", "x = a / (b * c)"},
      {"x = (-a)^2", "x = (-a)^2"},
      {"x = -(a^2)", "x = -a^2"},
      {"x = a^(b^c)", "x = a^(b^c)"},
      {"x = (a^b)^c", "x = a^b^c"},
      {"x = 2^-1", "x = 2^-1"},
      {"x = 2^-(-a')", "x = 2^--a'"},
      {"x = 2^(-(a + b))", "x = 2^(-(a + b))"},
      {"x = a^(-b^c)", "x = a^(-b^c)"},
      {"x = -(-a)", "x = --a"},
      {"x = -(-(a + b))", "x = --(a + b)"},
      {"x = (a + b)'", "x = (a + b)'"},
      {"x = [a -b, c - d; 1 -2 3]", "x = [a, -b, c - d; 1, -2, 3]"},
      {"x = [a (b)]", "x = [a, b]"},
      {"x = 1.5e3 + 0.25", "x = 1500 + 0.25"},
      {"x = (a == b)", "x = (a == b)"},
      {"model_likelihood (a <= b)", "model_likelihood (a <= b)"},
      {"x = sin((a || b))", "x = sin((a || b))"},
      {"x = [(a == b), c]", "x = [(a == b), c]"},
      {"(a == b) + 1 == c", "(a == b) + 1 == c"},
      {"a == b || (c == d || e == f)", "a == b || (c == d || e == f)"},
      {"\xCE\xB1\xE2\x82\x81 == \xCF\x95_2", "alpha_1 == phi_2"},
  };
  for (const auto& [text, printed] : cases) {
    const std::vector<Statement> statements = BlockStatements("  " + text);
    ASSERT_EQ(statements.size(), 1u) << text;
    EXPECT_EQ(ToSource(statements[0]), printed) << text;
    EXPECT_EQ(TreeOf(printed), Tree(statements[0])) << text;
  }
}

// Printing adds no nesting the source did not have: a chain of signs near the parser's nesting
// bound prints as signs, not as -(-(...)), and still parses.
TEST(ParserToSource, SignChainsPrintWithoutParenthesesAndStillParse) {
  for (const std::string& text :
       {"x = " + std::string(99, '-') + "a", "x = 2^" + std::string(98, '-') + "a",
        "x = " + std::string(60, '-') + "(" + std::string(30, '-') + "a)"}) {
    const std::vector<Statement> statements = BlockStatements("  " + text);
    ASSERT_EQ(statements.size(), 1u) << text;
    const std::string printed = ToSource(statements[0]);
    EXPECT_EQ(TreeOf(printed), Tree(statements[0])) << printed;
  }
}

TEST(ParserToSource, RoundTripsEveryBuiltinPrior) {
  for (const auto& [file, text] : BuiltinPriorTexts()) {
    const Result<PriorFile> parsed = ParsePrior(text, file);
    ASSERT_TRUE(parsed.ok()) << parsed.error();
    std::vector<const Statement*> statements;
    for (const Statement& s : parsed.value().definitions) statements.push_back(&s);
    for (const Block& b : parsed.value().blocks) {
      for (const Statement& s : b.statements) statements.push_back(&s);
    }
    ASSERT_FALSE(statements.empty()) << file;
    for (const Statement* s : statements) {
      const std::string printed = ToSource(*s);
      EXPECT_EQ(TreeOf(printed), Tree(*s)) << file << ": " << printed;
    }
  }
}

// Random statements in the language's syntax, with the blanks, parentheses and spellings a
// person might use: printing the parse and parsing that gives the same tree and the same text.
rc::Gen<std::string> GenExpression(int depth);

rc::Gen<std::string> GenAtom() {
  return rc::gen::element<std::string>("rho_1", "alpha_2", "phi_1", "x", "p_1", "tolerance", "pi",
                                       "\xCF\x81_2", "\xCE\xB1\xE2\x82\x81", "0", "2", "0.5", "90",
                                       "1e3", "1.5e-2", ".25", "3.");
}

rc::Gen<std::string> GenComparison(int depth) {
  return rc::gen::apply(
      [](const std::string& a, const std::string& op, const std::string& b) { return a + op + b; },
      GenExpression(depth),
      rc::gen::element<std::string>(" == ", "==", " <= ", " >= ", " < ", " > "),
      GenExpression(depth));
}

rc::Gen<std::string> GenMatrix(int depth) {
  return rc::gen::mapcat(
      rc::gen::pair(rc::gen::inRange(1, 3), rc::gen::inRange(1, 4)),
      [depth](const std::pair<int, int>& shape) {
        const auto [rows, cols] = shape;
        return rc::gen::apply(
            [rows, cols](const std::vector<std::string>& elements,
                         const std::string& column_separator, const std::string& row_separator) {
              std::string out = "[";
              for (int r = 0; r < rows; ++r) {
                if (r > 0) out += row_separator;
                for (int c = 0; c < cols; ++c) {
                  if (c > 0) out += column_separator;
                  out += elements[static_cast<std::size_t>(r * cols + c)];
                }
              }
              return out + "]";
            },
            rc::gen::container<std::vector<std::string>>(static_cast<std::size_t>(rows * cols),
                                                         GenExpression(depth)),
            rc::gen::element<std::string>(", ", ",", " "),
            rc::gen::element<std::string>("; ", ";"));
      });
}

rc::Gen<std::string> GenExpression(int depth) {
  if (depth <= 0) return GenAtom();
  const int d = depth - 1;
  return rc::gen::weightedOneOf<std::string>({
      {3, GenAtom()},
      {4, rc::gen::lazy([d] {
         return rc::gen::apply(
             [](const std::string& a, const std::string& op, const std::string& b) {
               return a + op + b;
             },
             GenExpression(d),
             rc::gen::element<std::string>(" + ", "+", " - ", "-", " * ", "*", " / ", " .* ", ".*",
                                           " ./ ", "^", ".^"),
             GenExpression(d));
       })},
      {1, rc::gen::lazy([d] {
         return rc::gen::apply(
             [](const std::string& sign, const std::string& a) { return sign + a; },
             rc::gen::element<std::string>("-", "+"), GenExpression(d));
       })},
      {1, rc::gen::lazy([d] {
         return rc::gen::apply(
             [](const std::string& a, const std::string& quote) { return a + quote; },
             GenExpression(d), rc::gen::element<std::string>("'", ".'"));
       })},
      {1, rc::gen::lazy([d] {
         return rc::gen::apply(
             [](const std::string& a, const std::string& open) {
               return open + a + (open == "(" ? ")" : " )");
             },
             GenExpression(d), rc::gen::element<std::string>("(", "( "));
       })},
      {1, rc::gen::lazy([d] {
         return rc::gen::apply(
             [](const std::string& name, const std::vector<std::string>& args) {
               std::string out = name + "(";
               for (std::size_t i = 0; i < args.size(); ++i) out += (i > 0 ? ", " : "") + args[i];
               return out + ")";
             },
             rc::gen::element<std::string>("sin", "norm", "atan2", "max", "f"),
             rc::gen::mapcat(rc::gen::inRange<std::size_t>(1, 3), [d](std::size_t n) {
               return rc::gen::container<std::vector<std::string>>(n, GenExpression(d));
             }));
       })},
      {1, rc::gen::lazy([d] { return GenMatrix(d); })},
      {1, rc::gen::lazy([d] {
         return rc::gen::map(GenComparison(d), [](const std::string& c) { return "(" + c + ")"; });
       })},
  });
}

rc::Gen<std::string> GenStatement(int depth) {
  return rc::gen::weightedOneOf<std::string>({
      {2, GenComparison(depth)},
      {1, rc::gen::apply(
              [](const std::vector<std::string>& branches, const std::string& op) {
                std::string out;
                for (std::size_t i = 0; i < branches.size(); ++i)
                  out += (i > 0 ? op : "") + branches[i];
                return out;
              },
              rc::gen::mapcat(rc::gen::inRange<std::size_t>(2, 4),
                              [depth](std::size_t n) {
                                return rc::gen::container<std::vector<std::string>>(
                                    n, rc::gen::oneOf(GenComparison(depth),
                                                      rc::gen::map(GenComparison(depth),
                                                                   [](const std::string& c) {
                                                                     return "( " + c + " )";
                                                                   })));
                              }),
              rc::gen::element<std::string>(" || ", "||", " | "))},
      {1, rc::gen::map(GenExpression(depth), [](const std::string& e) { return "y = " + e; })},
      {1, rc::gen::map(GenExpression(depth),
                       [](const std::string& e) { return "model_likelihood " + e; })},
  });
}

RC_GTEST_PROP(ParserToSource, PrintingAParsedStatementGivesTextThatParsesToTheSameTree, ()) {
  const int depth = *rc::gen::inRange(0, 5);
  const std::string text = *GenStatement(depth);
  const Result<PriorFile> first =
      ParsePrior("name: T\norder: 2\npriorlet same_region:\n  " + text + "\n", kPath);
  RC_ASSERT(first.ok());
  RC_ASSERT(first.value().blocks.size() == 1u);
  RC_ASSERT(first.value().blocks[0].statements.size() == 1u);
  const Statement& statement = first.value().blocks[0].statements[0];
  const std::string printed = ToSource(statement);

  const Result<PriorFile> second =
      ParsePrior("name: T\norder: 2\npriorlet same_region:\n  " + printed + "\n", kPath);
  RC_ASSERT(second.ok());
  RC_ASSERT(second.value().blocks[0].statements.size() == 1u);
  const Statement& reparsed = second.value().blocks[0].statements[0];
  RC_ASSERT(Tree(reparsed) == Tree(statement));
  RC_ASSERT(ToSource(reparsed) == printed);
}

}  // namespace
}  // namespace priormap::dsl
