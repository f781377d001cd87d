#pragma once
/// The Metropolis–Hastings sampler of polygonal colorings (Paskin & Thrun, Sec. 1.3.3 and 2.1):
/// the Clifford–Nicholls moves and their reverses, plus local recolor and slide, against the
/// Arak measure (eqs. 1–3). docs/prf-moves.md derives every proposal density and ratio that
/// Propose returns.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <priormap/core/rng.hpp>
#include <priormap/prf/birth_guide.hpp>
#include <priormap/prf/coloring.hpp>
#include <priormap/prf/data_term.hpp>
#include <priormap/prf/estimates.hpp>
#include <priormap/prf/moves.hpp>

namespace priormap::prf {

struct SamplerOptions {
  double p = 0.1;  ///< scale parameter of the Arak process (1/length)
  /// A preference for edges along two perpendicular directions, added to the Arak potential
  /// (off by default: the Arak process).
  OrientationPrior orientation;
  /// β of a preference for free space: the potential β · (black area in the window), per m²
  /// (0 by default: the Arak process, indifferent to colour). While it is on, edits whose
  /// flipped region crosses itself or holds structure are refused (black_area.hpp).
  double free_space = 0.0;
  MoveWeights weights;
  /// r of the births: the other vertices of a triangle within ±r of the first (per axis), a
  /// boundary triangle's second boundary vertex within r of the first, a corner edge's vertices
  /// within r of the corner.
  double birth_scale = 1.0;
  /// κ of the vertex birth: the new vertex is uniform in the rectangle along the edge with
  /// half-width κ|e|, κ drawn uniformly from these. A narrow κ keeps most births near their
  /// edge; a wide one lets a death straighten a tall wedge in one step.
  std::vector<double> vertex_birth_widths{0.5};
  /// Corner completion: the probability that a vertex birth on edge uw puts its vertex in the
  /// square of half-width corner_completion_jitter around the corner ahead of uw, where the edges
  /// beyond u and beyond w, extended past u and w, meet. It restores in one step a room's corner
  /// that a diagonal edge cuts off; and a death then weighs the corner it removes by this density
  /// too. Edges with no corner ahead (an end on the window's side, the extensions parallel or
  /// meeting behind an end) keep the rectangle alone. 0 (the default): off, and nothing extra is
  /// drawn.
  double corner_completion = 0.0;
  double corner_completion_jitter = 0.05;
  /// Neighbour births: the probability that a vertex birth on edge uw puts its vertex in the
  /// square of half-width neighbour_birth_jitter around the vertex beyond u or the one beyond w
  /// (each with probability ½; the one there is when the other end lies on the window's side).
  /// A black wedge whose face u'u stands where a wall is, with its far face uw across a room,
  /// becomes a thin wall along u'u in one step: v next to u' turns the rest of the wedge white.
  /// The death weighs a vertex next to its neighbour's neighbour by the same density. With
  /// corner completion, corner_completion + neighbour_birth < 1. 0 (the default): off, and
  /// nothing extra is drawn.
  double neighbour_birth = 0.0;
  double neighbour_birth_jitter = 0.1;
  /// Vertex jumps (MoveKind::kVertexJump, off while its weight is 0): an interior vertex v
  /// between u and w goes, with probability ½, into the square of half-width vertex_jump_jitter
  /// around the vertex beyond u or the one beyond w (each ½; the one there is when the other
  /// neighbour lies on the window's side), else uniformly into the square of half-width
  /// vertex_jump_reach around itself. A wedge u'–u–v–w whose face u'u stands on a wall becomes
  /// the thin wall u'–u–v' and a white room in one step; the far squares make every such jump
  /// reversible.
  double vertex_jump_reach = 2.0;
  double vertex_jump_jitter = 0.1;
  /// Where the data put surfaces, for the guided triangle births (their kind is off without
  /// one). Shared, read-only, by every chain.
  std::shared_ptr<const BirthGuide> guide;
  /// Half-widths of the symmetric random-walk steps of the vertex moves; each step draws one.
  std::vector<double> step_scales{0.02, 0.1, 0.5};
  /// The target is λ(dχ) · (exp(−F₀) · likelihood)^(1/temperature): 1 samples the posterior,
  /// lower anneals towards the coloring of least energy F₀ − log L against the Arak measure λ.
  double temperature = 1.0;
  /// Delayed acceptance (Christen & Fox 2005) with 1/screen_stride of the readings, their
  /// log-likelihood weighted by screen_stride, as the screen (1: none). A move first meets the
  /// Metropolis–Hastings test of the prior and the screen; only if it passes is the full data
  /// term evaluated, and the move accepted with probability min(1, exp(ΔL − ΔL_screen) ^ (1/T)).
  /// The two stages together satisfy detailed balance for the same target, and most rejected
  /// moves cost only the screen's fraction of the data. The screen itself is given with
  /// SetScreen whenever the chain runs on all its data.
  int screen_stride = 1;
  /// Debug: after each accepted move, check every invariant of the coloring by brute force and
  /// the data term's incremental state against a recomputation (slow).
  bool check_invariants = false;
};

class PrfSampler {
 public:
  /// Without a data term the chain samples the Arak prior. The data term is reset to `coloring`,
  /// which must have nonzero likelihood.
  PrfSampler(Coloring coloring, SamplerOptions options, std::uint64_t seed,
             std::unique_ptr<DataTerm> data = nullptr);

