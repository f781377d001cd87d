#pragma once
/// Strict UTF-8 decoding, shared by the writers that must know whether text is UTF-8 (map_server's
/// YAML), the figures that replace what is not (Cairo stops drawing at invalid UTF-8), and the
/// readers whose diagnostics count columns in characters, as an editor does.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace priormap {

struct Utf8Char {
  std::uint32_t code = 0;
  std::size_t length = 1;  ///< bytes
};

/// The character whose UTF-8 sequence starts at `text[at]` (at < text.size()), or nullopt when the
/// bytes there are not one: a stray continuation byte, a sequence cut short, an overlong form, a
/// surrogate or a code point beyond U+10FFFF.
[[nodiscard]] inline std::optional<Utf8Char> DecodeUtf8(std::string_view text, std::size_t at) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[at + k]); };
  const unsigned char lead = byte(0);
  if (lead < 0x80) return Utf8Char{lead, 1};
  std::size_t length = 0;
  std::uint32_t code = 0;
  std::uint32_t smallest = 0;
  if ((lead & 0xE0) == 0xC0) {
    length = 2, code = lead & 0x1Fu, smallest = 0x80;
  } else if ((lead & 0xF0) == 0xE0) {
    length = 3, code = lead & 0x0Fu, smallest = 0x800;
  } else if ((lead & 0xF8) == 0xF0) {
    length = 4, code = lead & 0x07u, smallest = 0x10000;
  } else {
    return std::nullopt;
  }
  if (at + length > text.size()) return std::nullopt;
  for (std::size_t k = 1; k < length; ++k) {
    if ((byte(k) & 0xC0) != 0x80) return std::nullopt;
    code = code << 6 | (byte(k) & 0x3Fu);
  }
  if (code < smallest || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return std::nullopt;
  return Utf8Char{code, length};
}

/// Where the first byte of `text` that does not start a UTF-8 character is (DecodeUtf8's rule),
/// or std::string_view::npos when all of `text` is UTF-8.
[[nodiscard]] inline std::size_t FirstNotUtf8(std::string_view text) {
  for (std::size_t at = 0; at < text.size();) {
    if (static_cast<unsigned char>(text[at]) < 0x80) {
      ++at;
      continue;
    }
    const std::optional<Utf8Char> c = DecodeUtf8(text, at);
    if (!c) return at;
    at += c->length;
  }
  return std::string_view::npos;
}

/// Whether `code` is a space other than ASCII's (a no-break, thin, ideographic, ... space): it
/// looks like a blank in an editor but is not one to a reader.
[[nodiscard]] constexpr bool IsNonAsciiSpace(std::uint32_t code) {
  return code == 0x00A0 || code == 0x1680 || (code >= 0x2000 && code <= 0x200A) || code == 0x202F ||
         code == 0x205F || code == 0x3000;
}

/// Whether `code` shows as nothing at all (pasted from a web page or a word processor): zero-width
/// spaces and joiners, direction marks, embeddings, overrides and isolates, the byte order mark,
/// the soft hyphen, the combining grapheme joiner, Hangul fillers, variation selectors,
/// interlinear annotation marks and tag characters.
[[nodiscard]] constexpr bool IsInvisibleCharacter(std::uint32_t code) {
  return code == 0x00AD || code == 0x034F || code == 0x061C || code == 0x115F || code == 0x1160 ||
         code == 0x180E || (code >= 0x200B && code <= 0x200F) ||
         (code >= 0x202A && code <= 0x202E) || (code >= 0x2060 && code <= 0x206F) ||
         code == 0x3164 || (code >= 0xFE00 && code <= 0xFE0F) || code == 0xFEFF || code == 0xFFA0 ||
         (code >= 0xFFF9 && code <= 0xFFFB) || (code >= 0xE0000 && code <= 0xE007F) ||
         (code >= 0xE0100 && code <= 0xE01EF);
}

/// Whether `code` is a combining mark of the Unicode blocks made of them (diacritics, their
/// extensions and supplements, marks for symbols, half marks): it draws on the character before
/// it. Script-specific marks elsewhere (vowel signs) are not included.
[[nodiscard]] constexpr bool IsCombiningMark(std::uint32_t code) {
  return (code >= 0x0300 && code <= 0x036F) || (code >= 0x1AB0 && code <= 0x1AFF) ||
         (code >= 0x1DC0 && code <= 0x1DFF) || (code >= 0x20D0 && code <= 0x20FF) ||
         (code >= 0xFE20 && code <= 0xFE2F);
}

/// How many characters an editor shows for `text`: one per UTF-8 character (DecodeUtf8's rule),
/// and one per byte that does not start one (shown as a replacement character).
[[nodiscard]] inline std::size_t CountCharacters(std::string_view text) {
  std::size_t count = 0;
  for (std::size_t at = 0; at < text.size(); ++count) {
    if (static_cast<unsigned char>(text[at]) < 0x80) {
      ++at;
      continue;
    }
    const std::optional<Utf8Char> c = DecodeUtf8(text, at);
    at += c ? c->length : 1;
  }
  return count;
}

/// The 1-based column of byte `offset` of `line` (the text of one line) counted in characters
/// (CountCharacters), as an editor shows it and as diagnostics give it: a line "café x" has its
/// 'x' at column 6, not at byte 7. An offset inside a character is that character's column; one
/// past the end of `line`, the column after its last character (and so on, a column per byte).
[[nodiscard]] inline int CharacterColumn(std::string_view line, std::size_t offset) {
  std::size_t count = 0;
  std::size_t at = 0;
  while (at < offset && at < line.size()) {
    std::size_t length = 1;
    if (static_cast<unsigned char>(line[at]) >= 0x80) {
      const std::optional<Utf8Char> c = DecodeUtf8(line, at);
      length = c ? c->length : 1;
    }
    if (at + length > offset) break;  // `offset` is inside this character
    at += length;
    ++count;
  }
  if (offset > line.size()) count += offset - line.size();
  return static_cast<int>(count) + 1;
}

/// CharacterColumn of a line's bytes asked for in increasing order, each found from the last, so
/// that a reader which locates every field of a long line walks it once, not once per field.
class ColumnCounter {
 public:
  explicit ColumnCounter(std::string_view line) : line_(line) {}

  /// CharacterColumn(line, offset); `offset` is at or after the offset last asked for, and at a
  /// character's first byte (or past the line's end) where that was not the line's start.
  [[nodiscard]] int At(std::size_t offset) {
    col_ +=
        CharacterColumn(line_.substr(at_ < line_.size() ? at_ : line_.size()), offset - at_) - 1;
    at_ = offset;
    return col_;
  }

 private:
  std::string_view line_;
  std::size_t at_ = 0;
  int col_ = 1;
};

/// CharacterColumn of byte `offset` of `text` within its line: the line starts after the last
/// '\n' before `offset`. A UTF-8 byte order mark at the start of `text` takes no column, as
/// editors do not show it.
[[nodiscard]] inline int CharacterColumnInText(std::string_view text, std::size_t offset) {
  offset = offset < text.size() ? offset : text.size();
  std::size_t start = offset == 0 ? std::string_view::npos : text.rfind('\n', offset - 1);
  start = start == std::string_view::npos ? 0 : start + 1;
  if (start == 0 && text.starts_with("\xef\xbb\xbf") && offset >= 3) start = 3;
  return CharacterColumn(text.substr(start), offset - start);
}

}  // namespace priormap
