// Recursive-descent parser for priorlet files. Grammar in docs/priorlet-language.md; operator
// precedence as in MATLAB, from loosest: || |, comparisons, + -, * / .* ./, unary + -, ^ .^,
// postfix ' and calls.
#include <algorithm>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>
#include <priormap/dsl/parse.hpp>

#include "lexer.hpp"

namespace priormap::dsl {

const std::string& SourceLocation::file_name() const {
  static const std::string kNone;
  return file ? *file : kNone;
}

const char* ToString(BlockKind kind) {
  switch (kind) {
    case BlockKind::kSameRegion:
      return "same_region";
    case BlockKind::kDifferentRegion:
      return "different_region";
    case BlockKind::kDifferentSurface:
      return "different_surface";
  }
  return "?";
}

const HeaderEntry* PriorFile::Header(const std::string& key) const {
  for (const HeaderEntry& entry : header) {
    if (entry.key == key) return &entry;
  }
  return nullptr;
}

namespace {

using detail::Line;
using detail::Token;
using detail::TokenKind;

// Thrown inside the parser; caught once at the top and turned into the result's diagnostic.
struct ParseError {
  Diagnostic diagnostic;
};

// Parses the tokens of one logical line.
class LineParser {
 public:
  LineParser(const Line& line, std::shared_ptr<const std::string> file)
      : line_(line), file_(std::move(file)) {}

  // statement (';' statement)* [';']
  std::vector<Statement> Statements() {
    std::vector<Statement> statements;
    for (;;) {
      statements.push_back(ParseStatement());
      CheckDepth(*statements.back().expr);
      if (Peek().kind == TokenKind::kSemicolon) {
        Take();
        if (Peek().kind == TokenKind::kEnd) break;
        continue;
      }
      if (Peek().kind == TokenKind::kRParen || Peek().kind == TokenKind::kRBracket) {
        Fail(Peek(),
             fmt::format("unmatched {}: nothing before it on the line opens it", Shown(Peek())));
      }
      if (Peek().kind != TokenKind::kEnd)
        Fail(Peek(), fmt::format("expected ';' or the end of the line, got {}", Shown(Peek())));
      break;
    }
    return statements;
  }

  // 'priorlet' kind ':'
  Block BlockHeader() {
    Block block;
    const Token& keyword = Take();  // 'priorlet'
    block.loc = Location(keyword);
    if (Peek().kind == TokenKind::kAssign)
      Fail(keyword, "'priorlet' is a keyword and cannot be defined");
    const Token& kind = Peek();
    if (kind.kind != TokenKind::kIdentifier) {
      Fail(kind,
           fmt::format(
               "expected a block kind (same_region, different_region or different_surface) after "
               "'priorlet', got {}",
               Shown(kind)));
    }
    if (kind.text == "same_region") {
      block.kind = BlockKind::kSameRegion;
    } else if (kind.text == "different_region") {
      block.kind = BlockKind::kDifferentRegion;
    } else if (kind.text == "different_surface") {
      block.kind = BlockKind::kDifferentSurface;
    } else {
      Fail(kind, fmt::format("unknown block kind '{}' (expected same_region, different_region or "
                             "different_surface)",
                             kind.text));
    }
    Take();
    if (Peek().kind != TokenKind::kColon)
      Fail(Peek(),
           fmt::format("expected ':' after 'priorlet {}', got {}", kind.text, Shown(Peek())));
    Take();
    if (Peek().kind != TokenKind::kEnd) {
      Fail(Peek(),
           "a priorlet block's body goes on the following, indented lines, not after the ':'");
    }
    return block;
  }

  const Token& Peek(std::size_t offset = 0) const {
    const std::size_t i = std::min(next_ + offset, line_.tokens.size() - 1);
    return line_.tokens[i];
  }

  [[noreturn]] void Fail(const Token& at, std::string message) const {
    throw ParseError{{*file_, at.line, at.col, std::move(message)}};
  }

 private:
  const Token& Take() { return line_.tokens[std::min(next_++, line_.tokens.size() - 1)]; }