  /// One Metropolis–Hastings step: choose a move type, propose, accept or reject.
  void Step();
  void Run(std::uint64_t steps) {
    for (std::uint64_t i = 0; i < steps; ++i) Step();
  }

  [[nodiscard]] const Coloring& coloring() const { return coloring_; }
  [[nodiscard]] const SamplerOptions& options() const { return options_; }
  [[nodiscard]] const MoveCounters& counters() const { return counters_; }
  [[nodiscard]] const DataTerm* data() const { return data_.get(); }
  /// Steps taken so far; the state after step n is sample n.
  [[nodiscard]] std::uint64_t steps() const { return steps_; }
  /// Starts recording every following sample into `estimates` (owned by the caller; nullptr
  /// stops recording).
  void RecordInto(PosteriorEstimates* estimates) {
    estimates_ = estimates;
    if (estimates_) estimates_->Start(coloring_, steps_ + 1);
  }
  /// Goes on recording into estimates that already hold this chain's samples up to steps()
  /// (restored from a checkpoint with the chain).
  void ContinueRecordingInto(PosteriorEstimates* estimates) { estimates_ = estimates; }
  /// log of the prior's density: the Arak measure with its potential, the orientation
  /// potential and the free-space potential.
  [[nodiscard]] double LogPrior() const {
    return coloring_.LogArakDensity(options_.p) -
           OrientationPotential(coloring_.stats(), options_.orientation) -
           options_.free_space * black_area_;
  }
  /// The black area of the coloring, kept while the free-space prior is on (else 0).
  [[nodiscard]] double black_area() const { return black_area_; }
  [[nodiscard]] double LogLikelihood() const {
    return data_ ? FromFixed(data_->log_likelihood()) : 0.0;
  }
  /// Untempered log density of the posterior (up to its normalizing constant).
  [[nodiscard]] double LogPosterior() const { return LogPrior() + LogLikelihood(); }
  void set_temperature(double temperature) { options_.temperature = temperature; }
  /// Goes on with another data term (the same data thinned, say), reset to the coloring, which
  /// must have nonzero likelihood under it; drops the screen, which was of the term replaced.
  void ReplaceDataTerm(std::unique_ptr<DataTerm> data);
  /// The delayed acceptance's screen: a data term on 1/options().screen_stride of the data term's
  /// readings, reset to the coloring (nullptr: none).
  void SetScreen(std::unique_ptr<DataTerm> screen);
  [[nodiscard]] bool has_screen() const { return screen_ != nullptr; }

  /// The chain's state: coloring, step count, random generator, counters and temperature. The
  /// data term is not saved: its state is a function of the coloring, rebuilt on Load.
  void Save(BinaryWriter& out) const;
  /// A sampler that continues exactly where the saved one stopped, given the same options and
  /// an equal data term. BinaryFormatError when the data are not a saved chain of `window`.
  [[nodiscard]] static std::unique_ptr<PrfSampler> Load(BinaryReader& in, const Window& window,
                                                        double cell_size, SamplerOptions options,
                                                        std::unique_ptr<DataTerm> data = nullptr);

