// The posterior over association hypotheses (Parsley & Julier, Sec. V-A) on examples small
// enough to check by hand.
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/check.hpp>
#include <priormap/slam/association_hypotheses.hpp>

namespace priormap::slam {
namespace {

// Two points, two lines: point 1 gated with line A; point 2 with lines A and B. The pairs are
// independent (diagonal S, sigma 0.5 m) so that every probability is a product of numbers:
//  line A factors: no point 0.11 + 0.89 * 0.4^2 = 0.2524; one point 0.89 * 0.6 * 0.4 = 0.2136;
//                  both 0.89 * 0.6^2 = 0.3204;  line B: none 0.11 + 0.89 * 0.4 = 0.466; one 0.534;
//  likelihoods N(theta; 0, 0.25): 0.7821 (0.1 m), 0.7365 (0.2 m), 0.008864 (1.5 m).
HypothesisProblem TwoPointsTwoLines() {
  HypothesisProblem problem;
  problem.pairs = {{1, 0}, {2, 0}, {2, 1}};
  problem.theta = Eigen::Vector3d(0.1, 0.2, 1.5);
  problem.S = Eigen::Matrix3d::Identity() * 0.25;
  return problem;
}

double Normal(double x, double variance) {
  return std::exp(-0.5 * x * x / variance) / std::sqrt(2.0 * std::numbers::pi * variance);
}

// The paper's model: per-line priors, independent across lines, so point 2 may be on both.
StructurePriors PapersPriors() {
  StructurePriors priors;
  priors.one_line_per_point = false;
  return priors;
}

TEST(AssociationHypotheses, TwoPointsTwoLinesMatchesTheHandComputedPosterior) {
  const HypothesisProblem problem = TwoPointsTwoLines();
  const HypothesisPosterior posterior = EnumerateHypotheses(problem, PapersPriors());
  EXPECT_EQ(posterior.num_hypotheses, 8u);
  // Unnormalised: D = 000: 0.2524 * 0.466; D = 110: 0.3204 * 0.466 * 0.7821 * 0.7365; ...
  const double l1 = Normal(0.1, 0.25), l2 = Normal(0.2, 0.25), l3 = Normal(1.5, 0.25);
  const double a0 = 0.11 + 0.89 * 0.16, a1 = 0.89 * 0.6 * 0.4, a2 = 0.89 * 0.36;
  const double b0 = 0.11 + 0.89 * 0.4, b1 = 0.89 * 0.6;
  const double w[8] = {a0 * b0,           a0 * b1 * l3,          a1 * b0 * l2,
                       a1 * b1 * l2 * l3, a1 * b0 * l1,          a1 * b1 * l1 * l3,
                       a2 * b0 * l1 * l2, a2 * b1 * l1 * l2 * l3};  // D = (d1A d2A d2B) in binary
  double total = 0.0;
  for (double x : w) total += x;
  EXPECT_NEAR(posterior.map_probability, w[0] / total, 1e-12);
  EXPECT_NEAR(posterior.map_probability, 0.328187, 1e-6);  // by hand, see above
  EXPECT_EQ(posterior.map, (std::vector<bool>{false, false, false}));
  EXPECT_NEAR(posterior.marginals[0], (w[4] + w[5] + w[6] + w[7]) / total, 1e-12);
  EXPECT_NEAR(posterior.marginals[0], 0.461838, 1e-6);
  EXPECT_NEAR(posterior.marginals[1], 0.449060, 1e-6);
  EXPECT_NEAR(posterior.marginals[2], 0.010055, 1e-6);
  // One point on one line of a 1 m-noisy map cannot be decided: nothing exceeds p_accept.
  EXPECT_LT(posterior.map_probability, StructurePriors{}.p_accept);
}

// One line per point: the two hypotheses with point 2 on both A and B (D = 011, 111) have no
// mass, and the other six keep their weights, renormalised.
TEST(AssociationHypotheses, OneLinePerPointDropsTheHypothesesThatShareAPoint) {
  const HypothesisProblem problem = TwoPointsTwoLines();
  const HypothesisPosterior posterior = EnumerateHypotheses(problem, StructurePriors{});
  EXPECT_EQ(posterior.num_hypotheses, 6u);
  const double l1 = Normal(0.1, 0.25), l2 = Normal(0.2, 0.25), l3 = Normal(1.5, 0.25);
  const double a0 = 0.11 + 0.89 * 0.16, a1 = 0.89 * 0.6 * 0.4, a2 = 0.89 * 0.36;
  const double b0 = 0.11 + 0.89 * 0.4, b1 = 0.89 * 0.6;
  const double w000 = a0 * b0, w001 = a0 * b1 * l3, w010 = a1 * b0 * l2, w100 = a1 * b0 * l1,
               w101 = a1 * b1 * l1 * l3, w110 = a2 * b0 * l1 * l2;
  const double total = w000 + w001 + w010 + w100 + w101 + w110;
  EXPECT_NEAR(posterior.map_probability, w000 / total, 1e-12);
  EXPECT_NEAR(posterior.marginals[0], (w100 + w101 + w110) / total, 1e-12);
  EXPECT_NEAR(posterior.marginals[1], (w010 + w110) / total, 1e-12);
  EXPECT_NEAR(posterior.marginals[2], (w001 + w101) / total, 1e-12);
}

// A wall and a spurious copy of it 3 m out, three collinear points on the wall: under the
// paper's independent priors "on both" costs only the copy's offset, which its 1 m endpoint
// noise largely pays for, and each point is more likely than not on the copy too (0.6-0.7);
// with one line per point they go to the wall (> 0.95) and not to the copy (< 0.04).
TEST(AssociationHypotheses, OneLinePerPointKeepsPointsOffAParallelCopy) {
  HypothesisProblem problem;
  const std::vector<double> xs{0.0, 10.0, 20.0};
  const auto n = static_cast<Eigen::Index>(2 * xs.size());
  problem.S.resize(n, n);
  problem.theta.resize(n);
  // Rows 2i: point i with the wall (line 0), 2i+1: with the copy (line 1). Each line: offset
  // variance 1, slope variance 0.01; the point noise 0.05 m is shared by its two rows.
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < n; ++j) {
      const double xi = xs[i / 2], xj = xs[j / 2];
      const double line = i % 2 == j % 2 ? 1.0 + 0.01 * xi * xj : 0.0;
      problem.S(i, j) = line + (i / 2 == j / 2 ? 0.05 * 0.05 : 0.0);
    }
    problem.pairs.push_back({static_cast<int>(i / 2), static_cast<int>(i % 2)});
    problem.theta[i] = i % 2 == 0 ? 0.3 : -2.7;
  }
  StructurePriors priors;  // SlamOptions' null density
  priors.unrelated_density = 0.05;
  StructurePriors papers = priors;
  papers.one_line_per_point = false;
  const HypothesisPosterior exclusive = EnumerateHypotheses(problem, priors);
  const HypothesisPosterior independent = EnumerateHypotheses(problem, papers);
  for (Eigen::Index i = 0; i < n; i += 2) {
    EXPECT_GT(exclusive.marginals[i], 0.9) << i;
    EXPECT_LT(exclusive.marginals[i + 1], 0.05) << i;
    EXPECT_GT(independent.marginals[i + 1], 0.5) << i;
  }
}

