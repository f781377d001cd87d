// Checking and lowering: every expression is evaluated symbolically into a matrix of graph
// nodes, so that shape errors, unknown names and bad indices surface with their location.
#include "lower.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string_view>

#include <fmt/format.h>

#include <priormap/core/angles.hpp>
#include <priormap/dsl/parse.hpp>

#include "constant_constraints.hpp"
#include "expression_graph.hpp"

namespace priormap::dsl::detail {
namespace {

constexpr int kMaxOrder = 16;
// Bounds on what one prior may ask for, so that a small hostile file cannot make the compiler
// allocate without limit: entries of one matrix value, multiply-adds of one matrix product,
// scalar terms of one block. (The expression graph bounds its own size and depth.)
constexpr long long kMaxEntries = 1024;
constexpr long long kMaxProductWork = 1 << 18;
constexpr std::size_t kMaxTerms = 1024;

struct CompileError {
  Diagnostic diagnostic;
};

[[noreturn]] void Fail(const SourceLocation& at, std::string message) {
  throw CompileError{{at.file_name(), at.line, at.col, std::move(message)}};
}

// A matrix of graph nodes, row-major.
struct Value {
  int rows = 1;
  int cols = 1;
  std::vector<NodeId> entries;

  [[nodiscard]] bool IsScalar() const { return rows == 1 && cols == 1; }
  [[nodiscard]] std::string Shape() const { return fmt::format("{}x{}", rows, cols); }
  [[nodiscard]] NodeId at(int r, int c) const {
    return entries[static_cast<std::size_t>(r * cols + c)];
  }
};

Value Scalar(NodeId id) {
  return {1, 1, {id}};
}

// The header values of a prior and its ancestors, the nearest given one winning.
struct Header {
  std::string name;
  int order = 0;
  SourceLocation order_loc;  // of the value that wins, which a child can set for its parent's text
  double max_curvature = std::numeric_limits<double>::infinity();
};

int ParseOrder(const HeaderEntry& entry) {
  int order = 0;
  const auto [ptr, ec] =
      std::from_chars(entry.value.data(), entry.value.data() + entry.value.size(), order);
  if (ec != std::errc() || ptr != entry.value.data() + entry.value.size() || order < 1 ||
      order > kMaxOrder) {
    Fail(entry.value_loc, fmt::format("order must be a whole number from 1 to {}, got {}",
                                      kMaxOrder, QuoteForMessage(entry.value)));
  }
  return order;
}

double ParseCurvature(const HeaderEntry& entry) {
  if (entry.value == "inf") return std::numeric_limits<double>::infinity();
  double value = 0.0;
  const auto [ptr, ec] =
      std::from_chars(entry.value.data(), entry.value.data() + entry.value.size(), value);
  const bool whole = ptr == entry.value.data() + entry.value.size();
  const bool out_of_range = ec == std::errc::result_out_of_range;
  // The sign is read from the text: out of range, from_chars leaves `value` at 0, and "-0" is a
  // sign the author wrote by mistake.
  const bool negative = entry.value.starts_with('-');
  if (!whole || (ec != std::errc() && !out_of_range) || !(value >= 0.0) || negative) {
    Fail(entry.value_loc,
         fmt::format("max_curvature must be a non-negative number (1/m) or inf, got {}",
                     QuoteForMessage(entry.value)));
  }
  // As for the literals of the expressions (lexer.cpp): from_chars leaves the value unset out of
  // range, and strtod tells an overflow (HUGE_VAL) from an underflow.
  if (out_of_range && std::isinf(std::strtod(entry.value.c_str(), nullptr))) {
    Fail(entry.value_loc,
         fmt::format("max_curvature {} is above the largest number, {} (it overflows; write inf "
                     "for no limit)",
                     QuoteForMessage(entry.value), std::numeric_limits<double>::max()));
  }
  if (out_of_range || (value != 0.0 && !std::isnormal(value))) {
    Fail(entry.value_loc,
         fmt::format("max_curvature {} is below the smallest normal magnitude, {} (it "
                     "underflows; write 0 for straight surfaces only)",
                     QuoteForMessage(entry.value), std::numeric_limits<double>::min()));
  }
  return value;
}

Header ResolveHeader(const ResolvedPrior& prior) {
  Header header;
  const PriorFile& own = *prior.files.front();
  const HeaderEntry* name = own.Header("name");
  if (!name)
    Fail({std::make_shared<const std::string>(own.path), 1, 1},
         "missing 'name:' (every prior file needs one)");
  header.name = name->value;
  std::optional<int> order;
  // Ancestors first, so that the nearest value overrides.
  for (auto it = prior.files.rbegin(); it != prior.files.rend(); ++it) {
    if (const HeaderEntry* entry = (*it)->Header("order")) {
      order = ParseOrder(*entry);
      header.order_loc = entry->value_loc;
    }
    if (const HeaderEntry* entry = (*it)->Header("max_curvature"))
      header.max_curvature = ParseCurvature(*entry);
  }
  if (!order) {
    Fail({std::make_shared<const std::string>(own.path), 1, 1},
         "missing 'order:' (the number of consecutive points a priorlet relates), and no parent "
         "prior gives one");
  }
  header.order = *order;
  return header;
}

struct Function {
  int min_args;
  int max_args;
};

const std::map<std::string, Function>& Functions() {
  static const std::map<std::string, Function> functions = {
      {"sin", {1, 1}},     {"cos", {1, 1}},     {"tan", {1, 1}},   {"asin", {1, 1}},
      {"acos", {1, 1}},    {"atan", {1, 1}},    {"atan2", {2, 2}}, {"sqrt", {1, 1}},
      {"exp", {1, 1}},     {"log", {1, 1}},     {"abs", {1, 1}},   {"norm", {1, 1}},
      {"deg2rad", {1, 1}}, {"rad2deg", {1, 1}}, {"min", {1, 2}},   {"max", {1, 2}}};
  return functions;
}

std::string FunctionList() {
  std::string list;
  for (const auto& [name, f] : Functions()) list += (list.empty() ? "" : ", ") + name;
  return list;
}

// rho_3 -> ("rho", 3); anything else -> nullopt.
std::optional<std::pair<std::string, int>> PredefinedName(const std::string& name) {
  for (const char* base : {"rho", "alpha", "phi"}) {
    const std::string prefix = std::string(base) + "_";
    if (name.rfind(prefix, 0) != 0 || name.size() == prefix.size()) continue;
    int index = 0;
    const char* first = name.data() + prefix.size();
    const auto [ptr, ec] = std::from_chars(first, name.data() + name.size(), index);
    if (ptr != name.data() + name.size()) continue;
    if (ec == std::errc()) return std::pair{std::string(base), index};
    // All digits, too many for an int: an index above any order.
    if (ec == std::errc::result_out_of_range)
      return std::pair{std::string(base), std::numeric_limits<int>::max()};
  }
  return std::nullopt;
}

// One scope of definitions being lowered (the file scope, then a block's body).
struct Scope {
  std::vector<const Statement*> statements;  // definitions in order, including not yet lowered ones
  std::map<std::string, Value> values;
  // The definitions lowered so far by name: looked up for each new one, so that a file of n
  // definitions is checked in n log n, not n^2, steps (200,000 took minutes).
  std::map<std::string, const Statement*> defined;
};

class Lowerer {
 public:
  Lowerer(const Header& header, ExpressionGraph& graph) : header_(header), graph_(graph) {}

