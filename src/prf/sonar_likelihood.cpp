#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/prf/sonar_likelihood.hpp>

namespace priormap::prf {
namespace {

// A hair beyond the extent, so that a cell touching the cone exactly there is listed too.
double Inflated(double extent) {
  return extent * (1.0 + 1e-9) + 1e-9;
}

// The edge a tag of an Evaluate names once the edit is applied: added edge k is tagged -1 - k.
EdgeId Resolved(std::int32_t tag, std::span<const EdgeId> added_edges) {
  return tag >= 0 ? tag : added_edges[static_cast<std::size_t>(-1 - tag)];
}

bool SameGrid(const CellGrid& a, const CellGrid& b) {
  return a.origin == b.origin && a.cell == b.cell && a.nx == b.nx && a.ny == b.ny;
}

// The cells of `grid` that may overlap the cone up to R: those meeting its disc and both
// half-planes of its wedge (a superset of the exact overlap), with their distance to the apex.
void AppendConeCells(const CellGrid& grid, const SonarCone& cone,
                     std::vector<std::pair<double, std::int32_t>>* out) {
  const double h = cone.half_spread;
  const double r = cone.max_range;
  const Vec2 side = Perp(cone.axis);
  Box2 box;
  box.extend(cone.origin);
  for (const double sign : {-1.0, 1.0})
    box.extend(cone.origin + r * (std::cos(h) * cone.axis + sign * std::sin(h) * side));
  for (const Vec2& direction : {Vec2(1, 0), Vec2(-1, 0), Vec2(0, 1), Vec2(0, -1)})
    if (cone.axis.dot(direction) >= std::cos(h)) box.extend(cone.origin + r * direction);
  const Vec2 normals[2] = {-std::sin(h) * cone.axis + std::cos(h) * side,
                           -std::sin(h) * cone.axis - std::cos(h) * side};
  const int x0 = grid.ClampX(box.min().x()), x1 = grid.ClampX(box.max().x());
  const int y0 = grid.ClampY(box.min().y()), y1 = grid.ClampY(box.max().y());
  for (int iy = y0; iy <= y1; ++iy) {
    for (int ix = x0; ix <= x1; ++ix) {
      const Vec2 lo = grid.origin + Vec2(ix * grid.cell.x(), iy * grid.cell.y());
      const Vec2 hi = lo + grid.cell;
      const Vec2 gap = (lo - cone.origin).cwiseMax(cone.origin - hi).cwiseMax(0.0);
      const double near = gap.norm();
      if (near > r) continue;
      bool in_wedge = true;
      for (const Vec2& n : normals) {
        double lowest = std::numeric_limits<double>::infinity();
        for (const Vec2& corner : {lo, hi, Vec2(lo.x(), hi.y()), Vec2(hi.x(), lo.y())})
          lowest = std::min(lowest, n.dot(corner - cone.origin));
        in_wedge = in_wedge && lowest <= 0.0;
      }
      if (in_wedge) out->push_back({near, iy * grid.nx + ix});
    }
  }
}

}  // namespace

SonarLikelihood::SonarLikelihood(std::shared_ptr<const SonarData> data, SonarModel model)
    : data_(std::move(data)), model_(model) {
  PRIORMAP_CHECK(data_ != nullptr && data_->max_range > 0.0, "sonar data without a max range");
  const std::string problem = model_.Problem();
  PRIORMAP_CHECK(problem.empty(), "sonar model: " + problem);
  for (const SonarReading& r : data_->readings)
    PRIORMAP_CHECK(r.cone.half_spread > 0.0 && r.cone.half_spread < std::numbers::pi / 2.0,
                   "a sonar cone's half-angle must be in (0, pi/2)");
}

std::unique_ptr<DataTerm> SonarLikelihood::Clone() const {
  return std::make_unique<SonarLikelihood>(*this);
}

bool SonarLikelihood::Leg::operator==(const Leg& other) const {
  const bool same_hit = hit.has_value() == other.hit.has_value() &&
                        (!hit || (hit->t == other.hit->t && hit->tag == other.hit->tag));
  return same_hit && path.from == other.path.from && path.direction == other.path.direction &&
         path.reach == other.path.reach;
}

bool SonarLikelihood::Leg::SameCells(const std::optional<Leg>& a, const std::optional<Leg>& b) {
  if (!a || !b) return a.has_value() == b.has_value();
  return a->path.from == b->path.from && a->path.direction == b->path.direction &&
         a->length() == b->length();
}

std::optional<SonarLikelihood::Leg> SonarLikelihood::LegOf(const Coloring& coloring, std::size_t i,
                                                           const Edit* ignoring,
                                                           std::span<const Segment> added) const {
  const auto mirror = AxisMirror(data_->readings[i].cone, view_, segments_, window_);
  if (!mirror) return std::nullopt;
  return Leg{*mirror, FirstLegHit(*mirror, coloring, ignoring, added)};
}

template <typename Visit>
void SonarLikelihood::ForEachLegCell(const Leg& leg, Visit&& visit) const {
  if (leg.length() <= 0.0) return;
  WalkCells(cone_cells_->grid, leg.path.from, leg.path.PointAt(leg.length()),
            [&](int cell, double, double) {
              visit(cell);
              return true;
            });
}

bool SonarLikelihood::ChangesLeg(const Leg& leg, const Edit& edit, std::span<const Segment> added) {
  if (leg.hit && edit.Removes(leg.hit->tag)) return true;
  const double length = leg.length();
  return std::any_of(added.begin(), added.end(), [&](const Segment& s) {
    return RaySegmentHit(leg.path.from, leg.path.direction, s.a, s.b, length).has_value();
  });
}

SonarLikelihood::ReadingResult SonarLikelihood::Compute(const Coloring& coloring, std::size_t i,
                                                        const Edit* ignoring,
                                                        std::span<const Segment> added) const {
  const ConeCells& cc = *cone_cells_;
  return ComputeWithin(coloring, i, ignoring, added, data_->readings[i].cone.max_range,
                       cc.offsets[i + 1] - cc.offsets[i]);
}

SonarLikelihood::ReadingResult SonarLikelihood::ComputeFromExtent(
    const Coloring& coloring, std::size_t i, const Edit* ignoring,
    std::span<const Segment> added) const {
  // Most recomputations only bring edges nearer, so the old extent bounds the new one: the sweep
  // over the cells the reading is listed in (those within its extent) gives the whole view unless
  // some direction sees nothing there (then the view may reach farther, and the sweep is redone
  // to R).
  const double reach = Inflated(state_[i].extent);
  if (reach < data_->readings[i].cone.max_range) {
    const ReadingResult near =
        ComputeWithin(coloring, i, ignoring, added, reach, state_[i].cone_cells);
    if (near.extent < reach) return near;
  }
  return Compute(coloring, i, ignoring, added);
}

SonarLikelihood::ReadingResult SonarLikelihood::ComputeWithin(const Coloring& coloring,
                                                              std::size_t i, const Edit* ignoring,
                                                              std::span<const Segment> added,
                                                              double reach,
                                                              std::uint32_t cells) const {
  const SonarReading& reading = data_->readings[i];
  const ConeCells& cc = *cone_cells_;
  segments_.clear();
  edge_marks_.NextRound();
  const std::uint32_t end = cc.offsets[i] + cells;
  for (std::uint32_t k = cc.offsets[i]; k < end; ++k) {
    for (const EdgeId e : coloring.cell_edges(cc.cells[k])) {
      const auto id = static_cast<std::size_t>(e);
      if (id >= edge_marks_size_) {
        edge_marks_size_ = std::max(2 * edge_marks_size_, id + 1);
        edge_marks_.resize(edge_marks_size_);
      }
      if (!edge_marks_.Mark(id)) continue;
      if (ignoring != nullptr && ignoring->Removes(e)) continue;
      segments_.push_back({coloring.EdgeSegment(e), e});
    }
  }
  for (std::size_t k = 0; k < added.size(); ++k)
    segments_.push_back({added[k], -1 - static_cast<std::int32_t>(k)});
  SonarCone cone = reading.cone;
  cone.max_range = reach;
  sweep_.Compute(cone, segments_, window_, &view_);
  std::optional<Leg> leg =
      model_.models_multipath() ? LegOf(coloring, i, ignoring, added) : std::nullopt;
  const std::optional<double> multipath =
      leg ? std::optional(prf::MultipathLength(leg->path, leg->hit)) : std::nullopt;
  return {ToFixed(model_.LogLikelihood(reading.range, reading.max_reading, view_.features,
                                       data_->max_range, view_.seen_fraction, multipath)),
          view_.extent, std::move(leg)};
}

SonarView SonarLikelihood::View(const Coloring& coloring, std::size_t i) const {
  Compute(coloring, i, nullptr, {});
  SonarView view = view_;
  for (VisiblePiece& piece : view.pieces)
    if (piece.segment >= 0) piece.segment = segments_[static_cast<std::size_t>(piece.segment)].tag;
  return view;
}

std::optional<double> SonarLikelihood::MultipathLength(const Coloring& coloring,
                                                       std::size_t i) const {
  // Compute's sweep leaves the reading's view in view_, where LegOf finds the face to mirror at;
  // its leg is that of the model at hand, so take it from LegOf whatever the model.
  Compute(coloring, i, nullptr, {});
  const std::optional<Leg> leg = LegOf(coloring, i, nullptr, {});
  if (!leg) return std::nullopt;
  return prf::MultipathLength(leg->path, leg->hit);
}

std::optional<std::string> SonarLikelihood::Reset(const Coloring& coloring) {
  window_ = coloring.window();
  const CellGrid& grid = coloring.grid();
  if (!cone_cells_ || !SameGrid(cone_cells_->grid, grid)) {
    auto cc = std::make_shared<ConeCells>();
    cc->grid = grid;
    std::vector<std::pair<double, std::int32_t>> cells;
    cc->offsets.push_back(0);
    for (const SonarReading& r : data_->readings) {
      cells.clear();
      AppendConeCells(grid, r.cone, &cells);
      std::sort(cells.begin(), cells.end());
      for (const auto& [near, cell] : cells) {
        cc->near.push_back(near);
        cc->cells.push_back(cell);
      }
      cc->offsets.push_back(static_cast<std::uint32_t>(cc->cells.size()));
    }
    cone_cells_ = std::move(cc);
  }
  sensor_cells_.assign(static_cast<std::size_t>(grid.NumCells()), {});
  for (std::size_t s = 0; s < data_->sensors.size(); ++s) {
    const Vec2& sensor = data_->sensors[s];
    if (!window_.ContainsInterior(sensor))
      return fmt::format("sensor {} at ({}, {}) lies outside the window", s, sensor.x(),
                         sensor.y());
    if (coloring.ColourAt(sensor) == Colour::kBlack)
      return fmt::format("sensor {} at ({}, {}) lies in occupied space", s, sensor.x(), sensor.y());
    sensor_cells_[static_cast<std::size_t>(grid.CellOf(sensor))].push_back(
        static_cast<std::int32_t>(s));
  }
  const std::size_t n = data_->readings.size();
  state_.assign(n, {});
  index_.Reset(grid.NumCells(), n);
  candidate_marks_.resize(n);
  total_ = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const ReadingResult result = Compute(coloring, i, nullptr, {});
    ReadingState& state = state_[i];
    state.log_lik = result.log_lik;
    state.extent = result.extent;
    state.leg = result.leg;
    state.contacts.assign(view_.contact_tags.begin(), view_.contact_tags.end());
    total_ += state.log_lik;
  }
  RebuildIndex();
  pending_.clear();
  pending_contacts_.clear();
  candidates_.clear();
  return std::nullopt;
}

