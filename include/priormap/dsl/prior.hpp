#pragma once
/// A compiled environment prior: for each topology case (same region, different region,
/// different surface) the priorlet's terms with exact values, gradients and Hessians.
/// (Paper: de la Puente & Censi, Def. 1-2; the language is in docs/priorlet-language.md.)

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <priormap/core/diagnostic.hpp>
#include <priormap/dsl/ast.hpp>

namespace priormap::dsl {

namespace detail {
class ExpressionGraph;
struct CompiledTape;
}  // namespace detail

/// How a term enters Problem 4 of the paper.
enum class TermKind : std::uint8_t {
  kEquality,    ///< f = 0; penalty f^2
  kInequality,  ///< g <= 0; penalty max(0, g)^2
  kEnergy,      ///< h, a cost to minimise (the file's `model_likelihood` expression, as written)
};

[[nodiscard]] const char* ToString(TermKind kind);

/// One scalar function of a priorlet. A vector equality gives one term per entry; the branches
/// of a disjunction share a `disjunction` id and differ in `branch`.
struct Term {
  TermKind kind = TermKind::kEquality;
  int disjunction = -1;  ///< index of the disjunction it belongs to, or -1
  int branch = -1;       ///< branch within the disjunction, or -1
  int entry = 0;         ///< entry of a vector/matrix (in)equality, row-major
  int entries = 1;
  SourceLocation loc;  ///< of the statement
  std::string source;  ///< the statement as written (normalised spacing)
};

/// Counts of a block's statements.
struct BlockSummary {
  int equalities = 0;    ///< equality statements outside disjunctions
  int inequalities = 0;  ///< inequality statements outside disjunctions
  int disjunctions = 0;
  int energies = 0;
  int scalar_terms = 0;                ///< Term objects
  std::vector<std::string> variables;  ///< rho_i, alpha_i, phi_i the block's terms depend on
};

/// The compiled form of one priorlet block, evaluated by a BlockEvaluator.
class CompiledBlock {
 public:
  /// Differentiates the terms (nodes of `graph`) and builds the evaluation tapes.
  CompiledBlock(BlockKind kind, int order, std::vector<Term> terms, BlockSummary summary,
                std::shared_ptr<detail::ExpressionGraph> graph, std::vector<int> term_nodes);
  ~CompiledBlock();
  CompiledBlock(CompiledBlock&&) noexcept;
  CompiledBlock& operator=(CompiledBlock&&) noexcept;

  [[nodiscard]] BlockKind kind() const { return kind_; }
  [[nodiscard]] int order() const { return order_; }
  /// 2 * order: x = (rho_1..rho_k, alpha_1..alpha_k).
  [[nodiscard]] int num_variables() const { return 2 * order_; }
  [[nodiscard]] int num_terms() const { return static_cast<int>(terms_.size()); }
  [[nodiscard]] const std::vector<Term>& terms() const { return terms_; }
  [[nodiscard]] const BlockSummary& summary() const { return summary_; }
  [[nodiscard]] int num_disjunctions() const { return summary_.disjunctions; }

  /// The simplified expression of term t, and of its derivative by variable v (0-based in x).
  [[nodiscard]] std::string TermExpression(int t) const;
  [[nodiscard]] std::string DerivativeExpression(int t, int v) const;
  /// Name of variable v of x ("rho_1", ..., "alpha_k").
  [[nodiscard]] std::string VariableName(int v) const;
  /// Instructions evaluated per call for values only / + gradients / + Hessians (excluding the
  /// parameter-only part, which runs when phi changes).
  [[nodiscard]] std::array<std::size_t, 3> TapeLengths() const;

 private:
  friend class BlockEvaluator;
  BlockKind kind_;
  int order_;
  std::vector<Term> terms_;
  BlockSummary summary_;
  std::shared_ptr<detail::ExpressionGraph> graph_;  ///< not changed after construction
  std::vector<int> term_nodes_;
  std::vector<int> gradient_nodes_;  ///< num_terms x num_variables
  std::unique_ptr<detail::CompiledTape> tape_;
};

/// Evaluates a CompiledBlock without allocating after construction: one evaluator per thread.
class BlockEvaluator {
 public:
  explicit BlockEvaluator(const CompiledBlock& block);

  /// Values (num_terms), gradients (num_terms x num_variables, row-major) and Hessians
  /// (num_terms x num_variables x num_variables) of every term at unknowns `x` (size
  /// num_variables) and beam angles `phi` (size order). Null outputs are not computed. The part
  /// that depends on phi only is reused while phi stays the same.
  void Evaluate(std::span<const double> x, std::span<const double> phi, double* values,
                double* gradients = nullptr, double* hessians = nullptr);

  /// Evaluate for `count` points at once: x is count x num_variables and phi count x order
  /// (row-major); the outputs are the single-point outputs of each point, one after the other.
  /// Several points share each instruction's dispatch and run in vectorisable loops, so this is
  /// the fast way to evaluate every window of a scan.
  void EvaluateBatch(std::size_t count, std::span<const double> x, std::span<const double> phi,
                     double* values, double* gradients = nullptr, double* hessians = nullptr);

 private:
  const CompiledBlock* block_;
  std::vector<double> slots_;       ///< one value per slot
  std::vector<double> lane_slots_;  ///< kLanes values per slot, for EvaluateBatch
  std::vector<double> cached_phi_;
  bool phi_valid_ = false;
  // EvaluateBatch: the phi of the last call and its parameter-only slots, chunk after chunk,
  // reused while a call repeats the same phi (Newton steps over the same windows).
  std::vector<double> batch_phi_;
  std::vector<double> batch_parameter_slots_;
};

/// Where a prior comes from (its file, or <builtin>/file.prior).
struct PriorOrigin {
  std::string name;
  std::string path;
};

class CompiledPrior {
 public:
  CompiledPrior(std::string name, int order, double max_curvature, std::vector<PriorOrigin> chain,
                std::array<std::unique_ptr<CompiledBlock>, kNumBlockKinds> blocks,
                std::vector<Diagnostic> warnings = {});

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] int order() const { return order_; }
  /// 1/m; +inf when the prior gives none.
  [[nodiscard]] double max_curvature() const { return max_curvature_; }
  /// This prior, then the prior it specializes, and so on.
  [[nodiscard]] const std::vector<PriorOrigin>& chain() const { return chain_; }
  /// The block for a topology case, or nullptr when the prior has none (no constraint).
  [[nodiscard]] const CompiledBlock* block(BlockKind kind) const;
  /// What is almost surely a mistake yet leaves the prior usable, by block then line: constraints
  /// that use no variable and always hold, disjunction branches that never can
  /// (docs/priorlet-language.md, "Constant constraints").
  /// The library does not print them; a caller that loads a prior for a user should.
  [[nodiscard]] const std::vector<Diagnostic>& warnings() const { return warnings_; }

 private:
  std::string name_;
  int order_;
  double max_curvature_;
  std::vector<PriorOrigin> chain_;
  std::array<std::unique_ptr<CompiledBlock>, kNumBlockKinds> blocks_;
  std::vector<Diagnostic> warnings_;
};

}  // namespace priormap::dsl
