// The flat instruction tape a CompiledBlock is evaluated from.
//
// Slots are numbered in evaluation order: constants, unknowns x, parameters phi, then one slot
// per instruction, so an instruction's output slot is implicit. The parameter-only part (nodes
// that depend on phi but not on x) runs first and only when phi changes. The rest is ordered
// values first, then what gradients add, then what Hessians add (each part closed under its
// dependencies), so the values-only and values+gradients evaluations are prefixes of one tape.
// Hessians are computed as upper triangles and mirrored on output.
//
// Within each part, instructions are scheduled so that runs of the same operation are as long as
// the dependencies allow, and the tape is executed run by run: one dispatch per run instead of
// one hard-to-predict branch per instruction (about 3x faster on the circular prior).
#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Core>
#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/dsl/prior.hpp>

#include "expression_graph.hpp"

namespace priormap::dsl {
namespace detail {

using Slot = std::uint32_t;

struct Instruction {
  Op op;
  Slot a, b, c, d;
};

// Instructions [begin, end) all perform op.
struct OpRun {
  Op op;
  std::uint32_t begin, end;
};

struct OutputRef {
  Slot slot;
  std::uint32_t index;   // into the output array of one point
  std::uint32_t mirror;  // Hessians: the symmetric entry (== index on the diagonal)
};

struct CompiledTape {
  std::vector<double> initial_slots;  // constants; everything else is written before it is read
  Slot first_var = 0;                 // x_i is slot first_var + i (unused unknowns get a slot too)
  Slot first_param = 0;               // phi_i is slot first_param + i
  Slot first_instruction = 0;         // instruction i writes slot first_instruction + i
  std::size_t parameter_count = 0;    // the first instructions depend on phi only
  std::array<std::size_t, 3> end{};   // tape lengths for values, +gradients, +Hessians
  std::size_t parameter_runs = 0;     // runs of the parameter-only part
  std::array<std::size_t, 3> run_end{};
  std::vector<Instruction> instructions;
  std::vector<OpRun> runs;
  // Short runs are faster dispatched one instruction at a time (then in id order): the branch
  // predictor learns a short sequence of operations but not the exits of tiny run loops.
  bool dispatch_per_instruction = false;
  std::vector<OutputRef> values, gradients, hessians;
};

namespace {

constexpr int kLanes = 8;

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

bool IsLeaf(Op op) {
  return op == Op::kConst || op == Op::kVar || op == Op::kParam;
}

// Orders the nodes of one tape part (ascending ids, so topologically sorted) into long runs of
// the same operation: greedy list scheduling that keeps the current operation while any node
// with it is ready, then switches to the operation with the most ready nodes.
std::vector<std::size_t> ScheduleByOperation(const ExpressionGraph& graph,
                                             const std::vector<std::size_t>& part) {
  std::vector<int> position(graph.size(), -1);
  for (std::size_t p = 0; p < part.size(); ++p) position[part[p]] = static_cast<int>(p);
  std::vector<int> pending(part.size(), 0);
  std::vector<std::vector<std::size_t>> users(part.size());
  for (std::size_t p = 0; p < part.size(); ++p) {
    const Node& n = graph.node(static_cast<NodeId>(part[p]));
    for (NodeId child : {n.a, n.b, n.c, n.d}) {
      if (child < 0 || position[static_cast<std::size_t>(child)] < 0) continue;
      ++pending[p];
      users[static_cast<std::size_t>(position[static_cast<std::size_t>(child)])].push_back(p);
    }
  }
  constexpr std::size_t kOps = static_cast<std::size_t>(Op::kSelect) + 1;
  std::array<std::vector<std::size_t>, kOps> ready;
  const auto op_of = [&](std::size_t p) {
    return static_cast<std::size_t>(graph.node(static_cast<NodeId>(part[p])).op);
  };
  for (std::size_t p = 0; p < part.size(); ++p) {
    if (pending[p] == 0) ready[op_of(p)].push_back(p);
  }
  std::vector<std::size_t> order;
  order.reserve(part.size());
  std::size_t current = 0;
  while (order.size() < part.size()) {
    if (ready[current].empty()) {
      current = static_cast<std::size_t>(
          std::max_element(ready.begin(), ready.end(),
                           [](const auto& a, const auto& b) { return a.size() < b.size(); }) -
          ready.begin());
    }
    const std::size_t p = ready[current].back();
    ready[current].pop_back();
    order.push_back(part[p]);
    for (std::size_t user : users[p]) {
      if (--pending[user] == 0) ready[op_of(user)].push_back(user);
    }
  }
  return order;
}

// One instruction on single values. The common operators are spelled out so that they inline.
inline double Apply(const Instruction& in, const double* s) {
  switch (in.op) {
    case Op::kAdd:
      return s[in.a] + s[in.b];
    case Op::kSub:
      return s[in.a] - s[in.b];
    case Op::kMul:
      return s[in.a] * s[in.b];
    case Op::kDiv:
      return s[in.a] / s[in.b];
    case Op::kNeg:
      return -s[in.a];
    case Op::kSqrt:
      return std::sqrt(s[in.a]);
    case Op::kSin:
      return std::sin(s[in.a]);
    case Op::kCos:
      return std::cos(s[in.a]);
    case Op::kSelect:
      return s[in.a] <= s[in.b] ? s[in.c] : s[in.d];
    default:
      return ApplyOp(in.op, s[in.a], s[in.b], 0.0, 0.0);
  }
}

// Executes runs [begin, end) on single values; instruction i writes slots[first_instruction + i].
void RunTape(const CompiledTape& tape, std::size_t begin, std::size_t end, double* s) {
  const Instruction* const ins = tape.instructions.data();
  double* const out = s + tape.first_instruction;
  if (tape.dispatch_per_instruction) {
    const std::uint32_t last = end > begin ? tape.runs[end - 1].end : 0;
    for (std::uint32_t i = end > begin ? tape.runs[begin].begin : 0; i < last; ++i)
      out[i] = Apply(ins[i], s);
    return;
  }
  for (std::size_t r = begin; r < end; ++r) {
    const auto [op, first, last] = tape.runs[r];
    switch (op) {
      case Op::kAdd:
        for (std::uint32_t i = first; i < last; ++i) out[i] = s[ins[i].a] + s[ins[i].b];
        break;
      case Op::kSub:
        for (std::uint32_t i = first; i < last; ++i) out[i] = s[ins[i].a] - s[ins[i].b];
        break;
      case Op::kMul:
        for (std::uint32_t i = first; i < last; ++i) out[i] = s[ins[i].a] * s[ins[i].b];
        break;
      case Op::kDiv:
        for (std::uint32_t i = first; i < last; ++i) out[i] = s[ins[i].a] / s[ins[i].b];
        break;
      case Op::kNeg:
        for (std::uint32_t i = first; i < last; ++i) out[i] = -s[ins[i].a];
        break;
      case Op::kSqrt:
        for (std::uint32_t i = first; i < last; ++i) out[i] = std::sqrt(s[ins[i].a]);
        break;
      case Op::kSin:
        for (std::uint32_t i = first; i < last; ++i) out[i] = std::sin(s[ins[i].a]);
        break;
      case Op::kCos:
        for (std::uint32_t i = first; i < last; ++i) out[i] = std::cos(s[ins[i].a]);
        break;
      case Op::kSelect:
        for (std::uint32_t i = first; i < last; ++i)
          out[i] = s[ins[i].a] <= s[ins[i].b] ? s[ins[i].c] : s[ins[i].d];
        break;
      default:
        for (std::uint32_t i = first; i < last; ++i)
          out[i] = ApplyOp(op, s[ins[i].a], s[ins[i].b], 0.0, 0.0);
    }
  }
}

// The same on kLanes points at once: slot s of lane l is slots[s * kLanes + l]. Eigen's fixed-size
// arrays give packed (SIMD) arithmetic over the lanes.
void RunLanes(const CompiledTape& tape, std::size_t begin, std::size_t end, double* slots) {
  using Lanes = Eigen::Array<double, kLanes, 1>;
  const auto lane = [slots](Slot s) {
    return Eigen::Map<const Lanes>(slots + static_cast<std::size_t>(s) * kLanes);
  };
  const Instruction* const ins = tape.instructions.data();
  double* const out = slots + static_cast<std::size_t>(tape.first_instruction) * kLanes;
  for (std::size_t r = begin; r < end; ++r) {
    const auto [op, first, last] = tape.runs[r];
    for (std::uint32_t i = first; i < last; ++i) {
      const Instruction& in = ins[i];
      Eigen::Map<Lanes> result(out + static_cast<std::size_t>(i) * kLanes);
      switch (op) {
        case Op::kAdd:
          result = lane(in.a) + lane(in.b);
          break;
        case Op::kSub:
          result = lane(in.a) - lane(in.b);
          break;
        case Op::kMul:
          result = lane(in.a) * lane(in.b);
          break;
        case Op::kDiv:
          result = lane(in.a) / lane(in.b);
          break;
        case Op::kNeg:
          result = -lane(in.a);
          break;
        case Op::kSqrt:
          result = lane(in.a).sqrt();
          break;
        case Op::kSelect:
          result = (lane(in.a) <= lane(in.b)).select(lane(in.c), lane(in.d));
          break;
        default: {
          const Lanes a = lane(in.a), b = lane(in.b);
          for (int l = 0; l < kLanes; ++l) result[l] = ApplyOp(op, a[l], b[l], 0.0, 0.0);
        }
      }
    }
  }
}

}  // namespace
}  // namespace detail

using detail::CompiledTape;
using detail::ExpressionGraph;
using detail::NodeId;
using detail::OutputRef;
using detail::Slot;

const char* ToString(TermKind kind) {
  switch (kind) {
    case TermKind::kEquality:
      return "equality";
    case TermKind::kInequality:
      return "inequality";
    case TermKind::kEnergy:
      return "energy";
  }
  return "?";
}

CompiledBlock::CompiledBlock(BlockKind kind, int order, std::vector<Term> terms,
                             BlockSummary summary, std::shared_ptr<ExpressionGraph> graph,
                             std::vector<int> term_nodes)
    : kind_(kind),
      order_(order),
      terms_(std::move(terms)),
      summary_(std::move(summary)),
      graph_(std::move(graph)),
      term_nodes_(std::move(term_nodes)),
      tape_(std::make_unique<CompiledTape>()) {
  // Derivatives are nodes of the graph too; the graph is complete after this loop.
  ExpressionGraph& g = *graph_;
  const std::size_t nv = static_cast<std::size_t>(num_variables()), nt = terms_.size();
  std::vector<NodeId> hessian(nt * nv * nv, -1);  // upper triangles
  // Forward mode, twice: on the priors we ship this gives the shortest Hessian tapes (reverse
  // mode gives shorter gradients but longer Hessians, forward-over-reverse too).
  for (std::size_t t = 0; t < nt; ++t) {
    for (std::size_t i = 0; i < nv; ++i) {
      const NodeId d = g.Derivative(term_nodes_[t], static_cast<int>(i));
      gradient_nodes_.push_back(d);
      for (std::size_t j = 0; j <= i; ++j)
        hessian[t * nv * nv + j * nv + i] = g.Derivative(d, static_cast<int>(j));
    }
  }

  // Which nodes each level needs (each set closed under dependencies, each a superset of the last).
  std::array<std::vector<char>, 3> needed;
  needed[0].assign(g.size(), 0);
  for (NodeId root : term_nodes_) detail::MarkNeeded(g, root, needed[0]);
  needed[1] = needed[0];
  for (NodeId d : gradient_nodes_) detail::MarkNeeded(g, d, needed[1]);
  needed[2] = needed[1];
  for (NodeId d : hessian) {
    if (d >= 0) detail::MarkNeeded(g, d, needed[2]);
  }

  // Slots: constants, x, phi, then instructions in evaluation order.
  CompiledTape& tape = *tape_;
  std::vector<Slot> slot_of(g.size(), std::numeric_limits<Slot>::max());
  for (std::size_t i = 0; i < g.size(); ++i) {
    const detail::Node& n = g.node(static_cast<NodeId>(i));
    if (n.op == detail::Op::kConst && needed[2][i]) {
      slot_of[i] = static_cast<Slot>(tape.initial_slots.size());
      tape.initial_slots.push_back(n.value);
    }
  }
  tape.first_var = static_cast<Slot>(tape.initial_slots.size());
  tape.first_param = tape.first_var + static_cast<Slot>(nv);
  tape.first_instruction = tape.first_param + static_cast<Slot>(order_);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const detail::Node& n = g.node(static_cast<NodeId>(i));
    if (n.op == detail::Op::kVar) slot_of[i] = tape.first_var + static_cast<Slot>(n.index);
    if (n.op == detail::Op::kParam) slot_of[i] = tape.first_param + static_cast<Slot>(n.index);
  }
  const auto emit = [&](std::size_t i) {
    const detail::Node& n = g.node(static_cast<NodeId>(i));
    const auto s = [&](NodeId child) {
      return child >= 0 ? slot_of[static_cast<std::size_t>(child)] : Slot{0};
    };
    slot_of[i] = tape.first_instruction + static_cast<Slot>(tape.instructions.size());
    tape.instructions.push_back({n.op, s(n.a), s(n.b), s(n.c), s(n.d)});
  };
  // The parameter-only part first, then each level's new nodes, each part scheduled into runs.
  // Node ids are topological, so each part listed in id order respects dependencies.
  // The parts: parameter-only nodes, then each level's new nodes (ascending ids, so each in
  // dependency order).
  std::array<std::vector<std::size_t>, 4> parts;
  std::vector<char> emitted(g.size(), 0);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const detail::Node& n = g.node(static_cast<NodeId>(i));
    if (needed[2][i] && !detail::IsLeaf(n.op) && n.var_mask == 0) {
      parts[0].push_back(i);
      emitted[i] = 1;
    }
  }
  for (std::size_t level = 0; level < 3; ++level) {
    for (std::size_t i = 0; i < g.size(); ++i) {
      if (!needed[level][i] || emitted[i] || detail::IsLeaf(g.node(static_cast<NodeId>(i)).op))
        continue;
      parts[level + 1].push_back(i);
      emitted[i] = 1;
    }
  }
  // Scheduled into runs only where runs average at least three instructions: on short tapes the
  // id order (producers next to their consumers, dispatched one by one) measured faster.
  std::array<std::vector<std::size_t>, 4> scheduled;
  std::size_t runs = 0, instructions = 0;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    scheduled[p] = detail::ScheduleByOperation(g, parts[p]);
    for (std::size_t i = 0; i < scheduled[p].size(); ++i) {
      runs += i == 0 || g.node(static_cast<NodeId>(scheduled[p][i])).op !=
                            g.node(static_cast<NodeId>(scheduled[p][i - 1])).op;
    }
    instructions += parts[p].size();
  }
  tape.dispatch_per_instruction = runs * 3 > instructions;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    bool part_start =
        true;  // runs never cross a part boundary, so every part ends at a run boundary
    for (std::size_t i : tape.dispatch_per_instruction ? parts[p] : scheduled[p]) {
      const detail::Op op = g.node(static_cast<NodeId>(i)).op;
      const auto index = static_cast<std::uint32_t>(tape.instructions.size());
      if (part_start || tape.runs.back().op != op) tape.runs.push_back({op, index, index});
      part_start = false;
      ++tape.runs.back().end;
      emit(i);
    }
    if (p == 0) {
      tape.parameter_count = tape.instructions.size();
      tape.parameter_runs = tape.runs.size();
    } else {
      tape.end[p - 1] = tape.instructions.size();
      tape.run_end[p - 1] = tape.runs.size();
    }
  }
  PRIORMAP_CHECK(
      tape.first_instruction + tape.instructions.size() < std::numeric_limits<Slot>::max(),
      "prior block too large to compile");

  // Outputs; zero derivatives are skipped (the output arrays are zero-filled).
  for (std::size_t t = 0; t < nt; ++t) {
    tape.values.push_back(
        {slot_of[static_cast<std::size_t>(term_nodes_[t])], static_cast<std::uint32_t>(t), 0});
    for (std::size_t i = 0; i < nv; ++i) {
      const NodeId d = gradient_nodes_[t * nv + i];
      if (!g.IsConst(d, 0.0)) {
        tape.gradients.push_back(
            {slot_of[static_cast<std::size_t>(d)], static_cast<std::uint32_t>(t * nv + i), 0});
      }
      for (std::size_t j = 0; j <= i; ++j) {
        const NodeId h = hessian[t * nv * nv + j * nv + i];
        if (g.IsConst(h, 0.0)) continue;
        const std::size_t base = t * nv * nv;
        tape.hessians.push_back({slot_of[static_cast<std::size_t>(h)],
                                 static_cast<std::uint32_t>(base + i * nv + j),
                                 static_cast<std::uint32_t>(base + j * nv + i)});
      }
    }
  }
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
  const CompiledTape& tape = *tape_;
  return {tape.end[0] - tape.parameter_count, tape.end[1] - tape.parameter_count,
          tape.end[2] - tape.parameter_count};
}