// One level up the hierarchy (eq. 3): a point at a corner, gated with walls A and B of building
// 7 (independent, sigma 0.5 m, theta 0.1 and 0.3 m) and with a spurious line C of another
// structure. With one line per point, the probability that it lies on some wall of building 7 is
// the eq. (3) evidence: P(d_S = 1) p(theta | d_S = 1) over P(d_S = 1) p(theta | d_S = 1) plus
// the rest, with the mixture p(theta | d_S = 1) = sum_s p(theta_s | d_s = 1) p(d_s = 1 | d_S = 1).
TEST(AssociationHypotheses, StructureMarginalIsTheEvidenceOfTheEqThreeMixture) {
  HypothesisProblem problem;
  problem.pairs = {{4, 0, {7}}, {4, 1, {7}}, {4, 2, {9}}};
  problem.theta = Eigen::Vector3d(0.1, 0.3, 0.2);
  problem.S = Eigen::Matrix3d::Identity() * 0.25;
  problem.lines_known_real = {1};  // wall B has accepted relations
  const StructurePriors priors;    // one line per point, unrelated density 1 per metre
  const HypothesisPosterior posterior = EnumerateHypotheses(problem, priors);
  ASSERT_EQ(posterior.structure_marginals.size(), 1u);  // C is alone in its structure
  const StructureMarginal& marginal = posterior.structure_marginals[0];
  EXPECT_EQ(marginal.point, 4);
  EXPECT_EQ(marginal.structure, 7);
  EXPECT_EQ(marginal.pairs, (std::vector<int>{0, 1}));

  // By hand. A line with none of the point: q = 1 - p_real * 0.6, so q_A = q_C = 0.466, q_B = 0.4;
  // "on s" has prior p_real(s) 0.6 prod_{t != s} q_t and the other pairs' null density 1.
  const double qa = 1 - 0.89 * 0.6, qb = 1 - 0.6, qc = qa;
  const double on_a = 0.89 * 0.6 * qb * qc, on_b = 1.0 * 0.6 * qa * qc, on_c = 0.89 * 0.6 * qa * qb;
  const double none = qa * qb * qc;
  const double la = Normal(0.1, 0.25), lb = Normal(0.3, 0.25), lc = Normal(0.2, 0.25);
  // Eq. (3): P(d_S = 1) = on_a + on_b, weights p(d_s = 1 | d_S = 1) = on_s / (on_a + on_b).
  const double p_structure = on_a + on_b;
  const double mixture = (on_a / p_structure) * la + (on_b / p_structure) * lb;
  const double evidence = p_structure * mixture;
  EXPECT_NEAR(marginal.probability, evidence / (evidence + on_c * lc + none), 1e-12);
  // The mixture's weights, as the filter applies them.
  ASSERT_EQ(marginal.weights.size(), 2u);
  EXPECT_NEAR(marginal.weights[0], on_a / p_structure, 1e-12);
  EXPECT_NEAR(marginal.weights[1], on_b / p_structure, 1e-12);
  // Exclusive events: the sum of the walls' marginals.
  EXPECT_NEAR(marginal.probability, posterior.marginals[0] + posterior.marginals[1], 1e-12);
}

