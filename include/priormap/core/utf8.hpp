#pragma once
/// Strict UTF-8 decoding, shared by the writers that must know whether text is UTF-8 (map_server's
/// YAML) and the figures that replace what is not (Cairo stops drawing at invalid UTF-8).

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

}  // namespace priormap
