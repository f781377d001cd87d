// Infix printing of expression-graph nodes with the fewest parentheses that keep the meaning.
#include <algorithm>
#include <unordered_map>

#include <fmt/format.h>

#include <priormap/core/angles.hpp>

#include "expression_graph.hpp"

namespace priormap::dsl::detail {
namespace {

constexpr int kAddPrecedence = 1, kMulPrecedence = 2, kNegPrecedence = 3, kPowPrecedence = 4,
              kAtomPrecedence = 5;

const char* FunctionName(Op op) {
  switch (op) {
    case Op::kSqrt:
      return "sqrt";
    case Op::kExp:
      return "exp";
    case Op::kLog:
      return "log";
    case Op::kSin:
      return "sin";
    case Op::kCos:
      return "cos";
    case Op::kTan:
      return "tan";
    case Op::kAsin:
      return "asin";
    case Op::kAcos:
      return "acos";
    case Op::kAtan:
      return "atan";
    case Op::kAbs:
      return "abs";
    case Op::kSign:
      return "sign";
    case Op::kAtan2:
      return "atan2";
    default:
      return "?";
  }
}

class Printer {
 public:
  Printer(const ExpressionGraph& graph, const std::function<std::string(bool, int)>& name)
      : graph_(graph), name_(name) {}

  // The text of `id` and its precedence.
  std::pair<std::string, int> Print(NodeId id) const {
    const Node& n = graph_.node(id);
    switch (n.op) {
      case Op::kConst: {
        if (n.value == kPi) return {"pi", kAtomPrecedence};
        return {fmt::format("{}", n.value), n.value < 0 ? kNegPrecedence : kAtomPrecedence};
      }
      case Op::kVar:
        return {name_(false, n.index), kAtomPrecedence};
      case Op::kParam:
        return {name_(true, n.index), kAtomPrecedence};
      case Op::kAdd:
        return Binary(n, " + ", kAddPrecedence);
      case Op::kSub:
        return Binary(n, " - ", kAddPrecedence);
      case Op::kMul: {
        if (n.a == n.b) return {fmt::format("{}^2", Wrapped(n.a, kAtomPrecedence)), kPowPrecedence};
        // a * (1/b), as the graph stores quotients, reads a/b.
        for (const auto& [numerator, reciprocal] : {std::pair{n.a, n.b}, std::pair{n.b, n.a}}) {
          const Node& r = graph_.node(reciprocal);
          if (r.op == Op::kDiv && graph_.IsConst(r.a, 1.0)) {
            Node quotient = n;
            quotient.op = Op::kDiv;
            quotient.a = numerator;
            quotient.b = r.b;
            return Binary(quotient, "/", kMulPrecedence);
          }
        }
        // Constants in front: 0.5*x rather than x*0.5.
        if (graph_.IsConst(n.b) && !graph_.IsConst(n.a)) {
          Node swapped = n;
          std::swap(swapped.a, swapped.b);
          return Binary(swapped, "*", kMulPrecedence);
        }
        return Binary(n, "*", kMulPrecedence);
      }
      case Op::kDiv:
        return Binary(n, "/", kMulPrecedence);
      case Op::kPow:
        return Binary(n, "^", kPowPrecedence);
      // -a*b reads as -(a*b) and means the same, so a product needs no parentheses.
      case Op::kNeg:
        return {fmt::format("-{}", Wrapped(n.a, kMulPrecedence, kAfterOperator)), kNegPrecedence};
      case Op::kAtan2:
        return {fmt::format("atan2({}, {})", Print(n.a).first, Print(n.b).first), kAtomPrecedence};
      case Op::kSelect: {
        if (n.c == n.a && n.d == n.b)
          return {fmt::format("min({}, {})", Print(n.a).first, Print(n.b).first), kAtomPrecedence};
        if (n.c == n.b && n.d == n.a)
          return {fmt::format("max({}, {})", Print(n.a).first, Print(n.b).first), kAtomPrecedence};
        // A guarded sqrt has the value of sqrt (the guard only sets its derivative at 0).
        if (graph_.IsGuardedSqrt(id)) return Print(n.d);
        return {fmt::format("select({} <= {}, {}, {})", Print(n.a).first, Print(n.b).first,
                            Print(n.c).first, Print(n.d).first),
                kAtomPrecedence};
      }
      default:
        return {fmt::format("{}({})", FunctionName(n.op), Print(n.a).first), kAtomPrecedence};
    }
  }

 private:
  // Left operands need parentheses when they bind looser; right operands of - / ^ also when
  // they bind equally (those operators do not associate to the right).
  std::pair<std::string, int> Binary(const Node& n, const char* op, int precedence) const {
    const bool right_strict = n.op == Op::kSub || n.op == Op::kDiv || n.op == Op::kPow;
    const int left_min = n.op == Op::kPow ? precedence + 1 : precedence;
    return {fmt::format("{}{}{}", Wrapped(n.a, left_min), op,
                        Wrapped(n.b, right_strict ? precedence + 1 : precedence, kAfterOperator)),
            precedence};
  }

  // After an operator, a text that starts with a sign (a product whose first factor is a
  // negative constant, -0.5*x) is wrapped too: "a - -0.5*x" and "--0.5*x" read as typos.
  static constexpr bool kAfterOperator = true;
  std::string Wrapped(NodeId id, int min_precedence, bool after_operator = false) const {
    auto [text, precedence] = Print(id);
    const bool signed_text = after_operator && text.starts_with('-');
    return precedence < min_precedence || signed_text ? fmt::format("({})", text) : text;
  }

  const ExpressionGraph& graph_;
  const std::function<std::string(bool, int)>& name_;
};

// How long a node's text would be with every shared subexpression written out in full, at least
// (names and numbers count one character), saturating: definitions used twice per line double the
// text at each line, so a chain of 30 is some 1e15 characters for a graph of 100 nodes.
std::size_t WrittenOutLength(const ExpressionGraph& graph, NodeId id,
                             std::unordered_map<NodeId, std::size_t>& memo) {
  constexpr std::size_t kSaturated = std::size_t{1} << 60;
  if (const auto it = memo.find(id); it != memo.end()) return it->second;
  const Node& n = graph.node(id);
  if (graph.IsGuardedSqrt(id)) return WrittenOutLength(graph, n.d, memo);
  std::size_t length = 1;
  for (const NodeId child : {n.a, n.b, n.c, n.d})
    if (child >= 0) length = std::min(kSaturated, length + WrittenOutLength(graph, child, memo));
  memo.emplace(id, length);
  return length;
}

// Beyond this, a term is described rather than printed: its text would take gigabytes and hours.
constexpr std::size_t kMaxPrintedLength = 100000;

}  // namespace

std::string ExpressionGraph::Print(
    NodeId id, const std::function<std::string(bool is_param, int index)>& name) const {
  std::unordered_map<NodeId, std::size_t> memo;
  if (const std::size_t length = WrittenOutLength(*this, id, memo); length > kMaxPrintedLength)
    return fmt::format(
        "<not printed: written out in full, with its shared subexpressions repeated, it would "
        "take over {:.1e} characters>",
        static_cast<double>(length));
  return Printer(*this, name).Print(id).first;
}

}  // namespace priormap::dsl::detail
