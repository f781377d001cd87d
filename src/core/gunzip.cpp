#include "gunzip.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>

#ifdef PRIORMAP_HAVE_LIBDEFLATE
#include <libdeflate.h>
#endif

namespace priormap::detail {
namespace {

namespace fs = std::filesystem;

Result<ByteBuffer> Copy(const std::string& text) {
  ByteBuffer bytes(text.size());
  std::memcpy(bytes.data(), text.data(), text.size());
  return bytes;
}

#ifdef PRIORMAP_HAVE_LIBDEFLATE

constexpr std::size_t kMinMember = 18;  // header, empty deflate stream and trailer
// DEFLATE inflates at most about 1032-fold.
constexpr std::size_t kMaxRatio = 1032;

bool StartsAMember(std::string_view bytes) {
  return bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0x1f &&
         static_cast<unsigned char>(bytes[1]) == 0x8b;
}

// How much room to give the members in `bytes`: what the last member says it inflates to (its
// ISIZE, modulo 2^32), exact for the usual single-member file, unless a corrupt trailer claims
// more than DEFLATE can give; then a guess, grown when short.
std::size_t RoomFor(std::string_view bytes) {
  std::size_t size = 0;
  if (bytes.size() >= kMinMember) {
    const auto* p = reinterpret_cast<const unsigned char*>(bytes.data() + bytes.size() - 4);
    size = static_cast<std::size_t>(p[0]) | static_cast<std::size_t>(p[1]) << 8 |
           static_cast<std::size_t>(p[2]) << 16 | static_cast<std::size_t>(p[3]) << 24;
  }
  return size <= kMaxRatio * bytes.size() ? size : 4 * bytes.size();
}

// `bytes` with room for `size` bytes, the first `used` kept.
ByteBuffer Grown(ByteBuffer bytes, std::size_t used, std::size_t size) {
  if (size <= bytes.size()) return bytes;
  ByteBuffer grown(size);
  if (used > 0) std::memcpy(grown.data(), bytes.data(), used);
  return grown;
}

// libdeflate skips a member header's CRC (FHCRC), which zlib and gzip check: unchecked, a file
// that ReadFileText refuses would read here. Anything malformed is left to libdeflate.
bool HeaderCrcMatches(std::string_view member) {
  const auto* p = reinterpret_cast<const unsigned char*>(member.data());
  const std::size_t n = member.size();
  constexpr unsigned kHeaderCrc = 0x02, kExtra = 0x04, kName = 0x08, kComment = 0x10;
  if (n < 10 || !(p[3] & kHeaderCrc)) return true;
  std::size_t at = 10;
  if (p[3] & kExtra) {
    if (at + 2 > n) return true;
    at += 2 + (static_cast<std::size_t>(p[at]) | static_cast<std::size_t>(p[at + 1]) << 8);
  }
  for (const unsigned field : {kName, kComment}) {
    if (!(p[3] & field)) continue;
    while (at < n && p[at] != 0) ++at;
    ++at;  // the terminating zero
  }
  if (at + 2 > n) return true;
  const unsigned stored = static_cast<unsigned>(p[at]) | static_cast<unsigned>(p[at + 1]) << 8;
  return (libdeflate_crc32(0, p, at) & 0xffffu) == stored;
}

struct FreeDecompressor {
  void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

// libdeflate says only that a member failed, not where nor why: zlib, reading `bytes` again on
// this rare path, says both, in the words of ReadFileText, so that every command reports a
// damaged file alike. Should zlib read what libdeflate refused, its bytes are the answer.
Result<ByteBuffer> DiagnoseWithZlib(std::string_view bytes, const std::string& name) {
  const Result<std::string> text = GunzipWithZlib(bytes, name);
  if (!text) return text.diagnostics();
  return Copy(text.value());
}

Result<ByteBuffer> Gunzip(std::string_view bytes, const std::string& name) {
  const std::unique_ptr<libdeflate_decompressor, FreeDecompressor> decompressor(
      libdeflate_alloc_decompressor());
  if (!decompressor) throw std::bad_alloc();
  const std::string_view whole = bytes;
  const std::size_t file_size = bytes.size();
  ByteBuffer text;
  std::size_t used = 0;  // bytes of `text` inflated so far
  std::size_t room = RoomFor(bytes);
  while (StartsAMember(bytes)) {
    if (!HeaderCrcMatches(bytes)) return DiagnoseWithZlib(whole, name);
    text = Grown(std::move(text), used, used + room);
    std::size_t in = 0, out = 0;
    const libdeflate_result result = libdeflate_gzip_decompress_ex(
        decompressor.get(), bytes.data(), bytes.size(), text.data() + used, room, &in, &out);
    if (result == LIBDEFLATE_INSUFFICIENT_SPACE) {
      // A member larger than guessed: inflate it again with more room, up to what DEFLATE can
      // give.
      if (room > kMaxRatio * bytes.size()) return DiagnoseWithZlib(whole, name);
      room = std::max<std::size_t>(2 * room, std::size_t{1} << 16);
      continue;
    }
    if (result != LIBDEFLATE_SUCCESS) return DiagnoseWithZlib(whole, name);
    used += out;
    bytes.remove_prefix(in);
    room = RoomFor(bytes);
  }
  // What follows the last member and does not start one is refused, not ignored as gzread
  // ignores it: it may be data that would go unread.
  if (!bytes.empty()) return TrailingGzipData(name, file_size - bytes.size(), file_size);
  text.Truncate(used);
  return text;
}

#endif

}  // namespace

Diagnostic TrailingGzipData(const std::string& name, std::size_t offset, std::size_t file_size) {
  return Diagnostic{name, 0, 0,
                    fmt::format("trailing data after the last gzip member, at byte offset {} (of "
                                "a {}-byte file): expected another gzip member (magic bytes 1f "
                                "8b) or the end of the file",
                                offset, file_size)};
}

Diagnostic CannotOpenForReading(const std::string& name) {
  // Why, when the system says: permission denied, no such device, too many open files, ...
  const int error = errno;
  return Diagnostic{name, 0, 0,
                    std::string("cannot open file for reading") +
                        (error != 0 ? std::string(": ") + std::strerror(error) : "")};
}

Result<ByteBuffer> ReadWholeFile(const fs::path& path) {
#ifndef PRIORMAP_HAVE_LIBDEFLATE
  const Result<std::string> text = ReadFileText(path);
  if (!text) return text.diagnostics();
  return Copy(text.value());
#else
  const std::string name = path.string();
  std::error_code ec;
  if (!fs::exists(path, ec)) return Diagnostic{name, 0, 0, "no such file"};
  if (fs::is_directory(path, ec)) return Diagnostic{name, 0, 0, "is a directory, expected a file"};
  errno = 0;
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(name.c_str(), "rb"),
                                                             &std::fclose);
  if (!file) return CannotOpenForReading(name);
  // The size is a hint: the file is read to its end whatever it is (a pipe, a growing file).
  const std::uintmax_t hint = fs::file_size(path, ec);
  ByteBuffer bytes(ec ? std::size_t{1} << 16 : static_cast<std::size_t>(hint) + 1);
  std::size_t size = 0;
  for (;;) {
    size += std::fread(bytes.data() + size, 1, bytes.size() - size, file.get());
    if (size < bytes.size()) break;
    bytes = Grown(std::move(bytes), size, 2 * size);
  }
  if (std::ferror(file.get())) return Diagnostic{name, 0, 0, "cannot read the file"};
  bytes.Truncate(size);
  if (!StartsAMember(bytes.view())) return bytes;
  return Gunzip(bytes.view(), name);
#endif
}

}  // namespace priormap::detail
