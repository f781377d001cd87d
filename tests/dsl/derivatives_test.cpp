// The acceptance test of the priorlet compiler (issue 3): for every prior of priors/, every block
// and every term, the gradients and Hessians that BlockEvaluator returns match central finite
// differences at 1,000 random configurations; values match a direct evaluation written by hand;
// and leaving outputs out (null gradients / Hessians) changes nothing else.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/dsl/prior.hpp>
#include <priormap/dsl/prior_library.hpp>

#include "testing/numeric_diff.hpp"

namespace priormap::dsl {
namespace {

namespace fs = std::filesystem;
using priormap::testing::JacobiansMatch;
using priormap::testing::NumericJacobian;

constexpr int kPointsPerPrior = 1000;
constexpr double kStep = 1e-5;       // finite-difference step (rho in metres, alpha in radians)
constexpr double kTolerance = 1e-6;  // relative to max(1, largest finite-difference entry)

// The files of priors/ by stem. The list is written out (and checked against the directory
// below) so that a new prior is added here consciously, with a guard if it has kinks.
const std::vector<std::string>& PriorStems() {
  static const std::vector<std::string> stems = {
      "circular",  "circular-radius",     "manhattan",           "octagonal",
      "polygonal", "rectangular",         "rectangular-relaxed", "rectangular-relaxed-alternative",
      "splines",   "straight-or-circular"};
  return stems;
}

// A configuration of a block: x = (rho_1..rho_k, alpha_1..alpha_k) and phi_1..phi_k.
struct Point {
  Eigen::VectorXd x;
  std::vector<double> phi;
};

// How points are picked, away from the places where a term is not smooth:
//  - rho_i uniform in [0.5, 5] m;
//  - phi_i sorted in [-pi/2, pi/2] with neighbouring beams at least 0.2 rad apart, so that the
//    points p_i = rho_i (cos phi_i, sin phi_i) are at least 0.5 sin(0.2) ~ 0.1 m apart and
//    norm(p_i - p_j) (circular priors) is smooth and well away from its kink at 0;
//  - alpha_i uniform in [-pi, pi] (the language does no wrapping; every term is smooth in alpha
//    except where a guard below says otherwise).
// Disjunctions need no care: each branch is its own Term, smooth on its own; the engine's
// "smallest branch" switch is not part of the compiled terms. No built-in prior uses min or max.
// Priors with abs() get a guard (KinkGuards) that rejects points near its switch; rejected
// points are resampled.
Point RandomPoint(Rng& rng, int order) {
  Point p;
  p.x.resize(2 * order);
  p.phi.resize(static_cast<std::size_t>(order));
  for (;;) {
    for (double& phi : p.phi) phi = rng.Uniform(-kPi / 2, kPi / 2);
    std::sort(p.phi.begin(), p.phi.end());
    bool separated = true;
    for (std::size_t i = 1; i < p.phi.size(); ++i)
      separated = separated && p.phi[i] - p.phi[i - 1] >= 0.2;
    if (separated) break;
  }
  for (int i = 0; i < order; ++i) {
    p.x[i] = rng.Uniform(0.5, 5.0);
    p.x[order + i] = rng.Uniform(-kPi, kPi);
  }
  return p;
}

using Guard = std::function<bool(const Point&)>;

// Per prior, whether a point is far enough from the non-smooth places of its terms.
//  - circular-radius: its energy uses the curvature 2 abs(r13), where
//    r13 = sin((alpha_3 - alpha_1)/2) / |p_3 - p_1|. abs switches where
//    sin((alpha_3 - alpha_1)/2) = 0. Keeping |sin(...)| >= 0.05 keeps the finite-difference
//    stencil on one side of the switch.
const std::map<std::string, Guard>& KinkGuards() {
  static const std::map<std::string, Guard> guards = {
      {"circular-radius",
       [](const Point& p) { return std::abs(std::sin((p.x[5] - p.x[3]) / 2)) >= 0.05; }},
  };
  return guards;
}

std::span<const double> Span(const Eigen::VectorXd& v) {
  return {v.data(), static_cast<std::size_t>(v.size())};
}

// Evaluates a block into Eigen vectors; a fresh evaluator per call would hide caching bugs, so
// one evaluator is reused.
class Evaluation {
 public:
  explicit Evaluation(const CompiledBlock& block) : block_(block), evaluator_(block) {}

  Eigen::VectorXd Values(const Eigen::VectorXd& x, const std::vector<double>& phi) {
    Eigen::VectorXd values(block_.num_terms());
    evaluator_.Evaluate(Span(x), phi, values.data());
    return values;
  }
  // Gradients of all terms, term after term (num_terms * num_variables).
  Eigen::VectorXd Gradients(const Eigen::VectorXd& x, const std::vector<double>& phi) {
    Eigen::VectorXd values(block_.num_terms());
    Eigen::VectorXd gradients(block_.num_terms() * block_.num_variables());
    evaluator_.Evaluate(Span(x), phi, values.data(), gradients.data());
    return gradients;
  }
  void All(const Eigen::VectorXd& x, const std::vector<double>& phi, Eigen::VectorXd& values,
           Eigen::VectorXd& gradients, Eigen::VectorXd& hessians) {
    const int nt = block_.num_terms(), nv = block_.num_variables();
    values.resize(nt);
    gradients.resize(nt * nv);
    hessians.resize(nt * nv * nv);
    evaluator_.Evaluate(Span(x), phi, values.data(), gradients.data(), hessians.data());
  }

