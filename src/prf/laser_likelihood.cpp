#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/prf/laser_likelihood.hpp>

namespace priormap::prf {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

LaserLikelihood::LaserLikelihood(std::shared_ptr<const LaserData> data, LaserModel model,
                                 double cell_size)
    : data_(std::move(data)), model_(model), cell_size_(cell_size) {
  PRIORMAP_CHECK(data_ != nullptr && data_->max_range > 0.0, "laser data without a max range");
  const std::string problem = model_.Problem();
  PRIORMAP_CHECK(problem.empty(), "laser model: " + problem);
  PRIORMAP_CHECK(cell_size_ > 0.0, "the beam index's cell size must be positive");
}

std::unique_ptr<DataTerm> LaserLikelihood::Clone() const {
  return std::make_unique<LaserLikelihood>(*this);
}

LaserLikelihood::BeamHit LaserLikelihood::WalkBeam(const Coloring& coloring, std::size_t beam,
                                                   double reach, const Edit* ignoring) const {
  const LaserBeam& b = data_->beams[beam];
  const auto hit = coloring.FirstHit(b.origin, b.direction, reach, ignoring);
  return hit ? BeamHit{.distance = hit->t, .edge = hit->edge}
             : BeamHit{.distance = kInf, .edge = kNoEdge};
}

FixedLogLik LaserLikelihood::BeamLogLik(std::size_t beam, double distance) const {
  const LaserBeam& b = data_->beams[beam];
  return ToFixed(model_.LogLikelihood(b.range, b.max_reading, distance, data_->max_range));
}

std::optional<std::string> LaserLikelihood::Reset(const Coloring& coloring) {
  const Window& window = coloring.window();
  grid_ = CellGrid::Covering(window.min, window.max, cell_size_);
  sensor_cells_.assign(static_cast<std::size_t>(grid_.NumCells()), {});
  for (std::size_t s = 0; s < data_->sensors.size(); ++s) {
    const Vec2& sensor = data_->sensors[s];
    if (!window.ContainsInterior(sensor))
      return fmt::format("sensor {} at ({}, {}) lies outside the window", s, sensor.x(),
                         sensor.y());
    if (coloring.ColourAt(sensor) == Colour::kBlack)
      return fmt::format("sensor {} at ({}, {}) lies in occupied space", s, sensor.x(), sensor.y());
    sensor_cells_[static_cast<std::size_t>(grid_.CellOf(sensor))].push_back(
        static_cast<std::int32_t>(s));
  }
  const std::size_t n = data_->beams.size();
  state_.assign(n, {});
  index_.Reset(grid_.NumCells(), n);
  beam_marks_ = VisitMarks();
  beam_marks_.resize(n);
  total_ = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const LaserBeam& beam = data_->beams[i];
    BeamState& state = state_[i];
    state.reach = std::min(data_->max_range, window.DistanceToSide(beam.origin, beam.direction));
    const BeamHit hit = WalkBeam(coloring, i, state.reach, nullptr);
    state.distance = hit.distance;
    state.hit = hit.edge;
    state.log_lik = BeamLogLik(i, state.distance);
    total_ += state.log_lik;
  }
  RebuildIndex();
  pending_.clear();
  candidates_.clear();
  return std::nullopt;
}

// The cells of the beam's extent, from its origin to its first edge (or its reach).
template <typename Add>
void LaserLikelihood::ForEachExtentCell(std::size_t beam, Add&& add) const {
  const BeamState& state = state_[beam];
  const LaserBeam& b = data_->beams[beam];
  const double extent = std::min(state.distance, state.reach);
  WalkCells(grid_, b.origin, b.origin + extent * b.direction, [&](int cell, double, double) {
    add(cell);
    return true;
  });
}

void LaserLikelihood::RebuildIndex() {
  index_.Clear();
  for (std::size_t i = 0; i < state_.size(); ++i)
    index_.List(i, [&](const auto& add) { ForEachExtentCell(i, add); });
}

bool LaserLikelihood::SensorFlips(const Edit& edit) const {
  const std::span<const Vec2> region{edit.flipped_region.begin(), edit.flipped_region.size()};
  bool flips = false;
  ForEachCellUnder(grid_, region, [&](int cell) {
    for (std::int32_t s : sensor_cells_[static_cast<std::size_t>(cell)])
      flips = flips || RingContains(region, data_->sensors[static_cast<std::size_t>(s)]);
  });
  return flips;
}

void LaserLikelihood::CollectBeams(const Vec2& a, const Vec2& b) {
  WalkCells(grid_, a, b, [&](int cell, double, double) {
    index_.VisitCell(cell, [&](std::int32_t beam) {
      if (beam_marks_.Mark(static_cast<std::size_t>(beam))) candidates_.push_back(beam);
    });
    return true;
  });
}

