#include "lexer.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <optional>

#include <fmt/format.h>

#include <priormap/core/utf8.hpp>

namespace priormap::dsl::detail {
namespace {

// One decoded UTF-8 character and its size in bytes; invalid bytes decode as U+FFFD, size 1.
struct Char {
  char32_t code = 0;
  int size = 1;
};

Char Decode(std::string_view s, std::size_t i) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = b(i);
  if (c < 0x80) return {c, 1};
  const int size = (c & 0xE0) == 0xC0 ? 2 : (c & 0xF0) == 0xE0 ? 3 : (c & 0xF8) == 0xF0 ? 4 : 0;
  if (size == 0 || i + static_cast<std::size_t>(size) > s.size()) return {0xFFFD, 1};
  char32_t code = c & (0x7F >> size);
  for (int k = 1; k < size; ++k) {
    const unsigned char next = b(i + static_cast<std::size_t>(k));
    if ((next & 0xC0) != 0x80) return {0xFFFD, 1};
    code = (code << 6) | (next & 0x3F);
  }
  return {code, size};
}

bool IsAsciiLetter(char32_t c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}
bool IsDigit(char32_t c) {
  return c >= '0' && c <= '9';
}
bool IsSubscriptDigit(char32_t c) {
  return c >= 0x2080 && c <= 0x2089;
}

// The ASCII name of a Greek letter priorlets predefine (ρ, α, φ, ϕ), or nullptr.
const char* GreekName(char32_t c) {
  switch (c) {
    case 0x03C1:
      return "rho";
    case 0x03B1:
      return "alpha";
    case 0x03C6:
      return "phi";
    case 0x03D5:
      return "phi";
    default:
      return nullptr;
  }
}

// Characters that look like a blank, or like nothing at all, in an editor (pasted from a web
// page or a word processor): what each is, for the message, as quoting it would show nothing;
// nullptr for the others.
const char* InvisibleCharacter(char32_t c) {
  if (IsNonAsciiSpace(c)) return "a non-ASCII space: use a plain space or a tab";
  if (c == 0x2028 || c == 0x2029) return "a Unicode line separator: use a line break";
  if (IsInvisibleCharacter(c)) return "an invisible zero-width character: delete it";
  return nullptr;
}

// A bound on the work and memory one logical line can ask of the parser (the parser bounds the
// depth of the trees it builds separately).
constexpr std::size_t kMaxTokensPerLine = 10000;

class LineLexer {
 public:
  LineLexer(std::string_view text, int line, int first_col,
            const std::shared_ptr<const std::string>& file)
      : text_(text), line_(line), col_(first_col), file_(file) {}

  // Appends the tokens of this physical line; returns false (with `error`) on a lexical error.
  bool Run(std::vector<Token>& tokens, Diagnostic& error) {
    // A line break separates tokens like a blank does (continuation lines).
    if (!tokens.empty()) tokens.back().space_after = true;
    while (pos_ < text_.size()) {
      const Char c = Decode(text_, pos_);
      if (c.code == ' ' || c.code == '\t' || c.code == '\r') {
        Advance(c);
        space_ = true;
        if (!tokens.empty()) tokens.back().space_after = true;
        continue;
      }
      if (tokens.size() >= kMaxTokensPerLine) {
        return Fail(error, col_,
                    fmt::format("more than {} tokens in one logical line: split the statement with "
                                "definitions",
                                kMaxTokensPerLine));
      }
      Token token;
      token.line = line_;
      token.col = col_;
      token.space_before = space_;
      space_ = false;
      if (!Next(c, tokens, token, error)) return false;
      token.end_col = col_;
      tokens.push_back(std::move(token));
    }
    if (!tokens.empty()) tokens.back().space_after = true;
    return true;
  }

