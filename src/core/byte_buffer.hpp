#pragma once
// A buffer for a whole file's bytes while a reader parses them. Large buffers get their own
// mapping with transparent huge pages where Linux offers them: on the project's VMs a 4 KB page
// fault costs about 27 us, so the 1.7 MB of an inflated CARMEN log would spend 11 ms in faults
// in 4 KB pages, and 0.1 ms in one 2 MB page.

#include <cstddef>
#include <memory>
#include <string_view>

namespace priormap::detail {

// Unmaps a mapping or deletes memory from operator new[].
struct ReleaseBytes {
  std::size_t mapped = 0;  // bytes mapped, or 0 for memory from operator new[]
  void operator()(char* bytes) const;
};

class ByteBuffer {
 public:
  ByteBuffer() = default;
  /// `size` bytes, uninitialised. Throws std::bad_alloc.
  explicit ByteBuffer(std::size_t size);

  [[nodiscard]] char* data() { return bytes_.get(); }
  [[nodiscard]] const char* data() const { return bytes_.get(); }
  [[nodiscard]] std::size_t size() const { return size_; }
  [[nodiscard]] std::string_view view() const { return {bytes_.get(), size_}; }
  /// Keeps the first `size` <= size() bytes (the memory stays until the buffer goes).
  void Truncate(std::size_t size) { size_ = size < size_ ? size : size_; }

 private:
  std::unique_ptr<char, ReleaseBytes> bytes_;
  std::size_t size_ = 0;
};

}  // namespace priormap::detail