  void Define(const Statement& definition, Scope& scope) {
    CheckNewName(definition);
    defining_.push_back(&definition);
    Value value;
    try {
      value = Lower(*definition.expr, scope);
    } catch (const GraphLimitExceeded& e) {
      Fail(definition.loc,
           fmt::format("'{}' is too large to compile: {}", definition.name, e.message));
    }
    defining_.pop_back();
    scope.values.emplace(definition.name, std::move(value));
    scope.defined.emplace(definition.name, &definition);
  }

  // Operations on constants are folded as the graph is built: one that folds to NaN or an
  // infinity (log(-1), 1/0) would make a term that is never finite, which the engine could
  // neither satisfy nor report where it came from.
  Value Finite(const Expr& e, Value value) {
    for (const NodeId id : value.entries) {
      if (!graph_.IsConst(id) || std::isfinite(graph_.node(id).value)) continue;
      Fail(e.loc,
           fmt::format("this is {} whatever the unknowns: a constant must be a finite number",
                       std::isnan(graph_.node(id).value) ? "not a number" : "infinite"));
    }
    return value;
  }

  // An operation on constants that underflows (1e-200 * 1e-200 folds to 0, 1e-300 * 1e-20 to a
  // subnormal whose reciprocal is inf) has lost the value written: refused at its place, as a
  // literal below the normal range is. `folds_before` is the graph's count before the operation.
  void RefuseUnderflow(const Expr& e, std::size_t folds_before) {
    if (graph_.underflowing_folds() == folds_before) return;
    Fail(e.loc, fmt::format("this underflows whatever the unknowns: an operation on constants "
                            "falls below the smallest normal magnitude, {} (write 0 for zero)",
                            std::numeric_limits<double>::min()));
  }

  // x / 0 with x unknown folds to x * inf, a term infinite or undefined everywhere, which Finite
  // cannot see as it is not a constant (a constant divided by 0 is, and Finite says so).
  void RefuseZeroDivisor(const Expr& e, const Value& dividend, const Value& divisor) {
    const auto constant = [&](NodeId id) { return graph_.IsConst(id); };
    if (std::all_of(dividend.entries.begin(), dividend.entries.end(), constant)) return;
    for (const NodeId id : divisor.entries)
      if (graph_.IsConst(id, 0.0)) Fail(e.loc, "division by zero (the divisor is the constant 0)");
  }