std::uint32_t SonarLikelihood::ListedCellCount(std::size_t i, double extent) const {
  const ConeCells& cc = *cone_cells_;
  const auto begin = cc.near.begin() + cc.offsets[i];
  const auto end = cc.near.begin() + cc.offsets[i + 1];
  return static_cast<std::uint32_t>(std::upper_bound(begin, end, Inflated(extent)) - begin);
}

// Lists (or re-lists) reading i on its cone's cells up to its extent (a prefix of its cells),
// then on the cells of its multipath leg up to the edge that ends it.
void SonarLikelihood::ListReading(std::size_t i, bool relist) {
  const ConeCells& cc = *cone_cells_;
  ReadingState& state = state_[i];
  state.cone_cells = ListedCellCount(i, state.extent);
  const auto cells = [&](const auto& add) {
    for (std::uint32_t k = 0; k < state.cone_cells; ++k) add(cc.cells[cc.offsets[i] + k]);
    if (state.leg) ForEachLegCell(*state.leg, add);
  };
  if (relist)
    index_.Relist(i, cells);
  else
    index_.List(i, cells);
}

void SonarLikelihood::RebuildIndex() {
  index_.Clear();
  for (std::size_t i = 0; i < state_.size(); ++i) ListReading(i, false);
}

bool SonarLikelihood::SensorFlips(const Edit& edit) const {
  const std::span<const Vec2> region{edit.flipped_region.begin(), edit.flipped_region.size()};
  bool flips = false;
  ForEachCellUnder(cone_cells_->grid, region, [&](int cell) {
    for (std::int32_t s : sensor_cells_[static_cast<std::size_t>(cell)])
      flips = flips || RingContains(region, data_->sensors[static_cast<std::size_t>(s)]);
  });
  return flips;
}