// A point at a corner gated with two walls of one building, both known to be real: the case
// where p_point_on_line = 1 made the eq. (3) weights p_real / (1 - p_real p_point_on_line)
// infinite and then NaN. Near the bounds every number stays finite; at them the priors are
// refused.
TEST(AssociationHypotheses, PointOnLineIsAProbabilityStrictlyBetweenZeroAndOne) {
  HypothesisProblem problem;
  problem.pairs = {{4, 0, {7}}, {4, 1, {7}}};
  problem.theta = Eigen::Vector2d(0.1, 0.3);
  problem.S = Eigen::Matrix2d::Identity() * 0.25;
  problem.lines_known_real = {0, 1};
  for (double p : {1e-12, 0.5, 1.0 - 1e-12}) {
    SCOPED_TRACE(p);
    StructurePriors priors;
    priors.p_point_on_line = p;
    ASSERT_TRUE(ArePriorsValid(priors));
    const HypothesisPosterior posterior = EnumerateHypotheses(problem, priors);
    EXPECT_TRUE(std::isfinite(posterior.map_probability));
    for (double m : posterior.marginals) EXPECT_TRUE(std::isfinite(m));
    ASSERT_EQ(posterior.structure_marginals.size(), 1u);
    EXPECT_TRUE(std::isfinite(posterior.structure_marginals[0].probability));
    for (double w : posterior.structure_marginals[0].weights) {
      EXPECT_TRUE(std::isfinite(w));
      EXPECT_GT(w, 0.0);
    }
  }
  for (double p : {0.0, 1.0, -0.1, 1.5, std::numeric_limits<double>::quiet_NaN()}) {
    SCOPED_TRACE(p);
    StructurePriors priors;
    priors.p_point_on_line = p;
    EXPECT_FALSE(ArePriorsValid(priors));
    EXPECT_THROW((void)EnumerateHypotheses(problem, priors), ContractError);
  }
  for (double p : {0.0, 1.0}) {  // the bounds of the other probabilities are valid
    StructurePriors priors;
    priors.p_line_real = p;
    priors.p_accept = p;
    EXPECT_TRUE(ArePriorsValid(priors)) << p;
    EXPECT_NO_THROW((void)EnumerateHypotheses(problem, priors)) << p;
  }
  StructurePriors priors;
  priors.p_line_real = 1.5;
  EXPECT_FALSE(ArePriorsValid(priors));
  priors = {};
  priors.p_accept = -0.5;
  EXPECT_FALSE(ArePriorsValid(priors));
}