  Value Lower(const Expr& e, const Scope& scope) {
    switch (e.kind) {
      case Expr::Kind::kNumber:
        return Scalar(graph_.Const(e.number));
      case Expr::Kind::kName:
        return Name(e, scope);
      case Expr::Kind::kNegate:
        return Finite(e,
                      Map(Lower(*e.children[0], scope), [&](NodeId a) { return graph_.Neg(a); }));
      case Expr::Kind::kTranspose:
        return Transpose(Lower(*e.children[0], scope));
      case Expr::Kind::kBinary: {
        // In sequence (not as two arguments, whose order is unspecified): the leftmost problem is
        // the one reported, with every compiler.
        const Value left = Lower(*e.children[0], scope);
        const Value right = Lower(*e.children[1], scope);
        const std::size_t folds_before = graph_.underflowing_folds();
        Value value = Finite(e, Binary(e, left, right));
        RefuseUnderflow(e, folds_before);
        return value;
      }
      case Expr::Kind::kCall: {
        // The arguments' own underflows are reported at their places, before the call's.
        const std::size_t folds_before = graph_.underflowing_folds();
        Value value = Finite(e, Call(e, scope));
        RefuseUnderflow(e, folds_before);
        return value;
      }
      case Expr::Kind::kMatrix:
        return Matrix(e, scope);
      case Expr::Kind::kCompare:
        Fail(e.loc,
             "a comparison is not a value: comparisons make constraints, one per line (or joined "
             "by ||)");
      case Expr::Kind::kOr:
        Fail(e.loc, "'||' joins constraints; it cannot be used inside an expression");
    }
    Fail(e.loc, "unsupported expression");
  }

  const Header& header() const { return header_; }
  ExpressionGraph& graph() { return graph_; }

 private:
  void CheckNewName(const Statement& definition) const {
    const std::string& name = definition.name;
    if (name == "pi") Fail(definition.loc, "'pi' is a constant and cannot be redefined");
    if (const auto predefined = PredefinedName(name))
      CheckNoLeadingZero(name, predefined->first, definition.loc);
    if (PredefinedName(name) || name == "rho" || name == "alpha" || name == "phi") {
      Fail(definition.loc,
           fmt::format("'{}' is predefined (rho_i, alpha_i, phi_i) and cannot be redefined (to "
                       "constrain it, compare with '==')",
                       name));
    }
    if (Functions().count(name))
      Fail(definition.loc, fmt::format("'{}' is a function and cannot be redefined", name));
    if (name == "model_likelihood" || name == "priorlet") {
      Fail(definition.loc, fmt::format("'{}' is a keyword and cannot be defined", name));
    }
    for (const Scope* scope : visible_) {
      if (const auto other = scope->defined.find(name); other != scope->defined.end()) {
        Fail(definition.loc, fmt::format("'{}' is already defined at {}:{}", name,
                                         other->second->loc.file_name(), other->second->loc.line));
      }
    }
  }

 public:
  std::vector<const Scope*> visible_;  // outer scopes, then the current one

 private:
  Value Name(const Expr& e, const Scope& scope) {
    if (e.name == "pi") return Scalar(graph_.Const(kPi));
    if (const auto predefined = PredefinedName(e.name)) {
      const auto& [base, index] = *predefined;
      if (index < 1) Fail(e.loc, fmt::format("'{}': indices start at 1", e.name));
      CheckNoLeadingZero(e.name, base, e.loc);
      if (index > header_.order) {
        // In a parent's text, the order that rules it out may be a child's.
        const SourceLocation& set_at = header_.order_loc;
        const std::string where_set = set_at.file_name() == e.loc.file_name()
                                          ? ""
                                          : fmt::format(" (order: {} at {}:{})", header_.order,
                                                        set_at.file_name(), set_at.line);
        Fail(e.loc, fmt::format("'{}': index {} is above the prior's order {}{}", e.name,
                                e.name.substr(base.size() + 1), header_.order, where_set));
      }
      const int k = header_.order;
      if (base == "rho") return Scalar(graph_.Var(index - 1));
      if (base == "alpha") return Scalar(graph_.Var(k + index - 1));
      return Scalar(graph_.Param(index - 1));
    }
    if (e.name == "rho" || e.name == "alpha" || e.name == "phi") {
      Fail(e.loc, fmt::format("'{0}' needs an index: {0}_1 ... {0}_{1}", e.name, header_.order));
    }
    for (auto it = visible_.rbegin(); it != visible_.rend(); ++it) {
      if (const auto found = (*it)->values.find(e.name); found != (*it)->values.end())
        return found->second;
    }
    (void)scope;
    UnknownName(e);
  }