std::optional<FixedLogLik> LaserLikelihood::Evaluate(const Coloring& coloring, const Edit& edit) {
  pending_.clear();
  candidates_.clear();
  pending_delta_ = 0;
  if (SensorFlips(edit)) return std::nullopt;

  beam_marks_.NextRound();
  SmallVector<Segment, 4> added;
  for (std::size_t k = 0; k < edit.added_edges.size(); ++k)
    added.push_back(coloring.AddedSegment(edit, k));
  for (EdgeId e : edit.removed_edges) {
    const Segment s = coloring.EdgeSegment(e);
    CollectBeams(s.a, s.b);
  }
  for (const Segment& s : added) CollectBeams(s.a, s.b);

  for (std::int32_t id : candidates_) {
    const auto i = static_cast<std::size_t>(id);
    const LaserBeam& beam = data_->beams[i];
    const BeamState& state = state_[i];
    Change change{
        .beam = id, .distance = state.distance, .hit = state.hit, .added = -1, .log_lik = 0};
    if (state.hit != kNoEdge && edit.Removes(state.hit)) {
      const BeamHit hit = WalkBeam(coloring, i, state.reach, &edit);
      change.distance = hit.distance;
      change.hit = hit.edge;
    }
    for (std::size_t k = 0; k < added.size(); ++k) {
      const auto t =
          RaySegmentHit(beam.origin, beam.direction, added[k].a, added[k].b, state.reach);
      if (t && *t < change.distance) {
        change.distance = *t;
        change.hit = kNoEdge;
        change.added = static_cast<int>(k);
      }
    }
    if (change.distance == state.distance && change.hit == state.hit) continue;
    change.log_lik =
        change.distance == state.distance ? state.log_lik : BeamLogLik(i, change.distance);
    pending_delta_ += change.log_lik - state.log_lik;
    pending_.push_back(change);
  }
  return pending_delta_;
}

void LaserLikelihood::Commit(std::span<const EdgeId> added_edges) {
  for (const Change& change : pending_) {
    const auto i = static_cast<std::size_t>(change.beam);
    BeamState& state = state_[i];
    const bool moved = change.distance != state.distance;
    state.distance = change.distance;
    state.hit =
        change.added >= 0 ? added_edges[static_cast<std::size_t>(change.added)] : change.hit;
    state.log_lik = change.log_lik;
    if (!moved) continue;  // another edge at the same distance: same cells
    index_.Relist(i, [&](const auto& add) { ForEachExtentCell(i, add); });
  }
  total_ += pending_delta_;
  pending_.clear();
  pending_delta_ = 0;
  if (index_.NeedsRebuild()) RebuildIndex();
}

FixedLogLik LaserLikelihood::RecomputeLogLikelihood(const Coloring& coloring) const {
  FixedLogLik total = 0;
  for (std::size_t i = 0; i < data_->beams.size(); ++i)
    total += BeamLogLik(i, WalkBeam(coloring, i, state_[i].reach, nullptr).distance);
  return total;
}

std::optional<std::string> LaserLikelihood::FindInconsistency(const Coloring& coloring) const {
  for (std::size_t s = 0; s < data_->sensors.size(); ++s)
    if (coloring.ColourAt(data_->sensors[s]) == Colour::kBlack)
      return fmt::format("sensor {} is in black", s);
  FixedLogLik total = 0;
  for (std::size_t i = 0; i < data_->beams.size(); ++i) {
    const BeamState& state = state_[i];
    const double distance = WalkBeam(coloring, i, state.reach, nullptr).distance;
    if (distance != state.distance)
      return fmt::format("beam {}: distance {} kept, {} recomputed", i, state.distance, distance);
    if (state.log_lik != BeamLogLik(i, distance))
      return fmt::format("beam {}: log-likelihood kept differs from its recomputation", i);
    total += state.log_lik;
    // Listed exactly on the cells of its extent: no fewer (missed updates), no more (wasted
    // recomputations).
    bool listed = true;
    std::uint32_t extent_cells = 0;
    ForEachExtentCell(i, [&](int cell) {
      listed = listed && index_.IsListed(cell, i);
      ++extent_cells;
    });
    if (!listed) return fmt::format("beam {} is missing from a cell of its extent", i);
    if (extent_cells != index_.listed_cells(i))
      return fmt::format("beam {} is listed in {} cells, its extent has {}", i,
                         index_.listed_cells(i), extent_cells);
  }
  if (total != total_)
    return fmt::format("total log-likelihood kept {} differs from the sum {}", FromFixed(total_),
                       FromFixed(total));
  return index_.CountProblem();
}

}  // namespace priormap::prf
