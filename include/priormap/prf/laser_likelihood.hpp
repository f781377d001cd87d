#pragma once
/// The PRF laser likelihood (Paskin & Thrun, Sec. 2.2) with dynamic indexing: each beam is listed
/// in the grid cells from its sensor to its current first impact (or to where it stops: R or the
/// window's side), so an edit recomputes only the beams listed in the cells of the edges it
/// removes or adds, and a recomputed beam is re-listed on its new extent.
///
/// A beam whose first edge survives the edit only needs the added edges tested; one whose first
/// edge is removed walks the edge index again. A sensor inside the region an edit reverses would
/// turn black (the state keeps every sensor white), which has likelihood zero.
///
/// Re-listing a beam bumps its version instead of searching its old cells: stale entries are
/// dropped when a cell is next read, and the whole index is rebuilt once they outnumber the live
/// ones, so the index stays proportional to the beams' extents.

#include <cstdint>
#include <memory>
#include <vector>

#include <priormap/prf/data_term.hpp>
#include <priormap/prf/dynamic_cell_index.hpp>
#include <priormap/prf/laser_data.hpp>
#include <priormap/prf/laser_model.hpp>

namespace priormap::prf {

class LaserLikelihood final : public DataTerm {
 public:
  /// `cell_size`: of the beam index (about the coloring's edge-index cell works well).
  LaserLikelihood(std::shared_ptr<const LaserData> data, LaserModel model, double cell_size);

  std::optional<std::string> Reset(const Coloring& coloring) override;
  std::optional<FixedLogLik> Evaluate(const Coloring& coloring, const Edit& edit) override;
  void Commit(std::span<const EdgeId> added_edges) override;
  [[nodiscard]] FixedLogLik log_likelihood() const override { return total_; }
  [[nodiscard]] FixedLogLik RecomputeLogLikelihood(const Coloring& coloring) const override;
  [[nodiscard]] std::optional<std::string> FindInconsistency(
      const Coloring& coloring) const override;
  [[nodiscard]] std::unique_ptr<DataTerm> Clone() const override;

  [[nodiscard]] const LaserData& data() const { return *data_; }
  [[nodiscard]] const LaserModel& model() const { return model_; }
  /// Distance to the beam's first edge, +inf when none within its reach.
  [[nodiscard]] double distance(std::size_t beam) const { return state_[beam].distance; }

 private:
  struct BeamState {
    double reach = 0.0;     // min(R, distance to the window's side)
    double distance = 0.0;  // to the first edge; +inf when none within reach
    EdgeId hit = kNoEdge;
    FixedLogLik log_lik = 0;
  };
  struct Change {
    std::int32_t beam;
    double distance;
    EdgeId hit;      // an existing edge, or kNoEdge
    int added = -1;  // else the index of the edit's added edge hit
    FixedLogLik log_lik;
  };

  struct BeamHit {
    double distance;  // +inf when none within reach
    EdgeId edge;
  };
  /// The beam's first edge within `reach`, passing over the edges `ignoring` removes.
  [[nodiscard]] BeamHit WalkBeam(const Coloring& coloring, std::size_t beam, double reach,
                                 const Edit* ignoring) const;
  [[nodiscard]] FixedLogLik BeamLogLik(std::size_t beam, double distance) const;
  [[nodiscard]] bool SensorFlips(const Edit& edit) const;
  void CollectBeams(const Vec2& a, const Vec2& b);
  /// Calls add(cell) for the cells of the beam's extent (defined and used in the .cpp only).
  template <typename Add>
  void ForEachExtentCell(std::size_t beam, Add&& add) const;
  void RebuildIndex();

  std::shared_ptr<const LaserData> data_;
  LaserModel model_;
  double cell_size_;
  CellGrid grid_;
  std::vector<BeamState> state_;
  DynamicCellIndex index_;  ///< the beams, each on the cells up to its first edge
  std::vector<std::vector<std::int32_t>> sensor_cells_;
  FixedLogLik total_ = 0;
  // Scratch of Evaluate, read by Commit.
  std::vector<std::int32_t> candidates_;
  VisitMarks beam_marks_;
  std::vector<Change> pending_;
  FixedLogLik pending_delta_ = 0;
};

}  // namespace priormap::prf