  // The passes over a syntax tree (checks and lowering, printing) recurse, so a tree may be at most
  // this deep; long operator chains (a + b + c ...) count, as they make left-deep trees. Checked
  // without recursion.
  static constexpr int kMaxTreeDepth = 500;
  void CheckDepth(const Expr& root) const {
    std::vector<std::pair<const Expr*, int>> stack = {{&root, 1}};
    while (!stack.empty()) {
      const auto [e, depth] = stack.back();
      stack.pop_back();
      if (depth > kMaxTreeDepth) {
        throw ParseError{
            {e->loc.file_name(), e->loc.line, e->loc.col,
             fmt::format(
                 "expression too deep: more than {} operations inside one another (split it "
                 "with definitions)",
                 kMaxTreeDepth)}};
      }
      for (const ExprPtr& child : e->children) stack.emplace_back(child.get(), depth + 1);
    }
  }

  // Brackets, parentheses, calls and signs nest by recursion: a bound keeps a hostile line from
  // exhausting the stack (here, and in the recursive passes over the tree that follow).
  static constexpr int kMaxNesting = 100;
  struct Nested {
    explicit Nested(LineParser& parser, const Token& at) : parser_(parser) {
      if (++parser_.depth_ > kMaxNesting) {
        parser_.Fail(
            at, fmt::format(
                    "expression nested too deeply (more than {} levels of parentheses, brackets "
                    "and signs)",
                    kMaxNesting));
      }
    }
    ~Nested() { --parser_.depth_; }
    Nested(const Nested&) = delete;
    Nested& operator=(const Nested&) = delete;
    LineParser& parser_;
  };

  SourceLocation Location(const Token& t) const { return {file_, t.line, t.col}; }

  static std::string Shown(const Token& t) {
    if (t.kind == TokenKind::kIdentifier) return fmt::format("'{}'", t.text);
    if (t.kind == TokenKind::kNumber) return fmt::format("the number {}", t.text);
    return detail::Describe(t.kind);
  }

  Statement ParseStatement() {
    Statement statement;
    const Token& first = Peek();
    statement.loc = Location(first);
    if (first.kind == TokenKind::kIdentifier &&
        (first.text == "priorlet" || first.text == "model_likelihood") &&
        Peek(1).kind == TokenKind::kAssign) {
      Fail(first, fmt::format("'{}' is a keyword and cannot be defined", first.text));
    }
    if (first.kind == TokenKind::kIdentifier && first.text == "priorlet") {
      Fail(first, "'priorlet' starts a block and must be at column 1 (blocks cannot be nested)");
    }
    if (first.kind == TokenKind::kIdentifier && Peek(1).kind == TokenKind::kColon) {
      if (detail::IsHeaderKey(first.text)) {
        Fail(first, fmt::format("'{}:' is a header line and must start at column 1, before the "
                                "first priorlet block",
                                first.text));
      }
      Fail(first,
           fmt::format(
               "unknown header key '{}:' (the keys are name, order, max_curvature and specializes)",
               first.text));
    }
    if (first.kind == TokenKind::kIdentifier && first.text == "model_likelihood") {
      Take();
      if (Peek().kind == TokenKind::kEnd || Peek().kind == TokenKind::kSemicolon) {
        Fail(Peek(), "expected an expression after 'model_likelihood'");
      }
      statement.kind = Statement::Kind::kEnergy;
      statement.expr = Expression(/*in_matrix=*/false);
      return statement;
    }
    if (first.kind == TokenKind::kIdentifier && Peek(1).kind == TokenKind::kAssign) {
      statement.kind = Statement::Kind::kDefinition;
      statement.name = first.text;
      Take();
      Take();
      if (Peek().kind == TokenKind::kEnd || Peek().kind == TokenKind::kSemicolon) {
        Fail(Peek(), fmt::format("expected an expression after '{} ='", statement.name));
      }
      statement.expr = Expression(false);
      return statement;
    }
    statement.kind = Statement::Kind::kConstraint;
    statement.expr = Disjunction();
    return statement;
  }