void SonarLikelihood::CollectReadings(const Vec2& a, const Vec2& b) {
  WalkCells(cone_cells_->grid, a, b, [&](int cell, double, double) {
    index_.VisitCell(cell, [&](std::int32_t reading) {
      candidate_marks_.Mark(static_cast<std::size_t>(reading));
    });
    return true;
  });
}

std::optional<FixedLogLik> SonarLikelihood::Evaluate(const Coloring& coloring, const Edit& edit) {
  pending_.clear();
  pending_contacts_.clear();
  candidates_.clear();
  pending_delta_ = 0;
  if (SensorFlips(edit)) return std::nullopt;

  SmallVector<Segment, 4> added;
  for (std::size_t k = 0; k < edit.added_edges.size(); ++k)
    added.push_back(coloring.AddedSegment(edit, k));
  for (EdgeId e : edit.removed_edges) {
    const Segment s = coloring.EdgeSegment(e);
    CollectReadings(s.a, s.b);
  }
  for (const Segment& s : added) CollectReadings(s.a, s.b);
  candidate_marks_.Drain(&candidates_);

  for (const std::int32_t id : candidates_) {
    const auto i = static_cast<std::size_t>(id);
    const ReadingState& state = state_[i];
    // Unchanged unless it loses an edge it sees or gains one in front of what it sees.
    const std::span<const Segment> added_span{added.begin(), added.size()};
    bool affected =
        std::any_of(edit.removed_edges.begin(), edit.removed_edges.end(), [&](EdgeId e) {
          return std::binary_search(state.contacts.begin(), state.contacts.end(), e);
        });
    for (std::size_t k = 0; !affected && k < added.size(); ++k)
      affected = SegmentMeetsCone(added[k], data_->readings[i].cone, state.extent);
    affected = affected || (state.leg && ChangesLeg(*state.leg, edit, added_span));
    if (!affected) continue;
    ReadingResult result = ComputeFromExtent(coloring, i, &edit, added_span);
    const std::vector<std::int32_t>& tags = view_.contact_tags;
    if (result.log_lik == state.log_lik && result.extent == state.extent &&
        result.leg == state.leg &&
        std::equal(tags.begin(), tags.end(), state.contacts.begin(), state.contacts.end()))
      continue;
    const auto begin = static_cast<std::uint32_t>(pending_contacts_.size());
    pending_contacts_.insert(pending_contacts_.end(), tags.begin(), tags.end());
    pending_.push_back({.reading = id,
                        .extent = result.extent,
                        .log_lik = result.log_lik,
                        .contacts_begin = begin,
                        .contacts_end = static_cast<std::uint32_t>(pending_contacts_.size()),
                        .leg = std::move(result.leg)});
    pending_delta_ += result.log_lik - state.log_lik;
  }
  return pending_delta_;
}