  // alpha_01 would otherwise be alpha_1 under another spelling: two names for one unknown, which
  // a reader takes for two.
  static void CheckNoLeadingZero(const std::string& name, const std::string& base,
                                 const SourceLocation& loc) {
    const std::string digits = name.substr(base.size() + 1);
    if (digits.size() < 2 || digits[0] != '0') return;
    const std::size_t significant = std::min(digits.find_first_not_of('0'), digits.size() - 1);
    Fail(loc, fmt::format("'{}': indices are written without leading zeros ({}_{})", name, base,
                          digits.substr(significant)));
  }

  // An unknown name: defined later (maybe in a cycle), a function without arguments, or a typo.
  [[noreturn]] void UnknownName(const Expr& e) {
    for (const Scope* s : visible_) {
      for (const Statement* later : s->statements) {
        if (later->name != e.name) continue;
        if (!defining_.empty() && later == defining_.back()) {
          Fail(e.loc, fmt::format("'{}' is used in its own definition", e.name));
        }
        if (const Statement* cycle = CycleThrough(*later)) {
          Fail(e.loc,
               fmt::format(
                   "definition cycle: '{}' uses '{}' (line {}), which depends on '{}' (line {})",
                   CurrentName(), e.name, later->loc.line, cycle->name, cycle->loc.line));
        }
        Fail(e.loc,
             fmt::format(
                 "'{}' is used before its definition at line {}; define names before using them",
                 e.name, later->loc.line));
      }
    }
    if (Functions().count(e.name))
      Fail(e.loc, fmt::format("'{}' is a function: call it as {}(...)", e.name, e.name));
    Fail(e.loc, fmt::format("unknown name '{}' (known: pi, rho_i, alpha_i, phi_i for i = 1..{}, "
                            "and the definitions "
                            "above this line)",
                            e.name, header_.order));
  }

  std::string CurrentName() const {
    return defining_.empty() ? "this line" : defining_.back()->name;
  }

  // The definition being lowered that `start` reaches through the names it uses, if any.
  const Statement* CycleThrough(const Statement& start) const {
    // The definitions by name, indexed once: a chain of n forward references is then followed
    // in n log n steps, not n^2 (a scan of every definition per name took minutes at 200,000).
    std::multimap<std::string_view, const Statement*> by_name;
    for (const Scope* scope : visible_) {
      for (const Statement* other : scope->statements) by_name.emplace(other->name, other);
    }
    std::set<const Statement*> seen;
    std::vector<const Statement*> stack = {&start};
    while (!stack.empty()) {
      const Statement* s = stack.back();
      stack.pop_back();
      if (!seen.insert(s).second) continue;
      for (const Statement* d : defining_) {
        if (d == s && s != &start) return s;
      }
      std::vector<const Expr*> exprs = {s->expr.get()};
      while (!exprs.empty()) {
        const Expr* x = exprs.back();
        exprs.pop_back();
        for (const ExprPtr& child : x->children) exprs.push_back(child.get());
        if (x->kind != Expr::Kind::kName) continue;
        for (const Statement* d : defining_) {
          if (d->name == x->name) return d;
        }
        const auto [first, last] = by_name.equal_range(x->name);
        for (auto it = first; it != last; ++it) stack.push_back(it->second);
      }
    }
    return nullptr;
  }

  Value Map(const Value& v, const std::function<NodeId(NodeId)>& f) {
    Value out = v;
    for (NodeId& id : out.entries) id = f(id);
    return out;
  }

  Value Transpose(const Value& v) {
    Value out{v.cols, v.rows, std::vector<NodeId>(v.entries.size())};
    for (int r = 0; r < v.rows; ++r) {
      for (int c = 0; c < v.cols; ++c)
        out.entries[static_cast<std::size_t>(c * v.rows + r)] = v.at(r, c);
    }
    return out;
  }

  // Element-wise with MATLAB's scalar expansion: same shapes, or one side a scalar.
  Value Elementwise(const Expr& e, const Value& a, const Value& b, const char* what,
                    const std::function<NodeId(NodeId, NodeId)>& f) {
    if (!a.IsScalar() && !b.IsScalar() && (a.rows != b.rows || a.cols != b.cols)) {
      Fail(e.loc,
           fmt::format(
               "{}: the operands are {} and {}; they need the same size, or one of them a scalar",
               what, a.Shape(), b.Shape()));
    }
    const Value& shape = a.IsScalar() ? b : a;
    Value out{shape.rows, shape.cols, std::vector<NodeId>(shape.entries.size())};
    for (std::size_t i = 0; i < out.entries.size(); ++i) {
      out.entries[i] =
          f(a.IsScalar() ? a.entries[0] : a.entries[i], b.IsScalar() ? b.entries[0] : b.entries[i]);
    }
    return out;
  }

