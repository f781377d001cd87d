#pragma once
/// The PRF sonar likelihood (Paskin & Thrun, Sec. 2.3) with dynamic indexing: each reading is
/// listed in the grid cells that overlap its cone up to its farthest contact (the farthest point
/// it sees, or R where part of its cone sees nothing), so an edit recomputes only the readings
/// listed in the cells of the edges it removes or adds, and a recomputed reading is re-listed on
/// its new extent.
///
/// A listed reading is recomputed only when the edit removes an edge it sees, or adds one that
/// meets its cone within its extent; a recomputation sweeps the cone anew (sonar_visibility.hpp)
/// over the edges the coloring's index holds in the cone's cells up to R. A sensor inside the
/// region an edit reverses would turn black, which has likelihood zero.
///
/// With the model's multipath component (SonarModel::multipath_weight), a reading also depends on
/// the leg of its axis's path beyond the face that mirrors it (sonar_multipath.hpp): it is listed
/// in the cells of that leg as well, up to the leg's first edge, and recomputed when an edit
/// removes that edge or adds one across the leg before it.
///
/// The index is the coloring's own cell grid, so that one list of cells per cone (computed once,
/// shared by the copies of the term) serves both the gathering of edges and the listing.

#include <cstdint>
#include <memory>
#include <vector>

#include <priormap/prf/data_term.hpp>
#include <priormap/prf/dynamic_cell_index.hpp>
#include <priormap/prf/inline_vector.hpp>
#include <priormap/prf/ordered_marks.hpp>
#include <priormap/prf/sonar_data.hpp>
#include <priormap/prf/sonar_model.hpp>
#include <priormap/prf/sonar_multipath.hpp>
#include <priormap/prf/sonar_visibility.hpp>

namespace priormap::prf {

class SonarLikelihood final : public DataTerm {
 public:
  SonarLikelihood(std::shared_ptr<const SonarData> data, SonarModel model);

  std::optional<std::string> Reset(const Coloring& coloring) override;
  std::optional<FixedLogLik> Evaluate(const Coloring& coloring, const Edit& edit) override;
  void Commit(std::span<const EdgeId> added_edges) override;
  [[nodiscard]] FixedLogLik log_likelihood() const override { return total_; }
  [[nodiscard]] FixedLogLik RecomputeLogLikelihood(const Coloring& coloring) const override;
  [[nodiscard]] std::optional<std::string> FindInconsistency(
      const Coloring& coloring) const override;
  [[nodiscard]] std::unique_ptr<DataTerm> Clone() const override;

  [[nodiscard]] const SonarData& data() const { return *data_; }
  [[nodiscard]] const SonarModel& model() const { return model_; }
  /// The farthest point reading `i` sees (R where part of its cone sees nothing).
  [[nodiscard]] double extent(std::size_t i) const { return state_[i].extent; }
  /// What reading `i` sees in `coloring` (tests, figures), its pieces naming the edge ids seen.
  [[nodiscard]] SonarView View(const Coloring& coloring, std::size_t i) const;
  /// The length of reading `i`'s multipath path in `coloring` (+inf when it is not heard within
  /// R), nullopt when its axis meets no face within R.
  [[nodiscard]] std::optional<double> MultipathLength(const Coloring& coloring,
                                                      std::size_t i) const;