 private:
  void Advance(const Char& c) {
    pos_ += static_cast<std::size_t>(c.size);
    ++col_;
  }
  char32_t Peek(std::size_t offset = 0) const {
    std::size_t p = pos_;
    for (std::size_t k = 0; k < offset && p < text_.size(); ++k)
      p += static_cast<std::size_t>(Decode(text_, p).size);
    return p < text_.size() ? Decode(text_, p).code : 0;
  }
  bool Fail(Diagnostic& error, int col, std::string message) {
    error = {*file_, line_, col, std::move(message)};
    return false;
  }

  bool Next(const Char& c, const std::vector<Token>& tokens, Token& token, Diagnostic& error) {
    if (IsAsciiLetter(c.code) || GreekName(c.code)) return Identifier(token, error);
    if (IsDigit(c.code) || (c.code == '.' && IsDigit(Peek(1)))) return Number(token, error);
    return Operator(c, tokens, token, error);
  }

  bool Identifier(Token& token, Diagnostic& error) {
    std::string name;
    while (pos_ < text_.size()) {
      const Char c = Decode(text_, pos_);
      if (IsAsciiLetter(c.code) || IsDigit(c.code)) {
        name += static_cast<char>(c.code);
      } else if (const char* greek = GreekName(c.code)) {
        name += greek;
      } else if (IsSubscriptDigit(c.code)) {
        // α₁ -> alpha_1: subscript digits are an index.
        if (name.empty() || name.back() != '_') {
          if (!IsSubscriptDigit(PreviousCode())) name += '_';
        }
        name += static_cast<char>('0' + (c.code - 0x2080));
      } else if (c.code >= 0x80 && c.code != 0xFFFD && IsLetterLike(c.code)) {
        return Fail(error, col_,
                    fmt::format("unexpected character U+{:04X} in a name (only ρ, α, φ and ϕ "
                                "may be written in Greek)",
                                static_cast<std::uint32_t>(c.code)));
      } else {
        break;
      }
      previous_code_ = c.code;
      Advance(c);
    }
    previous_code_ = 0;
    token.kind = TokenKind::kIdentifier;
    token.text = std::move(name);
    return true;
  }

  static bool IsLetterLike(char32_t c) {
    return c >= 0x0370 && c <= 0x03FF;
  }  // other Greek letters
  char32_t PreviousCode() const { return previous_code_; }

