// The flat instruction tapes a CompiledBlock is evaluated from. Every graph node has a slot in
// the evaluator's array (node ids are a topological order, so a tape is the needed nodes in id
// order). Constants are written once when the evaluator is made; nodes that depend on the beam
// angles only run when phi changes; the rest run on every call, in one of three tapes: values,
// values + gradients, values + gradients + Hessians (upper triangles, mirrored on output).
#include <priormap/core/check.hpp>
#include <priormap/dsl/prior.hpp>

#include <algorithm>
#include <cstring>

#include <fmt/format.h>

#include "expression_graph.hpp"

namespace priormap::dsl {
namespace detail {

struct Instruction {
  Op op;
  std::uint32_t out, a, b, c, d;
};

struct OutputRef {
  std::uint32_t slot;
  std::uint32_t index;  // into the output array
  std::uint32_t mirror; // Hessians: the index of the symmetric entry (== index on the diagonal)
};

struct CompiledTape {
  std::vector<double> initial_slots;
  std::vector<std::uint32_t> var_slots;    // slot of x_i, or kNoSlot
  std::vector<std::uint32_t> param_slots;  // slot of phi_i, or kNoSlot
  std::vector<Instruction> parameter_tape;
  std::array<std::vector<Instruction>, 3> tapes;
  std::vector<OutputRef> values, gradients, hessians;
};

namespace {

constexpr std::uint32_t kNoSlot = 0xFFFFFFFFu;

std::uint32_t Slot(NodeId id) { return static_cast<std::uint32_t>(id); }

// Marks `root` and everything it depends on.
void MarkNeeded(const ExpressionGraph& graph, NodeId root, std::vector<char>& needed) {
  std::vector<NodeId> stack = {root};
  while (!stack.empty()) {
    const NodeId id = stack.back();
    stack.pop_back();
    if (needed[static_cast<std::size_t>(id)]) continue;
    needed[static_cast<std::size_t>(id)] = 1;
    const Node& n = graph.node(id);
    for (NodeId child : {n.a, n.b, n.c, n.d}) {
      if (child >= 0) stack.push_back(child);
    }
  }
}

bool IsLeaf(Op op) { return op == Op::kConst || op == Op::kVar || op == Op::kParam; }

std::vector<Instruction> TapeOf(const ExpressionGraph& graph, const std::vector<char>& needed, bool parameter_only) {
  std::vector<Instruction> tape;
  for (std::size_t i = 0; i < needed.size(); ++i) {
    if (!needed[i]) continue;
    const Node& n = graph.node(static_cast<NodeId>(i));
    if (IsLeaf(n.op)) continue;
    const bool depends_on_x = n.var_mask != 0;
    if (depends_on_x == parameter_only) continue;
    const auto s = [](NodeId child) { return child >= 0 ? Slot(child) : 0u; };
    tape.push_back({n.op, static_cast<std::uint32_t>(i), s(n.a), s(n.b), s(n.c), s(n.d)});
  }
  return tape;
}

// The interpreter loop: the hot path of every prior evaluation.
inline void Run(const std::vector<Instruction>& tape, double* slots) {
  for (const Instruction& in : tape) {
    const double a = slots[in.a];
    double out;
    switch (in.op) {
      case Op::kAdd: out = a + slots[in.b]; break;
      case Op::kSub: out = a - slots[in.b]; break;
      case Op::kMul: out = a * slots[in.b]; break;
      case Op::kDiv: out = a / slots[in.b]; break;
      case Op::kNeg: out = -a; break;
      case Op::kSqrt: out = std::sqrt(a); break;
      case Op::kSin: out = std::sin(a); break;
      case Op::kCos: out = std::cos(a); break;
      default: out = ApplyOp(in.op, a, slots[in.b], slots[in.c], slots[in.d]); break;
    }
    slots[in.out] = out;
  }
}

}  // namespace
}  // namespace detail

using detail::CompiledTape;
using detail::ExpressionGraph;
using detail::NodeId;
using detail::OutputRef;

const char* ToString(TermKind kind) {
  switch (kind) {
    case TermKind::kEquality: return "equality";
    case TermKind::kInequality: return "inequality";
    case TermKind::kEnergy: return "energy";
  }
  return "?";
}

CompiledBlock::CompiledBlock(BlockKind kind, int order, std::vector<Term> terms, BlockSummary summary,
                             std::shared_ptr<ExpressionGraph> graph, std::vector<int> term_nodes)
    : kind_(kind), order_(order), terms_(std::move(terms)), summary_(std::move(summary)), graph_(std::move(graph)),
      term_nodes_(std::move(term_nodes)), tape_(std::make_unique<CompiledTape>()) {
  // Derivatives are nodes of the graph too; the graph is complete after this loop.
  ExpressionGraph& graph_mut = *graph_;
  const int nv = num_variables();
  const std::size_t nt = terms_.size();
  std::vector<std::vector<NodeId>> gradient(nt, std::vector<NodeId>(static_cast<std::size_t>(nv)));
  std::vector<std::vector<NodeId>> hessian(nt, std::vector<NodeId>(static_cast<std::size_t>(nv * nv), -1));
  for (std::size_t t = 0; t < nt; ++t) {
    for (int i = 0; i < nv; ++i) {
      gradient[t][static_cast<std::size_t>(i)] = graph_mut.Derivative(term_nodes_[t], i);
      gradient_nodes_.push_back(gradient[t][static_cast<std::size_t>(i)]);
      for (int j = 0; j <= i; ++j) {
        hessian[t][static_cast<std::size_t>(j * nv + i)] = graph_mut.Derivative(gradient[t][static_cast<std::size_t>(i)], j);
      }
    }
  }
  const ExpressionGraph& g = *graph_;
  CompiledTape& tape = *tape_;
  tape.initial_slots.assign(g.size(), 0.0);
  tape.var_slots.assign(static_cast<std::size_t>(nv), detail::kNoSlot);
  tape.param_slots.assign(static_cast<std::size_t>(order_), detail::kNoSlot);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const detail::Node& n = g.node(static_cast<NodeId>(i));
    if (n.op == detail::Op::kConst) tape.initial_slots[i] = n.value;
    if (n.op == detail::Op::kVar) tape.var_slots[static_cast<std::size_t>(n.index)] = static_cast<std::uint32_t>(i);
    if (n.op == detail::Op::kParam) tape.param_slots[static_cast<std::size_t>(n.index)] = static_cast<std::uint32_t>(i);
  }
  // Zero derivatives are skipped on output (the arrays are zero-filled).
  const auto nonzero = [&](NodeId id) { return !g.IsConst(id, 0.0); };
  std::vector<char> needed(g.size(), 0);
  for (std::size_t t = 0; t < nt; ++t) {
    detail::MarkNeeded(g, term_nodes_[t], needed);
    tape.values.push_back({detail::Slot(term_nodes_[t]), static_cast<std::uint32_t>(t), 0});
  }
  tape.tapes[0] = detail::TapeOf(g, needed, false);
  for (std::size_t t = 0; t < nt; ++t) {
    for (int i = 0; i < nv; ++i) {
      const NodeId d = gradient[t][static_cast<std::size_t>(i)];
      if (!nonzero(d)) continue;
      detail::MarkNeeded(g, d, needed);
      tape.gradients.push_back({detail::Slot(d), static_cast<std::uint32_t>(t * static_cast<std::size_t>(nv) + static_cast<std::size_t>(i)), 0});
    }
  }
  tape.tapes[1] = detail::TapeOf(g, needed, false);
  for (std::size_t t = 0; t < nt; ++t) {
    for (int i = 0; i < nv; ++i) {
      for (int j = 0; j <= i; ++j) {
        const NodeId d = hessian[t][static_cast<std::size_t>(j * nv + i)];
        if (!nonzero(d)) continue;
        detail::MarkNeeded(g, d, needed);
        const std::size_t base = t * static_cast<std::size_t>(nv * nv);
        tape.hessians.push_back({detail::Slot(d), static_cast<std::uint32_t>(base + static_cast<std::size_t>(i * nv + j)),
                                 static_cast<std::uint32_t>(base + static_cast<std::size_t>(j * nv + i))});
      }
    }
  }
  tape.tapes[2] = detail::TapeOf(g, needed, false);
  tape.parameter_tape = detail::TapeOf(g, needed, true);
}

