#pragma once
/// The syntax tree of a priorlet file (priors/*.prior, docs/priorlet-language.md), as parsed,
/// before names, shapes and inheritance are resolved.

#include <memory>
#include <string>
#include <vector>

namespace priormap::dsl {

/// A position in a prior file: 1-based line and column (columns count Unicode characters).
struct SourceLocation {
  std::shared_ptr<const std::string> file;
  int line = 0;
  int col = 0;

  [[nodiscard]] const std::string& file_name() const;
};

enum class BinaryOp {
  kAdd,
  kSubtract,
  kMatrixMultiply,
  kDivide,  // * and / (MATLAB: matrix product, right division)
  kElementMultiply,
  kElementDivide,
  kElementPower,  // .* ./ .^
  kPower,         // ^
};

enum class CompareOp { kEqual, kLessEqual, kGreaterEqual, kLess, kGreater };

struct Expr;
using ExprPtr = std::shared_ptr<const Expr>;

struct Expr {
  enum class Kind {
    kNumber,     ///< number
    kName,       ///< a variable, a definition or pi
    kNegate,     ///< -children[0]
    kBinary,     ///< children[0] op children[1]
    kTranspose,  ///< children[0]'
    kCall,       ///< name(children...)
    kMatrix,     ///< [children] with `rows` rows, row-major, every row the same length
    kCompare,    ///< children[0] compare children[1] (constraints only)
    kOr,         ///< children[0] || children[1] (constraints only)
  };
  Kind kind = Kind::kNumber;
  SourceLocation loc;
  double number = 0.0;
  std::string name;  ///< kName, kCall
  BinaryOp binary = BinaryOp::kAdd;
  CompareOp compare = CompareOp::kEqual;
  int rows = 0;  ///< kMatrix
  std::vector<ExprPtr> children;
};

/// One line of a block or of the file scope.
struct Statement {
  enum class Kind {
    kDefinition,  ///< name = expr
    kConstraint,  ///< comparisons joined by ||
    kEnergy,      ///< model_likelihood expr
  };
  Kind kind = Kind::kDefinition;
  SourceLocation loc;
  std::string name;  ///< kDefinition
  ExprPtr expr;
};

enum class BlockKind { kSameRegion = 0, kDifferentRegion = 1, kDifferentSurface = 2 };
inline constexpr int kNumBlockKinds = 3;

/// "same_region", "different_region", "different_surface".
[[nodiscard]] const char* ToString(BlockKind kind);

struct Block {
  BlockKind kind = BlockKind::kSameRegion;
  SourceLocation loc;
  std::vector<Statement> statements;
};

/// `key: value` at file scope.
struct HeaderEntry {
  std::string key;           ///< name, order, max_curvature or specializes
  std::string value;         ///< the rest of the line, trimmed, without its comment
  SourceLocation loc;        ///< of the key
  SourceLocation value_loc;  ///< of the value
};

struct PriorFile {
  std::string path;
  std::vector<HeaderEntry> header;
  std::vector<Statement> definitions;  ///< file-scope definitions, in order
  std::vector<Block> blocks;           ///< in order; at most one per kind

  /// The header entry with `key`, or nullptr.
  [[nodiscard]] const HeaderEntry* Header(const std::string& key) const;
};

}  // namespace priormap::dsl
