// The sonar term's small containers against the standard library's: OrderedMarks (its candidate
// readings) as a std::set drained in order, InlineVector (the edges a reading sees) as a
// std::vector across its inline capacity.
#include <cstdint>
#include <set>
#include <vector>

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <priormap/prf/inline_vector.hpp>
#include <priormap/prf/ordered_marks.hpp>

namespace priormap::prf {
namespace {

RC_GTEST_PROP(OrderedMarks, DrainsWhatWasMarkedInIncreasingOrderOnce, ()) {
  const std::size_t n = *rc::gen::inRange<std::size_t>(1, 300);
  OrderedMarks marks;
  marks.resize(n);
  const int rounds = *rc::gen::inRange(1, 4);
  for (int round = 0; round < rounds; ++round) {
    const auto items =
        *rc::gen::container<std::vector<std::size_t>>(rc::gen::inRange<std::size_t>(0, n));
    std::set<std::size_t> expected;
    for (const std::size_t i : items) {
      marks.Mark(i);
      expected.insert(i);
    }
    std::vector<std::int32_t> drained = {-1};  // Drain appends
    marks.Drain(&drained);
    std::vector<std::int32_t> want = {-1};
    want.insert(want.end(), expected.begin(), expected.end());
    RC_ASSERT(drained == want);
  }
  // Drained marks are forgotten.
  std::vector<std::int32_t> empty;
  marks.Drain(&empty);
  RC_ASSERT(empty.empty());
}

TEST(OrderedMarks, KeepsTheWordsEdgesApart) {
  OrderedMarks marks;
  marks.resize(130);
  for (const std::size_t i : {129u, 64u, 63u, 0u, 127u, 128u, 64u}) marks.Mark(i);
  std::vector<int> drained;
  marks.Drain(&drained);
  EXPECT_EQ(drained, (std::vector<int>{0, 63, 64, 127, 128, 129}));
}

RC_GTEST_PROP(InlineVector, HoldsWhatAVectorHolds, ()) {
  InlineVector<std::int32_t, 3> small;
  std::vector<std::int32_t> reference;
  const auto ops = *rc::gen::container<std::vector<std::pair<int, std::int32_t>>>(
      rc::gen::pair(rc::gen::inRange(0, 10), rc::gen::arbitrary<std::int32_t>()));
  for (const auto& [op, value] : ops) {
    if (op == 0) {
      small.clear();
      reference.clear();
    } else if (op == 1) {
      const auto values =
          *rc::gen::container<std::vector<std::int32_t>>(rc::gen::arbitrary<std::int32_t>());
      small.assign(values.begin(), values.end());
      reference = values;
    } else {
      small.push_back(value);
      reference.push_back(value);
    }
    RC_ASSERT(small.size() == reference.size());
    RC_ASSERT(small.empty() == reference.empty());
    RC_ASSERT(std::vector<std::int32_t>(small.begin(), small.end()) == reference);
  }
  // A copy holds the same items, inline or spilled.
  const InlineVector<std::int32_t, 3> copy = small;
  RC_ASSERT(std::vector<std::int32_t>(copy.begin(), copy.end()) == reference);
}

}  // namespace
}  // namespace priormap::prf