  Value Binary(const Expr& e, const Value& a, const Value& b) {
    ExpressionGraph& g = graph_;
    switch (e.binary) {
      case BinaryOp::kAdd:
        return Elementwise(e, a, b, "'+'", [&](NodeId x, NodeId y) { return g.Add(x, y); });
      case BinaryOp::kSubtract:
        return Elementwise(e, a, b, "'-'", [&](NodeId x, NodeId y) { return g.Sub(x, y); });
      case BinaryOp::kElementMultiply:
        return Elementwise(e, a, b, "'.*'", [&](NodeId x, NodeId y) { return g.Mul(x, y); });
      case BinaryOp::kElementDivide:
        RefuseZeroDivisor(e, a, b);
        return Elementwise(e, a, b, "'./'", [&](NodeId x, NodeId y) { return g.Div(x, y); });
      case BinaryOp::kElementPower:
        return Elementwise(e, a, b, "'.^'", [&](NodeId x, NodeId y) { return g.Pow(x, y); });
      case BinaryOp::kMatrixMultiply:
        return MatrixMultiply(e, a, b);
      case BinaryOp::kDivide:
        if (!b.IsScalar()) {
          Fail(e.loc,
               fmt::format(
                   "'/' divides by a scalar only, the right side is {} (use ./ for element-wise "
                   "division)",
                   b.Shape()));
        }
        RefuseZeroDivisor(e, a, b);
        return Elementwise(e, a, b, "'/'", [&](NodeId x, NodeId y) { return g.Div(x, y); });
      case BinaryOp::kPower:
        if (!a.IsScalar() || !b.IsScalar()) {
          Fail(e.loc, fmt::format("'^' needs scalars, got {} ^ {} (use .^ for element-wise powers)",
                                  a.Shape(), b.Shape()));
        }
        return Scalar(g.Pow(a.entries[0], b.entries[0]));
    }
    Fail(e.loc, "unsupported operator");
  }

  Value MatrixMultiply(const Expr& e, const Value& a, const Value& b) {
    if (a.IsScalar() || b.IsScalar()) {
      return Elementwise(e, a, b, "'*'", [&](NodeId x, NodeId y) { return graph_.Mul(x, y); });
    }
    if (a.cols != b.rows) {
      Fail(e.loc,
           fmt::format(
               "matrix product of {} and {}: the inner sizes differ (use .* for element-wise "
               "products, or ' to transpose)",
               a.Shape(), b.Shape()));
    }
    CheckEntries(e.loc, a.rows, b.cols);
    if (static_cast<long long>(a.rows) * b.cols * a.cols > kMaxProductWork) {
      Fail(e.loc, fmt::format("matrix product of {} and {}: more than {} multiplications",
                              a.Shape(), b.Shape(), kMaxProductWork));
    }
    Value out{a.rows, b.cols, {}};
    for (int r = 0; r < a.rows; ++r) {
      for (int c = 0; c < b.cols; ++c) {
        NodeId sum = graph_.Mul(a.at(r, 0), b.at(0, c));
        for (int k = 1; k < a.cols; ++k) sum = graph_.Add(sum, graph_.Mul(a.at(r, k), b.at(k, c)));
        out.entries.push_back(sum);
      }
    }
    return out;
  }