  /// Draws a move of `type` into `edit` with log(π(reverse) / π(forward)), the proposal part of
  /// the Hastings ratio against the base measure. False when the state offers no such move or
  /// its reverse could not be proposed; draws that leave the window or cross edges are returned
  /// and refused by Coloring::Evaluate.
  bool Propose(MoveType type, Edit* edit, double* log_proposal_ratio);

 private:
  /// An interior vertex drawn uniformly, with its neighbours across edges[0] and edges[1] and
  /// the number it was drawn from; nullopt when there is none.
  struct DrawnVertex {
    VertexId vertex;
    VertexId first;
    VertexId second;
    std::size_t count;
  };
  std::optional<DrawnVertex> DrawInteriorVertex();
  /// The edit that moves the drawn vertex to `moved`, keeping its edges' ends.
  void MoveVertex(const DrawnVertex& drawn, const Vec2& moved, Edit* edit) const;
  /// Two adjacent interior vertices a, b on the path p–a–b–q: a drawn uniformly among the
  /// `count` interior vertices, then one of its edges (½), so that a pair comes with probability
  /// 1/count from either of its vertices. nullopt when there is no interior vertex, b lies on
  /// the window's side, or p = q (a triangle, which edge shifts and pair deaths both refuse).
  struct InteriorPair {
    VertexId p, a, b, q;
    EdgeId pa, ab, bq;
    std::size_t count;
  };
  std::optional<InteriorPair> DrawInteriorPair();

  MoveType ChooseType();
  bool ProposeTriangleBirth(Edit* edit, double* log_q);
  bool ProposeTriangleDeath(Edit* edit, double* log_q);
  bool ProposeGuidedTriangleBirth(Edit* edit, double* log_q);
  bool ProposeGuidedTriangleDeath(Edit* edit, double* log_q);
  /// The free triangle (three interior vertices, each adjacent to the other two) at a vertex
  /// drawn uniformly, as a death edit with π = 3 / n_i, or false when the vertex has none.
  bool ProposeFreeTriangleRemoval(Edit* edit, double* log_pi, std::array<Vec2, 3>* corners);
  /// Adds the triangle abc as a birth edit.
  static void AddTriangle(const Vec2& a, const Vec2& b, const Vec2& c, Edit* edit);
  bool ProposeBoundaryTriangleBirth(Edit* edit, double* log_q);
  bool ProposeBoundaryTriangleDeath(Edit* edit, double* log_q);
  bool ProposeCornerBirth(Edit* edit, double* log_q);
  bool ProposeCornerDeath(Edit* edit, double* log_q);
  bool ProposeVertexBirth(Edit* edit, double* log_q);
  bool ProposeVertexDeath(Edit* edit, double* log_q);
  bool ProposeInteriorMove(Edit* edit);
  bool ProposeBoundaryMove(Edit* edit);
  bool ProposeRecolor(Edit* edit, double* log_q, bool local);
  bool ProposeSlide(Edit* edit);
  /// Both ends a, b of an edge between interior vertices moved by one random step: a wall
  /// shifted (or turned) as a whole, where moving one end at a time would tilt it through
  /// states the data refuse.
  bool ProposeEdgeShift(Edit* edit);
  /// An interior vertex moved next to the vertex beyond one of its neighbours, or anywhere
  /// within the reach (SamplerOptions::vertex_jump_reach); the graph keeps its structure.
  bool ProposeVertexJump(Edit* edit, double* log_q);
  /// Vertex pairs (MoveKind::kVertexPair) use the vertex births' rectangles
  /// (SamplerOptions::vertex_birth_widths) and nothing else: a pair born on edge uw, read from u
  /// or from w with probability ½ each, puts v₁ in a rectangle along uw and then v₂ in one along
  /// v₁w. Its death removes two adjacent interior vertices at once and joins their outer
  /// neighbours: a bump or a two-vertex wedge on a wall cut off along a new edge, where single
  /// deaths pass through a state with one vertex of it, which the data may refuse.
  bool ProposeVertexPairBirth(Edit* edit, double* log_q);
  bool ProposeVertexPairDeath(Edit* edit, double* log_q);

