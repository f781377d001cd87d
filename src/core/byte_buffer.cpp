#include "byte_buffer.hpp"

#include <new>

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace priormap::detail {
namespace {

#if defined(__linux__) && defined(MADV_HUGEPAGE)
constexpr std::size_t kHugePage = std::size_t{2} << 20;
// From this size a mapping of one huge page (a fault and 2 MB zeroed, about 0.1 ms) is cheaper
// than 4 KB pages faulted one by one (27 us each).
constexpr std::size_t kMapFrom = std::size_t{256} << 10;
#endif

}  // namespace

ByteBuffer::ByteBuffer(std::size_t size) : size_(size) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (size >= kMapFrom) {
    const std::size_t mapped = (size + kHugePage - 1) / kHugePage * kHugePage;
    void* memory =
        ::mmap(nullptr, mapped, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (memory == MAP_FAILED) throw std::bad_alloc();
    // Only advice: without huge pages the mapping works in small ones.
    ::madvise(memory, mapped, MADV_HUGEPAGE);
    bytes_ = std::unique_ptr<char, ReleaseBytes>(static_cast<char*>(memory), ReleaseBytes{mapped});
    return;
  }
#endif
  bytes_ = std::unique_ptr<char, ReleaseBytes>(new char[size], ReleaseBytes{0});
}

void ReleaseBytes::operator()(char* bytes) const {
#ifdef __linux__
  if (mapped > 0) {
    ::munmap(bytes, mapped);
    return;
  }
#endif
  delete[] bytes;
}

}  // namespace priormap::detail