CompiledBlock::~CompiledBlock() = default;
CompiledBlock::CompiledBlock(CompiledBlock&&) noexcept = default;
CompiledBlock& CompiledBlock::operator=(CompiledBlock&&) noexcept = default;

std::string CompiledBlock::VariableName(int v) const {
  return v < order_ ? fmt::format("rho_{}", v + 1) : fmt::format("alpha_{}", v - order_ + 1);
}

std::string CompiledBlock::TermExpression(int t) const {
  PRIORMAP_CHECK(t >= 0 && t < num_terms(), "term index out of range");
  return graph_->Print(term_nodes_[static_cast<std::size_t>(t)], [this](bool is_param, int index) {
    return is_param ? fmt::format("phi_{}", index + 1) : VariableName(index);
  });
}

std::string CompiledBlock::DerivativeExpression(int t, int v) const {
  PRIORMAP_CHECK(t >= 0 && t < num_terms() && v >= 0 && v < num_variables(), "index out of range");
  const NodeId d = gradient_nodes_[static_cast<std::size_t>(t * num_variables() + v)];
  return graph_->Print(d, [this](bool is_param, int index) {
    return is_param ? fmt::format("phi_{}", index + 1) : VariableName(index);
  });
}

std::array<std::size_t, 3> CompiledBlock::TapeLengths() const {
  return {tape_->tapes[0].size(), tape_->tapes[1].size(), tape_->tapes[2].size()};
}