  std::shared_ptr<Expr> Make(Expr::Kind kind, const Token& at,
                             std::vector<ExprPtr> children = {}) const {
    auto e = std::make_shared<Expr>();
    e->kind = kind;
    e->loc = Location(at);
    e->children = std::move(children);
    return e;
  }
  ExprPtr MakeBinary(BinaryOp op, const Token& at, ExprPtr left, ExprPtr right) const {
    auto e = Make(Expr::Kind::kBinary, at, {std::move(left), std::move(right)});
    e->binary = op;
    return e;
  }

  // disjunction := comparison (('||' | '|') comparison)*
  ExprPtr Disjunction() {
    ExprPtr left = Comparison();
    while (Peek().kind == TokenKind::kOrOr || Peek().kind == TokenKind::kOr) {
      const Token& op = Take();
      left = Make(Expr::Kind::kOr, op, {left, Comparison()});
    }
    return left;
  }

  // comparison := expression [compare expression]   (checked to be a comparison later)
  ExprPtr Comparison() {
    ExprPtr left = Expression(false);
    const TokenKind k = Peek().kind;
    CompareOp op;
    switch (k) {
      case TokenKind::kEqualEqual:
        op = CompareOp::kEqual;
        break;
      case TokenKind::kLessEqual:
        op = CompareOp::kLessEqual;
        break;
      case TokenKind::kGreaterEqual:
        op = CompareOp::kGreaterEqual;
        break;
      case TokenKind::kLess:
        op = CompareOp::kLess;
        break;
      case TokenKind::kGreater:
        op = CompareOp::kGreater;
        break;
      case TokenKind::kAssign:
        Fail(Peek(), "'=' defines a name; a constraint compares with '==', '<=' or '>='");
      default:
        return left;
    }
    const Token& at = Take();
    auto e = Make(Expr::Kind::kCompare, at, {left, Expression(false)});
    e->compare = op;
    const TokenKind after = Peek().kind;
    if (after == TokenKind::kEqualEqual || after == TokenKind::kLessEqual ||
        after == TokenKind::kGreaterEqual || after == TokenKind::kLess ||
        after == TokenKind::kGreater) {
      Fail(Peek(), "comparisons cannot be chained (write a <= b and b <= c as two constraints)");
    }
    return e;
  }

  // expression := term (('+' | '-') term)*
  // Inside [ ], "a -b" is two elements and "a - b" one, as in MATLAB.
  ExprPtr Expression(bool in_matrix) {
    ExprPtr left = Term(in_matrix);
    for (;;) {
      const Token& op = Peek();
      if (op.kind != TokenKind::kPlus && op.kind != TokenKind::kMinus) break;
      if (in_matrix && op.space_before && !op.space_after) break;
      Take();
      left = MakeBinary(op.kind == TokenKind::kPlus ? BinaryOp::kAdd : BinaryOp::kSubtract, op,
                        left, Term(in_matrix));
    }
    return left;
  }

  // term := unary (('*' | '/' | '.*' | './') unary)*
  ExprPtr Term(bool in_matrix) {
    ExprPtr left = Unary(in_matrix);
    for (;;) {
      const TokenKind k = Peek().kind;
      BinaryOp op;
      if (k == TokenKind::kStar)
        op = BinaryOp::kMatrixMultiply;
      else if (k == TokenKind::kSlash)
        op = BinaryOp::kDivide;
      else if (k == TokenKind::kDotStar)
        op = BinaryOp::kElementMultiply;
      else if (k == TokenKind::kDotSlash)
        op = BinaryOp::kElementDivide;
      else
        break;
      const Token& at = Take();
      left = MakeBinary(op, at, left, Unary(in_matrix));
    }
    return left;
  }

  // unary := ('-' | '+') unary | power
  ExprPtr Unary(bool in_matrix) {
    const Nested nested(*this, Peek());
    if (Peek().kind == TokenKind::kMinus) {
      const Token& at = Take();
      return Make(Expr::Kind::kNegate, at, {Unary(in_matrix)});
    }
    if (Peek().kind == TokenKind::kPlus) {
      Take();
      return Unary(in_matrix);
    }
    return Power(in_matrix);
  }

