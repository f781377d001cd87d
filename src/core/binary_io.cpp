#include <fmt/format.h>

#include <priormap/core/binary_io.hpp>

namespace priormap {

void BinaryReader::Fail(std::string_view problem) const {
  throw BinaryFormatError(fmt::format("{}: {} at byte {}", what_, problem, offset_));
}

std::uint64_t Fnv1a64(std::string_view bytes, std::uint64_t hash) {
  for (const char c : bytes) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ull;
  }
  return hash;
}

namespace {
constexpr std::size_t kKindSize = 8;
// kind, version, payload size, checksum
constexpr std::size_t kHeaderSize = kKindSize + 4 + 8 + 8;
}  // namespace

std::string SealBinary(std::string_view kind, std::uint32_t version, std::string_view payload) {
  std::string kind_field(kind.substr(0, kKindSize));
  kind_field.resize(kKindSize, ' ');
  BinaryWriter header;
  header.Put(version);
  header.Put<std::uint64_t>(payload.size());
  header.Put(Fnv1a64(payload));
  std::string sealed = kind_field + header.bytes();
  sealed.append(payload);
  return sealed;
}

std::string_view UnsealBinary(std::string_view bytes, std::string_view kind, std::uint32_t version,
                              const std::string& what) {
  std::string kind_field(kind.substr(0, kKindSize));
  kind_field.resize(kKindSize, ' ');
  if (bytes.size() < kHeaderSize || bytes.substr(0, kKindSize) != kind_field)
    throw BinaryFormatError(fmt::format("{}: not a {} file", what, kind));
  BinaryReader header(bytes.substr(kKindSize, kHeaderSize - kKindSize), what);
  const auto file_version = header.Get<std::uint32_t>();
  const auto size = header.Get<std::uint64_t>();
  const auto checksum = header.Get<std::uint64_t>();
  if (file_version != version)
    throw BinaryFormatError(fmt::format("{}: version {} of the {} format, this build reads {}",
                                        what, file_version, kind, version));
  const std::string_view payload = bytes.substr(kHeaderSize);
  if (payload.size() != size)
    throw BinaryFormatError(fmt::format(
        "{}: truncated or padded ({} bytes of payload, {} expected)", what, payload.size(), size));
  if (Fnv1a64(payload) != checksum)
    throw BinaryFormatError(fmt::format("{}: checksum mismatch (the file is damaged)", what));
  return payload;
}

}  // namespace priormap