BlockEvaluator::BlockEvaluator(const CompiledBlock& block)
    : block_(&block), slots_(block.tape_->initial_slots), cached_phi_(static_cast<std::size_t>(block.order()), 0.0) {}

void BlockEvaluator::Evaluate(std::span<const double> x, std::span<const double> phi, double* values, double* gradients,
                              double* hessians) {
  const CompiledTape& tape = *block_->tape_;
  const std::size_t nv = static_cast<std::size_t>(block_->num_variables());
  PRIORMAP_DCHECK(x.size() == nv && phi.size() == static_cast<std::size_t>(block_->order()),
                  "x needs 2 * order values and phi order values");
  double* slots = slots_.data();
  if (!phi_valid_ || !std::equal(phi.begin(), phi.end(), cached_phi_.begin())) {
    for (std::size_t i = 0; i < phi.size(); ++i) {
      if (tape.param_slots[i] != detail::kNoSlot) slots[tape.param_slots[i]] = phi[i];
    }
    detail::Run(tape.parameter_tape, slots);
    std::copy(phi.begin(), phi.end(), cached_phi_.begin());
    phi_valid_ = true;
  }
  for (std::size_t i = 0; i < nv; ++i) {
    if (tape.var_slots[i] != detail::kNoSlot) slots[tape.var_slots[i]] = x[i];
  }
  const int level = hessians ? 2 : (gradients ? 1 : 0);
  detail::Run(tape.tapes[static_cast<std::size_t>(level)], slots);
  const std::size_t nt = block_->terms_.size();
  if (values) {
    for (const OutputRef& o : tape.values) values[o.index] = slots[o.slot];
  }
  if (gradients) {
    std::fill(gradients, gradients + nt * nv, 0.0);
    for (const OutputRef& o : tape.gradients) gradients[o.index] = slots[o.slot];
  }
  if (hessians) {
    std::fill(hessians, hessians + nt * nv * nv, 0.0);
    for (const OutputRef& o : tape.hessians) {
      hessians[o.index] = slots[o.slot];
      hessians[o.mirror] = slots[o.slot];
    }
  }
}

CompiledPrior::CompiledPrior(std::string name, int order, double max_curvature, std::vector<PriorOrigin> chain,
                             std::array<std::unique_ptr<CompiledBlock>, kNumBlockKinds> blocks)
    : name_(std::move(name)), order_(order), max_curvature_(max_curvature), chain_(std::move(chain)),
      blocks_(std::move(blocks)) {}

const CompiledBlock* CompiledPrior::block(BlockKind kind) const { return blocks_[static_cast<std::size_t>(kind)].get(); }

}  // namespace priormap::dsl