  Value Call(const Expr& e, const Scope& scope) {
    const auto f = Functions().find(e.name);
    if (f == Functions().end()) {
      for (const Scope* s : visible_) {
        if (s->values.count(e.name)) {
          Fail(e.loc, fmt::format(
                          "'{}' is a definition, not a function: indexing with () is not supported",
                          e.name));
        }
      }
      if (PredefinedName(e.name))
        Fail(e.loc, fmt::format("'{}' is a variable, not a function", e.name));
      Fail(e.loc, fmt::format("unknown function '{}' (available: {})", e.name, FunctionList()));
    }
    const int n = static_cast<int>(e.children.size());
    if (n < f->second.min_args || n > f->second.max_args) {
      const std::string expected =
          f->second.min_args == f->second.max_args
              ? fmt::format("{}", f->second.min_args)
              : fmt::format("{} or {}", f->second.min_args, f->second.max_args);
      Fail(e.loc, fmt::format("'{}' takes {} argument{}, got {}", e.name, expected,
                              f->second.max_args == 1 ? "" : "s", n));
    }
    std::vector<Value> args;
    for (const ExprPtr& arg : e.children) args.push_back(Lower(*arg, scope));
    ExpressionGraph& g = graph_;
    const auto unary = [&](Op op) {
      return Map(args[0], [&](NodeId a) { return g.Unary(op, a); });
    };
    const std::string& name = e.name;
    if (name == "sin") return unary(Op::kSin);
    if (name == "cos") return unary(Op::kCos);
    if (name == "tan") return unary(Op::kTan);
    if (name == "asin") return unary(Op::kAsin);
    if (name == "acos") return unary(Op::kAcos);
    if (name == "atan") return unary(Op::kAtan);
    if (name == "sqrt") return unary(Op::kSqrt);
    if (name == "exp") return unary(Op::kExp);
    if (name == "log") return unary(Op::kLog);
    if (name == "abs") return unary(Op::kAbs);
    if (name == "deg2rad")
      return Map(args[0], [&](NodeId a) { return g.Mul(g.Const(kPi / 180.0), a); });
    if (name == "rad2deg")
      return Map(args[0], [&](NodeId a) { return g.Mul(g.Const(180.0 / kPi), a); });
    if (name == "atan2") {
      return Elementwise(e, args[0], args[1], "'atan2'",
                         [&](NodeId y, NodeId x) { return g.Atan2(y, x); });
    }
    if (name == "norm") return Scalar(Norm(args[0]));
    const bool is_min = name == "min";
    const auto pick = [&](NodeId x, NodeId y) { return is_min ? g.Min(x, y) : g.Max(x, y); };
    if (n == 2) return Elementwise(e, args[0], args[1], is_min ? "'min'" : "'max'", pick);
    NodeId best = args[0].entries[0];
    for (std::size_t i = 1; i < args[0].entries.size(); ++i) best = pick(best, args[0].entries[i]);
    return Scalar(best);
  }

  // norm has a kink at 0, like abs, where sqrt(v'v) alone would give the derivative
  // 0 * (1 / 0) = NaN (the engine's Newton steps would then be NaN). There it takes the
  // derivative 0, as abs does: a scalar's norm is abs, a vector's a guarded sqrt.
  NodeId Norm(const Value& v) {
    ExpressionGraph& g = graph_;
    if (v.IsScalar()) return g.Unary(Op::kAbs, v.entries[0]);
    NodeId sum = g.Const(0.0);
    for (NodeId x : v.entries) sum = g.Add(sum, g.Mul(x, x));
    return g.GuardedSqrt(sum);
  }

  static void CheckEntries(const SourceLocation& at, long long rows, long long cols) {
    if (rows * cols > kMaxEntries) {
      Fail(at, fmt::format("a {}x{} matrix: more than {} entries", rows, cols, kMaxEntries));
    }
  }

  // [a, b; c, d] with MATLAB concatenation: elements of a row side by side (same rows), rows
  // stacked (same columns).
  Value Matrix(const Expr& e, const Scope& scope) {
    const std::size_t per_row = e.children.size() / static_cast<std::size_t>(e.rows);
    Value out{0, 0, {}};
    std::vector<Value> block_rows;
    long long total_rows = 0;
    for (int r = 0; r < e.rows; ++r) {
      Value row{0, 0, {}};
      std::vector<Value> parts;
      for (std::size_t c = 0; c < per_row; ++c) {
        const Expr& element = *e.children[static_cast<std::size_t>(r) * per_row + c];
        Value v = Lower(element, scope);
        if (!parts.empty() && v.rows != parts.front().rows) {
          Fail(element.loc,
               fmt::format("horizontal concatenation of {} and {}: the row counts differ",
                           parts.front().Shape(), v.Shape()));
        }
        parts.push_back(std::move(v));
      }
      row.rows = parts.front().rows;
      long long cols = 0;
      for (const Value& p : parts) cols += p.cols;
      CheckEntries(e.loc, row.rows, cols);
      row.cols = static_cast<int>(cols);
      for (int i = 0; i < row.rows; ++i) {
        for (const Value& p : parts) {
          for (int j = 0; j < p.cols; ++j) row.entries.push_back(p.at(i, j));
        }
      }
      if (!block_rows.empty() && row.cols != block_rows.front().cols) {
        Fail(e.children[static_cast<std::size_t>(r) * per_row]->loc,
             fmt::format("vertical concatenation of {} and {}: the column counts differ",
                         block_rows.front().Shape(), row.Shape()));
      }
      total_rows += row.rows;
      CheckEntries(e.loc, total_rows, row.cols);
      block_rows.push_back(std::move(row));
    }
    out.cols = block_rows.front().cols;
    for (const Value& row : block_rows) {
      out.rows += row.rows;
      out.entries.insert(out.entries.end(), row.entries.begin(), row.entries.end());
    }
    return out;
  }

