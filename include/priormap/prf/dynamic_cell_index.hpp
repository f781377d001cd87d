#pragma once
/// The paper's *dynamic indexing* (Paskin & Thrun, Sec. 2.2), shared by the laser beams and the
/// sonar cones: an item is listed in the grid cells of its current extent (a beam up to its
/// first edge, a cone up to its farthest contact), so that an edit visits only the items whose
/// extent its edges cross. Re-listing an item bumps its version; the entries of older versions
/// go stale and are dropped lazily when a cell is visited, or all at once (the caller re-lists
/// every item) when they outnumber the live entries.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace priormap::prf {

class DynamicCellIndex {
 public:
  /// Empty cells, every item unlisted at version 0.
  void Reset(int num_cells, std::size_t num_items);
  /// Empties the cells, keeping the items' versions (before listing every item anew).
  void Clear();

  /// Lists `item` under its current version in the cells `for_each_cell(add)` passes to `add`.
  template <typename ForEachCell>
  void List(std::size_t item, ForEachCell&& for_each_cell) {
    std::uint32_t listed = 0;
    for_each_cell([&](int cell) {
      cells_[static_cast<std::size_t>(cell)].push_back(
          {static_cast<std::int32_t>(item), versions_[item]});
      ++listed;
    });
    listed_[item] = listed;
    live_entries_ += listed;
  }
  /// Re-lists `item` on new cells: its old entries go stale.
  template <typename ForEachCell>
  void Relist(std::size_t item, ForEachCell&& for_each_cell) {
    ++versions_[item];
    live_entries_ -= listed_[item];
    stale_entries_ += listed_[item];
    List(item, for_each_cell);
  }

  /// Calls visit(item) for each item listed in `cell`, dropping stale entries on the way.
  template <typename Visit>
  void VisitCell(int cell, Visit&& visit) {
    auto& entries = cells_[static_cast<std::size_t>(cell)];
    for (std::size_t k = 0; k < entries.size();) {
      const Entry entry = entries[k];
      if (entry.version != versions_[static_cast<std::size_t>(entry.item)]) {  // re-listed since
        entries[k] = entries.back();
        entries.pop_back();
        --stale_entries_;
        continue;
      }
      visit(entry.item);
      ++k;
    }
  }

  /// True when stale entries outnumber the live ones by enough that the caller should Clear()
  /// and list every item anew.
  [[nodiscard]] bool NeedsRebuild() const { return stale_entries_ > live_entries_ + 1024; }

  [[nodiscard]] std::uint32_t listed_cells(std::size_t item) const { return listed_[item]; }
  /// Whether `item` is listed, at its current version, in `cell`.
  [[nodiscard]] bool IsListed(int cell, std::size_t item) const;
  /// Empty when the live-entry count equals both the items' listed cells and the current
  /// entries in the cells, else what differs (FindInconsistency of the data terms).
  [[nodiscard]] std::optional<std::string> CountProblem() const;

 private:
  struct Entry {
    std::int32_t item;
    std::uint32_t version;
  };
  std::vector<std::vector<Entry>> cells_;
  std::vector<std::uint32_t> versions_;
  std::vector<std::uint32_t> listed_;
  std::size_t live_entries_ = 0;
  std::size_t stale_entries_ = 0;
};

}  // namespace priormap::prf