BlockEvaluator::BlockEvaluator(const CompiledBlock& block)
    : block_(&block), cached_phi_(static_cast<std::size_t>(block.order()), 0.0) {
  const CompiledTape& tape = *block.tape_;
  const std::size_t slots = tape.first_instruction + tape.instructions.size();
  slots_.assign(slots, 0.0);
  std::copy(tape.initial_slots.begin(), tape.initial_slots.end(), slots_.begin());
  lane_slots_.assign(slots * detail::kLanes, 0.0);
  for (std::size_t s = 0; s < tape.initial_slots.size(); ++s) {
    std::fill_n(lane_slots_.begin() + static_cast<long>(s * detail::kLanes), detail::kLanes,
                tape.initial_slots[s]);
  }
}

namespace {

// Writes one point's outputs from slot values (stride: distance between a slot's values).
void WriteOutputs(const CompiledTape& tape, std::size_t nt, std::size_t nv, const double* slots,
                  std::size_t stride, double* values, double* gradients, double* hessians) {
  if (values) {
    for (const OutputRef& o : tape.values) values[o.index] = slots[o.slot * stride];
  }
  if (gradients) {
    std::fill(gradients, gradients + nt * nv, 0.0);
    for (const OutputRef& o : tape.gradients) gradients[o.index] = slots[o.slot * stride];
  }
  if (hessians) {
    std::fill(hessians, hessians + nt * nv * nv, 0.0);
    for (const OutputRef& o : tape.hessians) {
      hessians[o.index] = slots[o.slot * stride];
      hessians[o.mirror] = slots[o.slot * stride];
    }
  }
}

}  // namespace