  // power := postfix (('^' | '.^') power_operand)*   (left-associative, as in MATLAB)
  ExprPtr Power(bool in_matrix) {
    ExprPtr left = Postfix(in_matrix);
    while (Peek().kind == TokenKind::kCaret || Peek().kind == TokenKind::kDotCaret) {
      const Token& at = Take();
      left = MakeBinary(at.kind == TokenKind::kCaret ? BinaryOp::kPower : BinaryOp::kElementPower,
                        at, left, PowerOperand(in_matrix));
    }
    return left;
  }

  // A signed exponent is allowed: 2^-1.
  ExprPtr PowerOperand(bool in_matrix) {
    const Nested nested(*this, Peek());
    if (Peek().kind == TokenKind::kMinus) {
      const Token& at = Take();
      return Make(Expr::Kind::kNegate, at, {PowerOperand(in_matrix)});
    }
    if (Peek().kind == TokenKind::kPlus) {
      Take();
      return PowerOperand(in_matrix);
    }
    return Postfix(in_matrix);
  }

  // postfix := primary ('\'')*
  ExprPtr Postfix(bool in_matrix) {
    ExprPtr e = Primary(in_matrix);
    while (Peek().kind == TokenKind::kTranspose) {
      const Token& at = Take();
      e = Make(Expr::Kind::kTranspose, at, {e});
    }
    return e;
  }

  ExprPtr Primary(bool in_matrix) {
    const Token& t = Peek();
    switch (t.kind) {
      case TokenKind::kNumber: {
        Take();
        auto e = Make(Expr::Kind::kNumber, t);
        e->number = t.number;
        return e;
      }
      case TokenKind::kIdentifier: {
        // Keywords are not names: printed back at the start of a statement, one would change its
        // kind.
        if (t.text == "model_likelihood") {
          Fail(t,
               "'model_likelihood' starts an energy statement ('model_likelihood expression'); it "
               "cannot be "
               "used in an expression");
        }
        if (t.text == "priorlet")
          Fail(t, "'priorlet' starts a block; it cannot be used in an expression");
        Take();
        auto e = std::make_shared<Expr>();
        e->loc = Location(t);
        e->name = t.text;
        if (Peek().kind == TokenKind::kLParen && !(in_matrix && Peek().space_before)) {
          e->kind = Expr::Kind::kCall;
          e->children = Arguments(t);
        } else {
          e->kind = Expr::Kind::kName;
        }
        return e;
      }
      case TokenKind::kLParen: {
        Take();
        // Parentheses may hold a comparison or a disjunction: ( a == b ) || ( a == c ).
        ExprPtr inner = Disjunction();
        Expect(TokenKind::kRParen, t, "')' to close the '('");
        return inner;
      }
      case TokenKind::kLBracket:
        return Matrix(t);
      default:
        Fail(t, fmt::format("expected an expression, got {}", Shown(t)));
    }
  }

  std::vector<ExprPtr> Arguments(const Token& name) {
    const Token& open = Take();  // '('
    std::vector<ExprPtr> args;
    if (Peek().kind == TokenKind::kRParen) {
      Take();
      return args;
    }
    for (;;) {
      args.push_back(Expression(false));
      if (Peek().kind == TokenKind::kComma) {
        Take();
        continue;
      }
      Expect(TokenKind::kRParen, open,
             fmt::format("',' or ')' in the arguments of '{}'", name.text));
      return args;
    }
  }