  bool Number(Token& token, Diagnostic& error) {
    const std::size_t start = pos_;
    const int start_col = col_;
    const auto skip_digits = [&] {
      while (pos_ < text_.size() && IsDigit(static_cast<unsigned char>(text_[pos_]))) {
        ++pos_;
        ++col_;
      }
    };
    skip_digits();
    // "1.*x" is 1 .* x: a dot followed by an operator belongs to the operator.
    if (pos_ < text_.size() && text_[pos_] == '.' &&
        !(pos_ + 1 < text_.size() && (text_[pos_ + 1] == '*' || text_[pos_ + 1] == '/' ||
                                      text_[pos_ + 1] == '^' || text_[pos_ + 1] == '\''))) {
      ++pos_;
      ++col_;
      skip_digits();
    }
    if (pos_ < text_.size() && (text_[pos_] == 'e' || text_[pos_] == 'E')) {
      std::size_t p = pos_ + 1;
      if (p < text_.size() && (text_[p] == '+' || text_[p] == '-')) ++p;
      if (p < text_.size() && IsDigit(static_cast<unsigned char>(text_[p]))) {
        col_ += static_cast<int>(p - pos_);
        pos_ = p;
        skip_digits();
      } else {
        pos_ = p;
        return Fail(error, start_col,
                    fmt::format("bad number {}: an exponent needs digits",
                                QuoteForMessage(text_.substr(start, pos_ - start))));
      }
    }
    // A number running into letters, digits or another dot ("3x", "1.2.3") is a typo, not two
    // tokens.
    if (pos_ < text_.size()) {
      const Char next = Decode(text_, pos_);
      if (IsAsciiLetter(next.code) || IsDigit(next.code) || next.code == '.') {
        const bool dot_operator = next.code == '.' && pos_ + 1 < text_.size() &&
                                  (text_[pos_ + 1] == '*' || text_[pos_ + 1] == '/' ||
                                   text_[pos_ + 1] == '^' || text_[pos_ + 1] == '\'');
        if (!dot_operator) {
          std::size_t end = pos_;
          while (end < text_.size() && (std::isalnum(static_cast<unsigned char>(text_[end])) ||
                                        text_[end] == '.' || text_[end] == '_')) {
            ++end;
          }
          return Fail(
              error, start_col,
              fmt::format("bad number {}", QuoteForMessage(text_.substr(start, end - start))));
        }
      }
    }
    token.kind = TokenKind::kNumber;
    token.text = std::string(text_.substr(start, pos_ - start));
    const auto [ptr, ec] =
        std::from_chars(token.text.data(), token.text.data() + token.text.size(), token.number);
    const bool whole = ptr == token.text.data() + token.text.size();
    const bool out_of_range = ec == std::errc::result_out_of_range;
    if (!whole || (ec != std::errc() && !out_of_range)) {
      return Fail(error, start_col, fmt::format("bad number {}", QuoteForMessage(token.text)));
    }
    // from_chars leaves the value unset out of range; strtod gives HUGE_VAL for an overflow and
    // 0 or a subnormal for an underflow (in the C locale, which priormap never changes).
    if (out_of_range && std::isinf(std::strtod(token.text.c_str(), nullptr))) {
      return Fail(error, start_col,
                  fmt::format("bad number {}: above the largest number, {} (it overflows)",
                              QuoteForMessage(token.text), std::numeric_limits<double>::max()));
    }
    // A subnormal keeps only some of the digits written, and its reciprocal overflows; no
    // quantity of a prior (metres, radians, 1/m) is that small, so the literal is a typo or
    // means 0, and the author says which rather than the compiler guessing.
    if (out_of_range || (token.number != 0.0 && !std::isnormal(token.number))) {
      return Fail(error, start_col,
                  fmt::format("bad number {}: below the smallest normal magnitude, {} (it "
                              "underflows; write 0 for zero)",
                              QuoteForMessage(token.text), std::numeric_limits<double>::min()));
    }
    return true;
  }