 private:
  // Cells overlapping each cone up to R (conservatively), nearest first, with their distance
  // to the apex: a cone up to extent e is listed in the prefix whose distance is at most e.
  struct ConeCells {
    CellGrid grid;
    std::vector<std::uint32_t> offsets;  // reading i: [offsets[i], offsets[i + 1])
    std::vector<std::int32_t> cells;
    std::vector<double> near;
  };
  // The leg of a reading's multipath path beyond its mirror, and the edge that ends it.
  struct Leg {
    MirrorLeg path;
    std::optional<LegHit> hit;  // its tag an edge id once committed
    /// The part of the leg whose edges matter: to its hit, or its whole reach.
    [[nodiscard]] double length() const { return hit ? hit->t : path.reach; }
    [[nodiscard]] bool operator==(const Leg& other) const;
    /// Both legs walk the same cells (ForEachLegCell): same start, direction and length.
    [[nodiscard]] static bool SameCells(const std::optional<Leg>& a, const std::optional<Leg>& b);
  };
  // What a proposal's test of a listed reading reads (the edges it sees, its extent) comes first
  // and inline: no second allocation to fetch for each of the hundreds of readings it tests.
  struct ReadingState {
    InlineVector<EdgeId, 4> contacts;  // the edges it sees, sorted
    double extent = 0.0;
    FixedLogLik log_lik = 0;
    std::uint32_t cone_cells = 0;  // listed: the prefix of its cone's cells within its extent
    std::optional<Leg> leg;        // with the multipath model, when its axis meets a face
  };
  struct Change {
    std::int32_t reading;
    double extent;
    FixedLogLik log_lik;
    std::uint32_t contacts_begin;  // into pending_contacts_; added edge k is -1 - k
    std::uint32_t contacts_end;
    std::optional<Leg> leg;  // tags as contacts
  };
  struct ReadingResult {
    FixedLogLik log_lik;
    double extent;
    std::optional<Leg> leg;
  };

  /// Sweeps reading i's cone to R over the coloring's edges in its cells, less those `ignoring`
  /// removes, plus `added` (tagged -1 - k); the view is left in view_.
  ReadingResult Compute(const Coloring& coloring, std::size_t i, const Edit* ignoring,
                        std::span<const Segment> added) const;
  /// Compute, first tried over the cells within the reading's current extent only.
  ReadingResult ComputeFromExtent(const Coloring& coloring, std::size_t i, const Edit* ignoring,
                                  std::span<const Segment> added) const;
  /// The sweep of the cone cut at `reach`, over the edges of the first `cells` of its cells.
  ReadingResult ComputeWithin(const Coloring& coloring, std::size_t i, const Edit* ignoring,
                              std::span<const Segment> added, double reach,
                              std::uint32_t cells) const;
  /// The multipath leg of reading i given its view (in view_, over segments_), when the axis
  /// meets a face.
  [[nodiscard]] std::optional<Leg> LegOf(const Coloring& coloring, std::size_t i,
                                         const Edit* ignoring,
                                         std::span<const Segment> added) const;
  /// The cells of a leg up to the edge that ends it (or its reach).
  template <typename Visit>
  void ForEachLegCell(const Leg& leg, Visit&& visit) const;
  /// Whether the edit changes what ends a kept leg: it removes the leg's edge or adds one
  /// across the leg before it.
  [[nodiscard]] static bool ChangesLeg(const Leg& leg, const Edit& edit,
                                       std::span<const Segment> added);
  [[nodiscard]] bool SensorFlips(const Edit& edit) const;
  void CollectReadings(const Vec2& a, const Vec2& b);
  [[nodiscard]] std::uint32_t ListedCellCount(std::size_t i, double extent) const;
  void ListReading(std::size_t i, bool relist);
  void RebuildIndex();

  std::shared_ptr<const SonarData> data_;
  SonarModel model_;
  std::shared_ptr<const ConeCells> cone_cells_;
  Window window_;
  std::vector<ReadingState> state_;
  DynamicCellIndex index_;  ///< the readings, each on its cone's cells up to its extent
  std::vector<std::vector<std::int32_t>> sensor_cells_;
  FixedLogLik total_ = 0;
  // Scratch of Evaluate, read by Commit.
  std::vector<std::int32_t> candidates_;
  OrderedMarks candidate_marks_;
  std::vector<Change> pending_;
  std::vector<std::int32_t> pending_contacts_;
  FixedLogLik pending_delta_ = 0;
  // Scratch of every sweep.
  mutable ConeSweep sweep_;
  mutable SonarView view_;
  mutable std::vector<TaggedSegment> segments_;
  mutable VisitMarks edge_marks_;
  mutable std::size_t edge_marks_size_ = 0;
};

}  // namespace priormap::prf