 private:
  const CompiledBlock& block_;
  BlockEvaluator evaluator_;
};

std::string Describe(const CompiledBlock& block, int t, const Point& p) {
  std::ostringstream text;
  text << ToString(block.kind()) << " term " << t << " '"
       << block.terms()[static_cast<std::size_t>(t)].source << "' at";
  for (int v = 0; v < block.num_variables(); ++v)
    text << " " << block.VariableName(v) << "=" << p.x[v];
  for (std::size_t i = 0; i < p.phi.size(); ++i) text << " phi_" << i + 1 << "=" << p.phi[i];
  return text.str();
}

CompiledPrior LoadBuiltin(const std::string& stem) {
  Result<CompiledPrior> prior = PriorLibrary().Load(stem);
  if (!prior) ADD_FAILURE() << stem << ": " << prior.error();
  return std::move(prior).value();
}

TEST(PriorDerivatives, TheCheckedListIsEveryFileOfThePriorsDirectory) {
  std::set<std::string> stems;
  for (const auto& entry : fs::directory_iterator(PRIORMAP_PRIORS_DIR)) {
    if (entry.path().extension() == ".prior") stems.insert(entry.path().stem().string());
  }
  EXPECT_EQ(stems, std::set<std::string>(PriorStems().begin(), PriorStems().end()));
  EXPECT_EQ(stems.size(), 10u);
}

// The terms of `block` whose value, gradient or Hessian at `p` is not finite, or whose gradient
// and Hessian do not match central differences (of the values for the gradients, of the compiled
// gradients for the Hessians), or whose Hessian is not symmetric; each is reported, after
// `label`.
int DerivativeMismatches(Evaluation& evaluation, const CompiledBlock& block, const Point& p,
                         const std::string& label) {
  const int nt = block.num_terms(), nv = block.num_variables();
  Eigen::VectorXd values, gradients, hessians;
  evaluation.All(p.x, p.phi, values, gradients, hessians);
  const Eigen::MatrixXd numeric_gradients = NumericJacobian(
      [&](const Eigen::VectorXd& x) { return evaluation.Values(x, p.phi); }, p.x, kStep);
  const Eigen::MatrixXd numeric_hessians = NumericJacobian(
      [&](const Eigen::VectorXd& x) { return evaluation.Gradients(x, p.phi); }, p.x, kStep);
  int failures = 0;
  for (int t = 0; t < nt; ++t) {
    const Eigen::MatrixXd gradient = gradients.segment(t * nv, nv).transpose();
    const Eigen::MatrixXd hessian = Eigen::Map<const Eigen::MatrixXd>(
        hessians.data() + static_cast<std::ptrdiff_t>(t) * nv * nv, nv, nv);
    const bool finite = std::isfinite(values[t]) && gradient.allFinite() && hessian.allFinite();
    const auto gradient_match = JacobiansMatch(gradient, numeric_gradients.row(t), kTolerance);
    const auto hessian_match =
        JacobiansMatch(hessian, numeric_hessians.middleRows(t * nv, nv), kTolerance);
    const bool symmetric = hessian == hessian.transpose();
    if (finite && gradient_match && hessian_match && symmetric) continue;
    ++failures;
    ADD_FAILURE() << label << Describe(block, t, p) << "\nvalue " << values[t]
                  << (symmetric ? "" : "\nHessian not symmetric")
                  << "\ngradient: " << gradient_match.message()
                  << "\nHessian: " << hessian_match.message();
  }
  return failures;
}

class EveryBuiltinPrior : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryBuiltinPrior, GradientsAndHessiansMatchCentralDifferencesAtRandomPoints) {
  const CompiledPrior prior = LoadBuiltin(GetParam());
  const auto guard = KinkGuards().find(GetParam());
  int blocks = 0;
  for (int b = 0; b < kNumBlockKinds; ++b) {
    const CompiledBlock* block = prior.block(static_cast<BlockKind>(b));
    if (!block) continue;
    ++blocks;
    const int nt = block->num_terms(), nv = block->num_variables();
    ASSERT_GT(nt, 0);
    ASSERT_EQ(nv, 2 * prior.order());
    Evaluation evaluation(*block);
    Rng rng(1000 + static_cast<std::uint64_t>(b));
    int failures = 0, rejected = 0;
    for (int n = 0; n < kPointsPerPrior && failures < 5; ++n) {
      Point p = RandomPoint(rng, prior.order());
      while (guard != KinkGuards().end() && !guard->second(p)) {
        ++rejected;
        p = RandomPoint(rng, prior.order());
      }
      failures += DerivativeMismatches(evaluation, *block, p, GetParam() + ": ");
    }
    // The guards reject a small part of the space only: the test still covers it.
    EXPECT_LT(rejected, kPointsPerPrior / 5) << ToString(block->kind());
  }
  EXPECT_GT(blocks, 0);
}

TEST_P(EveryBuiltinPrior, NullOutputsLeaveTheOtherOutputsUnchanged) {
  const CompiledPrior prior = LoadBuiltin(GetParam());
  Rng rng(7);
  for (int b = 0; b < kNumBlockKinds; ++b) {
    const CompiledBlock* block = prior.block(static_cast<BlockKind>(b));
    if (!block) continue;
    const std::size_t nt = static_cast<std::size_t>(block->num_terms());
    const std::size_t nv = static_cast<std::size_t>(block->num_variables());
    BlockEvaluator full(*block), partial(*block);
    for (int n = 0; n < 20; ++n) {
      Point p = RandomPoint(rng, prior.order());
      if (const auto guard = KinkGuards().find(GetParam());
          guard != KinkGuards().end() && !guard->second(p))
        continue;
      std::vector<double> values(nt), gradients(nt * nv), hessians(nt * nv * nv);
      full.Evaluate(Span(p.x), p.phi, values.data(), gradients.data(), hessians.data());

      std::vector<double> only_values(nt, -1.0);
      partial.Evaluate(Span(p.x), p.phi, only_values.data());
      EXPECT_EQ(only_values, values);

      std::vector<double> values_gradients(nt, -1.0), only_gradients(nt * nv, -1.0);
      partial.Evaluate(Span(p.x), p.phi, values_gradients.data(), only_gradients.data());
      EXPECT_EQ(values_gradients, values);
      EXPECT_EQ(only_gradients, gradients);

      // Values left out while derivatives are asked for.
      std::vector<double> no_values_gradients(nt * nv, -1.0),
          no_values_hessians(nt * nv * nv, -1.0);
      partial.Evaluate(Span(p.x), p.phi, nullptr, no_values_gradients.data(),
                       no_values_hessians.data());
      EXPECT_EQ(no_values_gradients, gradients);
      EXPECT_EQ(no_values_hessians, hessians);

      std::vector<double> no_gradients_hessians(nt * nv * nv, -1.0), no_gradients_values(nt, -1.0);
      partial.Evaluate(Span(p.x), p.phi, no_gradients_values.data(), nullptr,
                       no_gradients_hessians.data());
      EXPECT_EQ(no_gradients_values, values);
      EXPECT_EQ(no_gradients_hessians, hessians);
    }
  }
}

// EvaluateBatch (several points per instruction) gives what Evaluate gives point by point, also
// for a count that is not a multiple of its lane width and with outputs left out.
TEST_P(EveryBuiltinPrior, BatchEvaluationMatchesPointByPointEvaluation) {
  const CompiledPrior prior = LoadBuiltin(GetParam());
  const auto guard = KinkGuards().find(GetParam());
  Rng rng(11);
  for (int b = 0; b < kNumBlockKinds; ++b) {
    const CompiledBlock* block = prior.block(static_cast<BlockKind>(b));
    if (!block) continue;
    const std::size_t nt = static_cast<std::size_t>(block->num_terms());
    const std::size_t nv = static_cast<std::size_t>(block->num_variables());
    for (const std::size_t count : {std::size_t{1}, std::size_t{13}}) {
      std::vector<double> xs, phis, values(count * nt), gradients(count * nt * nv),
          hessians(count * nt * nv * nv);
      BlockEvaluator single(*block);
      for (std::size_t n = 0; n < count; ++n) {
        Point p = RandomPoint(rng, prior.order());
        while (guard != KinkGuards().end() && !guard->second(p))
          p = RandomPoint(rng, prior.order());
        xs.insert(xs.end(), p.x.data(), p.x.data() + p.x.size());
        phis.insert(phis.end(), p.phi.begin(), p.phi.end());
        single.Evaluate(Span(p.x), p.phi, values.data() + n * nt, gradients.data() + n * nt * nv,
                        hessians.data() + n * nt * nv * nv);
      }
      BlockEvaluator batch(*block);
      std::vector<double> batch_values(count * nt), batch_gradients(count * nt * nv),
          batch_hessians(count * nt * nv * nv);
      batch.EvaluateBatch(count, xs, phis, batch_values.data(), batch_gradients.data(),
                          batch_hessians.data());
      EXPECT_THAT(batch_values, ::testing::Pointwise(::testing::DoubleEq(), values))
          << ToString(block->kind());
      EXPECT_THAT(batch_gradients, ::testing::Pointwise(::testing::DoubleEq(), gradients));
      EXPECT_THAT(batch_hessians, ::testing::Pointwise(::testing::DoubleEq(), hessians));

      std::vector<double> only_values(count * nt, -1.0);
      batch.EvaluateBatch(count, xs, phis, only_values.data());
      EXPECT_EQ(only_values, batch_values);
      std::vector<double> only_gradients(count * nt * nv, -1.0);
      batch.EvaluateBatch(count, xs, phis, nullptr, only_gradients.data());
      EXPECT_EQ(only_gradients, batch_gradients);
    }
  }
}

// "rectangular-relaxed" -> "rectangular_relaxed" (test names are identifiers).
std::string TestName(const ::testing::TestParamInfo<std::string>& param_info) {
  std::string name = param_info.param;
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
}

INSTANTIATE_TEST_SUITE_P(PriorsDirectory, EveryBuiltinPrior, ::testing::ValuesIn(PriorStems()),
                         TestName);

// --- values against formulas written out by hand (no expression graph involved) ---------------

struct Configuration {
  std::vector<double> rho, alpha, phi;
  [[nodiscard]] Eigen::VectorXd X() const {
    Eigen::VectorXd x(static_cast<Eigen::Index>(rho.size() + alpha.size()));
    for (std::size_t i = 0; i < rho.size(); ++i) x[static_cast<Eigen::Index>(i)] = rho[i];
    for (std::size_t i = 0; i < alpha.size(); ++i)
      x[static_cast<Eigen::Index>(rho.size() + i)] = alpha[i];
    return x;
  }
};

struct Evaluated {
  std::vector<double> values, gradients;
};

Evaluated EvaluateBuiltin(const std::string& stem, BlockKind kind, const Configuration& c) {
  const CompiledPrior prior = LoadBuiltin(stem);
  const CompiledBlock* block = prior.block(kind);
  EXPECT_NE(block, nullptr) << stem << " " << ToString(kind);
  if (!block) return {};
  BlockEvaluator evaluator(*block);
  Evaluated out;
  out.values.resize(static_cast<std::size_t>(block->num_terms()));
  out.gradients.resize(static_cast<std::size_t>(block->num_terms() * block->num_variables()));
  const Eigen::VectorXd x = c.X();
  evaluator.Evaluate(Span(x), c.phi, out.values.data(), out.gradients.data());
  return out;
}

constexpr double kExact = 1e-12;

TEST(PriorValues, PolygonalSameRegionIsTheNormalDifferenceAndTheDistanceAlongTheNormal) {
  // p_1 = (1, 0), p_2 = 2 (cos 0.5, sin 0.5); normal of point 1 at alpha_1 = 0.3.
  const Configuration c{{1.0, 2.0}, {0.3, -0.1}, {0.0, 0.5}};
  const Evaluated e = EvaluateBuiltin("polygonal", BlockKind::kSameRegion, c);
  ASSERT_EQ(e.values.size(), 2u);
  EXPECT_NEAR(e.values[0], 0.3 - (-0.1), kExact);
  const double dx = 2.0 * std::cos(0.5) - 1.0, dy = 2.0 * std::sin(0.5);
  EXPECT_NEAR(e.values[1], dx * std::cos(0.3) + dy * std::sin(0.3), kExact);
  // d/drho_1 of (p_2 - p_1)' n(alpha_1) is -(cos phi_1, sin phi_1)' n = -cos(phi_1 - alpha_1);
  // d/drho_2 is cos(phi_2 - alpha_1); d/dalpha_1 is (p_2 - p_1)' (-sin alpha_1, cos alpha_1).
  ASSERT_EQ(e.gradients.size(), 8u);
  EXPECT_THAT(std::vector<double>(e.gradients.begin(), e.gradients.begin() + 4),
              ::testing::ElementsAre(0.0, 0.0, 1.0, -1.0));
  EXPECT_NEAR(e.gradients[4], -std::cos(0.0 - 0.3), kExact);
  EXPECT_NEAR(e.gradients[5], std::cos(0.5 - 0.3), kExact);
  EXPECT_NEAR(e.gradients[6], -dx * std::sin(0.3) + dy * std::cos(0.3), kExact);
  EXPECT_EQ(e.gradients[7], 0.0);
}

TEST(PriorValues, PolygonalSameRegionVanishesOnAStraightWall) {
  // The wall x = 2 seen at -0.4 and 0.3 rad: both points on it, normal (1, 0).
  const double phi_1 = -0.4, phi_2 = 0.3;
  const Configuration c{{2.0 / std::cos(phi_1), 2.0 / std::cos(phi_2)}, {0.0, 0.0}, {phi_1, phi_2}};
  const Evaluated e = EvaluateBuiltin("polygonal", BlockKind::kSameRegion, c);
  ASSERT_EQ(e.values.size(), 2u);
  EXPECT_NEAR(e.values[0], 0.0, kExact);
  EXPECT_NEAR(e.values[1], 0.0, kExact);
}

TEST(PriorValues, RectangularDifferentRegionBranchesAreTheTwoRightAngles) {
  const Configuration c{{1.0, 1.5}, {0.2, 1.9}, {-0.1, 0.1}};
  const Evaluated e = EvaluateBuiltin("rectangular", BlockKind::kDifferentRegion, c);
  ASSERT_EQ(e.values.size(), 2u);
  EXPECT_NEAR(e.values[0], 1.9 - (0.2 - kPi / 2), kExact);
  EXPECT_NEAR(e.values[1], 1.9 - (0.2 + kPi / 2), kExact);
}

TEST(PriorValues, RelaxedRectangularInequalitiesBoundTheCosineOfTheAngle) {
  const double d = 1.4;
  const Configuration c{{1.0, 1.5}, {0.3, 0.3 + d}, {-0.1, 0.1}};
  const Evaluated e = EvaluateBuiltin("rectangular-relaxed", BlockKind::kDifferentRegion, c);
  ASSERT_EQ(e.values.size(), 2u);
  EXPECT_NEAR(e.values[0], std::cos(d) - std::cos(87 * kPi / 180), kExact);
  EXPECT_NEAR(e.values[1], -std::cos(d) + std::cos(93 * kPi / 180), kExact);
}

TEST(PriorValues, EnergiesAreTheExpressionAsWritten) {
  const Configuration c{{1.0, 1.5}, {0.3, 1.1}, {-0.1, 0.1}};
  const Evaluated alternative =
      EvaluateBuiltin("rectangular-relaxed-alternative", BlockKind::kDifferentRegion, c);
  ASSERT_EQ(alternative.values.size(), 1u);
  EXPECT_NEAR(alternative.values[0], std::pow(std::cos(0.8), 2), kExact);
  // The splines prior: the bending energy stiffness * (alpha_2 - alpha_1)^2 / |p_2 - p_1|,
  // then the chord perpendicular to the mean normal.
  const Evaluated splines = EvaluateBuiltin("splines", BlockKind::kSameRegion, c);
  ASSERT_EQ(splines.values.size(), 2u);
  const double chord_x = 1.5 * std::cos(0.1) - 1.0 * std::cos(-0.1);
  const double chord_y = 1.5 * std::sin(0.1) - 1.0 * std::sin(-0.1);
  const double chord = std::hypot(chord_x, chord_y);
  EXPECT_NEAR(splines.values[0], 1000 * 0.8 * 0.8 / chord, 1e-9);
  EXPECT_NEAR(splines.gradients[2], -1000 * 2 * 0.8 / chord, 1e-9);
  EXPECT_NEAR(splines.gradients[3], 1000 * 2 * 0.8 / chord, 1e-9);
  EXPECT_NEAR(splines.values[1], chord_x * std::cos(0.7) + chord_y * std::sin(0.7), kExact);
}

// r_ij = sin((alpha_j - alpha_i)/2) / |p_i - p_j| for the circular priors.
double HalfCurvature(const Configuration& c, std::size_t i, std::size_t j) {
  const double xi = c.rho[i] * std::cos(c.phi[i]), yi = c.rho[i] * std::sin(c.phi[i]);
  const double xj = c.rho[j] * std::cos(c.phi[j]), yj = c.rho[j] * std::sin(c.phi[j]);
  return std::sin((c.alpha[j] - c.alpha[i]) / 2) / std::hypot(xi - xj, yi - yj);
}

TEST(PriorValues, CircularSameRegionComparesTheHalfCurvaturesOfThePairs) {
  const Configuration c{{2.0, 2.5, 3.0}, {0.1, 0.5, 1.2}, {-0.3, 0.0, 0.4}};
  const Evaluated e = EvaluateBuiltin("circular", BlockKind::kSameRegion, c);
  ASSERT_EQ(e.values.size(), 3u);
  const double r12 = HalfCurvature(c, 0, 1), r23 = HalfCurvature(c, 1, 2),
               r13 = HalfCurvature(c, 0, 2);
  EXPECT_NEAR(e.values[0], r12 - r23, kExact);
  EXPECT_NEAR(e.values[1], r23 - r13, kExact);
  // The chord p_1 p_3 against the mean normal of its ends.
  const double mean_normal = (c.alpha[0] + c.alpha[2]) / 2;
  const double chord_x = c.rho[2] * std::cos(c.phi[2]) - c.rho[0] * std::cos(c.phi[0]);
  const double chord_y = c.rho[2] * std::sin(c.phi[2]) - c.rho[0] * std::sin(c.phi[0]);
  EXPECT_NEAR(e.values[2], chord_x * std::cos(mean_normal) + chord_y * std::sin(mean_normal),
              kExact);

  const Evaluated radius = EvaluateBuiltin("circular-radius", BlockKind::kSameRegion, c);
  ASSERT_EQ(radius.values.size(), 4u);
  EXPECT_NEAR(radius.values[0], r12 - r23, kExact);
  EXPECT_NEAR(radius.values[1], r23 - r13, kExact);
  EXPECT_NEAR(radius.values[2], e.values[2], kExact);
  EXPECT_NEAR(radius.values[3], 0.5 * std::pow((2 * std::abs(r13) - 0.5) / 0.1, 2), kExact);
}

TEST(PriorValues, CircularSameRegionVanishesOnACircle) {
  // Three points of the circle of radius 2 around (3, 1), with their outward normals.
  const double cx = 3.0, cy = 1.0, radius = 2.0;
  Configuration c;
  for (double t : {2.6, 3.0, 3.5}) {
    const double px = cx + radius * std::cos(t), py = cy + radius * std::sin(t);
    c.rho.push_back(std::hypot(px, py));
    c.phi.push_back(std::atan2(py, px));
    c.alpha.push_back(t);
  }
  const Evaluated e = EvaluateBuiltin("circular-radius", BlockKind::kSameRegion, c);
  ASSERT_EQ(e.values.size(), 4u);
  EXPECT_NEAR(e.values[0], 0.0, kExact);
  EXPECT_NEAR(e.values[1], 0.0, kExact);
  EXPECT_NEAR(e.values[2], 0.0, kExact);
  EXPECT_NEAR(e.values[3], 0.0, 1e-9);  // the radius is 2
  // Normals all turned by the same angle keep the radii equal but leave the circle.
  for (double& a : c.alpha) a += 0.1;
  const Evaluated turned = EvaluateBuiltin("circular", BlockKind::kSameRegion, c);
  EXPECT_NEAR(turned.values[0], 0.0, kExact);
  EXPECT_NEAR(turned.values[1], 0.0, kExact);
  EXPECT_GT(std::abs(turned.values[2]), 0.1);
}

TEST(PriorValues, StraightOrCircularBranchesAreTheLineAndTheCircleConditions) {
  const Configuration c{{2.0, 2.5, 3.0}, {0.1, 0.5, 1.2}, {-0.3, 0.0, 0.4}};
  const CompiledPrior prior = LoadBuiltin("straight-or-circular");
  const CompiledBlock* block = prior.block(BlockKind::kSameRegion);
  ASSERT_NE(block, nullptr);
  const Evaluated e = EvaluateBuiltin("straight-or-circular", BlockKind::kSameRegion, c);
  ASSERT_EQ(e.values.size(), 7u);
  const auto p = [&](std::size_t i) {
    return Eigen::Vector2d(c.rho[i] * std::cos(c.phi[i]), c.rho[i] * std::sin(c.phi[i]));
  };
  const Eigen::Vector2d n1(std::cos(c.alpha[0]), std::sin(c.alpha[0]));
  const std::vector<double> expected = {
      c.alpha[1] - c.alpha[0], c.alpha[2] - c.alpha[0], (p(1) - p(0)).dot(n1),
      (p(2) - p(0)).dot(n1),
      // The circle branch's half-curvature differences are scaled by the chord p_1 p_3.
      (HalfCurvature(c, 0, 1) - HalfCurvature(c, 1, 2)) * (p(2) - p(0)).norm(),
      (HalfCurvature(c, 1, 2) - HalfCurvature(c, 0, 2)) * (p(2) - p(0)).norm(),
      (p(2) - p(0))
          .dot(Eigen::Vector2d(std::cos((c.alpha[0] + c.alpha[2]) / 2),
                               std::sin((c.alpha[0] + c.alpha[2]) / 2)))};
  for (std::size_t t = 0; t < expected.size(); ++t) {
    EXPECT_NEAR(e.values[t], expected[t], kExact) << "term " << t;
    EXPECT_EQ(block->terms()[t].disjunction, 0);
    EXPECT_EQ(block->terms()[t].branch, t < 4 ? 0 : 1);
  }
}

TEST(PriorValues, ManhattanAndOctagonalConstrainTheAngleBetweenNeighbours) {
  const Configuration c{{1.0, 1.5}, {0.3, 1.0}, {-0.1, 0.1}};
  const Evaluated manhattan = EvaluateBuiltin("manhattan", BlockKind::kDifferentSurface, c);
  ASSERT_EQ(manhattan.values.size(), 1u);
  EXPECT_NEAR(manhattan.values[0], std::sin(2 * 0.7), kExact);
  const Evaluated octagonal = EvaluateBuiltin("octagonal", BlockKind::kDifferentRegion, c);
  ASSERT_EQ(octagonal.values.size(), 1u);
  EXPECT_NEAR(octagonal.values[0], std::sin(4 * 0.7), kExact);
}

// --- every operator's derivative rule ----------------------------------------------------------

// The built-in priors never use exp, log, tan, asin, acos, atan, atan2, a power with an unknown
// in the exponent, min or max, and use sqrt, abs and division only in a few shapes (norm of a
// 2-vector, abs of one quotient), so every function and operator of the language
// (ExpressionGraph::MakeDerivative and the lowering of norm, deg2rad, rad2deg, min and max of a
// vector, ./ and .^) is checked here on a prior written for the purpose: one energy per operator,
// so that a wrong rule shows up as the failure of its own term. The Hessians apply each rule
// twice (the derivative of the derivative), so they check the rules once more on the rules' own
// output.
constexpr const char* kEveryOperatorPrior =
    "name: Every operator\n"
    "order: 2\n"
    "priorlet same_region:\n"
    "  model_likelihood exp(0.3*rho_1 - rho_2)\n"
    "  model_likelihood log(rho_1 + rho_2)\n"
    "  model_likelihood tan(0.3*(alpha_2 - alpha_1))\n"
    "  model_likelihood asin(0.4*sin(alpha_1))\n"
    "  model_likelihood acos(0.4*cos(alpha_2))\n"
    "  model_likelihood atan(rho_1 - rho_2)\n"
    "  model_likelihood atan2(rho_2*sin(alpha_2), rho_1*cos(alpha_1))\n"
    "  model_likelihood rho_1^rho_2\n"
    "  model_likelihood rho_1^2.5\n"
    "  model_likelihood min(rho_1, rho_2) + max(alpha_1, alpha_2)\n"
    "  model_likelihood sqrt(rho_1 + 0.5*rho_2)\n"
    "  model_likelihood abs(rho_1 - rho_2) * alpha_1\n"
    "  model_likelihood norm(alpha_2 - alpha_1) * rho_1\n"
    "  model_likelihood norm([rho_1*cos(alpha_1); rho_2*sin(alpha_2)])\n"
    "  model_likelihood norm([rho_1, alpha_1; alpha_2, rho_2])\n"
    "  model_likelihood deg2rad(rho_1*alpha_2) + rad2deg(alpha_1/rho_2)\n"
    "  model_likelihood min([rho_1; rho_2]) * max([alpha_1, alpha_2])\n"
    "  model_likelihood [rho_1, rho_2] .^ [alpha_1, -1.5] * [1; 1] + rho_2 ./ rho_1\n"
    "  model_likelihood 2^(rho_1 - alpha_2)\n";
constexpr int kEveryOperatorTerms = 19;

// The same terms written with <cmath>, at x = (rho_1, rho_2, alpha_1, alpha_2).
std::vector<double> EveryOperatorByHand(const Eigen::VectorXd& x) {
  const double r1 = x[0], r2 = x[1], a1 = x[2], a2 = x[3];
  return {std::exp(0.3 * r1 - r2),
          std::log(r1 + r2),
          std::tan(0.3 * (a2 - a1)),
          std::asin(0.4 * std::sin(a1)),
          std::acos(0.4 * std::cos(a2)),
          std::atan(r1 - r2),
          std::atan2(r2 * std::sin(a2), r1 * std::cos(a1)),
          std::pow(r1, r2),
          std::pow(r1, 2.5),
          std::min(r1, r2) + std::max(a1, a2),
          std::sqrt(r1 + 0.5 * r2),
          std::abs(r1 - r2) * a1,
          std::abs(a2 - a1) * r1,
          std::hypot(r1 * std::cos(a1), r2 * std::sin(a2)),
          std::sqrt(r1 * r1 + a1 * a1 + a2 * a2 + r2 * r2),
          kPi / 180 * r1 * a2 + 180 / kPi * a1 / r2,
          std::min(r1, r2) * std::max(a1, a2),
          std::pow(r1, a1) + std::pow(r2, -1.5) + r2 / r1,
          std::pow(2.0, r1 - a2)};
}

CompiledPrior CompileEveryOperatorPrior() {
  Result<CompiledPrior> prior = PriorLibrary().CompileText(kEveryOperatorPrior, "every.prior");
  if (!prior) ADD_FAILURE() << prior.error();
  return std::move(prior).value();
}

// Whether the central-difference stencil (step kStep = 1e-5) around p stays in one smooth piece
// of every term, and away from the poles where finite differences lose their accuracy:
//  - tan(0.3 d), d = alpha_2 - alpha_1 in (-2 pi, 2 pi), has poles at |0.3 d| = pi/2; keeping
//    cos(0.3 d) >= 0.3 bounds tan' = 1/cos^2 by ~11;
//  - atan2(y, x) jumps by 2 pi across x < 0, y = 0 and is singular at the origin; keep
//    |(x, y)| >= 0.5 m and |y| >= 0.05 m where x < 0 (both 5,000 steps away);
//  - min(rho_1, rho_2) and max(alpha_1, alpha_2) switch where their arguments are equal, and
//    abs(rho_1 - rho_2) and norm(alpha_2 - alpha_1) have their kinks there; keep them 1e-3 (100
//    steps) apart. The norm of (rho_1 cos alpha_1, rho_2 sin alpha_2) is the atan2 guard's
//    |(x, y)| >= 0.5 m, and the 2x2 matrix's norm is at least rho_1 >= 0.5 m.
// rho >= 0.5 m keeps log(rho_1 + rho_2) and rho_1^rho_2 smooth; asin and acos see |arg| <= 0.4.
bool AwayFromEveryOperatorsKinks(const Point& p) {
  const double r1 = p.x[0], r2 = p.x[1], a1 = p.x[2], a2 = p.x[3];
  const double x = r1 * std::cos(a1), y = r2 * std::sin(a2);
  return std::cos(0.3 * (a2 - a1)) >= 0.3 && std::hypot(x, y) >= 0.5 &&
         (x > 0 || std::abs(y) >= 0.05) && std::abs(r1 - r2) > 1e-3 && std::abs(a1 - a2) > 1e-3;
}

TEST(OperatorDerivatives, TheOperatorPriorCompilesToOneTermPerOperatorWithTheLibmValues) {
  const CompiledPrior prior = CompileEveryOperatorPrior();
  const CompiledBlock* block = prior.block(BlockKind::kSameRegion);
  ASSERT_NE(block, nullptr);
  ASSERT_EQ(block->num_terms(), kEveryOperatorTerms);
  ASSERT_EQ(block->num_variables(), 4);
  Evaluation evaluation(*block);
  Rng rng(2024);
  for (int n = 0; n < 100; ++n) {
    Point p = RandomPoint(rng, 2);
    while (!AwayFromEveryOperatorsKinks(p)) p = RandomPoint(rng, 2);
    const Eigen::VectorXd values = evaluation.Values(p.x, p.phi);
    const std::vector<double> expected = EveryOperatorByHand(p.x);
    for (int t = 0; t < kEveryOperatorTerms; ++t) {
      // 1e-12 relative: the tapes and <cmath> may round differently (e.g. a * (1/b) for a/b).
      EXPECT_NEAR(values[t], expected[static_cast<std::size_t>(t)],
                  1e-12 * std::max(1.0, std::abs(expected[static_cast<std::size_t>(t)])))
          << Describe(*block, t, p);
    }
  }
}

TEST(OperatorDerivatives, EveryOperatorsGradientAndHessianMatchCentralDifferences) {
  const CompiledPrior prior = CompileEveryOperatorPrior();
  const CompiledBlock* block = prior.block(BlockKind::kSameRegion);
  ASSERT_NE(block, nullptr);
  ASSERT_EQ(block->num_terms(), kEveryOperatorTerms);
  Evaluation evaluation(*block);
  Rng rng(4242);
  int failures = 0, rejected = 0;
  for (int n = 0; n < kPointsPerPrior && failures < 20; ++n) {
    Point p = RandomPoint(rng, 2);
    while (!AwayFromEveryOperatorsKinks(p)) {
      ++rejected;
      p = RandomPoint(rng, 2);
    }
    failures += DerivativeMismatches(evaluation, *block, p, "");
  }
  // The guards leave most of the space in the test (tan's guard alone rejects ~10 %).
  EXPECT_LT(rejected, kPointsPerPrior / 3);
}

// norm, like abs, has a kink at 0; there sqrt(v'v) alone gave the derivative 0 * (1/0) = NaN,
// which the engine's Newton steps would carry. At the kink both take the derivative 0 (the
// subgradient in the middle), so a cost such as norm(alpha_2 - alpha_1) stays usable where the
// normals are equal.
TEST(OperatorDerivatives, NormAndAbsHaveTheFiniteDerivativeZeroAtTheirKink) {
  const Result<CompiledPrior> prior = PriorLibrary().CompileText(
      "name: Kinks\norder: 2\npriorlet same_region:\n"
      "  model_likelihood norm(alpha_2 - alpha_1)\n"
      "  model_likelihood norm([rho_1 - rho_2; alpha_1 - alpha_2])\n"
      "  model_likelihood norm([rho_1 - rho_2, 0; 0, alpha_1 - alpha_2])\n"
      "  model_likelihood abs(alpha_2 - alpha_1)\n",
      "kinks.prior");
  ASSERT_TRUE(prior.ok()) << prior.error();
  const CompiledBlock* block = prior.value().block(BlockKind::kSameRegion);
  ASSERT_NE(block, nullptr);
  ASSERT_EQ(block->num_terms(), 4);
  Evaluation evaluation(*block);
  Eigen::VectorXd values, gradients, hessians;
  Eigen::VectorXd x(4);
  x << 2.0, 2.0, 0.3, 0.3;  // rho_1 = rho_2, alpha_1 = alpha_2: every term at its kink
  evaluation.All(x, {0.1, 0.2}, values, gradients, hessians);
  for (int t = 0; t < 4; ++t) EXPECT_EQ(values[t], 0.0) << t;
  for (int i = 0; i < gradients.size(); ++i) EXPECT_EQ(gradients[i], 0.0) << "gradient entry " << i;
  for (int i = 0; i < hessians.size(); ++i) EXPECT_EQ(hessians[i], 0.0) << "Hessian entry " << i;
}

// min and max at a tie, where their arguments are equal, take the derivatives of their first
// argument (the documented choice; the two one-sided derivatives differ there).
TEST(OperatorDerivatives, MinAndMaxAtATieTakeTheirFirstArgumentsDerivatives) {
  const Result<CompiledPrior> prior = PriorLibrary().CompileText(
      "name: Ties\norder: 2\npriorlet same_region:\n"
      "  model_likelihood min(alpha_1, alpha_2^2)\n"
      "  model_likelihood max(alpha_2^2, alpha_1)\n",
      "ties.prior");
  ASSERT_TRUE(prior.ok()) << prior.error();
  const CompiledBlock* block = prior.value().block(BlockKind::kSameRegion);
  ASSERT_NE(block, nullptr);
  Evaluation evaluation(*block);
  Eigen::VectorXd values, gradients, hessians;
  Eigen::VectorXd x(4);
  x << 1.0, 1.0, 0.25, 0.5;  // alpha_1 = alpha_2^2
  evaluation.All(x, {0.1, 0.2}, values, gradients, hessians);
  // Gradients by (rho_1, rho_2, alpha_1, alpha_2), term after term; Hessian entry (alpha_2,
  // alpha_2) of each term.
  EXPECT_THAT(std::vector<double>(gradients.begin(), gradients.end()),
              ::testing::ElementsAre(0, 0, 1, 0, 0, 0, 0, 1));
  EXPECT_EQ(hessians[15], 0.0);
  EXPECT_EQ(hessians[16 + 15], 2.0);
}

// 0^y is 0 for every y > 0: its derivative is 0 there, where the general rule
// d a^b = a^b (b' log a + ...) gives 0 * -inf = NaN. Checked against central differences with the
// exponent positive (rho_i > 0), alone and inside other operations.
TEST(OperatorDerivatives, ZeroToAVariablePowerHasTheFiniteDerivativeZero) {
  const Result<CompiledPrior> prior = PriorLibrary().CompileText(
      "name: Zero base\norder: 2\npriorlet same_region:\n"
      "  model_likelihood 0^rho_1\n"
      "  model_likelihood (1 - 1)^(alpha_1^2 + rho_2) + rho_1 * alpha_2\n"
      "  model_likelihood [0, 0] .^ [rho_1, rho_2] * [alpha_1; 1]\n"
      "  model_likelihood sin(0^(rho_1 * rho_2)) + 2^rho_1\n",
      "zero-base.prior");
  ASSERT_TRUE(prior.ok()) << prior.error();
  const CompiledBlock* block = prior.value().block(BlockKind::kSameRegion);
  ASSERT_NE(block, nullptr);
  ASSERT_EQ(block->num_terms(), 4);
  Evaluation evaluation(*block);
  Rng rng(17);
  int failures = 0;
  for (int n = 0; n < 100 && failures < 5; ++n) {
    failures += DerivativeMismatches(evaluation, *block, RandomPoint(rng, 2), "zero base: ");
  }
}

// Dividing by a constant multiplies by its reciprocal only where that keeps the value written:
// the reciprocal of a huge divisor is subnormal, with digits lost (that of a subnormal one, which
// no prior can hold now, overflowed: x / 1e-320 was x * inf), and a product of two constant
// factors can overflow or underflow where the factors applied in turn do not.
TEST(OperatorValues, FoldingConstantsKeepsTheValueOfTheExpressionAsWritten) {
  const Result<CompiledPrior> prior = PriorLibrary().CompileText(
      "name: Extreme constants\norder: 2\npriorlet same_region:\n"
      "  model_likelihood alpha_2 / 1e308\n"
      "  model_likelihood 1e-200 * (1e-200 * rho_1)\n"
      "  model_likelihood 1e200 * (1e200 * rho_2)\n"
      "  model_likelihood alpha_2 / 4\n",
      "extremes.prior");
  ASSERT_TRUE(prior.ok()) << prior.error();
  const CompiledBlock* block = prior.value().block(BlockKind::kSameRegion);
  ASSERT_NE(block, nullptr);
  ASSERT_EQ(block->num_terms(), 4);
  Evaluation evaluation(*block);
  // The expected values evaluate the expressions as written, operation after operation (the
  // compiler does not reassociate floating-point arithmetic).
  const double rho_1 = 1e300, rho_2 = 1e-300, alpha_1 = 1e-300, alpha_2 = 1e300;
  Eigen::VectorXd x(4);
  x << rho_1, rho_2, alpha_1, alpha_2;
  const Eigen::VectorXd values = evaluation.Values(x, {0.1, 0.2});
  const double expected[] = {alpha_2 / 1e308, 1e-200 * (1e-200 * rho_1), 1e200 * (1e200 * rho_2),
                             alpha_2 / 4};
  for (int t = 0; t < 4; ++t) {
    EXPECT_TRUE(std::isfinite(expected[t])) << t;
    EXPECT_GT(expected[t], 0.0) << t;
    EXPECT_DOUBLE_EQ(values[t], expected[t]) << "term " << t + 1;
  }
}

}  // namespace
}  // namespace priormap::dsl