  const Header& header_;
  ExpressionGraph& graph_;
  std::vector<const Statement*> defining_;
};

// Where an expression starts in the source (an operator node is located at its operator).
const SourceLocation& StartOf(const Expr& e) {
  const Expr* x = &e;
  while ((x->kind == Expr::Kind::kBinary || x->kind == Expr::Kind::kTranspose ||
          x->kind == Expr::Kind::kCompare || x->kind == Expr::Kind::kOr) &&
         !x->children.empty()) {
    x = x->children[0].get();
  }
  return x->loc;
}

// Flattens a || b || c into its branches.
void Branches(const ExprPtr& e, std::vector<const Expr*>& out) {
  if (e->kind == Expr::Kind::kOr) {
    Branches(e->children[0], out);
    Branches(e->children[1], out);
  } else {
    out.push_back(e.get());
  }
}

struct BlockInput {
  BlockKind kind;
  SourceLocation loc;
  std::vector<const Statement*> statements;  // ancestors' first
};

std::string VariableName(int order, int v) {
  return v < order ? fmt::format("rho_{}", v + 1) : fmt::format("alpha_{}", v - order + 1);
}

// A constraint that holds, or fails, whatever the unknowns: refused when it makes the block
// infeasible, kept with a warning when it merely constrains nothing.
void CheckNotConstant(const ExpressionGraph& graph, const Statement& constraint,
                      const std::vector<LoweredComparison>& branches, BlockKind kind,
                      std::vector<Diagnostic>& warnings) {
  const auto finding = FindConstantConstraint(graph, branches, kind);
  if (!finding) return;
  if (finding->is_error) Fail(constraint.loc, finding->message);
  const SourceLocation& at = constraint.loc;
  warnings.push_back({at.file_name(), at.line, at.col, finding->message});
}

std::unique_ptr<CompiledBlock> CompileBlock(const Header& header,
                                            const std::vector<const Statement*>& file_scope,
                                            const BlockInput& input,
                                            std::vector<Diagnostic>& warnings) {
  const int k = header.order;
  auto graph = std::make_shared<ExpressionGraph>(2 * k, k);
  Lowerer lowerer(header, *graph);
  Scope file;
  file.statements = file_scope;
  lowerer.visible_ = {&file};
  for (const Statement* d : file_scope) lowerer.Define(*d, file);

  Scope local;
  for (const Statement* s : input.statements) {
    if (s->kind == Statement::Kind::kDefinition) local.statements.push_back(s);
  }
  lowerer.visible_ = {&file, &local};

  std::vector<Term> terms;
  std::vector<int> nodes;
  BlockSummary summary;
  const auto add = [&](Term term, NodeId node) {
    if (terms.size() >= kMaxTerms) {
      Fail(term.loc, fmt::format("more than {} scalar terms in 'priorlet {}'", kMaxTerms,
                                 ToString(input.kind)));
    }
    terms.push_back(std::move(term));
    nodes.push_back(node);
  };
  for (const Statement* s : input.statements) {
    try {
      switch (s->kind) {
        case Statement::Kind::kDefinition:
          lowerer.Define(*s, local);
          break;
        case Statement::Kind::kEnergy: {
          const Value v = lowerer.Lower(*s->expr, local);
          if (!v.IsScalar())
            Fail(s->loc, fmt::format("model_likelihood needs a scalar, got {}", v.Shape()));
          add({TermKind::kEnergy, -1, -1, 0, 1, s->loc, ToSource(*s)}, v.entries[0]);
          ++summary.energies;
          break;
        }
        case Statement::Kind::kConstraint: {
          std::vector<const Expr*> branches;
          Branches(s->expr, branches);
          const bool disjunction = branches.size() > 1;
          const int group = disjunction ? summary.disjunctions++ : -1;
          std::vector<LoweredComparison> lowered;
          for (std::size_t b = 0; b < branches.size(); ++b) {
            const Expr& c = *branches[b];
            if (c.kind != Expr::Kind::kCompare) {
              Fail(disjunction ? StartOf(c) : s->loc,
                   "expected a constraint: a comparison with '==', '<=' or '>=' (a plain "
                   "expression constrains "
                   "nothing; use model_likelihood for a cost)");
            }
            const Value lhs = lowerer.Lower(*c.children[0], local);
            const Value rhs = lowerer.Lower(*c.children[1], local);
            const bool equality = c.compare == CompareOp::kEqual;
            if (!equality && (!lhs.IsScalar() || !rhs.IsScalar())) {
              Fail(c.loc, fmt::format("an inequality compares scalars, got {} and {}", lhs.Shape(),
                                      rhs.Shape()));
            }
            if (!lhs.IsScalar() && !rhs.IsScalar() &&
                (lhs.rows != rhs.rows || lhs.cols != rhs.cols)) {
              Fail(c.loc,
                   fmt::format(
                       "'==' compares values of the same size (or one scalar), got {} and {}",
                       lhs.Shape(), rhs.Shape()));
            }
            const Value& shape = lhs.IsScalar() ? rhs : lhs;
            const int entries = static_cast<int>(shape.entries.size());
            lowered.push_back({ToSource(c), equality, {}});
            for (int i = 0; i < entries; ++i) {
              const NodeId l =
                  lhs.IsScalar() ? lhs.entries[0] : lhs.entries[static_cast<std::size_t>(i)];
              const NodeId r =
                  rhs.IsScalar() ? rhs.entries[0] : rhs.entries[static_cast<std::size_t>(i)];
              // g <= 0 form: a <= b is a - b <= 0, a >= b is b - a <= 0 (strict < and > alike).
              const bool flip =
                  c.compare == CompareOp::kGreaterEqual || c.compare == CompareOp::kGreater;
              const NodeId f = flip ? graph->Sub(r, l) : graph->Sub(l, r);
              lowered.back().terms.push_back(f);
              add({equality ? TermKind::kEquality : TermKind::kInequality, group,
                   disjunction ? static_cast<int>(b) : -1, i, entries, s->loc, ToSource(*s)},
                  f);
            }
          }
          CheckNotConstant(*graph, *s, lowered, input.kind, warnings);
          if (!disjunction) {
            if (branches[0]->compare == CompareOp::kEqual) {
              ++summary.equalities;
            } else {
              ++summary.inequalities;
            }
          }
          break;
        }
      }
    } catch (const GraphLimitExceeded& e) {
      Fail(s->loc, fmt::format("this statement is too large to compile: {}", e.message));
    }
  }
  // Like a constraint that always holds, a block of definitions only constrains nothing: most
  // likely its constraints were forgotten (a block left empty is an error).
  if (terms.empty()) {
    warnings.push_back({input.loc.file_name(), input.loc.line, input.loc.col,
                        fmt::format("'priorlet {}' holds definitions only: it constrains nothing, "
                                    "as a missing block",
                                    ToString(input.kind))});
  }
  std::uint64_t vars = 0, params = 0;
  for (int node : nodes) {
    vars |= graph->node(node).var_mask;
    params |= graph->node(node).param_mask;
  }
  for (int v = 0; v < 2 * k; ++v) {
    if (vars & (std::uint64_t{1} << v)) summary.variables.push_back(VariableName(k, v));
  }
  for (int p = 0; p < k; ++p) {
    if (params & (std::uint64_t{1} << p)) summary.variables.push_back(fmt::format("phi_{}", p + 1));
  }
  summary.scalar_terms = static_cast<int>(terms.size());
  try {
    return std::make_unique<CompiledBlock>(input.kind, k, std::move(terms), std::move(summary),
                                           std::move(graph), std::move(nodes));
  } catch (const GraphLimitExceeded& e) {
    Fail(input.loc, fmt::format("the derivatives of 'priorlet {}' are too large to compile: {}",
                                ToString(input.kind), e.message));
  }
}

}  // namespace

Result<CompiledPrior> LowerAndCompile(const ResolvedPrior& prior) {
  try {
    const Header header = ResolveHeader(prior);
    std::vector<const Statement*> file_scope;
    std::array<std::optional<BlockInput>, kNumBlockKinds> blocks;
    std::vector<PriorOrigin> chain;
    for (auto it = prior.files.rbegin(); it != prior.files.rend(); ++it) {
      const PriorFile& file = **it;
      for (const Statement& d : file.definitions) file_scope.push_back(&d);
      for (const Block& b : file.blocks) {
        std::optional<BlockInput>& slot = blocks[static_cast<std::size_t>(b.kind)];
        if (!slot) slot = BlockInput{b.kind, b.loc, {}};
        for (const Statement& s : b.statements) slot->statements.push_back(&s);
      }
    }
    for (const auto& file : prior.files) {
      const HeaderEntry* name = file->Header("name");
      chain.push_back({name ? name->value : "", file->path});
    }
    // File-scope definitions are checked even when no block uses them.
    {
      ExpressionGraph scratch(2 * header.order, header.order);
      Lowerer lowerer(header, scratch);
      Scope file;
      file.statements = file_scope;
      lowerer.visible_ = {&file};
      for (const Statement* d : file_scope) lowerer.Define(*d, file);
    }
    std::array<std::unique_ptr<CompiledBlock>, kNumBlockKinds> compiled;
    std::vector<Diagnostic> warnings;
    for (std::size_t i = 0; i < blocks.size(); ++i) {
      if (blocks[i]) compiled[i] = CompileBlock(header, file_scope, *blocks[i], warnings);
    }
    return CompiledPrior(header.name, header.order, header.max_curvature, std::move(chain),
                         std::move(compiled), std::move(warnings));
  } catch (const CompileError& error) {
    return error.diagnostic;
  }
}

}  // namespace priormap::dsl::detail
