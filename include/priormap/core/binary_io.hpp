#pragma once
/// A flat binary encoding for checkpoints: values are appended in a fixed order and read back
/// in the same order. Numbers are stored as their little-endian bytes (doubles bit for bit, so
/// a restored state is the saved one exactly). The reader checks every length against what is
/// left, so a truncated or corrupt file is refused with an error, never read out of bounds.

#include <bit>
#include <concepts>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace priormap {

static_assert(std::endian::native == std::endian::little, "checkpoints assume little-endian");

/// A checkpoint or other binary file is truncated, corrupt or of another kind or run.
class BinaryFormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

template <class T>
concept BinaryScalar = std::is_arithmetic_v<T> || std::is_enum_v<T>;

class BinaryWriter {
 public:
  template <BinaryScalar T>
  void Put(T value) {
    const auto* bytes = reinterpret_cast<const char*>(&value);
    bytes_.append(bytes, sizeof(T));
  }
  template <BinaryScalar T>
  void PutVector(const std::vector<T>& values) {
    Put<std::uint64_t>(values.size());
    if (!values.empty())
      bytes_.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
  }
  void PutString(std::string_view text) {
    Put<std::uint64_t>(text.size());
    bytes_.append(text);
  }

  [[nodiscard]] const std::string& bytes() const { return bytes_; }
  [[nodiscard]] std::string TakeBytes() { return std::move(bytes_); }

 private:
  std::string bytes_;
};

class BinaryReader {
 public:
  /// `what` names the data in errors ("checkpoint chain-0.bin").
  BinaryReader(std::string_view bytes, std::string what) : bytes_(bytes), what_(std::move(what)) {}

  template <BinaryScalar T>
  [[nodiscard]] T Get() {
    Need(sizeof(T));
    T value;
    std::memcpy(&value, bytes_.data() + offset_, sizeof(T));
    offset_ += sizeof(T);
    return value;
  }
  template <BinaryScalar T>
  [[nodiscard]] std::vector<T> GetVector() {
    const std::uint64_t n = Get<std::uint64_t>();
    if (n > (bytes_.size() - offset_) / sizeof(T)) Fail("a length beyond the end of the data");
    std::vector<T> values(n);
    if (n > 0) std::memcpy(values.data(), bytes_.data() + offset_, n * sizeof(T));
    offset_ += n * sizeof(T);
    return values;
  }
  [[nodiscard]] std::string GetString() {
    const std::uint64_t n = Get<std::uint64_t>();
    Need(n);
    std::string text(bytes_.substr(offset_, n));
    offset_ += n;
    return text;
  }
  /// A count that must not exceed `limit`.
  [[nodiscard]] std::uint64_t GetCount(std::uint64_t limit, std::string_view of) {
    const auto n = Get<std::uint64_t>();
    if (n > limit) Fail("too many " + std::string(of));
    return n;
  }

  [[nodiscard]] bool AtEnd() const { return offset_ == bytes_.size(); }
  [[nodiscard]] std::size_t remaining() const { return bytes_.size() - offset_; }
  /// Throws BinaryFormatError naming the data and the offset.
  [[noreturn]] void Fail(std::string_view problem) const;

 private:
  void Need(std::uint64_t n) const {
    if (n > bytes_.size() - offset_) Fail("unexpected end of data");
  }

  std::string_view bytes_;
  std::size_t offset_ = 0;
  std::string what_;
};

/// 64-bit FNV-1a of `bytes`: a checksum against truncation and bit rot, and a fingerprint of
/// a run's inputs (not a cryptographic hash).
[[nodiscard]] std::uint64_t Fnv1a64(std::string_view bytes,
                                    std::uint64_t hash = 14695981039346656037ull);

/// A file of `kind` (8 characters) holding `payload`, with a version and the payload's
/// checksum, and the reverse: the payload, or BinaryFormatError when the bytes are not such a
/// file, of another version, or damaged.
[[nodiscard]] std::string SealBinary(std::string_view kind, std::uint32_t version,
                                     std::string_view payload);
[[nodiscard]] std::string_view UnsealBinary(std::string_view bytes, std::string_view kind,
                                            std::uint32_t version, const std::string& what);

}  // namespace priormap