void SonarLikelihood::Commit(std::span<const EdgeId> added_edges) {
  for (const Change& change : pending_) {
    const auto i = static_cast<std::size_t>(change.reading);
    ReadingState& state = state_[i];
    state.log_lik = change.log_lik;
    state.contacts.clear();
    for (std::uint32_t k = change.contacts_begin; k < change.contacts_end; ++k)
      state.contacts.push_back(Resolved(pending_contacts_[k], added_edges));
    std::sort(state.contacts.begin(), state.contacts.end());
    std::optional<Leg> leg = change.leg;
    if (leg) {
      leg->path.mirror_tag = Resolved(leg->path.mirror_tag, added_edges);
      if (leg->hit) leg->hit->tag = Resolved(leg->hit->tag, added_edges);
    }
    const bool same_leg_cells = Leg::SameCells(leg, state.leg);
    state.leg = std::move(leg);
    if (change.extent == state.extent && same_leg_cells) continue;  // the same cells
    state.extent = change.extent;
    if (same_leg_cells && ListedCellCount(i, state.extent) == state.cone_cells) continue;
    ListReading(i, true);
  }
  total_ += pending_delta_;
  pending_.clear();
  pending_contacts_.clear();
  pending_delta_ = 0;
  if (index_.NeedsRebuild()) RebuildIndex();
}

