// How often the sampler proposes each move type. PrfSampler::Step chooses a kind with probability
// weight / (sum of weights) (guided triangles count as weight 0 without a guide), splits the
// kinds with births and deaths evenly between the two, and counts the choice in
// MoveCounter::proposed *before* proposing: a type the state offers no move of (a death with
// nothing to remove, a move with no vertex) is still counted as proposed, and as invalid, and the
// chain stays where it is. So whatever the states the chain visits, the proposal counts over N
// steps are multinomial(N, the configured shares), and they are tested here against exactly that:
// a chi-square test at p = 1e-6 over the types with a positive share, every type within 5
// binomial standard errors, and zero proposals of a type whose share is zero.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/rng.hpp>
#include <priormap/prf/sampler.hpp>

namespace priormap::prf {
namespace {

const Window kUnit{Vec2::Zero(), Vec2::Ones()};

using Shares = std::array<double, kNumMoveTypes>;

// The move types of each kind, written out here rather than taken from the sampler: births and
// deaths share their kind's weight half and half, the other kinds have one type each.
struct KindTypes {
  MoveKind kind;
  std::vector<MoveType> types;
};
const std::vector<KindTypes> kKindTypes{
    {MoveKind::kTriangle, {MoveType::kTriangleBirth, MoveType::kTriangleDeath}},
    {MoveKind::kBoundaryTriangle,
     {MoveType::kBoundaryTriangleBirth, MoveType::kBoundaryTriangleDeath}},
    {MoveKind::kCorner, {MoveType::kCornerBirth, MoveType::kCornerDeath}},
    {MoveKind::kVertex, {MoveType::kVertexBirth, MoveType::kVertexDeath}},
    {MoveKind::kInteriorMove, {MoveType::kInteriorMove}},
    {MoveKind::kBoundaryMove, {MoveType::kBoundaryMove}},
    {MoveKind::kRecolor, {MoveType::kRecolor}},
    {MoveKind::kLocalRecolor, {MoveType::kLocalRecolor}},
    {MoveKind::kSlide, {MoveType::kSlide}},
    {MoveKind::kGuidedTriangle, {MoveType::kGuidedTriangleBirth, MoveType::kGuidedTriangleDeath}},
    {MoveKind::kEdgeShift, {MoveType::kEdgeShift}},
    {MoveKind::kVertexJump, {MoveType::kVertexJump}},
    {MoveKind::kVertexPair, {MoveType::kVertexPairBirth, MoveType::kVertexPairDeath}},
};

// The probability that a step proposes each type. `guided`: whether the sampler has a non-empty
// birth guide (without one, guided triangles have weight 0 whatever their configured weight).
Shares ExpectedShares(const MoveWeights& weights, bool guided) {
  double total = 0.0;
  for (const KindTypes& k : kKindTypes)
    if (k.kind != MoveKind::kGuidedTriangle || guided) total += weights[k.kind];
  Shares shares{};
  for (const KindTypes& k : kKindTypes) {
    const double w = k.kind != MoveKind::kGuidedTriangle || guided ? weights[k.kind] : 0.0;
    for (MoveType t : k.types)
      shares[static_cast<std::size_t>(t)] = w / total / static_cast<double>(k.types.size());
  }
  return shares;
}

// P(X >= x) for X chi-square with `dof` degrees of freedom: the regularized upper incomplete
// gamma function Q(dof/2, x/2), from Q(1, h) = exp(-h) or Q(1/2, h) = erfc(sqrt(h)) and
// Q(a + 1, h) = Q(a, h) + h^a exp(-h) / Gamma(a + 1).
double ChiSquareSurvival(double x, int dof) {
  const double h = x / 2.0;
  double a = dof % 2 == 0 ? 1.0 : 0.5;
  double q = dof % 2 == 0 ? std::exp(-h) : std::erfc(std::sqrt(h));
  for (; a < dof / 2.0; a += 1.0) q += std::exp(a * std::log(h) - h - std::lgamma(a + 1.0));
  return q;
}

// The level of the chi-square tests: with fixed seeds they pass or fail for good, and a correct
// sampler fails one with probability 1e-6.
constexpr double kLevel = 1e-6;

struct FrequencyCheck {
  double chi_square = 0.0;
  int dof = 0;
  double p_value = 1.0;
  double worst_z = 0.0;  // the largest |observed - expected| / standard error over the types
};

// Checks the proposal counts of a chain of `steps` steps against `shares` and returns the
// statistics (for the test's recorded properties).
FrequencyCheck ExpectProposalsFollow(const MoveCounters& counters, const Shares& shares,
                                     std::uint64_t steps) {
  FrequencyCheck check;
  const double n = static_cast<double>(steps);
  int positive = 0;
  for (int t = 0; t < kNumMoveTypes; ++t) {
    const auto type = static_cast<MoveType>(t);
    const double p = shares[static_cast<std::size_t>(t)];
    const auto observed = static_cast<double>(counters[static_cast<std::size_t>(t)].proposed);
    if (p == 0.0) {
      EXPECT_EQ(observed, 0.0) << MoveTypeName(type) << " has weight 0 but was proposed";
      continue;
    }
    ++positive;
    const double expected = n * p;
    const double z = (observed - expected) / std::sqrt(n * p * (1.0 - p));
    check.chi_square += (observed - expected) * (observed - expected) / expected;
    check.worst_z = std::max(check.worst_z, std::abs(z));
    EXPECT_LT(std::abs(z), 5.0) << MoveTypeName(type) << ": proposed " << observed << " times, "
                                << expected << " expected (z = " << z << ")";
  }
  check.dof = positive - 1;
  check.p_value = ChiSquareSurvival(check.chi_square, check.dof);
  EXPECT_GT(check.p_value, kLevel) << "chi-square " << check.chi_square << " over " << positive
                                   << " types with a positive share";
  EXPECT_EQ(Total(counters).proposed, steps);
  ::testing::Test::RecordProperty("chi_square", std::to_string(check.chi_square));
  ::testing::Test::RecordProperty("chi_square_dof", check.dof);
  ::testing::Test::RecordProperty("p_value", std::to_string(check.p_value));
  ::testing::Test::RecordProperty("worst_z", std::to_string(check.worst_z));
  return check;
}

// Guide points along two walls of the unit square.
std::shared_ptr<const BirthGuide> Guide() {
  std::vector<Vec2> points;
  for (int i = 0; i <= 30; ++i) {
    points.emplace_back(0.1 + 0.8 * i / 30.0, 0.4);
    points.emplace_back(0.6, 0.05 + 0.9 * i / 30.0);
  }
  return std::make_shared<const BirthGuide>(points, 0.3, 0.03);
}

SamplerOptions PriorOptions() {
  SamplerOptions options;
  options.p = 1.0;
  options.birth_scale = 0.3;
  options.step_scales = {0.01, 0.05, 0.2};
  return options;
}

// The survival function against tables: the 5% points of 1 and 5 degrees of freedom, and the
// 1e-6 points of 6 and 10 (even and odd dof take different recurrences).
TEST(MoveFrequencies, ChiSquareSurvivalMatchesTheTables) {
  EXPECT_NEAR(ChiSquareSurvival(3.841459, 1), 0.05, 1e-6);
  EXPECT_NEAR(ChiSquareSurvival(11.070498, 5), 0.05, 1e-6);
  EXPECT_NEAR(ChiSquareSurvival(12.591587, 6), 0.05, 1e-6);
  EXPECT_NEAR(ChiSquareSurvival(46.863047, 10), 1e-6, 1e-10);
  EXPECT_NEAR(ChiSquareSurvival(0.0, 7), 1.0, 1e-12);
}

// The default weights (triangle 1, boundary triangle 1, corner 1, vertex 2, interior move 2,
// boundary move 1, recolor 0.5, local recolor 1, slide 1, guided triangle 3, and 0 for edge
// shifts, vertex jumps and vertex pairs) without a guide: the guided triangles' 3 counts as 0, so
// the shares are the weights over 10.5 (births and deaths 1/21 each for weight 1), and guided
// triangles, edge shifts, vertex jumps and vertex pairs are never proposed. The chain starts
// empty, where every death and vertex move is impossible, and grows: the shares do not depend on
// the state.
TEST(MoveFrequencies, DefaultWeightsWithoutAGuide) {
  const SamplerOptions options = PriorOptions();
  ASSERT_EQ(options.guide, nullptr);
  ASSERT_GT(options.weights[MoveKind::kGuidedTriangle], 0.0);
  PrfSampler sampler(Coloring(kUnit, 0.125), options, 20261121);
  constexpr std::uint64_t kSteps = 300000;
  sampler.Run(kSteps);
  const Shares shares = ExpectedShares(options.weights, false);
  EXPECT_NEAR(shares[static_cast<std::size_t>(MoveType::kTriangleBirth)], 1.0 / 21.0, 1e-15);
  EXPECT_NEAR(shares[static_cast<std::size_t>(MoveType::kInteriorMove)], 2.0 / 10.5, 1e-15);
  EXPECT_EQ(shares[static_cast<std::size_t>(MoveType::kGuidedTriangleBirth)], 0.0);
  ExpectProposalsFollow(sampler.counters(), shares, kSteps);
  // The chain did move: the shares held while the state changed.
  EXPECT_GT(Total(sampler.counters()).accepted, kSteps / 20);
}

// Uneven weights with zeros at the first kind (triangles) and in the middle (boundary moves),
// the guided triangles on (with a guide) and the kinds that are off by default on.
TEST(MoveFrequencies, UnevenWeightsWithZerosAndAGuide) {
  SamplerOptions options = PriorOptions();
  options.guide = Guide();
  options.vertex_jump_reach = 0.3;
  MoveWeights& w = options.weights;
  w[MoveKind::kTriangle] = 0.0;
  w[MoveKind::kBoundaryTriangle] = 0.5;
  w[MoveKind::kCorner] = 0.25;
  w[MoveKind::kVertex] = 3.0;
  w[MoveKind::kInteriorMove] = 1.5;
  w[MoveKind::kBoundaryMove] = 0.0;
  w[MoveKind::kRecolor] = 0.75;
  w[MoveKind::kLocalRecolor] = 2.0;
  w[MoveKind::kSlide] = 0.5;
  w[MoveKind::kGuidedTriangle] = 1.25;
  w[MoveKind::kEdgeShift] = 1.0;
  w[MoveKind::kVertexJump] = 0.4;
  w[MoveKind::kVertexPair] = 0.6;
  PrfSampler sampler(Coloring(kUnit, 0.125), options, 77);
  constexpr std::uint64_t kSteps = 300000;
  sampler.Run(kSteps);
  const Shares shares = ExpectedShares(options.weights, true);
  EXPECT_EQ(shares[static_cast<std::size_t>(MoveType::kTriangleBirth)], 0.0);
  EXPECT_EQ(shares[static_cast<std::size_t>(MoveType::kBoundaryMove)], 0.0);
  const FrequencyCheck check = ExpectProposalsFollow(sampler.counters(), shares, kSteps);
  EXPECT_EQ(check.dof, 15);  // 16 types with a positive share
  EXPECT_GT(Total(sampler.counters()).accepted, kSteps / 20);
}

// Only kinds that need edges or vertices (moves, recolors, slides, edge shifts, vertex jumps),
// from the empty coloring and with nothing that could add an edge: every proposal is impossible.
// Each is still counted as proposed, at the configured share (the choice is not redrawn among the
// moves the state allows, which would make the selection probability depend on the state and
// enter the Hastings ratio), and as invalid; nothing is accepted and the coloring stays empty.
// The last kind (vertex pairs) has weight 0 here.
TEST(MoveFrequencies, ImpossibleMovesAreCountedAtTheirShareAndAsInvalid) {
  SamplerOptions options = PriorOptions();
  options.weights.weight.fill(0.0);
  MoveWeights& w = options.weights;
  w[MoveKind::kInteriorMove] = 1.0;
  w[MoveKind::kBoundaryMove] = 2.0;
  w[MoveKind::kRecolor] = 0.5;
  w[MoveKind::kLocalRecolor] = 1.0;
  w[MoveKind::kSlide] = 3.0;
  w[MoveKind::kEdgeShift] = 1.5;
  w[MoveKind::kVertexJump] = 0.5;
  PrfSampler sampler(Coloring(kUnit, 0.125), options, 5);
  constexpr std::uint64_t kSteps = 1000000;
  sampler.Run(kSteps);
  const Shares shares = ExpectedShares(options.weights, false);
  EXPECT_NEAR(shares[static_cast<std::size_t>(MoveType::kSlide)], 3.0 / 9.5, 1e-15);
  ExpectProposalsFollow(sampler.counters(), shares, kSteps);
  for (int t = 0; t < kNumMoveTypes; ++t) {
    const MoveCounter& c = sampler.counters()[static_cast<std::size_t>(t)];
    EXPECT_EQ(c.invalid, c.proposed) << MoveTypeName(static_cast<MoveType>(t));
    EXPECT_EQ(c.accepted, 0u) << MoveTypeName(static_cast<MoveType>(t));
  }
  EXPECT_EQ(sampler.coloring().stats().edges, 0);
  EXPECT_EQ(sampler.steps(), kSteps);
}

// A guide without points is no guide: the guided triangles' weight counts as 0 and the other
// kinds share the steps as if it were absent.
TEST(MoveFrequencies, AnEmptyGuideSwitchesGuidedTrianglesOff) {
  SamplerOptions options = PriorOptions();
  options.guide = std::make_shared<const BirthGuide>(std::vector<Vec2>{}, 0.3, 0.03);
  PrfSampler sampler(Coloring(kUnit, 0.125), options, 31);
  constexpr std::uint64_t kSteps = 100000;
  sampler.Run(kSteps);
  ExpectProposalsFollow(sampler.counters(), ExpectedShares(options.weights, false), kSteps);
}

}  // namespace
}  // namespace priormap::prf