  bool Operator(const Char& c, const std::vector<Token>& tokens, Token& token, Diagnostic& error) {
    const char32_t n = Peek(1);
    const auto take = [&](TokenKind kind, int length) {
      token.kind = kind;
      token.text = std::string(text_.substr(pos_, static_cast<std::size_t>(length)));
      pos_ += static_cast<std::size_t>(length);
      col_ += length;
      return true;
    };
    switch (c.code) {
      case '+':
        return take(TokenKind::kPlus, 1);
      case '-':
        return take(TokenKind::kMinus, 1);
      case '*':
        return take(TokenKind::kStar, 1);
      case '/':
        return take(TokenKind::kSlash, 1);
      case '^':
        return take(TokenKind::kCaret, 1);
      case '(':
        return take(TokenKind::kLParen, 1);
      case ')':
        return take(TokenKind::kRParen, 1);
      case '[':
        return take(TokenKind::kLBracket, 1);
      case ']':
        return take(TokenKind::kRBracket, 1);
      case ',':
        return take(TokenKind::kComma, 1);
      case ';':
        return take(TokenKind::kSemicolon, 1);
      case ':':
        return take(TokenKind::kColon, 1);
      case '.':
        if (n == '*') return take(TokenKind::kDotStar, 2);
        if (n == '/') return take(TokenKind::kDotSlash, 2);
        if (n == '^') return take(TokenKind::kDotCaret, 2);
        if (n == '\'') return take(TokenKind::kTranspose, 2);
        break;
      case '\'': {
        // A quote right after an operand is a transpose; anywhere else it would start a string.
        const bool after_operand =
            !tokens.empty() && !token.space_before &&
            (tokens.back().kind == TokenKind::kIdentifier ||
             tokens.back().kind == TokenKind::kNumber || tokens.back().kind == TokenKind::kRParen ||
             tokens.back().kind == TokenKind::kRBracket ||
             tokens.back().kind == TokenKind::kTranspose);
        if (after_operand) return take(TokenKind::kTranspose, 1);
        return Fail(
            error, col_,
            "unexpected ' (transpose must follow an operand directly; strings are not supported)");
      }
      case '=':
        if (n == '=') return take(TokenKind::kEqualEqual, 2);
        return take(TokenKind::kAssign, 1);
      case '<':
        if (n == '=') return take(TokenKind::kLessEqual, 2);
        return take(TokenKind::kLess, 1);
      case '>':
        if (n == '=') return take(TokenKind::kGreaterEqual, 2);
        return take(TokenKind::kGreater, 1);
      case '|':
        if (n == '|') return take(TokenKind::kOrOr, 2);
        return take(TokenKind::kOr, 1);
      case '&':
        return Fail(error, col_,
                    fmt::format("{} is not supported: every constraint of a priorlet must hold, so "
                                "write them on separate lines",
                                n == '&' ? "'&&'" : "'&'"));
      case '~':
      case '!':
        if (n == '=')
          return Fail(error, col_, "'~=' / '!=' constraints are not supported (use == , <= or >=)");
        break;
      default:
        break;
    }
    if (c.code == 0xFFFD && c.size == 1) {
      return Fail(error, col_,
                  fmt::format("unexpected byte 0x{:02X} (prior files are UTF-8 text)",
                              static_cast<unsigned char>(text_[pos_])));
    }
    std::string shown = c.code < 0x80 && c.code >= 0x20
                            ? fmt::format("'{}'", static_cast<char>(c.code))
                            : fmt::format("U+{:04X}", static_cast<std::uint32_t>(c.code));
    if (const char* invisible = InvisibleCharacter(c.code))
      return Fail(error, col_, fmt::format("unexpected character {} ({})", shown, invisible));
    if (c.code >= 0xA1 && !IsLetterLike(c.code)) {
      // Printable (not a control character): shown as itself too, as the user sees it.
      return Fail(error, col_,
                  fmt::format("unexpected character '{}' ({})",
                              text_.substr(pos_, static_cast<std::size_t>(c.size)), shown));
    }
    if (IsLetterLike(c.code)) {
      // Shown as itself too: it is a printable letter, and the hint names the Greek letters
      // allowed.
      return Fail(
          error, col_,
          fmt::format("unexpected character '{}' ({}); only ρ, α, φ and ϕ may be written in Greek",
                      text_.substr(pos_, static_cast<std::size_t>(c.size)), shown));
    }
    return Fail(error, col_, fmt::format("unexpected character {}", shown));
  }

