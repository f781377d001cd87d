// The dynamic cell index shared by the laser and sonar likelihoods: listing, re-listing with
// lazily dropped stale entries, and its consistency checks.
#include <algorithm>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/prf/dynamic_cell_index.hpp>

namespace priormap::prf {
namespace {

// The cells `cells` as a lister for List/Relist.
auto On(std::vector<int> cells) {
  return [cells](const auto& add) {
    for (int cell : cells) add(cell);
  };
}

std::vector<std::int32_t> ItemsIn(DynamicCellIndex& index, int cell) {
  std::vector<std::int32_t> items;
  index.VisitCell(cell, [&](std::int32_t item) { items.push_back(item); });
  std::sort(items.begin(), items.end());
  return items;
}

TEST(DynamicCellIndex, ListsItemsOnTheirCellsAndRelistingDropsTheOldEntries) {
  DynamicCellIndex index;
  index.Reset(6, 3);
  index.List(0, On({0, 1, 2}));
  index.List(1, On({2, 3}));
  index.List(2, On({}));
  EXPECT_EQ(index.listed_cells(0), 3u);
  EXPECT_EQ(index.listed_cells(2), 0u);
  EXPECT_EQ(ItemsIn(index, 2), (std::vector<std::int32_t>{0, 1}));
  EXPECT_TRUE(index.IsListed(1, 0));
  EXPECT_FALSE(index.IsListed(3, 0));
  EXPECT_FALSE(index.CountProblem());

  // Item 0 moves to cells 4 and 5: it is no longer found where it was.
  index.Relist(0, On({4, 5}));
  EXPECT_EQ(index.listed_cells(0), 2u);
  EXPECT_FALSE(index.IsListed(1, 0));
  EXPECT_TRUE(index.IsListed(5, 0));
  EXPECT_EQ(ItemsIn(index, 2), (std::vector<std::int32_t>{1}));
  EXPECT_TRUE(ItemsIn(index, 0).empty());
  EXPECT_EQ(ItemsIn(index, 4), (std::vector<std::int32_t>{0}));
  EXPECT_FALSE(index.CountProblem());
}

TEST(DynamicCellIndex, AsksForARebuildWhenStaleEntriesPileUpAndKeepsWhatIsLive) {
  DynamicCellIndex index;
  index.Reset(2, 1);
  index.List(0, On({0}));
  // Each re-listing leaves a stale entry in cell 1 (nobody visits it).
  int relists = 0;
  while (!index.NeedsRebuild()) {
    index.Relist(0, On({1}));
    ++relists;
  }
  EXPECT_EQ(relists, 1026);  // stale 1026 > live 1 + 1024
  index.Clear();
  index.List(0, On({1}));
  EXPECT_FALSE(index.NeedsRebuild());
  EXPECT_EQ(ItemsIn(index, 1), (std::vector<std::int32_t>{0}));
  EXPECT_FALSE(index.CountProblem());
}

TEST(DynamicCellIndex, ReportsCountsThatDoNotAddUp) {
  DynamicCellIndex index;
  index.Reset(3, 2);
  index.List(0, On({0, 1}));
  index.List(1, On({1, 2}));
  EXPECT_FALSE(index.CountProblem());
  // Listing an item twice without re-listing doubles its entries: the counts disagree.
  index.List(1, On({0}));
  ASSERT_TRUE(index.CountProblem());
  EXPECT_NE(index.CountProblem()->find("live index entries"), std::string::npos);
}

}  // namespace
}  // namespace priormap::prf
