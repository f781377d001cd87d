#pragma once
/// A set of items numbered 0..n-1, read back in increasing order: a bit per item, so that
/// marking is a store and the drain a scan of the words touched. The sonar term gathers a
/// proposal's candidate readings with it, so that they are recomputed in the data's order and
/// readings of consecutive rings, which see the same walls, are read from memory one after the
/// other rather than in the order the cell lists happen to hold them.

#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace priormap::prf {

class OrderedMarks {
 public:
  /// Room for items 0..n-1; forgets every mark.
  void resize(std::size_t n) {
    words_.assign((n + 63) / 64, 0);
    lowest_ = words_.size();
    highest_ = 0;
  }
  /// Marks item i (again: no effect).
  void Mark(std::size_t i) {
    const std::size_t w = i / 64;
    words_[w] |= std::uint64_t{1} << (i % 64);
    if (w < lowest_) lowest_ = w;
    if (w + 1 > highest_) highest_ = w + 1;
  }
  /// Appends the marked items to `out` in increasing order and forgets them.
  template <class Int>
  void Drain(std::vector<Int>* out) {
    for (std::size_t w = lowest_; w < highest_; ++w) {
      for (std::uint64_t bits = words_[w]; bits != 0; bits &= bits - 1)
        out->push_back(static_cast<Int>(w * 64 + static_cast<std::size_t>(std::countr_zero(bits))));
      words_[w] = 0;
    }
    lowest_ = words_.size();
    highest_ = 0;
  }

 private:
  std::vector<std::uint64_t> words_;
  std::size_t lowest_ = 0, highest_ = 0;  ///< the words that may hold marks: [lowest_, highest_)
};

}  // namespace priormap::prf