  // '[' row (';' row)* ']' with elements separated by ',' or blanks.
  ExprPtr Matrix(const Token& open) {
    Take();  // '['
    std::vector<std::vector<ExprPtr>> rows(1);
    for (;;) {
      const Token& t = Peek();
      if (t.kind == TokenKind::kRBracket) {
        Take();
        break;
      }
      if (t.kind == TokenKind::kEnd)
        Fail(open, "unterminated '[': expected ']' before the end of the line");
      if (t.kind == TokenKind::kSemicolon) {
        Take();
        rows.emplace_back();
        continue;
      }
      if (t.kind == TokenKind::kComma) {
        if (rows.back().empty()) Fail(t, "expected a matrix element before ','");
        Take();
        if (Peek().kind == TokenKind::kRBracket || Peek().kind == TokenKind::kSemicolon) {
          Fail(Peek(), "expected a matrix element after ','");
        }
        rows.back().push_back(Expression(true));
        continue;
      }
      if (rows.back().empty()) {
        if (!StartsOperand(t.kind))
          Fail(t, fmt::format("expected a matrix element or ']', got {}", Shown(t)));
      } else if (!t.space_before || !StartsOperand(t.kind)) {
        Fail(t, fmt::format("expected ',', ';' or ']' in the matrix opened at column {}, got {}",
                            open.col, Shown(t)));
      }
      rows.back().push_back(Expression(true));
    }
    if (!rows.empty() && rows.back().empty() && rows.size() > 1) rows.pop_back();  // "[a; b;]"
    if (rows.size() == 1 && rows[0].empty()) Fail(open, "empty matrix '[]'");
    const std::size_t width = rows[0].size();
    auto e = Make(Expr::Kind::kMatrix, open);
    e->rows = static_cast<int>(rows.size());
    for (std::size_t r = 0; r < rows.size(); ++r) {
      if (rows[r].size() != width) {
        Fail(open, fmt::format("matrix rows must have the same length: row 1 has {}, row {} has {}",
                               width, r + 1, rows[r].size()));
      }
      for (ExprPtr& element : rows[r]) e->children.push_back(std::move(element));
    }
    return e;
  }

  static bool StartsOperand(TokenKind kind) {
    return kind == TokenKind::kNumber || kind == TokenKind::kIdentifier ||
           kind == TokenKind::kLParen || kind == TokenKind::kLBracket ||
           kind == TokenKind::kMinus || kind == TokenKind::kPlus;
  }

  void Expect(TokenKind kind, const Token& opened_at, const std::string& what) {
    if (Peek().kind == kind) {
      Take();
      return;
    }
    if (Peek().kind == TokenKind::kEnd) {
      Fail(opened_at, fmt::format("unterminated {}: expected {} before the end of the line",
                                  detail::Describe(opened_at.kind), detail::Describe(kind)));
    }
    Fail(Peek(), fmt::format("expected {}, got {}", what, Shown(Peek())));
  }

  const Line& line_;
  std::shared_ptr<const std::string> file_;
  std::size_t next_ = 0;
  int depth_ = 0;
};

class FileParser {
 public:
  explicit FileParser(const std::string& path) : file_(std::make_shared<const std::string>(path)) {}

  PriorFile Parse(const std::vector<Line>& lines) {
    PriorFile prior;
    prior.path = *file_;
    for (const Line& line : lines) {
      if (line.is_header) {
        Header(line, prior);
      } else if (line.indent_width == 0) {
        TopLevel(line, prior);
      } else {
        BlockLine(line, prior);
      }
    }
    CloseBlock(prior);
    return prior;
  }

 private:
  [[noreturn]] void Fail(int line, int col, std::string message) const {
    throw ParseError{{*file_, line, col, std::move(message)}};
  }

  void Header(const Line& line, PriorFile& prior) {
    CloseBlock(prior);
    if (!prior.blocks.empty()) {
      Fail(line.number, 1,
           fmt::format("'{}:' must come before the first priorlet block", line.header_key));
    }
    if (const HeaderEntry* previous = prior.Header(line.header_key)) {
      Fail(line.number, 1,
           fmt::format("duplicate '{}:' (already given at line {})", line.header_key,
                       previous->loc.line));
    }
    if (line.header_value.empty()) {
      Fail(line.number, line.header_value_col,
           fmt::format("expected a value after '{}:'", line.header_key));
    }
    prior.header.push_back({line.header_key,
                            line.header_value,
                            {file_, line.number, 1},
                            {file_, line.number, line.header_value_col}});
  }

