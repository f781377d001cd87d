#pragma once
/// A vector that keeps up to N items inline and moves them all to the heap beyond that (unlike
/// SmallVector, whose capacity is a hard limit). The sonar term keeps one per reading for the
/// edges it sees, usually one to three: inline, a proposal's test of hundreds of readings ("does
/// it see a removed edge?") fetches no second allocation per reading.

#include <array>
#include <cstddef>
#include <vector>

namespace priormap::prf {

template <class T, std::size_t N>
class InlineVector {
 public:
  void clear() {
    size_ = 0;
    spill_.clear();
  }
  void push_back(const T& value) {
    if (size_ < N) {
      items_[size_++] = value;
      return;
    }
    if (size_ == N) spill_.assign(items_.begin(), items_.end());
    spill_.push_back(value);
    ++size_;
  }
  template <class It>
  void assign(It first, It last) {
    clear();
    for (; first != last; ++first) push_back(*first);
  }
  [[nodiscard]] std::size_t size() const { return size_; }
  [[nodiscard]] bool empty() const { return size_ == 0; }
  T* begin() { return size_ <= N ? items_.data() : spill_.data(); }
  T* end() { return begin() + size_; }
  const T* begin() const { return size_ <= N ? items_.data() : spill_.data(); }
  const T* end() const { return begin() + size_; }

 private:
  std::array<T, N> items_{};
  std::size_t size_ = 0;
  std::vector<T> spill_;  ///< every item once there are more than N
};

}  // namespace priormap::prf