// A wall that buildings 7 and 9 share (line 0) is some wall of each: a point gated with it and
// with one other wall of each building has a marginal per building, each the sum of its two
// walls' marginals (one line per point), and the shared line is in both.
TEST(AssociationHypotheses, ALineOfTwoStructuresCountsForEach) {
  HypothesisProblem problem;
  problem.pairs = {{4, 0, {7, 9}}, {4, 1, {7}}, {4, 2, {9}}};
  problem.theta = Eigen::Vector3d(0.1, 0.3, 0.2);
  problem.S = Eigen::Matrix3d::Identity() * 0.25;
  const HypothesisPosterior posterior = EnumerateHypotheses(problem, StructurePriors{});
  ASSERT_EQ(posterior.structure_marginals.size(), 2u);
  const std::vector<double>& m = posterior.marginals;
  for (const auto& [k, structure, other] : {std::tuple{0, 7, 1}, std::tuple{1, 9, 2}}) {
    const StructureMarginal& marginal = posterior.structure_marginals[k];
    EXPECT_EQ(marginal.point, 4);
    EXPECT_EQ(marginal.structure, structure);
    EXPECT_EQ(marginal.pairs, (std::vector<int>{0, other}));
    EXPECT_NEAR(marginal.probability, m[0] + m[other], 1e-12);
    // Lines 0 and `other` have the same prior and null density: equal weights.
    EXPECT_NEAR(marginal.weights[0], 0.5, 1e-12);
  }
  // Naming the line's structures does not change the wall-level posterior.
  HypothesisProblem first_only = problem;
  first_only.pairs[0].structures = {7};
  const HypothesisPosterior before = EnumerateHypotheses(first_only, StructurePriors{});
  EXPECT_EQ(before.marginals, posterior.marginals);
  ASSERT_EQ(before.structure_marginals.size(), 1u);  // building 9 has one wall left: no marginal
  EXPECT_EQ(before.structure_marginals[0].structure, 7);
}

// Without one line per point the events overlap; the structure marginal counts each hypothesis
// once (the probability of "on A or on B", not the sum).
TEST(AssociationHypotheses, StructureMarginalCountsOverlappingHypothesesOnce) {
  HypothesisProblem problem;
  problem.pairs = {{4, 0, {7}}, {4, 1, {7}}};
  problem.theta = Eigen::Vector2d(0.1, 0.3);
  problem.S = Eigen::Matrix2d::Identity() * 0.25;
  const HypothesisPosterior posterior = EnumerateHypotheses(problem, PapersPriors());
  ASSERT_EQ(posterior.structure_marginals.size(), 1u);
  const double qa = 1 - 0.89 * 0.6;
  const double la = Normal(0.1, 0.25), lb = Normal(0.3, 0.25);
  const double a = 0.89 * 0.6, none = qa * qa;
  const double w_a = a * qa * la, w_b = qa * a * lb, w_ab = a * a * la * lb;
  EXPECT_NEAR(posterior.structure_marginals[0].probability,
              (w_a + w_b + w_ab) / (w_a + w_b + w_ab + none), 1e-12);
  EXPECT_GT(posterior.marginals[0] + posterior.marginals[1],
            posterior.structure_marginals[0].probability);
}

// With a null density per pair, a wall whose pair is less likely unrelated weighs more: the
// weights are "on s, not on the others" over "on none", so each divides by its own null density.
TEST(AssociationHypotheses, StructureWeightsFollowThePairsNullDensities) {
  HypothesisProblem problem;
  problem.pairs = {{4, 0, {7}}, {4, 1, {7}}};
  problem.theta = Eigen::Vector2d(0.1, 0.3);
  problem.S = Eigen::Matrix2d::Identity() * 0.25;
  problem.null_density = {0.2, 0.05};
  const HypothesisPosterior posterior = EnumerateHypotheses(problem, StructurePriors{});
  ASSERT_EQ(posterior.structure_marginals.size(), 1u);
  const auto& weights = posterior.structure_marginals[0].weights;
  // Both lines have the same prior, so the weights go as 1 / null: 0.05 : 0.2.
  EXPECT_NEAR(weights[0], 0.05 / 0.25, 1e-12);
  EXPECT_NEAR(weights[1], 0.2 / 0.25, 1e-12);
  // And they are the enumeration's own: P(on A) / P(on B) = w_A N_A / (w_B N_B).
  const double la = Normal(0.1, 0.25), lb = Normal(0.3, 0.25);
  EXPECT_NEAR(posterior.marginals[0] / posterior.marginals[1], weights[0] * la / (weights[1] * lb),
              1e-12);
}

