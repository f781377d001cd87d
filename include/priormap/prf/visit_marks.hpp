#pragma once
/// Marks "seen in this round" over items numbered 0..n-1, forgotten all at once by starting a
/// new round (a counter, not a clear): walks that reach an edge, beam or cell from several grid
/// cells visit it once.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace priormap::prf {

class VisitMarks {
 public:
  void resize(std::size_t n) { marks_.resize(n, 0u); }
  /// Forgets every mark.
  void NextRound() {
    if (++round_ == 0) {  // wrapped: old marks could match again
      std::fill(marks_.begin(), marks_.end(), 0u);
      round_ = 1;
    }
  }
  /// Marks item i; true when it was not marked yet in this round.
  bool Mark(std::size_t i) {
    if (marks_[i] == round_) return false;
    marks_[i] = round_;
    return true;
  }
  [[nodiscard]] bool Marked(std::size_t i) const { return marks_[i] == round_; }

 private:
  std::vector<std::uint32_t> marks_;
  std::uint32_t round_ = 0;
};

}  // namespace priormap::prf
