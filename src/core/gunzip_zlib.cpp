// Gzip data inflated by zlib, member by member, for ReadFileText (and ReadWholeFile without
// libdeflate): the same contract as libdeflate's path in gunzip.cpp.
#include <algorithm>
#include <array>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <zlib.h>

#include <priormap/core/check.hpp>

#include "gunzip.hpp"

namespace priormap::detail {
namespace {

// Why a member could not be inflated: zlib's reason, or the end of the data inside it, and
// whether its header was read (damage after it is in the DEFLATE data or the trailer).
struct Failure {
  bool truncated = false;
  bool in_header = false;
  std::string why;
};

// Inflates the gzip member at the start of `bytes` onto `text` with zlib: the number of bytes
// the member took, or nullopt when it is corrupt or truncated (`failure` says which).
std::optional<std::size_t> InflateMember(z_stream& stream, std::string_view bytes,
                                         std::string& text, Failure& failure) {
  if (inflateReset(&stream) != Z_OK) throw std::bad_alloc();
  // zlib sets `header.done` once the member's header is read (inflateReset forgets `header`).
  gz_header header{};
  PRIORMAP_CHECK(inflateGetHeader(&stream, &header) == Z_OK, "zlib inflates gzip here");
  // What the previous member left unread is this one: fed again from `bytes`.
  stream.next_in = nullptr;
  stream.avail_in = 0;
  // zlib counts in 32 bits: the input goes in slices, the output comes out in chunks.
  constexpr std::size_t kSlice = std::size_t{1} << 30;
  std::array<char, std::size_t{1} << 16> chunk;
  std::size_t fed = 0;  // bytes of `bytes` given to zlib so far
  for (;;) {
    if (stream.avail_in == 0 && fed < bytes.size()) {
      const std::size_t slice = std::min(kSlice, bytes.size() - fed);
      stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data() + fed));
      stream.avail_in = static_cast<uInt>(slice);
      fed += slice;
    }
    stream.next_out = reinterpret_cast<Bytef*>(chunk.data());
    stream.avail_out = static_cast<uInt>(chunk.size());
    const int status = inflate(&stream, Z_NO_FLUSH);
    text.append(chunk.data(), chunk.size() - stream.avail_out);
    if (status == Z_STREAM_END) return fed - stream.avail_in;
    // No progress possible: the data ends inside the member.
    const bool truncated = status == Z_BUF_ERROR && stream.avail_in == 0 && fed == bytes.size();
    if (truncated || (status != Z_OK && status != Z_BUF_ERROR)) {
      failure = {truncated, header.done != 1,
                 truncated ? "" : (stream.msg ? stream.msg : "inflate failed")};
      return std::nullopt;
    }
  }
}

}  // namespace

Result<std::string> GunzipWithZlib(std::string_view bytes, const std::string& name) {
  z_stream stream{};
  if (inflateInit2(&stream, 16 + MAX_WBITS) != Z_OK) throw std::bad_alloc();
  const std::unique_ptr<z_stream, int (*)(z_stream*)> end(&stream, &inflateEnd);
  std::string text;
  std::size_t at = 0;  // where the next member starts
  while (at < bytes.size() && bytes.substr(at).starts_with("\x1f\x8b")) {
    Failure failure;
    const std::optional<std::size_t> member =
        InflateMember(stream, bytes.substr(at), text, failure);
    // Where, as for trailing data: a file cut short by a copy is told from one damaged.
    if (!member && failure.truncated)
      return Diagnostic{name, 0, 0,
                        fmt::format("corrupt or truncated gzip data: the file ends at byte {}, "
                                    "inside the gzip member at byte offset {}: expected the rest "
                                    "of that member",
                                    bytes.size(), at)};
    // What zlib's reason says was wrong: "header crc mismatch", "unknown compression method",
    // ... before the header was read; "invalid distance too far back", "incorrect data check",
    // ... after it.
    if (!member)
      return Diagnostic{
          name, 0, 0,
          fmt::format(
              "corrupt or truncated gzip data: the gzip member at byte "
              "offset {} (of a {}-byte file) is damaged ({}): expected {}",
              at, bytes.size(), failure.why,
              failure.in_header ? "a gzip header" : "DEFLATE data and a trailer that matches it")};
    at += *member;
  }
  if (at < bytes.size()) return TrailingGzipData(name, at, bytes.size());
  return text;
}

}  // namespace priormap::detail