TEST(AssociationHypotheses, LogPriorIsThePapersProductOverLines) {
  const HypothesisProblem problem = TwoPointsTwoLines();
  const StructurePriors priors;
  EXPECT_NEAR(LogHypothesisPrior(problem, {true, true, false}, priors),
              std::log(0.89 * 0.36 * (0.11 + 0.89 * 0.4)), 1e-12);
  EXPECT_NEAR(LogHypothesisPrior(problem, {false, false, true}, priors),
              std::log((0.11 + 0.89 * 0.16) * 0.89 * 0.6), 1e-12);
  // Priors over all hypotheses sum to one.
  double sum = 0.0;
  for (int bits = 0; bits < 8; ++bits) {
    sum += std::exp(
        LogHypothesisPrior(problem, {(bits & 4) != 0, (bits & 2) != 0, (bits & 1) != 0}, priors));
  }
  EXPECT_NEAR(sum, 1.0, 1e-12);
}

TEST(AssociationHypotheses, KnownRealLineDropsTheSpuriousTerm) {
  HypothesisProblem problem;
  problem.pairs = {{7, 3}};
  problem.theta = Eigen::VectorXd::Constant(1, 0.0);
  problem.S = Eigen::MatrixXd::Constant(1, 1, 0.01);
  problem.lines_known_real = {3};
  const HypothesisPosterior posterior = EnumerateHypotheses(problem, StructurePriors{});
  // 0.6 N(0; 0, 0.01) against 0.4 * 1.
  const double on = 0.6 * Normal(0.0, 0.01);
  EXPECT_NEAR(posterior.marginals[0], on / (on + 0.4), 1e-12);
  EXPECT_EQ(posterior.map, std::vector<bool>{true});
}

// Collinear points on one uncertain line: their thetas share the line's offset and slope errors,
// so once two points fix the line, each further point on it is strong evidence. Built from a
// line y = c + s x with c ~ N(0, 1), s ~ N(0, 0.1^2) and points at x = -10 .. 30 with 0.01 m noise
// (landmarks after a few dozen observations). With 0.05 m the null hypothesis still wins: the
// paper's uninformative p(theta | d = 0) = 1 per metre asks for points well localised.
TEST(AssociationHypotheses, CorrelatedCollinearPointsAreAcceptedAndAnOffsetOneIsNot) {
  const std::vector<double> xs{-10.0, 0.0, 10.0, 20.0, 30.0};
  const double point_var = 0.01 * 0.01;
  HypothesisProblem problem;
  const auto n = static_cast<Eigen::Index>(xs.size());
  problem.S.resize(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    problem.pairs.push_back({static_cast<int>(i), 0});
    for (Eigen::Index j = 0; j < n; ++j) {
      problem.S(i, j) = 1.0 + 0.01 * xs[i] * xs[j] + (i == j ? point_var : 0.0);
    }
  }
  // The truth: line at 0.8 + 0.02 x; points 0-3 on it, point 4 is 1.5 m off.
  problem.theta.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) problem.theta[i] = 0.8 + 0.02 * xs[i];
  problem.theta[4] += 1.5;
  const HypothesisPosterior posterior = EnumerateHypotheses(problem, StructurePriors{});
  EXPECT_EQ(posterior.num_hypotheses, 32u);
  EXPECT_EQ(posterior.map, (std::vector<bool>{true, true, true, true, false}));
  EXPECT_GT(posterior.map_probability, 0.7);
  EXPECT_LT(posterior.marginals[4], 0.01);
}

}  // namespace
}  // namespace priormap::slam