FixedLogLik SonarLikelihood::RecomputeLogLikelihood(const Coloring& coloring) const {
  FixedLogLik total = 0;
  for (std::size_t i = 0; i < data_->readings.size(); ++i)
    total += Compute(coloring, i, nullptr, {}).log_lik;
  return total;
}

std::optional<std::string> SonarLikelihood::FindInconsistency(const Coloring& coloring) const {
  for (std::size_t s = 0; s < data_->sensors.size(); ++s)
    if (coloring.ColourAt(data_->sensors[s]) == Colour::kBlack)
      return fmt::format("sensor {} is in black", s);
  FixedLogLik total = 0;
  const ConeCells& cc = *cone_cells_;
  for (std::size_t i = 0; i < data_->readings.size(); ++i) {
    const ReadingState& state = state_[i];
    const ReadingResult result = Compute(coloring, i, nullptr, {});
    if (result.extent != state.extent)
      return fmt::format("reading {}: extent {} kept, {} recomputed", i, state.extent,
                         result.extent);
    if (result.log_lik != state.log_lik)
      return fmt::format("reading {}: log-likelihood {} kept, {} recomputed", i,
                         FromFixed(state.log_lik), FromFixed(result.log_lik));
    if (!std::equal(view_.contact_tags.begin(), view_.contact_tags.end(), state.contacts.begin(),
                    state.contacts.end()))
      return fmt::format("reading {}: the edges it sees differ from the recomputed ones", i);
    if (!(result.leg == state.leg))
      return fmt::format("reading {}: its multipath leg differs from the recomputed one", i);
    total += state.log_lik;
    // Listed exactly on the cells of its cone up to its extent, then on those of its leg.
    if (state.cone_cells != ListedCellCount(i, state.extent))
      return fmt::format("reading {} is listed in {} cells of its cone, its extent has {}", i,
                         state.cone_cells, ListedCellCount(i, state.extent));
    std::uint32_t listed = state.cone_cells;
    for (std::uint32_t k = 0; k < state.cone_cells; ++k)
      if (!index_.IsListed(cc.cells[cc.offsets[i] + k], i))
        return fmt::format("reading {} is missing from a cell of its cone", i);
    bool missing = false;
    if (state.leg)
      ForEachLegCell(*state.leg, [&](int cell) {
        missing = missing || !index_.IsListed(cell, i);
        ++listed;
      });
    if (missing) return fmt::format("reading {} is missing from a cell of its leg", i);
    if (index_.listed_cells(i) != listed)
      return fmt::format("reading {} is listed in {} cells, its cone and leg have {}", i,
                         index_.listed_cells(i), listed);
  }
  if (total != total_)
    return fmt::format("total log-likelihood kept {} differs from the sum {}", FromFixed(total_),
                       FromFixed(total));
  return index_.CountProblem();
}

}  // namespace priormap::prf
