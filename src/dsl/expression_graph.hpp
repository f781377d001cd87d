#pragma once
// A DAG of scalar expressions over the unknowns x = (rho_1..rho_k, alpha_1..alpha_k) and the
// parameters phi_1..phi_k. Nodes are hash-consed (a node is created once, so common
// subexpressions are shared), constants are folded and simple algebraic identities applied as
// nodes are made, and symbolic derivatives are nodes of the same graph. Node ids are a
// topological order: children always have smaller ids.

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

namespace priormap::dsl::detail {

using NodeId = int;

enum class Op : std::uint8_t {
  kConst,
  kVar,
  kParam,
  kAdd,
  kSub,
  kMul,
  kDiv,
  kNeg,
  kSqrt,
  kExp,
  kLog,
  kSin,
  kCos,
  kTan,
  kAsin,
  kAcos,
  kAtan,
  kAbs,
  kSign,
  kAtan2,   // atan2(a, b)
  kPow,     // a ^ b
  kSelect,  // a <= b ? c : d
};

struct Node {
  Op op = Op::kConst;
  NodeId a = -1, b = -1, c = -1, d = -1;
  double value = 0.0;            ///< kConst
  int index = 0;                 ///< kVar, kParam
  std::uint64_t var_mask = 0;    ///< unknowns this node depends on (bit i: x_i)
  std::uint64_t param_mask = 0;  ///< parameters it depends on
  int depth = 0;                 ///< longest path to a leaf (leaves: 0)
};

/// Thrown when making a node would exceed ExpressionGraph::kMaxNodes or kMaxDepth (the graph is
/// unchanged). Lowering turns it into a located diagnostic.
struct GraphLimitExceeded {
  std::string message;
};

class ExpressionGraph {
 public:
  /// Bounds that keep a hostile prior from exhausting memory, and the recursive passes over the
  /// graph (derivatives, printing) from exhausting the stack. Real priors are far below both.
  static constexpr std::size_t kMaxNodes = std::size_t{1} << 17;
  static constexpr int kMaxDepth = 2000;

  /// `num_vars` unknowns and `num_params` parameters, each at most 64.
  ExpressionGraph(int num_vars, int num_params);

  [[nodiscard]] int num_vars() const { return num_vars_; }
  [[nodiscard]] int num_params() const { return num_params_; }
  [[nodiscard]] std::size_t size() const { return nodes_.size(); }
  [[nodiscard]] const Node& node(NodeId id) const { return nodes_[static_cast<std::size_t>(id)]; }
  [[nodiscard]] bool IsConst(NodeId id, double value) const;
  [[nodiscard]] bool IsConst(NodeId id) const { return node(id).op == Op::kConst; }

  NodeId Const(double value);
  NodeId Var(int index);
  NodeId Param(int index);
  NodeId Add(NodeId a, NodeId b);
  NodeId Sub(NodeId a, NodeId b);
  NodeId Mul(NodeId a, NodeId b);
  NodeId Div(NodeId a, NodeId b);
  NodeId Neg(NodeId a);
  NodeId Pow(NodeId a, NodeId b);
  /// sqrt exp log sin cos tan asin acos atan abs sign.
  NodeId Unary(Op op, NodeId a);
  NodeId Atan2(NodeId y, NodeId x);
  NodeId Min(NodeId a, NodeId b);
  NodeId Max(NodeId a, NodeId b);
  /// a <= b ? then : otherwise.
  NodeId Select(NodeId a, NodeId b, NodeId then, NodeId otherwise);
  /// sqrt(s) of an `s` >= 0 (a sum of squares), with the derivative 0 where s = 0 (a kink, as
  /// a norm's at 0) rather than 0 * (1 / 0) = NaN: the node s <= 0 ? 0 : sqrt(s).
  NodeId GuardedSqrt(NodeId s);
  /// Whether `id` was made by GuardedSqrt.
  [[nodiscard]] bool IsGuardedSqrt(NodeId id) const;

  /// How many operations on constants have folded to a magnitude below the smallest normal one
  /// (0 or a subnormal) from nonzero normal operands, e.g. 1e-200 * 1e-200: lowering compares
  /// the counts before and after an operation to report it at its place.
  [[nodiscard]] std::size_t underflowing_folds() const { return underflowing_folds_; }

  /// d node / d x_var, as a node (memoised; forward mode).
  NodeId Derivative(NodeId id, int var);

  /// The value of `id` for unknowns `x` and parameters `phi` (slow; for tests and checks).
  [[nodiscard]] double Evaluate(NodeId id, std::span<const double> x,
                                std::span<const double> phi) const;
  /// Infix text, with `name(var)` / `param_name(index)` naming leaves.
  [[nodiscard]] std::string Print(
      NodeId id, const std::function<std::string(bool is_param, int index)>& name) const;

 private:
  NodeId Make(Node node);
  /// The constant `result` of `op` on constant `operands`, counted when it underflows.
  NodeId Folded(Op op, double result, std::initializer_list<double> operands);
  NodeId MakeDerivative(NodeId id, int var);

  struct KeyHash {
    std::size_t operator()(const Node& n) const;
  };
  struct KeyEqual {
    bool operator()(const Node& x, const Node& y) const;
  };

  int num_vars_;
  int num_params_;
  std::vector<Node> nodes_;
  std::unordered_map<Node, NodeId, KeyHash, KeyEqual> index_;
  std::unordered_map<std::uint64_t, NodeId> derivatives_;  // (node << 8 | var) -> derivative
  std::size_t underflowing_folds_ = 0;
};

/// One application of an operator to node values (shared by Evaluate and the tape).
double ApplyOp(Op op, double a, double b, double c, double d);

}  // namespace priormap::dsl::detail
