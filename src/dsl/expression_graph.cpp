#include "expression_graph.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include <fmt/format.h>

#include <priormap/core/check.hpp>

namespace priormap::dsl::detail {
namespace {

bool IsCommutative(Op op) {
  return op == Op::kAdd || op == Op::kMul;
}

std::uint64_t Bits(double v) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits;
}

}  // namespace

double ApplyOp(Op op, double a, double b, double c, double d) {
  switch (op) {
    case Op::kAdd:
      return a + b;
    case Op::kSub:
      return a - b;
    case Op::kMul:
      return a * b;
    case Op::kDiv:
      return a / b;
    case Op::kNeg:
      return -a;
    case Op::kSqrt:
      return std::sqrt(a);
    case Op::kExp:
      return std::exp(a);
    case Op::kLog:
      return std::log(a);
    case Op::kSin:
      return std::sin(a);
    case Op::kCos:
      return std::cos(a);
    case Op::kTan:
      return std::tan(a);
    case Op::kAsin:
      return std::asin(a);
    case Op::kAcos:
      return std::acos(a);
    case Op::kAtan:
      return std::atan(a);
    case Op::kAbs:
      return std::abs(a);
    case Op::kSign:
      return a > 0.0 ? 1.0 : (a < 0.0 ? -1.0 : 0.0);
    case Op::kAtan2:
      return std::atan2(a, b);
    case Op::kPow:
      return std::pow(a, b);
    case Op::kSelect:
      return a <= b ? c : d;
    case Op::kConst:
    case Op::kVar:
    case Op::kParam:
      break;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

std::size_t ExpressionGraph::KeyHash::operator()(const Node& n) const {
  std::uint64_t h = static_cast<std::uint64_t>(n.op) * 0x9E3779B97F4A7C15ULL;
  for (std::uint64_t v : {static_cast<std::uint64_t>(n.a), static_cast<std::uint64_t>(n.b),
                          static_cast<std::uint64_t>(n.c), static_cast<std::uint64_t>(n.d),
                          Bits(n.value), static_cast<std::uint64_t>(n.index)}) {
    h ^= v + 0x9E3779B97F4A7C15ULL + (h << 6) + (h >> 2);
  }
  return static_cast<std::size_t>(h);
}

bool ExpressionGraph::KeyEqual::operator()(const Node& x, const Node& y) const {
  return x.op == y.op && x.a == y.a && x.b == y.b && x.c == y.c && x.d == y.d &&
         Bits(x.value) == Bits(y.value) && x.index == y.index;
}

ExpressionGraph::ExpressionGraph(int num_vars, int num_params)
    : num_vars_(num_vars), num_params_(num_params) {
  PRIORMAP_CHECK(num_vars >= 0 && num_vars <= 64 && num_params >= 0 && num_params <= 64,
                 "an expression graph has at most 64 unknowns and 64 parameters");
}

bool ExpressionGraph::IsConst(NodeId id, double value) const {
  const Node& n = node(id);
  return n.op == Op::kConst && n.value == value;
}

NodeId ExpressionGraph::Make(Node n) {
  if (IsCommutative(n.op) && n.b < n.a) std::swap(n.a, n.b);  // canonical order: more sharing
  if (const auto it = index_.find(n); it != index_.end()) return it->second;
  for (NodeId child : {n.a, n.b, n.c, n.d}) {
    if (child < 0) continue;
    n.var_mask |= node(child).var_mask;
    n.param_mask |= node(child).param_mask;
    n.depth = std::max(n.depth, node(child).depth + 1);
  }
  if (nodes_.size() >= kMaxNodes) {
    throw GraphLimitExceeded{fmt::format("more than {} distinct subexpressions", kMaxNodes)};
  }
  if (n.depth > kMaxDepth) {
    throw GraphLimitExceeded{fmt::format("operations nested more than {} deep", kMaxDepth)};
  }
  const NodeId id = static_cast<NodeId>(nodes_.size());
  nodes_.push_back(n);
  index_.emplace(n, id);
  return id;
}

NodeId ExpressionGraph::Const(double value) {
  if (value == 0.0) value = 0.0;  // one zero: -0 and 0 fold together
  Node n;
  n.op = Op::kConst;
  n.value = value;
  return Make(n);
}

NodeId ExpressionGraph::Folded(Op op, double result, std::initializer_list<double> operands) {
  const bool normal_operands = std::all_of(operands.begin(), operands.end(),
                                           [](double operand) { return std::isnormal(operand); });
  // From nonzero operands, only a cancellation (1 - 1), log 1 and acos 1 are exactly 0; any
  // other 0, and every subnormal, has lost the value (1e-200 * 1e-200 is not 0) or would lose it
  // in a reciprocal, which overflows: the reasons a literal below the normal range is refused.
  const bool exact_zero = op == Op::kAdd || op == Op::kSub || op == Op::kLog || op == Op::kAcos;
  if (normal_operands && !std::isnormal(result) && std::isfinite(result) &&
      (result != 0.0 || !exact_zero)) {
    ++underflowing_folds_;
  }
  return Const(result);
}

NodeId ExpressionGraph::Var(int index) {
  PRIORMAP_CHECK(index >= 0 && index < num_vars_, "unknown index out of range");
  Node n;
  n.op = Op::kVar;
  n.index = index;
  n.var_mask = std::uint64_t{1} << index;
  return Make(n);
}

NodeId ExpressionGraph::Param(int index) {
  PRIORMAP_CHECK(index >= 0 && index < num_params_, "parameter index out of range");
  Node n;
  n.op = Op::kParam;
  n.index = index;
  n.param_mask = std::uint64_t{1} << index;
  return Make(n);
}

NodeId ExpressionGraph::Add(NodeId a, NodeId b) {
  if (IsConst(a) && IsConst(b))
    return Folded(Op::kAdd, node(a).value + node(b).value, {node(a).value, node(b).value});
  if (IsConst(a, 0.0)) return b;
  if (IsConst(b, 0.0)) return a;
  if (node(b).op == Op::kNeg) return Sub(a, node(b).a);  // a + (-b) = a - b
  if (node(a).op == Op::kNeg) return Sub(b, node(a).a);
  if (a == b) return Mul(Const(2.0), a);  // product rules give x*y + x*y
  return Make({Op::kAdd, a, b});
}

NodeId ExpressionGraph::Sub(NodeId a, NodeId b) {
  if (IsConst(a) && IsConst(b))
    return Folded(Op::kSub, node(a).value - node(b).value, {node(a).value, node(b).value});
  if (a == b) return Const(0.0);
  if (IsConst(b, 0.0)) return a;
  if (IsConst(a, 0.0)) return Neg(b);
  if (node(b).op == Op::kNeg) return Add(a, node(b).a);  // a - (-b) = a + b
  return Make({Op::kSub, a, b});
}

NodeId ExpressionGraph::Mul(NodeId a, NodeId b) {
  if (IsConst(b) && !IsConst(a)) std::swap(a, b);  // constant first
  if (IsConst(a) && IsConst(b))
    return Folded(Op::kMul, node(a).value * node(b).value, {node(a).value, node(b).value});
  if (IsConst(a, 0.0)) return a;  // symbolic zero: derivatives of unused unknowns vanish
  if (IsConst(a, 1.0)) return b;
  if (IsConst(a, -1.0)) return Neg(b);
  if (node(a).op == Op::kNeg && node(b).op == Op::kNeg) return Mul(node(a).a, node(b).a);
  if (node(a).op == Op::kNeg) return Neg(Mul(node(a).a, b));
  if (node(b).op == Op::kNeg) return Neg(Mul(a, node(b).a));
  // c1 * (c2 * x) = (c1 c2) * x, unless c1 c2 overflows or underflows where c1 (c2 x) need not.
  if (IsConst(a) && node(b).op == Op::kMul && IsConst(node(b).a)) {
    const double product = node(a).value * node(node(b).a).value;
    if (std::isnormal(product)) return Mul(Const(product), node(b).b);
  }
  return Make({Op::kMul, a, b});
}

NodeId ExpressionGraph::Div(NodeId a, NodeId b) {
  if (IsConst(a) && IsConst(b))
    return Folded(Op::kDiv, node(a).value / node(b).value, {node(a).value, node(b).value});
  if (IsConst(a, 0.0)) return a;
  if (IsConst(b, 1.0)) return a;
  if (IsConst(b, -1.0)) return Neg(a);
  if (a == b) return Const(1.0);
  if (IsConst(b)) {
    // Multiplying is cheaper, and by a normal reciprocal it rounds at most once more; by an
    // infinite or subnormal one (of a divisor near the ends of the double range) it would change
    // the value written, e.g. x / 1e-320 into x * inf.
    const double reciprocal = 1.0 / node(b).value;
    if (std::isnormal(reciprocal)) return Mul(Const(reciprocal), a);
    return Make({Op::kDiv, a, b});
  }
  if (node(a).op == Op::kNeg) return Neg(Div(node(a).a, b));
  if (node(b).op == Op::kNeg) return Neg(Div(a, node(b).a));
  // a / b = a * (1 / b): derivatives divide many numerators by the same denominators, and one
  // shared reciprocal then replaces a division (slow, ~15 cycles) per numerator.
  if (!IsConst(a, 1.0)) return Mul(a, Div(Const(1.0), b));
  return Make({Op::kDiv, a, b});
}

NodeId ExpressionGraph::Neg(NodeId a) {
  if (IsConst(a)) return Const(-node(a).value);
  if (node(a).op == Op::kNeg) return node(a).a;
  if (node(a).op == Op::kSub) return Sub(node(a).b, node(a).a);  // -(x - y) = y - x
  return Make({Op::kNeg, a});
}

NodeId ExpressionGraph::Pow(NodeId a, NodeId b) {
  if (IsConst(a) && IsConst(b)) {
    return Folded(Op::kPow, std::pow(node(a).value, node(b).value), {node(a).value, node(b).value});
  }
  if (IsConst(b)) {
    const double e = node(b).value;
    if (e == 0.0) return Const(1.0);
    if (e == 1.0) return a;
    if (e == 2.0) return Mul(a, a);
    if (e == 0.5) return Unary(Op::kSqrt, a);
    if (e == -1.0) return Div(Const(1.0), a);
  }
  return Make({Op::kPow, a, b});
}

NodeId ExpressionGraph::Unary(Op op, NodeId a) {
  if (IsConst(a)) return Folded(op, ApplyOp(op, node(a).value, 0.0, 0.0, 0.0), {node(a).value});
  switch (op) {
    case Op::kSin:
      if (node(a).op == Op::kNeg) return Neg(Unary(Op::kSin, node(a).a));
      break;
    case Op::kCos:
      if (node(a).op == Op::kNeg) return Unary(Op::kCos, node(a).a);
      break;
    case Op::kAbs:
      if (node(a).op == Op::kNeg) return Unary(Op::kAbs, node(a).a);
      if (node(a).op == Op::kAbs) return a;
      break;
    case Op::kSqrt:
    case Op::kExp:
    case Op::kLog:
    case Op::kTan:
    case Op::kAsin:
    case Op::kAcos:
    case Op::kAtan:
    case Op::kSign:
      break;
    default:
      PRIORMAP_CHECK(false, "Unary() takes a one-argument function");
  }
  return Make({op, a});
}

NodeId ExpressionGraph::Atan2(NodeId y, NodeId x) {
  if (IsConst(y) && IsConst(x)) {
    return Folded(Op::kAtan2, std::atan2(node(y).value, node(x).value),
                  {node(y).value, node(x).value});
  }
  return Make({Op::kAtan2, y, x});
}

NodeId ExpressionGraph::Select(NodeId a, NodeId b, NodeId then, NodeId otherwise) {
  if (then == otherwise) return then;
  if (IsConst(a) && IsConst(b)) return node(a).value <= node(b).value ? then : otherwise;
  Node n;
  n.op = Op::kSelect;
  n.a = a;
  n.b = b;
  n.c = then;
  n.d = otherwise;
  return Make(n);
}

NodeId ExpressionGraph::GuardedSqrt(NodeId s) {
  const NodeId zero = Const(0.0);
  return Select(s, zero, zero, Unary(Op::kSqrt, s));
}

bool ExpressionGraph::IsGuardedSqrt(NodeId id) const {
  const Node& n = node(id);
  return n.op == Op::kSelect && IsConst(n.b, 0.0) && IsConst(n.c, 0.0) &&
         node(n.d).op == Op::kSqrt && node(n.d).a == n.a;
}

NodeId ExpressionGraph::Min(NodeId a, NodeId b) {
  return Select(a, b, a, b);
}
NodeId ExpressionGraph::Max(NodeId a, NodeId b) {
  return Select(b, a, a, b);
}

NodeId ExpressionGraph::Derivative(NodeId id, int var) {
  PRIORMAP_CHECK(var >= 0 && var < num_vars_, "derivative with respect to an unknown out of range");
  if ((node(id).var_mask & (std::uint64_t{1} << var)) == 0) return Const(0.0);
  const std::uint64_t key = (static_cast<std::uint64_t>(id) << 8) | static_cast<std::uint64_t>(var);
  if (const auto it = derivatives_.find(key); it != derivatives_.end()) return it->second;
  const NodeId d = MakeDerivative(id, var);
  derivatives_.emplace(key, d);
  return d;
}

NodeId ExpressionGraph::MakeDerivative(NodeId id, int var) {
  const Node n = node(id);  // a copy: making nodes may reallocate nodes_
  const auto D = [&](NodeId child) { return Derivative(child, var); };
  switch (n.op) {
    case Op::kConst:
    case Op::kParam:
    case Op::kSign:
      return Const(0.0);
    case Op::kVar:
      return Const(n.index == var ? 1.0 : 0.0);
    case Op::kAdd:
      return Add(D(n.a), D(n.b));
    case Op::kSub:
      return Sub(D(n.a), D(n.b));
    case Op::kMul:
      return Add(Mul(D(n.a), n.b), Mul(n.a, D(n.b)));
    case Op::kDiv:  // (a' - (a/b) b') / b, reusing the node a/b
      return Div(Sub(D(n.a), Mul(id, D(n.b))), n.b);
    case Op::kNeg:
      return Neg(D(n.a));
    case Op::kSqrt:
      return Div(Mul(Const(0.5), D(n.a)), id);
    case Op::kExp:
      return Mul(D(n.a), id);
    case Op::kLog:
      return Div(D(n.a), n.a);
    case Op::kSin:
      return Mul(D(n.a), Unary(Op::kCos, n.a));
    case Op::kCos:
      return Neg(Mul(D(n.a), Unary(Op::kSin, n.a)));
    case Op::kTan:
      return Mul(D(n.a), Add(Const(1.0), Mul(id, id)));
    case Op::kAsin:
      return Div(D(n.a), Unary(Op::kSqrt, Sub(Const(1.0), Mul(n.a, n.a))));
    case Op::kAcos:
      return Neg(Div(D(n.a), Unary(Op::kSqrt, Sub(Const(1.0), Mul(n.a, n.a)))));
    case Op::kAtan:
      return Div(D(n.a), Add(Const(1.0), Mul(n.a, n.a)));
    case Op::kAbs:
      return Mul(D(n.a), Unary(Op::kSign, n.a));
    case Op::kAtan2: {  // d atan2(y, x) = (x y' - y x') / (x^2 + y^2)
      const NodeId y = n.a, x = n.b;
      return Div(Sub(Mul(x, D(y)), Mul(y, D(x))), Add(Mul(x, x), Mul(y, y)));
    }
    case Op::kPow: {
      if (IsConst(n.b) || (node(n.b).var_mask & (std::uint64_t{1} << var)) == 0) {
        // d a^b = b a^(b - 1) a' for b independent of x_var
        return Mul(Mul(n.b, Pow(n.a, Sub(n.b, Const(1.0)))), D(n.a));
      }
      // 0^b is 0 for every b > 0 (and +inf for b < 0): constant on either side, so its
      // derivative is 0, where the general rule below gives 0^b (b' log 0) = 0 * -inf = NaN.
      if (IsConst(n.a, 0.0)) return Const(0.0);
      // d a^b = a^b (b' log a + b a' / a)
      return Mul(id, Add(Mul(D(n.b), Unary(Op::kLog, n.a)), Div(Mul(n.b, D(n.a)), n.a)));
    }
    case Op::kSelect:
      return Select(n.a, n.b, D(n.c), D(n.d));  // the active branch's derivative
  }
  return Const(0.0);
}

double ExpressionGraph::Evaluate(NodeId id, std::span<const double> x,
                                 std::span<const double> phi) const {
  std::vector<double> values(static_cast<std::size_t>(id) + 1);
  for (NodeId i = 0; i <= id; ++i) {
    const Node& n = node(i);
    const auto v = [&](NodeId child) {
      return child >= 0 ? values[static_cast<std::size_t>(child)] : 0.0;
    };
    double out;
    switch (n.op) {
      case Op::kConst:
        out = n.value;
        break;
      case Op::kVar:
        out = x[static_cast<std::size_t>(n.index)];
        break;
      case Op::kParam:
        out = phi[static_cast<std::size_t>(n.index)];
        break;
      default:
        out = ApplyOp(n.op, v(n.a), v(n.b), v(n.c), v(n.d));
    }
    values[static_cast<std::size_t>(i)] = out;
  }
  return values[static_cast<std::size_t>(id)];
}

}  // namespace priormap::dsl::detail
