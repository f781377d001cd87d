#include <algorithm>
#include <numeric>

#include <fmt/format.h>

#include <priormap/prf/dynamic_cell_index.hpp>

namespace priormap::prf {

void DynamicCellIndex::Reset(int num_cells, std::size_t num_items) {
  cells_.assign(static_cast<std::size_t>(num_cells), {});
  versions_.assign(num_items, 0);
  listed_.assign(num_items, 0);
  live_entries_ = 0;
  stale_entries_ = 0;
}

void DynamicCellIndex::Clear() {
  for (auto& entries : cells_) entries.clear();
  std::fill(listed_.begin(), listed_.end(), 0);
  live_entries_ = 0;
  stale_entries_ = 0;
}

bool DynamicCellIndex::IsListed(int cell, std::size_t item) const {
  const auto& entries = cells_[static_cast<std::size_t>(cell)];
  return std::any_of(entries.begin(), entries.end(), [&](const Entry& entry) {
    return entry.item == static_cast<std::int32_t>(item) && entry.version == versions_[item];
  });
}

std::optional<std::string> DynamicCellIndex::CountProblem() const {
  const std::size_t listed = std::accumulate(listed_.begin(), listed_.end(), std::size_t{0});
  std::size_t current = 0;
  for (const auto& entries : cells_)
    for (const Entry& entry : entries)
      current += entry.version == versions_[static_cast<std::size_t>(entry.item)] ? 1 : 0;
  if (listed != live_entries_ || current != live_entries_)
    return fmt::format("{} live index entries counted, {} listed, {} in the cells", live_entries_,
                       listed, current);
  return std::nullopt;
}

}  // namespace priormap::prf