  std::string_view text_;
  int line_;
  int col_;
  const std::shared_ptr<const std::string>& file_;
  std::size_t pos_ = 0;
  bool space_ = true;
  char32_t previous_code_ = 0;
};

// Byte offset of the comment start (# or %), or npos.
std::size_t CommentStart(std::string_view line) {
  const std::size_t p = line.find_first_of("#%");
  return p;
}

std::string_view TrimRight(std::string_view s) {
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

// "key:" at the start of `body` with key a header key: the key and the byte offset after ':'.
std::optional<std::pair<std::string, std::size_t>> HeaderPrefix(std::string_view body) {
  std::size_t end = 0;
  while (end < body.size() &&
         (std::isalpha(static_cast<unsigned char>(body[end])) || body[end] == '_'))
    ++end;
  std::size_t colon = end;
  while (colon < body.size() && (body[colon] == ' ' || body[colon] == '\t')) ++colon;
  if (end == 0 || colon >= body.size() || body[colon] != ':' || !IsHeaderKey(body.substr(0, end)))
    return std::nullopt;
  return std::pair{std::string(body.substr(0, end)), colon + 1};
}

// Number of characters (not bytes) in the UTF-8 text.
int CharacterCount(std::string_view s) {
  int n = 0;
  for (std::size_t i = 0; i < s.size(); i += static_cast<std::size_t>(Decode(s, i).size)) ++n;
  return n;
}

// The first character of body[from..] that a header value may not hold, as an error: bytes that
// are not UTF-8, control characters (a NUL, a stray form feed), and characters that look like a
// blank or like nothing. A name is matched as written by `specializes:`, and printed: such a
// character would make two names that look alike differ, or garble the terminal.
std::optional<Diagnostic> UnreadableCharacter(std::string_view body, std::size_t from, int line,
                                              const std::string& file) {
  int col = 1 + CharacterCount(body.substr(0, from));
  for (std::size_t i = from; i < body.size(); ++col) {
    const Char c = Decode(body, i);
    if (c.code == 0xFFFD && c.size == 1) {
      return Diagnostic{file, line, col,
                        fmt::format("unexpected byte 0x{:02X} (prior files are UTF-8 text)",
                                    static_cast<unsigned char>(body[i]))};
    }
    if ((c.code < 0x20 && c.code != '\t') || (c.code >= 0x7F && c.code < 0xA0)) {
      return Diagnostic{file, line, col,
                        fmt::format("unexpected control character U+{:04X} in a header value",
                                    static_cast<std::uint32_t>(c.code))};
    }
    if (const char* invisible = InvisibleCharacter(c.code)) {
      return Diagnostic{file, line, col,
                        fmt::format("unexpected character U+{:04X} in a header value ({})",
                                    static_cast<std::uint32_t>(c.code), invisible)};
    }
    i += static_cast<std::size_t>(c.size);
  }
  return std::nullopt;
}

}  // namespace

std::string_view WithoutByteOrderMark(std::string_view text) {
  constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";
  if (text.starts_with(kByteOrderMark)) text.remove_prefix(kByteOrderMark.size());
  return text;
}

LineEnd FindLineEnd(std::string_view text, std::size_t start) {
  const std::size_t end = text.find_first_of("\r\n", start);
  if (end == std::string_view::npos) return {text.size(), std::string_view::npos};
  if (text[end] == '\n') return {end, end + 1};
  // Inside a run of CRs that the previous line's end found no LF after.
  if (end == start && start > 0 && text[start - 1] == '\r') return {end, end + 1};
  const std::size_t after_run = text.find_first_not_of('\r', end);
  if (after_run != std::string_view::npos && text[after_run] == '\n') return {end, after_run + 1};
  return {end, end + 1};
}

bool IsHeaderKey(std::string_view word) {
  return word == "name" || word == "order" || word == "max_curvature" || word == "specializes";
}

const char* Describe(TokenKind kind) {
  switch (kind) {
    case TokenKind::kIdentifier:
      return "a name";
    case TokenKind::kNumber:
      return "a number";
    case TokenKind::kPlus:
      return "'+'";
    case TokenKind::kMinus:
      return "'-'";
    case TokenKind::kStar:
      return "'*'";
    case TokenKind::kSlash:
      return "'/'";
    case TokenKind::kCaret:
      return "'^'";
    case TokenKind::kDotStar:
      return "'.*'";
    case TokenKind::kDotSlash:
      return "'./'";
    case TokenKind::kDotCaret:
      return "'.^'";
    case TokenKind::kTranspose:
      return "a transpose '''";
    case TokenKind::kEqualEqual:
      return "'=='";
    case TokenKind::kLessEqual:
      return "'<='";
    case TokenKind::kGreaterEqual:
      return "'>='";
    case TokenKind::kLess:
      return "'<'";
    case TokenKind::kGreater:
      return "'>'";
    case TokenKind::kAssign:
      return "'='";
    case TokenKind::kOrOr:
      return "'||'";
    case TokenKind::kOr:
      return "'|'";
    case TokenKind::kLParen:
      return "'('";
    case TokenKind::kRParen:
      return "')'";
    case TokenKind::kLBracket:
      return "'['";
    case TokenKind::kRBracket:
      return "']'";
    case TokenKind::kComma:
      return "','";
    case TokenKind::kSemicolon:
      return "';'";
    case TokenKind::kColon:
      return "':'";
    case TokenKind::kEnd:
      return "the end of the line";
  }
  return "?";
}

Result<std::vector<Line>> Lex(std::string_view source,
                              const std::shared_ptr<const std::string>& file) {
  source = WithoutByteOrderMark(source);
  std::vector<Line> lines;
  std::size_t start = 0;
  int number = 0;
  bool continuing = false;  // the previous physical line ended in "..."
  while (start <= source.size()) {
    const LineEnd line_end = FindLineEnd(source, start);
    const std::size_t end = line_end.end;
    std::string_view physical = source.substr(start, end - start);
    ++number;
    start = line_end.next == std::string_view::npos ? source.size() + 1 : line_end.next;
    if (const std::size_t comment = CommentStart(physical); comment != std::string_view::npos) {
      physical = physical.substr(0, comment);
    }
    physical = TrimRight(physical);
    std::size_t indent_end = 0;
    int indent_width = 0;
    while (indent_end < physical.size() &&
           (physical[indent_end] == ' ' || physical[indent_end] == '\t')) {
      indent_width = physical[indent_end] == '\t' ? (indent_width / 8 + 1) * 8 : indent_width + 1;
      ++indent_end;
    }
    std::string_view body = physical.substr(indent_end);
    const bool continues = body.size() >= 3 && body.substr(body.size() - 3) == "...";
    const int continuation_col = continues ? static_cast<int>(indent_end) + 1 +
                                                 CharacterCount(body.substr(0, body.size() - 3))
                                           : 0;
    if (continues) body = TrimRight(body.substr(0, body.size() - 3));
    if (body.empty() && !continuing) {
      if (end == source.size()) break;
      continue;
    }
    if (!continuing) {
      Line line;
      line.number = number;
      line.indentation = std::string(physical.substr(0, indent_end));
      line.indent_width = indent_width;
      if (const auto header = HeaderPrefix(body); header && indent_end == 0) {
        line.is_header = true;
        line.header_key = header->first;
        std::size_t value = header->second;
        while (value < body.size() && (body[value] == ' ' || body[value] == '\t')) ++value;
        if (auto unreadable = UnreadableCharacter(body, value, number, *file)) return *unreadable;
        // A header value is the rest of its line: continuing it would either drop the "..."
        // silently or read the next line into a name, and neither is what was written.
        if (continues) {
          return Diagnostic{*file, number, continuation_col,
                            fmt::format("a header line cannot be continued: '{}:' takes the rest "
                                        "of its line, without a '...' at its end",
                                        header->first)};
        }
        line.header_value = std::string(body.substr(value));
        line.header_value_col = 1 + CharacterCount(body.substr(0, value));
        lines.push_back(std::move(line));
        continuing = false;
        if (end == source.size()) break;
        continue;
      }
      lines.push_back(std::move(line));
    }
    Diagnostic error;
    LineLexer lexer(body, number, static_cast<int>(indent_end) + 1, file);
    if (!lexer.Run(lines.back().tokens, error)) return error;
    continuing = continues;
    if (end == source.size()) break;
  }
  for (Line& line : lines) {
    if (line.is_header) continue;
    Token end_token;
    end_token.kind = TokenKind::kEnd;
    const Token* last = line.tokens.empty() ? nullptr : &line.tokens.back();
    end_token.line = last ? last->line : line.number;
    end_token.col = last ? last->end_col : static_cast<int>(line.indentation.size()) + 1;
    end_token.space_before = true;
    line.tokens.push_back(end_token);
  }
  return lines;
}

}  // namespace priormap::dsl::detail
