#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>

#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/prf/black_area.hpp>
#include <priormap/prf/sampler.hpp>

namespace priormap::prf {
namespace {

VertexRef Old(VertexId v) {
  return VertexRef::Existing(v);
}
VertexRef Fresh(int k) {
  return VertexRef::New(k);
}

double ChebyshevDistance(const Vec2& a, const Vec2& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

// The density at v of the uniform law on the square of half-width h around `centre`.
double SquareDensity(const Vec2& v, const Vec2& centre, double h) {
  return ChebyshevDistance(v, centre) <= h ? 1.0 / (4.0 * h * h) : 0.0;
}

// Adds the path p–x–y–q through two new interior vertices x and y.
void AddPathThroughNewPair(VertexId p, const Vec2& x, const Vec2& y, VertexId q, Edit* edit) {
  edit->new_vertices.push_back({x, kInterior});
  edit->new_vertices.push_back({y, kInterior});
  edit->added_edges.push_back({Old(p), Fresh(0)});
  edit->added_edges.push_back({Fresh(0), Fresh(1)});
  edit->added_edges.push_back({Fresh(1), Old(q)});
}

// The edge of an interior vertex other than `e`.
EdgeId OtherEdge(const ColoringVertex& vertex, EdgeId e) {
  return vertex.edges[0] == e ? vertex.edges[1] : vertex.edges[0];
}

}  // namespace

PrfSampler::PrfSampler(Coloring coloring, SamplerOptions options, std::uint64_t seed,
                       std::unique_ptr<DataTerm> data)
    : coloring_(std::move(coloring)),
      options_(std::move(options)),
      data_(std::move(data)),
      rng_(seed) {
  PRIORMAP_CHECK(options_.p > 0.0, "the Arak scale p must be positive");
  PRIORMAP_CHECK(options_.birth_scale > 0.0, "the birth scale must be positive");
  PRIORMAP_CHECK(!options_.vertex_birth_widths.empty(),
                 "at least one vertex birth width is needed");
  for (double width : options_.vertex_birth_widths)
    PRIORMAP_CHECK(width > 0.0, "vertex birth widths must be positive");
  PRIORMAP_CHECK(options_.corner_completion >= 0.0 && options_.corner_completion < 1.0,
                 "the corner completion probability must be in [0, 1)");
  PRIORMAP_CHECK(options_.corner_completion_jitter > 0.0,
                 "the corner completion jitter must be positive");
  PRIORMAP_CHECK(options_.neighbour_birth >= 0.0 &&
                     options_.corner_completion + options_.neighbour_birth < 1.0,
                 "the neighbour birth probability must be in [0, 1 - corner completion)");
  PRIORMAP_CHECK(options_.neighbour_birth_jitter > 0.0,
                 "the neighbour birth jitter must be positive");
  PRIORMAP_CHECK(!options_.step_scales.empty(), "at least one step scale is needed");
  for (double scale : options_.step_scales)
    PRIORMAP_CHECK(scale > 0.0 && scale < 0.5 * coloring_.window().Perimeter(),
                   "step scales must be positive and below half the perimeter");
  PRIORMAP_CHECK(options_.temperature > 0.0, "the temperature must be positive");
  PRIORMAP_CHECK(options_.screen_stride >= 1, "the screen stride must be at least 1");
  PRIORMAP_CHECK(options_.vertex_jump_reach > 0.0 && options_.vertex_jump_jitter > 0.0,
                 "the vertex jumps' reach and jitter must be positive");
  double total = 0.0;
  const bool guided = options_.guide && options_.guide->size() > 0;
  for (int k = 0; k < kNumMoveKinds; ++k) {
    double w = options_.weights.weight[static_cast<std::size_t>(k)];
    PRIORMAP_CHECK(w >= 0.0, "move weights must be non-negative");
    if (static_cast<MoveKind>(k) == MoveKind::kGuidedTriangle && !guided) w = 0.0;
    total += w;
    cumulative_weights_.push_back(total);
  }
  PRIORMAP_CHECK(total > 0.0, "at least one move kind needs a positive weight");
  cell_marks_.resize(static_cast<std::size_t>(coloring_.grid().NumCells()));
  PRIORMAP_CHECK(options_.free_space >= 0.0 && std::isfinite(options_.free_space),
                 "the free-space weight must be finite and not negative");
  if (options_.free_space > 0.0) black_area_ = BlackArea(coloring_);
  if (data_) {
    const auto problem = data_->Reset(coloring_);
    PRIORMAP_CHECK(!problem, "the initial coloring has likelihood zero: " + problem.value_or(""));
  }
}

void PrfSampler::ReplaceDataTerm(std::unique_ptr<DataTerm> data) {
  if (data) {
    const auto problem = data->Reset(coloring_);
    PRIORMAP_CHECK(!problem, "the coloring has likelihood zero under the new data term: " +
                                 problem.value_or(""));
  }
  data_ = std::move(data);
  screen_.reset();
}

void PrfSampler::SetScreen(std::unique_ptr<DataTerm> screen) {
  PRIORMAP_CHECK(!screen || (data_ && options_.screen_stride > 1),
                 "a screen needs a data term and a screen stride above 1");
  if (screen) {
    const auto problem = screen->Reset(coloring_);
    PRIORMAP_CHECK(!problem,
                   "the coloring has likelihood zero under the screen: " + problem.value_or(""));
  }
  screen_ = std::move(screen);
}

MoveType PrfSampler::ChooseType() {
  const double u = rng_.Uniform() * cumulative_weights_.back();
  int kind =
      static_cast<int>(std::upper_bound(cumulative_weights_.begin(), cumulative_weights_.end(), u) -
                       cumulative_weights_.begin());
  // u can round up to the total; then take the last kind that has weight.
  while (kind >= kNumMoveKinds ||
         cumulative_weights_[static_cast<std::size_t>(kind)] ==
             (kind > 0 ? cumulative_weights_[static_cast<std::size_t>(kind) - 1] : 0.0))
    --kind;
  switch (static_cast<MoveKind>(kind)) {
    case MoveKind::kTriangle:
    case MoveKind::kBoundaryTriangle:
    case MoveKind::kCorner:
    case MoveKind::kVertex: {
      // Births and deaths of a kind are equally likely, so their selection probabilities cancel
      // in the Hastings ratio.
      const int birth = 2 * kind;
      return static_cast<MoveType>(rng_.Bernoulli(0.5) ? birth : birth + 1);
    }
    case MoveKind::kInteriorMove:
      return MoveType::kInteriorMove;
    case MoveKind::kBoundaryMove:
      return MoveType::kBoundaryMove;
    case MoveKind::kRecolor:
      return MoveType::kRecolor;
    case MoveKind::kLocalRecolor:
      return MoveType::kLocalRecolor;
    case MoveKind::kSlide:
      return MoveType::kSlide;
    case MoveKind::kGuidedTriangle:
      return rng_.Bernoulli(0.5) ? MoveType::kGuidedTriangleBirth : MoveType::kGuidedTriangleDeath;
    case MoveKind::kEdgeShift:
      return MoveType::kEdgeShift;
    case MoveKind::kVertexJump:
      return MoveType::kVertexJump;
    case MoveKind::kVertexPair:
      return rng_.Bernoulli(0.5) ? MoveType::kVertexPairBirth : MoveType::kVertexPairDeath;
  }
  return MoveType::kInteriorMove;
}

void PrfSampler::Step() {
  ++steps_;
  const MoveType type = ChooseType();
  MoveCounter& counter = counters_[static_cast<std::size_t>(type)];
  ++counter.proposed;
  double log_q = 0.0;
  if (!Propose(type, &edit_, &log_q) || !coloring_.Evaluate(edit_, &effect_)) {
    ++counter.invalid;
    return;
  }
  // Only the energy (potential and data) is tempered, not the reference measure λ: the
  // density against ν grows without bound as edges shrink, so tempering all of it would anneal
  // towards swarms of tiny polygons instead of the minimum-energy map.
  double log_energy_change = -ArakPotential(effect_.delta, options_.p) -
                             OrientationPotential(effect_.delta, options_.orientation);
  double black_area_change = 0.0;
  if (options_.free_space > 0.0) {
    const std::optional<double> change = BlackAreaChange(coloring_, edit_);
    if (!change) {
      ++counter.invalid;
      return;
    }
    black_area_change = *change;
    log_energy_change -= options_.free_space * black_area_change;
  }
  const auto passes = [&](double log_alpha) {
    return log_alpha >= 0.0 || rng_.Uniform() < std::exp(log_alpha);
  };
  const double log_measure = ArakLogMeasure(effect_.delta, options_.p);
  // Delayed acceptance: the screen's test first; the full data's ratio is then taken against
  // the screen's, so that the two stages' product is the full Hastings ratio.
  double log_screen = 0.0;
  if (screen_) {
    const auto screened = screen_->Evaluate(coloring_, edit_);
    if (!screened) return;  // a sensor in black: likelihood zero under all data alike
    log_screen = options_.screen_stride * FromFixed(*screened);
    if (!passes(log_measure + (log_energy_change + log_screen) / options_.temperature + log_q)) {
      ++counter.screened_out;
      return;
    }
  }
  double log_data = 0.0;
  if (data_) {
    const auto delta = data_->Evaluate(coloring_, edit_);
    if (!delta) return;  // likelihood zero: rejected
    log_data = FromFixed(*delta);
  }
  const bool accepted =
      screen_ ? passes((log_data - log_screen) / options_.temperature)
              : passes(log_measure + (log_energy_change + log_data) / options_.temperature + log_q);
  if (accepted) {
    if (estimates_) estimates_->Record(coloring_, edit_, steps_);
    const auto added = coloring_.Apply(edit_, effect_);
    black_area_ += black_area_change;
    if (data_) data_->Commit({added.begin(), added.size()});
    if (screen_) screen_->Commit({added.begin(), added.size()});
    ++counter.accepted;
    if (options_.check_invariants) {
      auto violation = coloring_.FindInvariantViolation(1e-6);
      if (!violation && data_) violation = data_->FindInconsistency(coloring_);
      if (!violation && screen_) violation = screen_->FindInconsistency(coloring_);
      PRIORMAP_CHECK(!violation, fmt::format("after {}: {}", MoveTypeName(type), *violation));
    }
  }
}

bool PrfSampler::Propose(MoveType type, Edit* edit, double* log_q) {
  edit->clear();
  *log_q = 0.0;
  switch (type) {
    case MoveType::kTriangleBirth:
      return ProposeTriangleBirth(edit, log_q);
    case MoveType::kTriangleDeath:
      return ProposeTriangleDeath(edit, log_q);
    case MoveType::kBoundaryTriangleBirth:
      return ProposeBoundaryTriangleBirth(edit, log_q);
    case MoveType::kBoundaryTriangleDeath:
      return ProposeBoundaryTriangleDeath(edit, log_q);
    case MoveType::kCornerBirth:
      return ProposeCornerBirth(edit, log_q);
    case MoveType::kCornerDeath:
      return ProposeCornerDeath(edit, log_q);
    case MoveType::kVertexBirth:
      return ProposeVertexBirth(edit, log_q);
    case MoveType::kVertexDeath:
      return ProposeVertexDeath(edit, log_q);
    case MoveType::kInteriorMove:
      return ProposeInteriorMove(edit);
    case MoveType::kBoundaryMove:
      return ProposeBoundaryMove(edit);
    case MoveType::kRecolor:
      return ProposeRecolor(edit, log_q, false);
    case MoveType::kLocalRecolor:
      return ProposeRecolor(edit, log_q, true);
    case MoveType::kSlide:
      return ProposeSlide(edit);
    case MoveType::kGuidedTriangleBirth:
      return ProposeGuidedTriangleBirth(edit, log_q);
    case MoveType::kGuidedTriangleDeath:
      return ProposeGuidedTriangleDeath(edit, log_q);
    case MoveType::kEdgeShift:
      return ProposeEdgeShift(edit);
    case MoveType::kVertexJump:
      return ProposeVertexJump(edit, log_q);
    case MoveType::kVertexPairBirth:
      return ProposeVertexPairBirth(edit, log_q);
    case MoveType::kVertexPairDeath:
      return ProposeVertexPairDeath(edit, log_q);
  }
  return false;
}

double PrfSampler::DrawOneOf(const std::vector<double>& values) {
  return values.size() == 1 ? values[0] : values[rng_.UniformIndex(values.size())];
}

std::optional<PrfSampler::DrawnVertex> PrfSampler::DrawInteriorVertex() {
  const auto interior = coloring_.interior_vertices();
  if (interior.empty()) return std::nullopt;
  const VertexId v = interior[rng_.UniformIndex(interior.size())];
  const ColoringVertex& vertex = coloring_.vertex(v);
  return DrawnVertex{v, coloring_.Other(vertex.edges[0], v), coloring_.Other(vertex.edges[1], v),
                     interior.size()};
}

std::optional<PrfSampler::InteriorPair> PrfSampler::DrawInteriorPair() {
  const auto drawn = DrawInteriorVertex();
  if (!drawn) return std::nullopt;
  const bool along_second = rng_.Bernoulli(0.5);
  const ColoringVertex& va = coloring_.vertex(drawn->vertex);
  InteriorPair pair{.p = along_second ? drawn->first : drawn->second,
                    .a = drawn->vertex,
                    .b = along_second ? drawn->second : drawn->first,
                    .q = kNoVertex,
                    .pa = va.edges[along_second ? 0 : 1],
                    .ab = va.edges[along_second ? 1 : 0],
                    .bq = kNoEdge,
                    .count = drawn->count};
  const ColoringVertex& vb = coloring_.vertex(pair.b);
  if (vb.side != kInterior) return std::nullopt;
  pair.bq = OtherEdge(vb, pair.ab);
  pair.q = coloring_.Other(pair.bq, pair.b);
  if (pair.q == pair.p) return std::nullopt;
  return pair;
}

// ---- proposal densities -------------------------------------------------------------------

double PrfSampler::TriangleDensity(const Vec2& a, const Vec2& b, const Vec2& c) const {
  // One vertex uniform in the window, the other two uniform in the square of half-width r
  // around it; summed over the six orders that give the same triangle.
  const double r = options_.birth_scale;
  const int first_choices = (ChebyshevDistance(a, b) <= r && ChebyshevDistance(a, c) <= r) +
                            (ChebyshevDistance(b, a) <= r && ChebyshevDistance(b, c) <= r) +
                            (ChebyshevDistance(c, a) <= r && ChebyshevDistance(c, b) <= r);
  return first_choices / (8.0 * coloring_.window().Area() * std::pow(r, 4));
}

double PrfSampler::BoundaryTriangleDensity(const Vec2& b1, int side1, const Vec2& b2, int side2,
                                           const Vec2& v) const {
  // b1 uniform on the perimeter, b2 within r of it along the same side, v uniform in the
  // square of half-width r around their midpoint; both orders of b1, b2.
  const Window& w = coloring_.window();
  const double r = options_.birth_scale;
  if (side1 == kInterior || side1 != side2) return 0.0;
  if (std::abs(w.CoordinateOf(b1, side1) - w.CoordinateOf(b2, side2)) > r) return 0.0;
  if (ChebyshevDistance(v, 0.5 * (b1 + b2)) > r) return 0.0;
  return 1.0 / (4.0 * w.Perimeter() * r * r * r);
}

double PrfSampler::RectangleDensity(const Vec2& u, const Vec2& w, const Vec2& v) const {
  const Vec2 along = w - u;
  const double length2 = along.squaredNorm();
  const double t = along.dot(v - u) / length2;
  if (t < 0.0 || t > 1.0) return 0.0;
  const double length = std::sqrt(length2);
  const double offset = std::abs(Cross(along, v - u)) / length;
  double density = 0.0;
  for (double width : options_.vertex_birth_widths)
    if (offset <= width * length) density += 1.0 / (2.0 * width * length2);
  return density / static_cast<double>(options_.vertex_birth_widths.size());
}

Vec2 PrfSampler::DrawInRectangle(const Vec2& u, const Vec2& w) {
  const Vec2 along = w - u;
  const double length = along.norm();
  const double half_width = DrawOneOf(options_.vertex_birth_widths) * length;
  return u + rng_.Uniform() * along +
         rng_.Uniform(-half_width, half_width) * (Perp(along) / length);
}

double PrfSampler::VertexPairDensity(const Vec2& u, const Vec2& a, const Vec2& b,
                                     const Vec2& w) const {
  // Read from u, a is drawn first; read from w, b is. Either end with probability ½.
  return 0.5 * (RectangleDensity(u, w, a) * RectangleDensity(a, w, b) +
                RectangleDensity(w, u, b) * RectangleDensity(b, u, a));
}

double PrfSampler::VertexBirthDensity(const Vec2& u, const Vec2& w, const Vec2& v,
                                      const ChordAnchors& anchors) const {
  // The rectangles, mixed with the squares around the chord's anchors.
  const double rectangles = RectangleDensity(u, w, v);
  const auto square = [&v](const Vec2& centre, double h) { return SquareDensity(v, centre, h); };
  double anchored = 0.0;
  double rectangles_share = 1.0;
  if (anchors.corner) {
    anchored +=
        options_.corner_completion * square(*anchors.corner, options_.corner_completion_jitter);
    rectangles_share -= options_.corner_completion;
  }
  if (anchors.num_beyond > 0) {
    double squares = 0.0;
    for (int k = 0; k < anchors.num_beyond; ++k)
      squares +=
          square(anchors.beyond[static_cast<std::size_t>(k)], options_.neighbour_birth_jitter);
    anchored += options_.neighbour_birth * squares / anchors.num_beyond;
    rectangles_share -= options_.neighbour_birth;
  }
  return anchored + rectangles_share * rectangles;
}

std::optional<Vec2> PrfSampler::CornerAhead(const Vec2& pu, const Vec2& beyond_u, const Vec2& pw,
                                            const Vec2& beyond_w) {
  // The lines through beyond_u → u and beyond_w → w.
  const Vec2 du = pu - beyond_u;
  const Vec2 dw = pw - beyond_w;
  const double denominator = Cross(du, dw);
  if (std::abs(denominator) <= 1e-9 * du.norm() * dw.norm()) return std::nullopt;
  // pu + a du = pw + b dw; ahead of both ends: a > 0 and b > 0.
  const double a = Cross(pw - pu, dw) / denominator;
  const double b = Cross(pw - pu, du) / denominator;
  if (a <= 0.0 || b <= 0.0) return std::nullopt;
  return pu + a * du;
}

std::optional<Vec2> PrfSampler::BeyondEnd(VertexId end, EdgeId side) const {
  const ColoringVertex& vertex = coloring_.vertex(end);
  if (vertex.side != kInterior) return std::nullopt;  // a boundary vertex has no neighbour beyond
  return coloring_.vertex(coloring_.Other(OtherEdge(vertex, side), end)).position;
}

PrfSampler::ChordAnchors PrfSampler::AnchorsOf(VertexId u, EdgeId u_side, VertexId w,
                                               EdgeId w_side) const {
  ChordAnchors anchors;
  if (options_.corner_completion == 0.0 && options_.neighbour_birth == 0.0) return anchors;
  const std::optional<Vec2> beyond_u = BeyondEnd(u, u_side);
  const std::optional<Vec2> beyond_w = BeyondEnd(w, w_side);
  if (options_.corner_completion > 0.0 && beyond_u && beyond_w) {
    const Vec2& pu = coloring_.vertex(u).position;
    const Vec2& pw = coloring_.vertex(w).position;
    // From the lower vertex id, so that a birth and its death, which may see the chord's ends
    // in either order, round the corner's position alike.
    anchors.corner = u < w ? CornerAhead(pu, *beyond_u, pw, *beyond_w)
                           : CornerAhead(pw, *beyond_w, pu, *beyond_u);
  }
  if (options_.neighbour_birth > 0.0)
    for (const std::optional<Vec2>& anchor : {beyond_u, beyond_w})
      if (anchor) anchors.beyond[static_cast<std::size_t>(anchors.num_beyond++)] = *anchor;
  return anchors;
}

namespace {

// The corner shared by adjacent sides, with the vertex on the side ending there first; -1
// when the sides are not adjacent.
int SharedCorner(int side1, int side2) {
  if (side1 == kInterior || side2 == kInterior) return -1;
  if (side2 == (side1 + 1) % kNumSides) return side2;
  if (side1 == (side2 + 1) % kNumSides) return side1;
  return -1;
}

}  // namespace

// ---- births and deaths --------------------------------------------------------------------

void PrfSampler::AddTriangle(const Vec2& a, const Vec2& b, const Vec2& c, Edit* edit) {
  for (const Vec2& x : {a, b, c}) edit->new_vertices.push_back({x, kInterior});
  edit->added_edges.push_back({Fresh(0), Fresh(1)});
  edit->added_edges.push_back({Fresh(1), Fresh(2)});
  edit->added_edges.push_back({Fresh(2), Fresh(0)});
  for (const Vec2& x : {a, b, c}) edit->flipped_region.push_back(x);
}

bool PrfSampler::ProposeFreeTriangleRemoval(Edit* edit, double* log_pi,
                                            std::array<Vec2, 3>* corners) {
  const auto drawn = DrawInteriorVertex();
  if (!drawn) return false;
  const auto [v, u, x, n_interior] = *drawn;
  const ColoringVertex& vertex = coloring_.vertex(v);
  if (coloring_.vertex(u).side != kInterior || coloring_.vertex(x).side != kInterior) return false;
  const EdgeId closing = OtherEdge(coloring_.vertex(u), vertex.edges[0]);
  if (coloring_.Other(closing, u) != x) return false;
  for (EdgeId e : {vertex.edges[0], vertex.edges[1], closing}) edit->removed_edges.push_back(e);
  int k = 0;
  for (VertexId y : {v, u, x}) {
    edit->removed_vertices.push_back(y);
    edit->flipped_region.push_back(coloring_.vertex(y).position);
    (*corners)[k++] = coloring_.vertex(y).position;
  }
  // A given triangle is drawn through any of its three vertices.
  *log_pi = std::log(3.0 / static_cast<double>(n_interior));
  return true;
}

bool PrfSampler::ProposeTriangleBirth(Edit* edit, double* log_q) {
  const Window& w = coloring_.window();
  const double r = options_.birth_scale;
  const Vec2 a(rng_.Uniform(w.min.x(), w.max.x()), rng_.Uniform(w.min.y(), w.max.y()));
  const Vec2 b = a + Vec2(rng_.Uniform(-r, r), rng_.Uniform(-r, r));
  const Vec2 c = a + Vec2(rng_.Uniform(-r, r), rng_.Uniform(-r, r));
  AddTriangle(a, b, c, edit);
  const double n_after = static_cast<double>(coloring_.interior_vertices().size() + 3);
  *log_q = std::log(3.0 / n_after) - std::log(TriangleDensity(a, b, c));
  return true;
}

bool PrfSampler::ProposeTriangleDeath(Edit* edit, double* log_q) {
  std::array<Vec2, 3> t;
  double log_pi = 0.0;
  if (!ProposeFreeTriangleRemoval(edit, &log_pi, &t)) return false;
  const double density = TriangleDensity(t[0], t[1], t[2]);
  if (density == 0.0) return false;  // the birth could not have proposed it
  *log_q = std::log(density) - log_pi;
  return true;
}

// The guided births are a kind of their own: each birth/death pair is in detailed balance by
// itself, with the guide's density in place of the blind one (docs/prf-moves.md).
bool PrfSampler::ProposeGuidedTriangleBirth(Edit* edit, double* log_q) {
  Vec2 a, b, c;
  options_.guide->Draw(rng_, &a, &b, &c);
  const double density = options_.guide->Density(a, b, c);
  if (density == 0.0) return false;  // rounding at the edge of a square: measure zero
  AddTriangle(a, b, c, edit);
  const double n_after = static_cast<double>(coloring_.interior_vertices().size() + 3);
  *log_q = std::log(3.0 / n_after) - std::log(density);
  return true;
}

bool PrfSampler::ProposeGuidedTriangleDeath(Edit* edit, double* log_q) {
  std::array<Vec2, 3> t;
  double log_pi = 0.0;
  if (!ProposeFreeTriangleRemoval(edit, &log_pi, &t)) return false;
  const double density = options_.guide->Density(t[0], t[1], t[2]);
  if (density == 0.0) return false;
  *log_q = std::log(density) - log_pi;
  return true;
}

bool PrfSampler::ProposeBoundaryTriangleBirth(Edit* edit, double* log_q) {
  const Window& w = coloring_.window();
  const double r = options_.birth_scale;
  const double perimeter = w.Perimeter();
  const double s1 = rng_.Uniform(0.0, perimeter);
  const double s2 = s1 + rng_.Uniform(-r, r);
  const int side = w.SideAt(s1);
  if (side < 0 || s2 < 0.0 || s2 >= perimeter || w.SideAt(s2) != side) return false;
  const Vec2 b1 = w.PointAt(s1);
  const Vec2 b2 = w.PointAt(s2);
  const Vec2 v = 0.5 * (b1 + b2) + Vec2(rng_.Uniform(-r, r), rng_.Uniform(-r, r));
  edit->new_vertices.push_back({b1, side});
  edit->new_vertices.push_back({v, kInterior});
  edit->new_vertices.push_back({b2, side});
  edit->added_edges.push_back({Fresh(0), Fresh(1)});
  edit->added_edges.push_back({Fresh(1), Fresh(2)});
  for (const Vec2& x : {b1, v, b2}) edit->flipped_region.push_back(x);
  const double n_after = static_cast<double>(coloring_.interior_vertices().size() + 1);
  *log_q = -std::log(n_after) - std::log(BoundaryTriangleDensity(b1, side, b2, side, v));
  return true;
}

bool PrfSampler::ProposeBoundaryTriangleDeath(Edit* edit, double* log_q) {
  const auto drawn = DrawInteriorVertex();
  if (!drawn) return false;
  const auto [v, b1, b2, n_interior] = *drawn;
  const ColoringVertex& vertex = coloring_.vertex(v);
  const ColoringVertex& first = coloring_.vertex(b1);
  const ColoringVertex& second = coloring_.vertex(b2);
  const double density = BoundaryTriangleDensity(first.position, first.side, second.position,
                                                 second.side, vertex.position);
  if (density == 0.0) return false;
  edit->removed_edges.push_back(vertex.edges[0]);
  edit->removed_edges.push_back(vertex.edges[1]);
  for (VertexId y : {b1, v, b2}) {
    edit->removed_vertices.push_back(y);
    edit->flipped_region.push_back(coloring_.vertex(y).position);
  }
  *log_q = std::log(density) + std::log(static_cast<double>(n_interior));
  return true;
}

bool PrfSampler::ProposeCornerBirth(Edit* edit, double* log_q) {
  const Window& w = coloring_.window();
  const double r = options_.birth_scale;
  const int corner = static_cast<int>(rng_.UniformIndex(kNumSides));
  const double before = rng_.Uniform(0.0, r);
  const double after = rng_.Uniform(0.0, r);
  const int side_before = (corner + kNumSides - 1) % kNumSides;
  const int side_after = corner;
  const double c = w.CornerCoordinate(corner);
  if (w.SideAt(c - before) != side_before || w.SideAt(c + after) != side_after) return false;
  const Vec2 b1 = w.PointAt(c - before);
  const Vec2 b2 = w.PointAt(c + after);
  edit->new_vertices.push_back({b1, side_before});
  edit->new_vertices.push_back({b2, side_after});
  edit->added_edges.push_back({Fresh(0), Fresh(1)});
  for (const Vec2& x : {b1, w.Corner(corner), b2}) edit->flipped_region.push_back(x);
  const double n_after = static_cast<double>(coloring_.boundary_vertices().size() + 2);
  // Density 1/(4 r²): a corner in four, two uniform distances in [0, r).
  *log_q = std::log(2.0 / n_after) + std::log(4.0 * r * r);
  return true;
}

bool PrfSampler::ProposeCornerDeath(Edit* edit, double* log_q) {
  const Window& w = coloring_.window();
  const double r = options_.birth_scale;
  const auto boundary = coloring_.boundary_vertices();
  if (boundary.empty()) return false;
  const VertexId b = boundary[rng_.UniformIndex(boundary.size())];
  const EdgeId e = coloring_.vertex(b).edges[0];
  const VertexId u = coloring_.Other(e, b);
  const ColoringVertex& vb = coloring_.vertex(b);
  const ColoringVertex& vu = coloring_.vertex(u);
  const int corner = SharedCorner(vb.side, vu.side);
  if (corner < 0) return false;
  const Vec2 corner_point = w.Corner(corner);
  if (ChebyshevDistance(vb.position, corner_point) > r ||
      ChebyshevDistance(vu.position, corner_point) > r)
    return false;
  edit->removed_edges.push_back(e);
  edit->removed_vertices.push_back(b);
  edit->removed_vertices.push_back(u);
  for (const Vec2& x : {vb.position, corner_point, vu.position}) edit->flipped_region.push_back(x);
  *log_q = -std::log(4.0 * r * r) - std::log(2.0 / static_cast<double>(boundary.size()));
  return true;
}

bool PrfSampler::ProposeVertexBirth(Edit* edit, double* log_q) {
  const auto edges = coloring_.edge_ids();
  if (edges.empty()) return false;
  const EdgeId e = edges[rng_.UniformIndex(edges.size())];
  const VertexId u = coloring_.edge(e).vertices[0];
  const VertexId w = coloring_.edge(e).vertices[1];
  const Vec2& pu = coloring_.vertex(u).position;
  const Vec2& pw = coloring_.vertex(w).position;
  const ChordAnchors anchors = AnchorsOf(u, e, w, e);
  const auto in_square = [this](const Vec2& centre, double h) -> Vec2 {
    return centre + Vec2(rng_.Uniform(-h, h), rng_.Uniform(-h, h));
  };
  // Without a corner ahead its share goes to the rest, so the neighbours' share is
  // neighbour_birth of the whole either way.
  const double after_corner = 1.0 - (anchors.corner ? options_.corner_completion : 0.0);
  Vec2 v;
  if (anchors.corner && rng_.Bernoulli(options_.corner_completion)) {
    v = in_square(*anchors.corner, options_.corner_completion_jitter);
  } else if (anchors.num_beyond > 0 && rng_.Bernoulli(options_.neighbour_birth / after_corner)) {
    const std::size_t k = anchors.num_beyond == 1 ? 0 : rng_.UniformIndex(2);
    v = in_square(anchors.beyond[k], options_.neighbour_birth_jitter);
  } else {
    v = DrawInRectangle(pu, pw);
  }
  edit->removed_edges.push_back(e);
  edit->new_vertices.push_back({v, kInterior});
  edit->added_edges.push_back({Old(u), Fresh(0)});
  edit->added_edges.push_back({Fresh(0), Old(w)});
  for (const Vec2& x : {pu, v, pw}) edit->flipped_region.push_back(x);
  const double n_after = static_cast<double>(coloring_.interior_vertices().size() + 1);
  const double forward = VertexBirthDensity(pu, pw, v, anchors) / static_cast<double>(edges.size());
  if (forward == 0.0) return false;  // only at the rim of a rectangle or square, by rounding
  *log_q = -std::log(n_after) - std::log(forward);
  return true;
}

bool PrfSampler::ProposeVertexDeath(Edit* edit, double* log_q) {
  const auto drawn = DrawInteriorVertex();
  if (!drawn) return false;
  const auto [v, u, w, n_interior] = *drawn;
  const ColoringVertex& vertex = coloring_.vertex(v);
  const Vec2& pu = coloring_.vertex(u).position;
  const Vec2& pw = coloring_.vertex(w).position;
  const double edges_after = static_cast<double>(coloring_.edge_ids().size() - 1);
  const ChordAnchors anchors = AnchorsOf(u, vertex.edges[0], w, vertex.edges[1]);
  const double reverse = VertexBirthDensity(pu, pw, vertex.position, anchors) / edges_after;
  if (reverse == 0.0) return false;
  edit->removed_edges.push_back(vertex.edges[0]);
  edit->removed_edges.push_back(vertex.edges[1]);
  edit->removed_vertices.push_back(v);
  edit->added_edges.push_back({Old(u), Old(w)});
  for (const Vec2& x : {pu, vertex.position, pw}) edit->flipped_region.push_back(x);
  *log_q = std::log(reverse) + std::log(static_cast<double>(n_interior));
  return true;
}

bool PrfSampler::ProposeVertexPairBirth(Edit* edit, double* log_q) {
  const auto edges = coloring_.edge_ids();
  if (edges.empty()) return false;
  const EdgeId e = edges[rng_.UniformIndex(edges.size())];
  const int from = rng_.Bernoulli(0.5) ? 1 : 0;
  const VertexId u = coloring_.edge(e).vertices[static_cast<std::size_t>(from)];
  const VertexId w = coloring_.edge(e).vertices[static_cast<std::size_t>(1 - from)];
  const Vec2& pu = coloring_.vertex(u).position;
  const Vec2& pw = coloring_.vertex(w).position;
  const Vec2 v1 = DrawInRectangle(pu, pw);
  if (v1 == pw) return false;
  const Vec2 v2 = DrawInRectangle(v1, pw);
  const double forward = VertexPairDensity(pu, v1, v2, pw) / static_cast<double>(edges.size());
  if (forward == 0.0) return false;  // only at the rim of a rectangle, by rounding
  edit->removed_edges.push_back(e);
  AddPathThroughNewPair(u, v1, v2, w, edit);
  for (const Vec2& x : {pu, v1, v2, pw}) edit->flipped_region.push_back(x);
  // The death draws the pair with probability 1/n: either of its vertices, then the edge
  // towards the other.
  const double n_after = static_cast<double>(coloring_.interior_vertices().size() + 2);
  *log_q = -std::log(n_after) - std::log(forward);
  return true;
}

bool PrfSampler::ProposeVertexPairDeath(Edit* edit, double* log_q) {
  const auto pair = DrawInteriorPair();
  if (!pair) return false;
  const Vec2& pu = coloring_.vertex(pair->p).position;
  const Vec2& pa = coloring_.vertex(pair->a).position;
  const Vec2& pb = coloring_.vertex(pair->b).position;
  const Vec2& pw = coloring_.vertex(pair->q).position;
  const double edges_after = static_cast<double>(coloring_.edge_ids().size() - 2);
  const double reverse = VertexPairDensity(pu, pa, pb, pw) / edges_after;
  if (reverse == 0.0) return false;  // no pair birth on uw draws these two
  for (EdgeId e : {pair->pa, pair->ab, pair->bq}) edit->removed_edges.push_back(e);
  edit->removed_vertices.push_back(pair->a);
  edit->removed_vertices.push_back(pair->b);
  edit->added_edges.push_back({Old(pair->p), Old(pair->q)});
  for (const Vec2& x : {pu, pa, pb, pw}) edit->flipped_region.push_back(x);
  *log_q = std::log(reverse) + std::log(static_cast<double>(pair->count));
  return true;
}

// ---- moves that keep the graph's structure ------------------------------------------------

bool PrfSampler::ProposeInteriorMove(Edit* edit) {
  const auto drawn = DrawInteriorVertex();
  if (!drawn) return false;
  const double step = DrawOneOf(options_.step_scales);
  const Vec2 moved = coloring_.vertex(drawn->vertex).position +
                     Vec2(rng_.Uniform(-step, step), rng_.Uniform(-step, step));
  MoveVertex(*drawn, moved, edit);
  return true;
}

void PrfSampler::MoveVertex(const DrawnVertex& drawn, const Vec2& moved, Edit* edit) const {
  const auto [v, u, w, n_interior] = drawn;
  const ColoringVertex& vertex = coloring_.vertex(v);
  edit->removed_edges.push_back(vertex.edges[0]);
  edit->removed_edges.push_back(vertex.edges[1]);
  edit->removed_vertices.push_back(v);
  edit->new_vertices.push_back({moved, kInterior});
  edit->added_edges.push_back({Old(u), Fresh(0)});
  edit->added_edges.push_back({Fresh(0), Old(w)});
  for (const Vec2& x :
       {coloring_.vertex(u).position, vertex.position, coloring_.vertex(w).position, moved})
    edit->flipped_region.push_back(x);
}

double PrfSampler::VertexJumpDensity(const Vec2& from, const Vec2& to,
                                     const ChordAnchors& beyond) const {
  const auto square = [&to](const Vec2& centre, double h) { return SquareDensity(to, centre, h); };
  const double far = square(from, options_.vertex_jump_reach);
  if (beyond.num_beyond == 0) return far;
  double squares = 0.0;
  for (int k = 0; k < beyond.num_beyond; ++k)
    squares += square(beyond.beyond[static_cast<std::size_t>(k)], options_.vertex_jump_jitter);
  return 0.5 * squares / beyond.num_beyond + 0.5 * far;
}

bool PrfSampler::ProposeVertexJump(Edit* edit, double* log_q) {
  // The vertex is drawn with probability 1/n_i both ways, and the jump keeps the graph's
  // structure, so the vertices beyond v's neighbours neither move nor change: the reverse jump
  // draws from the same squares, and only the densities of the two jumps enter the ratio.
  const auto drawn = DrawInteriorVertex();
  if (!drawn) return false;
  const ColoringVertex& vertex = coloring_.vertex(drawn->vertex);
  ChordAnchors beyond;
  for (const std::optional<Vec2>& anchor :
       {BeyondEnd(drawn->first, vertex.edges[0]), BeyondEnd(drawn->second, vertex.edges[1])})
    if (anchor) beyond.beyond[static_cast<std::size_t>(beyond.num_beyond++)] = *anchor;
  const auto uniform_around = [this](const Vec2& centre, double h) {
    return Vec2(centre + Vec2(rng_.Uniform(-h, h), rng_.Uniform(-h, h)));
  };
  const Vec2& from = vertex.position;
  Vec2 to;
  if (beyond.num_beyond > 0 && rng_.Bernoulli(0.5)) {
    const std::size_t k = beyond.num_beyond == 1 ? 0 : rng_.UniformIndex(2);
    to = uniform_around(beyond.beyond[k], options_.vertex_jump_jitter);
  } else {
    to = uniform_around(from, options_.vertex_jump_reach);
  }
  const double forward = VertexJumpDensity(from, to, beyond);
  const double reverse = VertexJumpDensity(to, from, beyond);
  // A jump to a neighbour's neighbour farther than the reach from v, when v lies in no square
  // of the jump back, cannot be undone: refused.
  if (forward == 0.0 || reverse == 0.0) return false;
  *log_q = std::log(reverse) - std::log(forward);
  MoveVertex(*drawn, to, edit);
  return true;
}

bool PrfSampler::ProposeEdgeShift(Edit* edit) {
  // The pair {a, b} is drawn with probability 1/n_i (DrawInteriorPair), the shift from a
  // symmetric density, and neither changes n_i: the move is its own reverse with ratio 1. On a
  // free triangle p, a, b the shift would move two of its three vertices; DrawInteriorPair
  // refuses it in both directions alike, since the shift keeps the graph's structure.
  const auto pair = DrawInteriorPair();
  if (!pair) return false;
  const Vec2& pa = coloring_.vertex(pair->a).position;
  const Vec2& pb = coloring_.vertex(pair->b).position;
  const double step = DrawOneOf(options_.step_scales);
  const Vec2 shift(rng_.Uniform(-step, step), rng_.Uniform(-step, step));
  const Vec2 new_a = pa + shift;
  const Vec2 new_b = pb + shift;
  for (EdgeId e : {pair->pa, pair->ab, pair->bq}) edit->removed_edges.push_back(e);
  edit->removed_vertices.push_back(pair->a);
  edit->removed_vertices.push_back(pair->b);
  AddPathThroughNewPair(pair->p, new_a, new_b, pair->q, edit);
  // The ring between the old path p, a, b, q and the new one.
  for (const Vec2& x : {coloring_.vertex(pair->p).position, pa, pb,
                        coloring_.vertex(pair->q).position, new_b, new_a})
    edit->flipped_region.push_back(x);
  return true;
}

bool PrfSampler::ProposeBoundaryMove(Edit* edit) {
  const Window& w = coloring_.window();
  const auto boundary = coloring_.boundary_vertices();
  if (boundary.empty()) return false;
  const VertexId b = boundary[rng_.UniformIndex(boundary.size())];
  const ColoringVertex& vertex = coloring_.vertex(b);
  const double step = DrawOneOf(options_.step_scales);
  const double delta = rng_.Uniform(-step, step);
  const double s = w.CoordinateOf(vertex.position, vertex.side);
  const double moved_s = w.Wrap(s + delta);
  const int side = w.SideAt(moved_s);
  if (side < 0) return false;
  const Vec2 moved = w.PointAt(moved_s);
  const EdgeId e = vertex.edges[0];
  const VertexId u = coloring_.Other(e, b);
  edit->removed_edges.push_back(e);
  edit->removed_vertices.push_back(b);
  edit->new_vertices.push_back({moved, side});
  edit->added_edges.push_back({Old(u), Fresh(0)});
  // The reversed region runs from u to the old position, along the boundary (through the
  // corners passed, in order) to the new one, and back to u.
  edit->flipped_region.push_back(coloring_.vertex(u).position);
  edit->flipped_region.push_back(vertex.position);
  const double perimeter = w.Perimeter();
  for (int j = 0; j < kNumSides; ++j) {
    const int corner =
        delta > 0.0 ? (vertex.side + 1 + j) % kNumSides : (vertex.side - j + kNumSides) % kNumSides;
    const double c = w.CornerCoordinate(corner);
    const double distance = delta > 0.0 ? w.Wrap(c - s) : w.Wrap(s - c);
    if (distance > 0.0 && distance < std::abs(delta) && distance < perimeter)
      edit->flipped_region.push_back(w.Corner(corner));
  }
  edit->flipped_region.push_back(moved);
  return true;
}

bool PrfSampler::ProposeSlide(Edit* edit) {
  const auto drawn = DrawInteriorVertex();
  if (!drawn) return false;
  const VertexId v = drawn->vertex;
  const ColoringVertex& vertex = coloring_.vertex(v);
  const std::size_t k = rng_.UniformIndex(2);
  const EdgeId kept_direction = vertex.edges[k];
  const EdgeId turning = vertex.edges[1 - k];
  const VertexId w = k == 0 ? drawn->first : drawn->second;
  const VertexId u = k == 0 ? drawn->second : drawn->first;
  // v' = v + t (v − w), t uniform in [−½, 1]: the edge to w keeps its direction and its
  // length goes from |e| to (1 + t)|e| in [|e|/2, 2|e|], a range that contains the reverse.
  const double t = rng_.Uniform(-0.5, 1.0);
  const Vec2 moved = vertex.position + t * (vertex.position - coloring_.vertex(w).position);
  edit->removed_edges.push_back(kept_direction);
  edit->removed_edges.push_back(turning);
  edit->removed_vertices.push_back(v);
  edit->new_vertices.push_back({moved, kInterior});
  edit->added_edges.push_back({Old(u), Fresh(0)});
  edit->added_edges.push_back({Fresh(0), Old(w)});
  for (const Vec2& x : {coloring_.vertex(u).position, vertex.position, moved})
    edit->flipped_region.push_back(x);
  return true;
}

int PrfSampler::CellNeighbourCount(const Vec2& a, const Vec2& b, EdgeId self, EdgeId removed1,
                                   EdgeId removed2) const {
  int count = 0;
  coloring_.ForEachEdgeNear(a, b, [&](EdgeId e) {
    if (e != self && e != removed1 && e != removed2) ++count;
  });
  return count;
}

bool PrfSampler::ShareACell(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  cell_marks_.NextRound();
  WalkCells(coloring_.grid(), a, b, [&](int cell, double, double) {
    cell_marks_.Mark(static_cast<std::size_t>(cell));
    return true;
  });
  bool shared = false;
  WalkCells(coloring_.grid(), c, d, [&](int cell, double, double) {
    shared = cell_marks_.Marked(static_cast<std::size_t>(cell));
    return !shared;
  });
  return shared;
}

bool PrfSampler::ProposeRecolor(Edit* edit, double* log_q, bool local) {
  const auto edges = coloring_.edge_ids();
  if (edges.size() < 2) return false;
  const EdgeId e1 = edges[rng_.UniformIndex(edges.size())];
  EdgeId e2 = kNoEdge;
  double forward = 0.0;  // Σ over the two orders of drawing {e1, e2}, without the common 1/|E|
  if (local) {
    // The second edge uniformly among those sharing a grid cell with the first (Sec. 2.1).
    scratch_edges_.clear();
    const Segment s1 = coloring_.EdgeSegment(e1);
    coloring_.ForEachEdgeNear(s1.a, s1.b, [&](EdgeId e) {
      if (e != e1) scratch_edges_.push_back(e);
    });
    if (scratch_edges_.empty()) return false;
    e2 = scratch_edges_[rng_.UniformIndex(scratch_edges_.size())];
    const Segment s2 = coloring_.EdgeSegment(e2);
    forward = 1.0 / static_cast<double>(scratch_edges_.size()) +
              1.0 / CellNeighbourCount(s2.a, s2.b, e2, kNoEdge, kNoEdge);
  } else {
    std::size_t j = rng_.UniformIndex(edges.size() - 1);
    if (edges[j] == e1) j = edges.size() - 1;
    e2 = edges[j];
  }
  const auto [a, b] = coloring_.edge(e1).vertices;
  const auto [c, d] = coloring_.edge(e2).vertices;
  if (a == c || a == d || b == c || b == d) return false;
  edit->removed_edges.push_back(e1);
  edit->removed_edges.push_back(e2);
  const auto pos = [&](VertexId v) { return coloring_.vertex(v).position; };
  if (rng_.UniformIndex(2) == 0) {
    // ab, cd -> ac, bd: the quadrilateral a b d c changes colour.
    edit->added_edges.push_back({Old(a), Old(c)});
    edit->added_edges.push_back({Old(b), Old(d)});
    for (VertexId v : {a, b, d, c}) edit->flipped_region.push_back(pos(v));
  } else {
    // ab, cd -> ad, bc: the quadrilateral a b c d changes colour.
    edit->added_edges.push_back({Old(a), Old(d)});
    edit->added_edges.push_back({Old(b), Old(c)});
    for (VertexId v : {a, b, c, d}) edit->flipped_region.push_back(pos(v));
  }
  if (local) {
    const auto [f1a, f1b] = edit->added_edges[0];
    const auto [f2a, f2b] = edit->added_edges[1];
    const Vec2 p1a = pos(f1a.id()), p1b = pos(f1b.id()), p2a = pos(f2a.id()), p2b = pos(f2b.id());
    // The reverse move must be able to draw the new edges as a local pair.
    if (!ShareACell(p1a, p1b, p2a, p2b)) return false;
    const double reverse = 1.0 / (CellNeighbourCount(p1a, p1b, kNoEdge, e1, e2) + 1) +
                           1.0 / (CellNeighbourCount(p2a, p2b, kNoEdge, e1, e2) + 1);
    *log_q = std::log(reverse) - std::log(forward);
  }
  return true;
}

namespace {

// A chain without vertex pairs (and without vertex jumps) saves the counters of the types there
// were before them, so that its checkpoints are those of the versions before them.
std::size_t SavedMoveTypes(const SamplerOptions& options) {
  if (options.weights[MoveKind::kVertexPair] > 0.0) return kNumMoveTypes;
  return options.weights[MoveKind::kVertexJump] > 0.0 ? kNumMoveTypesBeforePairs
                                                      : kNumMoveTypesBeforeJumps;
}

}  // namespace

void PrfSampler::Save(BinaryWriter& out) const {
  coloring_.Save(out);
  out.Put(steps_);
  rng_.Save(out);
  const std::size_t saved = SavedMoveTypes(options_);
  for (std::size_t t = 0; t < saved; ++t) {
    out.Put(counters_[t].proposed);
    out.Put(counters_[t].invalid);
    out.Put(counters_[t].accepted);
  }
  out.Put(options_.temperature);
  out.Put(black_area_);
  // Only chains with delayed acceptance have screened-out counts to save.
  if (options_.screen_stride > 1)
    for (std::size_t t = 0; t < saved; ++t) out.Put(counters_[t].screened_out);
}

std::unique_ptr<PrfSampler> PrfSampler::Load(BinaryReader& in, const Window& window,
                                             double cell_size, SamplerOptions options,
                                             std::unique_ptr<DataTerm> data) {
  Coloring coloring = Coloring::Load(in, window, cell_size);
  const std::uint64_t steps = in.Get<std::uint64_t>();
  Rng rng(0);
  rng.Load(in);
  MoveCounters counters{};
  const std::size_t saved = SavedMoveTypes(options);
  for (std::size_t t = 0; t < saved; ++t) {
    counters[t].proposed = in.Get<std::uint64_t>();
    counters[t].invalid = in.Get<std::uint64_t>();
    counters[t].accepted = in.Get<std::uint64_t>();
  }
  options.temperature = in.Get<double>();
  if (!(options.temperature > 0.0)) in.Fail("a chain with a temperature that is not positive");
  // As kept, not recomputed from the faces: a resumed chain continues bit for bit.
  const double black_area = in.Get<double>();
  if (!std::isfinite(black_area)) in.Fail("a black area that is not finite");
  if (options.screen_stride > 1)
    for (std::size_t t = 0; t < saved; ++t) counters[t].screened_out = in.Get<std::uint64_t>();
  if (data && data->Reset(coloring)) in.Fail("a chain whose coloring has likelihood zero");
  auto sampler =
      std::make_unique<PrfSampler>(std::move(coloring), std::move(options), 0, std::move(data));
  sampler->steps_ = steps;
  sampler->rng_ = rng;
  sampler->counters_ = counters;
  sampler->black_area_ = black_area;
  return sampler;
}

}  // namespace priormap::prf