  /// Unordered proposal densities of the births, shared by births and their deaths.
  [[nodiscard]] double TriangleDensity(const Vec2& a, const Vec2& b, const Vec2& c) const;
  [[nodiscard]] double BoundaryTriangleDensity(const Vec2& b1, int side1, const Vec2& b2, int side2,
                                               const Vec2& v) const;
  /// The points a vertex birth on a chord may be drawn next to, besides its rectangles.
  struct ChordAnchors {
    std::optional<Vec2> corner;  // the corner ahead (SamplerOptions::corner_completion)
    std::array<Vec2, 2> beyond;  // the vertices beyond the ends (SamplerOptions::neighbour_birth)
    int num_beyond = 0;
  };
  /// The density at v of the mixture, over the vertex birth widths κ, of the uniform laws on the
  /// rectangles along uw of half-width κ|uw|.
  [[nodiscard]] double RectangleDensity(const Vec2& u, const Vec2& w, const Vec2& v) const;
  /// A point drawn from RectangleDensity(u, w, ·).
  Vec2 DrawInRectangle(const Vec2& u, const Vec2& w);
  /// The density of a vertex pair birth on the edge uw that makes the path u–a–b–w, given the
  /// edge: the sum over the two ends it may be read from, so that the death, which takes the
  /// pair from either vertex, weighs it alike.
  [[nodiscard]] double VertexPairDensity(const Vec2& u, const Vec2& a, const Vec2& b,
                                         const Vec2& w) const;
  /// The density of a vertex birth at v on the edge from u to w with these anchors.
  [[nodiscard]] double VertexBirthDensity(const Vec2& u, const Vec2& w, const Vec2& v,
                                          const ChordAnchors& anchors) const;
  /// The anchors of the chord from u to w: u_side and w_side are the chord's edges at u and at w
  /// (the edge uw itself before a birth; uv and vw before a death), so that a birth and the death
  /// that undoes it see the same vertices beyond the ends, and so the same anchors. Empty when
  /// corner completion and neighbour births are both off.
  [[nodiscard]] ChordAnchors AnchorsOf(VertexId u, EdgeId u_side, VertexId w, EdgeId w_side) const;
  /// The vertex beyond `end` along its edge other than `side`; nullopt when `end` lies on the
  /// window's side.
  [[nodiscard]] std::optional<Vec2> BeyondEnd(VertexId end, EdgeId side) const;
  /// The density of a vertex jump from `from` to `to` with the vertices beyond the neighbours
  /// `beyond` (the same before and after the jump, which keeps the graph's structure).
  [[nodiscard]] double VertexJumpDensity(const Vec2& from, const Vec2& to,
                                         const ChordAnchors& beyond) const;
  /// The corner ahead of the chord from pu to pw, where the lines beyond_u → pu and beyond_w → pw
  /// meet ahead of both ends; nullopt when they are parallel or meet behind an end.
  [[nodiscard]] static std::optional<Vec2> CornerAhead(const Vec2& pu, const Vec2& beyond_u,
                                                       const Vec2& pw, const Vec2& beyond_w);
  /// Number of edges other than `self`, `removed1` and `removed2` sharing a grid cell with
  /// segment ab.
  [[nodiscard]] int CellNeighbourCount(const Vec2& a, const Vec2& b, EdgeId self, EdgeId removed1,
                                       EdgeId removed2) const;
  [[nodiscard]] bool ShareACell(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d);
  /// A step scale or a vertex birth width, drawn uniformly. With one value it draws nothing from
  /// the stream, so the chains of a run with one value are those recorded before there was a
  /// choice.
  [[nodiscard]] double DrawOneOf(const std::vector<double>& values);

  Coloring coloring_;
  SamplerOptions options_;
  std::unique_ptr<DataTerm> data_;
  std::unique_ptr<DataTerm> screen_;
  PosteriorEstimates* estimates_ = nullptr;
  std::uint64_t steps_ = 0;
  Rng rng_;
  MoveCounters counters_{};
  std::vector<double> cumulative_weights_;
  Edit edit_;
  EditEffect effect_;
  double black_area_ = 0.0;
  std::vector<EdgeId> scratch_edges_;
  VisitMarks cell_marks_;
};

}  // namespace priormap::prf
