#pragma once
// Splits prior text into logical lines of tokens. A logical line is a physical line, joined with
// the following ones when it ends in "..." (MATLAB's continuation). Comments (# or %) and blank
// lines are dropped. Greek identifiers are normalised: α₁ and α_1 become alpha_1, ρ rho, φ/ϕ phi.

#include <string>
#include <string_view>
#include <vector>

#include <priormap/core/diagnostic.hpp>
#include <priormap/dsl/ast.hpp>

namespace priormap::dsl::detail {

enum class TokenKind {
  kIdentifier,
  kNumber,
  kPlus,
  kMinus,
  kStar,
  kSlash,
  kCaret,
  kDotStar,
  kDotSlash,
  kDotCaret,
  kTranspose,
  kEqualEqual,
  kLessEqual,
  kGreaterEqual,
  kLess,
  kGreater,
  kAssign,
  kOrOr,
  kOr,
  kLParen,
  kRParen,
  kLBracket,
  kRBracket,
  kComma,
  kSemicolon,
  kColon,
  kEnd,  // end of the logical line
};

/// How a token kind is written ("'=='", "a number", ...), for messages.
[[nodiscard]] const char* Describe(TokenKind kind);

struct Token {
  TokenKind kind = TokenKind::kEnd;
  std::string text;  ///< identifiers: normalised name; numbers and operators: as written
  double number = 0.0;
  int line = 0;
  int col = 0;      ///< 1-based, in characters
  int end_col = 0;  ///< the column just after the token as written (α₁ is 2 characters)
  bool space_before = false;
  bool space_after = false;
};

struct Line {
  int number = 0;             ///< of the first physical line
  std::string indentation;    ///< leading blanks, as written
  int indent_width = 0;       ///< in columns, tabs to the next multiple of 8
  std::vector<Token> tokens;  ///< ends with kEnd; empty for header lines

  // Header lines ("name: text", "order: 2", ... at column 1) are not tokenised: a name may hold
  // any text.
  bool is_header = false;
  std::string header_key;
  std::string header_value;  ///< trimmed, without its comment
  int header_value_col = 1;
};

/// The header keys: name, order, max_curvature, specializes.
[[nodiscard]] bool IsHeaderKey(std::string_view word);

/// `text` without the UTF-8 byte order mark some editors (Windows Notepad) write at its start:
/// invisible in an editor, it would otherwise be the first character of line 1.
[[nodiscard]] std::string_view WithoutByteOrderMark(std::string_view text);

/// Where a physical line of `text` ends, and where the next one starts.
struct LineEnd {
  std::size_t end = 0;   ///< text.size() for the last line
  std::size_t next = 0;  ///< std::string_view::npos after the last line
};

/// The end of the physical line that starts at `start`: 0, or the `next` of the line before (a
/// lone CR there tells that the CRs right after it end lines of their own, so a long run of CRs
/// is read once, not once per line). "\n", "\r\n" and a lone "\r" (classic Mac OS) each end one
/// line, and so does a run of CRs before an LF: "\r\r\n" is CRLF passed twice through a
/// text-mode layer, and counting two lines there would make every later line:col wrong. CRs that
/// no LF follows each end one line: in a CR-only file "\r\r" is a blank line.
[[nodiscard]] LineEnd FindLineEnd(std::string_view text, std::size_t start);

/// The logical lines of `source` (a byte order mark at its start ignored), or the first lexical
/// error.
[[nodiscard]] Result<std::vector<Line>> Lex(std::string_view source,
                                            const std::shared_ptr<const std::string>& file);

}  // namespace priormap::dsl::detail
