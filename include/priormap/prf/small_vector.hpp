#pragma once
/// A vector with a fixed capacity stored inline: the edits of the sampler touch at most a few
/// vertices and edges, and a proposal must not allocate.

#include <array>
#include <cstddef>

#include <priormap/core/check.hpp>

namespace priormap::prf {

template <class T, std::size_t N>
class SmallVector {
 public:
  void push_back(const T& value) {
    PRIORMAP_CHECK(size_ < N, "SmallVector capacity exceeded");
    items_[size_++] = value;
  }
  void clear() { size_ = 0; }
  [[nodiscard]] std::size_t size() const { return size_; }
  [[nodiscard]] bool empty() const { return size_ == 0; }
  T& operator[](std::size_t i) { return items_[i]; }
  const T& operator[](std::size_t i) const { return items_[i]; }
  T* begin() { return items_.data(); }
  T* end() { return items_.data() + size_; }
  const T* begin() const { return items_.data(); }
  const T* end() const { return items_.data() + size_; }

 private:
  std::array<T, N> items_{};
  std::size_t size_ = 0;
};

}  // namespace priormap::prf