void BlockEvaluator::Evaluate(std::span<const double> x, std::span<const double> phi,
                              double* values, double* gradients, double* hessians) {
  const CompiledTape& tape = *block_->tape_;
  const std::size_t nv = static_cast<std::size_t>(block_->num_variables());
  PRIORMAP_DCHECK(x.size() == nv && phi.size() == static_cast<std::size_t>(block_->order()),
                  "x needs 2 * order values and phi order values");
  double* slots = slots_.data();
  if (!phi_valid_ || !std::equal(phi.begin(), phi.end(), cached_phi_.begin())) {
    std::copy(phi.begin(), phi.end(), slots + tape.first_param);
    detail::RunTape(tape, 0, tape.parameter_runs, slots);
    std::copy(phi.begin(), phi.end(), cached_phi_.begin());
    phi_valid_ = true;
  }
  std::copy(x.begin(), x.end(), slots + tape.first_var);
  const std::size_t level = hessians ? 2 : (gradients ? 1 : 0);
  detail::RunTape(tape, tape.parameter_runs, tape.run_end[level], slots);
  WriteOutputs(tape, block_->terms_.size(), nv, slots, 1, values, gradients, hessians);
}

void BlockEvaluator::EvaluateBatch(std::size_t count, std::span<const double> x,
                                   std::span<const double> phi, double* values, double* gradients,
                                   double* hessians) {
  const CompiledTape& tape = *block_->tape_;
  const std::size_t nv = static_cast<std::size_t>(block_->num_variables());
  const std::size_t k = static_cast<std::size_t>(block_->order());
  const std::size_t nt = block_->terms_.size();
  PRIORMAP_CHECK(x.size() == count * nv && phi.size() == count * k,
                 "EvaluateBatch: wrong input sizes");
  const std::size_t level = hessians ? 2 : (gradients ? 1 : 0);
  double* slots = lane_slots_.data();
  constexpr std::size_t kLanes = detail::kLanes;
  const std::size_t parameter_values = tape.parameter_count * kLanes;
  const bool same_phi =
      batch_phi_.size() == phi.size() && std::equal(phi.begin(), phi.end(), batch_phi_.begin());
  if (!same_phi) {
    batch_phi_.assign(phi.begin(), phi.end());
    batch_parameter_slots_.resize((count + kLanes - 1) / kLanes * parameter_values);
  }
  double* parameter_slots = slots + static_cast<std::size_t>(tape.first_instruction) * kLanes;
  for (std::size_t first = 0, chunk = 0; first < count; first += kLanes, ++chunk) {
    const std::size_t lanes = std::min(kLanes, count - first);
    // A short last chunk repeats its last point in the spare lanes.
    for (std::size_t l = 0; l < kLanes; ++l) {
      const std::size_t p = first + std::min(l, lanes - 1);
      for (std::size_t i = 0; i < nv; ++i) slots[(tape.first_var + i) * kLanes + l] = x[p * nv + i];
      for (std::size_t i = 0; i < k; ++i)
        slots[(tape.first_param + i) * kLanes + l] = phi[p * k + i];
    }
    double* cached = batch_parameter_slots_.data() + chunk * parameter_values;
    if (same_phi) {
      std::copy(cached, cached + parameter_values, parameter_slots);
    } else {
      detail::RunLanes(tape, 0, tape.parameter_runs, slots);
      std::copy(parameter_slots, parameter_slots + parameter_values, cached);
    }
    detail::RunLanes(tape, tape.parameter_runs, tape.run_end[level], slots);
    for (std::size_t l = 0; l < lanes; ++l) {
      const std::size_t p = first + l;
      WriteOutputs(tape, nt, nv, slots + l, kLanes, values ? values + p * nt : nullptr,
                   gradients ? gradients + p * nt * nv : nullptr,
                   hessians ? hessians + p * nt * nv * nv : nullptr);
    }
  }
}

CompiledPrior::CompiledPrior(std::string name, int order, double max_curvature,
                             std::vector<PriorOrigin> chain,
                             std::array<std::unique_ptr<CompiledBlock>, kNumBlockKinds> blocks,
                             std::vector<Diagnostic> warnings)
    : name_(std::move(name)),
      order_(order),
      max_curvature_(max_curvature),
      chain_(std::move(chain)),
      blocks_(std::move(blocks)),
      warnings_(std::move(warnings)) {}

const CompiledBlock* CompiledPrior::block(BlockKind kind) const {
  return blocks_[static_cast<std::size_t>(kind)].get();
}

}  // namespace priormap::dsl