  void TopLevel(const Line& line, PriorFile& prior) {
    CloseBlock(prior);
    LineParser parser(line, file_);
    const Token& first = parser.Peek();
    if (first.kind == TokenKind::kIdentifier && first.text == "priorlet") {
      Block block = parser.BlockHeader();
      for (const Block& existing : prior.blocks) {
        if (existing.kind == block.kind) {
          parser.Fail(first, fmt::format("duplicate 'priorlet {}' block (the first is at line {})",
                                         ToString(block.kind), existing.loc.line));
        }
      }
      prior.blocks.push_back(std::move(block));
      open_block_ = true;
      body_indentation_.reset();
      return;
    }
    for (Statement& statement : parser.Statements()) {
      if (statement.kind != Statement::Kind::kDefinition) {
        throw ParseError{{*file_, statement.loc.line, statement.loc.col,
                          statement.kind == Statement::Kind::kEnergy
                              ? "'model_likelihood' must be inside a priorlet block (indent it "
                                "under 'priorlet ...:')"
                              : "a constraint must be inside a priorlet block (indent it under "
                                "'priorlet ...:'); "
                                "at file scope only definitions 'name = expression' are allowed"}};
      }
      prior.definitions.push_back(std::move(statement));
    }
  }

  // Columns count characters, as everywhere in diagnostics: a line's first character after its
  // indentation (blanks only) is at column indentation.size() + 1.
  void BlockLine(const Line& line, PriorFile& prior) {
    const int col = static_cast<int>(line.indentation.size()) + 1;
    if (!open_block_) {
      Fail(line.number, col,
           "unexpected indentation: only the lines of a priorlet block are indented");
    }
    if (!body_indentation_) {
      body_indentation_ = line.indentation;
    } else if (line.indentation != *body_indentation_) {
      const bool tabs = line.indentation.find('\t') != std::string::npos ||
                        body_indentation_->find('\t') != std::string::npos;
      if (tabs) {
        Fail(line.number, col,
             fmt::format("inconsistent indentation: this line is indented with {}, the block's "
                         "first line with {} "
                         "(do not mix tabs and spaces)",
                         Blanks(line.indentation), Blanks(*body_indentation_)));
      }
      Fail(line.number, col,
           fmt::format("inconsistent indentation: the lines of this block start at column {}",
                       body_indentation_->size() + 1));
    }
    LineParser parser(line, file_);
    for (Statement& statement : parser.Statements())
      prior.blocks.back().statements.push_back(std::move(statement));
  }

  // "2 spaces", "1 tab", "1 tab and 2 spaces".
  static std::string Blanks(const std::string& indentation) {
    const auto tabs = std::count(indentation.begin(), indentation.end(), '\t');
    const auto spaces = static_cast<std::ptrdiff_t>(indentation.size()) - tabs;
    const auto count = [](std::ptrdiff_t n, const char* what) {
      return fmt::format("{} {}{}", n, what, n == 1 ? "" : "s");
    };
    if (tabs == 0) return count(spaces, "space");
    if (spaces == 0) return count(tabs, "tab");
    return count(tabs, "tab") + " and " + count(spaces, "space");
  }

  // A block ends at the next line at column 1 (or at the end of the file); it may not be empty.
  void CloseBlock(const PriorFile& prior) {
    if (!open_block_) return;
    open_block_ = false;
    const Block& block = prior.blocks.back();
    if (block.statements.empty()) {
      throw ParseError{
          {*file_, block.loc.line, block.loc.col,
           fmt::format("empty block 'priorlet {}': give its constraints on the following, indented "
                       "lines, or leave the block out (no block means no constraint)",
                       ToString(block.kind))}};
    }
  }

  std::shared_ptr<const std::string> file_;
  bool open_block_ = false;
  std::optional<std::string> body_indentation_;
};

}  // namespace

Result<PriorFile> ParsePrior(std::string_view text, const std::string& path) {
  const auto file = std::make_shared<const std::string>(path);
  Result<std::vector<Line>> lines = detail::Lex(text, file);
  if (!lines) return lines.diagnostics();
  try {
    return FileParser(path).Parse(lines.value());
  } catch (const ParseError& error) {
    return error.diagnostic;
  }
}

Result<PriorFile> ReadPriorFile(const std::filesystem::path& path) {
  Result<std::string> text = ReadFileText(path);
  if (!text) return text.diagnostics();
  return ParsePrior(text.value(), path.string());
}

}  // namespace priormap::dsl
