// Printing syntax trees back as priorlet source, with the fewest parentheses that keep the parse.
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <priormap/dsl/ast.hpp>
#include <priormap/dsl/parse.hpp>

namespace priormap::dsl {
namespace {

// Precedences as in the parser: 1 ||, 2 comparison, 3 + -, 4 * / .* ./, 5 unary -, 6 ^ .^, 7
// postfix/atom. Where the grammar wants a value (a definition, an energy, an argument, a matrix
// element) rather than a constraint, a comparison or disjunction keeps its parentheses: (a == b)
// stays so.
constexpr int kValuePrecedence = 3;

int Precedence(const Expr& e) {
  switch (e.kind) {
    case Expr::Kind::kOr:
      return 1;
    case Expr::Kind::kCompare:
      return 2;
    case Expr::Kind::kBinary:
      switch (e.binary) {
        case BinaryOp::kAdd:
        case BinaryOp::kSubtract:
          return 3;
        case BinaryOp::kPower:
        case BinaryOp::kElementPower:
          return 6;
        default:
          return 4;
      }
    case Expr::Kind::kNegate:
      return 5;
    case Expr::Kind::kNumber:
      return e.number < 0 ? 5 : 7;
    default:
      return 7;
  }
}

const char* OperatorText(const Expr& e) {
  if (e.kind == Expr::Kind::kCompare) {
    switch (e.compare) {
      case CompareOp::kEqual:
        return " == ";
      case CompareOp::kLessEqual:
        return " <= ";
      case CompareOp::kGreaterEqual:
        return " >= ";
      case CompareOp::kLess:
        return " < ";
      case CompareOp::kGreater:
        return " > ";
    }
  }
  switch (e.binary) {
    case BinaryOp::kAdd:
      return " + ";
    case BinaryOp::kSubtract:
      return " - ";
    case BinaryOp::kMatrixMultiply:
      return " * ";
    case BinaryOp::kDivide:
      return " / ";
    case BinaryOp::kElementMultiply:
      return " .* ";
    case BinaryOp::kElementDivide:
      return " ./ ";
    case BinaryOp::kElementPower:
      return ".^";
    case BinaryOp::kPower:
      return "^";
  }
  return " ? ";
}

std::string Print(const Expr& e);

// -x, --x, ... with x an atom or a postfix expression (the exponents the grammar takes unwrapped).
bool IsSignedAtom(const Expr& e) {
  const Expr* x = &e;
  while (x->kind == Expr::Kind::kNegate) x = x->children[0].get();
  return x != &e && Precedence(*x) >= 7;
}

std::string Wrapped(const Expr& e, int min_precedence) {
  const std::string text = Print(e);
  return Precedence(e) < min_precedence ? fmt::format("({})", text) : text;
}

std::string Print(const Expr& e) {
  switch (e.kind) {
    case Expr::Kind::kNumber:
      return fmt::format("{}", e.number);
    case Expr::Kind::kName:
      return e.name;
    case Expr::Kind::kNegate: {
      // Sign chains print as signs, --a rather than -(-a): parentheses would nest deeper than the
      // source, past the parser's nesting bound.
      const Expr& child = *e.children[0];
      return fmt::format("-{}",
                         child.kind == Expr::Kind::kNegate ? Print(child) : Wrapped(child, 6));
    }
    case Expr::Kind::kTranspose:
      return fmt::format("{}'", Wrapped(*e.children[0], 7));
    case Expr::Kind::kCall: {
      std::vector<std::string> args;
      for (const ExprPtr& child : e.children) args.push_back(Wrapped(*child, kValuePrecedence));
      return fmt::format("{}({})", e.name, fmt::join(args, ", "));
    }
    case Expr::Kind::kMatrix: {
      std::string out;
      const std::size_t cols =
          e.rows > 0 ? e.children.size() / static_cast<std::size_t>(e.rows) : 0;
      for (std::size_t i = 0; i < e.children.size(); ++i) {
        if (i > 0) out.append(i % cols == 0 ? "; " : ", ");
        out.append(Wrapped(*e.children[i], kValuePrecedence));
      }
      return fmt::format("[{}]", out);
    }
    case Expr::Kind::kOr:
      return fmt::format("{} || {}", Wrapped(*e.children[0], 1), Wrapped(*e.children[1], 2));
    case Expr::Kind::kCompare:
      return fmt::format("{}{}{}", Wrapped(*e.children[0], 3), OperatorText(e),
                         Wrapped(*e.children[1], 3));
    case Expr::Kind::kBinary: {
      const int p = Precedence(e);
      const bool power = e.binary == BinaryOp::kPower || e.binary == BinaryOp::kElementPower;
      // Powers associate to the left: a^b^c is (a^b)^c; their right side needs an atom, or signs
      // before one (2^-1), which print without parentheses as they parse without.
      const Expr& right = *e.children[1];
      return fmt::format(
          "{}{}{}", Wrapped(*e.children[0], p), OperatorText(e),
          power && IsSignedAtom(right) ? Print(right) : Wrapped(right, power ? 7 : p + 1));
    }
  }
  return "?";
}

}  // namespace

std::string ToSource(const Expr& expr) {
  return Print(expr);
}

std::string ToSource(const Statement& statement) {
  switch (statement.kind) {
    case Statement::Kind::kDefinition:
      return fmt::format("{} = {}", statement.name, Wrapped(*statement.expr, kValuePrecedence));
    case Statement::Kind::kEnergy:
      return fmt::format("model_likelihood {}", Wrapped(*statement.expr, kValuePrecedence));
    case Statement::Kind::kConstraint:
      return Print(*statement.expr);
  }
  return "?";
}

}  // namespace priormap::dsl
