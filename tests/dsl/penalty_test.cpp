#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/dsl/penalty.hpp>
#include <priormap/dsl/prior_library.hpp>

#include "testing/numeric_diff.hpp"

namespace priormap::dsl {
namespace {

// Everything a penalty needs at one point.
struct Evaluation {
  std::vector<double> values, gradients, hessians;
};

Evaluation Evaluate(const CompiledBlock& block, const std::vector<double>& x,
                    const std::vector<double>& phi) {
  const std::size_t nt = static_cast<std::size_t>(block.num_terms()), nv = x.size();
  Evaluation e{std::vector<double>(nt), std::vector<double>(nt * nv),
               std::vector<double>(nt * nv * nv)};
  BlockEvaluator(block).Evaluate(x, phi, e.values.data(), e.gradients.data(), e.hessians.data());
  return e;
}

double Total(const CompiledBlock& block, const std::vector<double>& x,
             const std::vector<double>& phi, const PenaltyOptions& options) {
  const Evaluation e = Evaluate(block, x, phi);
  return AccumulatePenalty(block, e.values.data(), e.gradients.data(), e.hessians.data(), options,
                           nullptr, nullptr)
      .Total(options.lambda);
}

CompiledPrior Load(const std::string& name) {
  return PriorLibrary().Load(name).value();
}

// The accumulated gradient and Hessian are the derivatives of lambda * constraint + energy.
void ExpectDerivativesMatch(const CompiledBlock& block, const std::vector<double>& x,
                            const std::vector<double>& phi) {
  const PenaltyOptions options{2.5, false};
  const std::size_t nv = x.size();
  const Evaluation e = Evaluate(block, x, phi);
  std::vector<double> gradient(nv, 0.0), hessian(nv * nv, 0.0);
  (void)AccumulatePenalty(block, e.values.data(), e.gradients.data(), e.hessians.data(), options,
                          gradient.data(), hessian.data());
  const Eigen::VectorXd x0 =
      Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(nv));
  const auto total = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    return Eigen::VectorXd::Constant(
        1, Total(block, std::vector<double>(v.data(), v.data() + v.size()), phi, options));
  };
  const auto grad = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    const std::vector<double> point(v.data(), v.data() + v.size());
    const Evaluation ev = Evaluate(block, point, phi);
    std::vector<double> g(nv, 0.0);
    (void)AccumulatePenalty(block, ev.values.data(), ev.gradients.data(), ev.hessians.data(),
                            options, g.data(), nullptr);
    return Eigen::Map<const Eigen::VectorXd>(g.data(), static_cast<Eigen::Index>(nv));
  };
  const Eigen::Map<const Eigen::RowVectorXd> analytic_gradient(gradient.data(),
                                                               static_cast<Eigen::Index>(nv));
  EXPECT_TRUE(
      testing::JacobiansMatch(analytic_gradient, testing::NumericJacobian(total, x0, 1e-6)));
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>
      analytic_hessian(hessian.data(), static_cast<Eigen::Index>(nv),
                       static_cast<Eigen::Index>(nv));
  EXPECT_TRUE(testing::JacobiansMatch(analytic_hessian, testing::NumericJacobian(grad, x0, 1e-6)));
}

TEST(Penalty, EqualitiesAreSquared) {
  const CompiledPrior prior = Load("Polygonal prior");
  const CompiledBlock& block = *prior.block(BlockKind::kSameRegion);
  const std::vector<double> x = {1.0, 2.0, 0.3, 0.5}, phi = {0.0, 0.2};
  const Evaluation e = Evaluate(block, x, phi);
  const PenaltyValue p =
      AccumulatePenalty(block, e.values.data(), nullptr, nullptr, {}, nullptr, nullptr);
  EXPECT_DOUBLE_EQ(p.constraint, e.values[0] * e.values[0] + e.values[1] * e.values[1]);
  EXPECT_DOUBLE_EQ(p.energy, 0.0);
  ExpectDerivativesMatch(block, x, phi);
}

// f = 0 exactly still curves f^2: its Hessian there is 2 grad f grad f^T, which Newton steps on
// a satisfied constraint need (alpha_1 == alpha_2 holds exactly here).
TEST(Penalty, SatisfiedEqualityKeepsItsCurvature) {
  const CompiledPrior prior = Load("Polygonal prior");
  const CompiledBlock& block = *prior.block(BlockKind::kSameRegion);
  const std::vector<double> x = {1.0, 2.0, 0.3, 0.3}, phi = {0.0, 0.2};
  const Evaluation e = Evaluate(block, x, phi);
  ASSERT_EQ(e.values[0], 0.0);
  // Gauss-Newton: (alpha_1 - alpha_2)^2 alone gives 2 on the alpha_1 diagonal.
  std::vector<double> hessian(16, 0.0);
  (void)AccumulatePenalty(block, e.values.data(), e.gradients.data(), e.hessians.data(),
                          {1.0, true}, nullptr, hessian.data());
  EXPECT_GE(hessian[2 * 4 + 2], 2.0);
  // Exact: the finite differences of the gradient.
  ExpectDerivativesMatch(block, x, phi);
}

TEST(Penalty, DisjunctionTakesTheSmallestBranch) {
  const CompiledPrior prior = Load("Rectangular prior");
  const CompiledBlock& block = *prior.block(BlockKind::kDifferentRegion);
  // alpha_2 - alpha_1 = pi/2 + 0.1: the "+ pi/2" branch (index 1) is off by 0.1, the other by pi +
  // 0.1.
  const std::vector<double> x = {1.0, 1.0, 0.2, 0.2 + kPi / 2 + 0.1}, phi = {0.0, 0.1};
  const Evaluation e = Evaluate(block, x, phi);
  std::vector<int> active;
  const PenaltyValue p =
      AccumulatePenalty(block, e.values.data(), nullptr, nullptr, {}, nullptr, nullptr, &active);
  ASSERT_EQ(active.size(), 1u);
  EXPECT_EQ(active[0], 1);
  EXPECT_NEAR(p.constraint, 0.01, 1e-12);
  ExpectDerivativesMatch(block, x, phi);
}

// The penalty at `e` (where some term is NaN) is infinitely violated, and adds no NaN to the
// derivatives.
void ExpectInfinitelyViolatedWithFiniteDerivatives(const CompiledBlock& block,
                                                   const Evaluation& e) {
  const std::size_t n = static_cast<std::size_t>(block.num_variables());
  std::vector<double> gradient(n, 0.0), hessian(n * n, 0.0);
  const PenaltyValue p = AccumulatePenalty(block, e.values.data(), e.gradients.data(),
                                           e.hessians.data(), {}, gradient.data(), hessian.data());
  EXPECT_EQ(p.constraint, std::numeric_limits<double>::infinity());
  EXPECT_EQ(p.max_residual, std::numeric_limits<double>::infinity());
  for (const double g : gradient) EXPECT_TRUE(std::isfinite(g));
  for (const double h : hessian) EXPECT_TRUE(std::isfinite(h));
}

// A term outside its domain (here a NaN put in its place) is infinitely violated: std::max alone
// would have dropped it and called the point feasible. It adds no NaN to the derivatives.
TEST(Penalty, ATermThatIsNotANumberIsInfinitelyViolated) {
  const CompiledPrior prior = Load("Polygonal prior");
  const CompiledBlock& block = *prior.block(BlockKind::kSameRegion);
  const std::vector<double> x = {1.0, 2.0, 0.3, 0.5}, phi = {0.0, 0.2};
  Evaluation e = Evaluate(block, x, phi);
  e.values[0] = std::nan("");
  ExpectInfinitelyViolatedWithFiniteDerivatives(block, e);
}

// The same for an inequality, where max(0, NaN) is 0: sqrt(rho_1 - 100) <= 0 at rho_1 = 1 was
// taken as satisfied.
TEST(Penalty, AnInequalityThatIsNotANumberIsInfinitelyViolated) {
  const CompiledPrior prior = Load("Rectangular prior (relaxed)");
  const CompiledBlock& block = *prior.block(BlockKind::kDifferentRegion);
  const auto inequality = std::ranges::find_if(
      block.terms(), [](const Term& term) { return term.kind == TermKind::kInequality; });
  ASSERT_NE(inequality, block.terms().end());
  const std::vector<double> x = {1.0, 1.0, 0.0, kPi / 2}, phi = {0.0, 0.1};
  Evaluation e = Evaluate(block, x, phi);
  e.values[static_cast<std::size_t>(inequality - block.terms().begin())] = std::nan("");
  ExpectInfinitelyViolatedWithFiniteDerivatives(block, e);
}

// A disjunction whose every branch leaves its domain: no branch is satisfied.
TEST(Penalty, ADisjunctionOfUndefinedBranchesIsInfinitelyViolated) {
  const CompiledPrior prior = PriorLibrary()
                                  .CompileText(
                                      "name: Undefined\norder: 2\npriorlet same_region:\n"
                                      "  sqrt(rho_1 - 100) <= 0 || sqrt(rho_2 - 100) <= 0\n",
                                      "undefined.prior")
                                  .value();
  const CompiledBlock& block = *prior.block(BlockKind::kSameRegion);
  const std::vector<double> x = {1.0, 2.0, 0.3, 0.5}, phi = {0.0, 0.2};
  const Evaluation e = Evaluate(block, x, phi);
  ASSERT_TRUE(std::ranges::all_of(e.values, [](double v) { return std::isnan(v); }));
  ExpectInfinitelyViolatedWithFiniteDerivatives(block, e);
}

// An energy outside its domain is an infinite cost, as a constraint there is infinitely
// violated: a NaN energy made the engine's costs NaN (they compare false with every other). It
// adds no NaN to the derivatives, and another energy's -inf does not cancel it.
TEST(Penalty, AnEnergyThatIsNotANumberIsAnInfiniteCostWithFiniteDerivatives) {
  const CompiledPrior prior = PriorLibrary()
                                  .CompileText(
                                      "name: Undefined\norder: 2\npriorlet same_region:\n"
                                      "  model_likelihood -log(rho_1 - 3)\n"
                                      "  model_likelihood alpha_2 - alpha_1\n"
                                      "  model_likelihood rho_2^2\n",
                                      "undefined.prior")
                                  .value();
  const CompiledBlock& block = *prior.block(BlockKind::kSameRegion);
  const std::vector<double> x = {1.0, 2.0, 0.3, 0.5}, phi = {0.0, 0.2};
  Evaluation e = Evaluate(block, x, phi);
  ASSERT_TRUE(std::isnan(e.values[0]));  // log of -2
  e.values[1] = -std::numeric_limits<double>::infinity();
  std::vector<double> gradient(4, 0.0), hessian(16, 0.0);
  const PenaltyValue p = AccumulatePenalty(block, e.values.data(), e.gradients.data(),
                                           e.hessians.data(), {}, gradient.data(), hessian.data());
  EXPECT_EQ(p.energy, std::numeric_limits<double>::infinity());
  EXPECT_EQ(p.constraint, 0.0);
  // The derivatives of the other two energies only.
  EXPECT_THAT(gradient, ::testing::ElementsAre(0.0, 4.0, -1.0, 1.0));
  EXPECT_THAT(hessian, ::testing::ElementsAre(0, 0, 0, 0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0));
}

TEST(Penalty, InequalitiesCountOnlyWhenViolated) {
  const CompiledPrior prior = Load("Rectangular prior (relaxed)");
  const CompiledBlock& block = *prior.block(BlockKind::kDifferentRegion);
  const std::vector<double> phi = {0.0, 0.1};
  const std::vector<double> inside = {1.0, 1.0, 0.0,
                                      kPi / 2 + DegToRad(1.0)};  // 91 degrees: feasible
  const std::vector<double> outside = {1.0, 1.0, 0.0,
                                       kPi / 2 + DegToRad(10.0)};  // 100 degrees: violated
  EXPECT_DOUBLE_EQ(Total(block, inside, phi, {}), 0.0);
  const double violation = -std::cos(kPi / 2 + DegToRad(10.0)) - std::cos(DegToRad(93.0)) * -1.0;
  EXPECT_NEAR(Total(block, outside, phi, {}), violation * violation, 1e-12);
  ExpectDerivativesMatch(block, outside, phi);
}

TEST(Penalty, EnergiesAreAddedUnweighted) {
  const CompiledPrior prior = Load("Circular prior (with prior on radius)");
  const CompiledBlock& block = *prior.block(BlockKind::kSameRegion);
  const std::vector<double> x = {2.0, 2.1, 2.3, 2.9, 3.0, 3.2}, phi = {-0.3, 0.0, 0.3};
  const Evaluation e = Evaluate(block, x, phi);
  const PenaltyValue p =
      AccumulatePenalty(block, e.values.data(), nullptr, nullptr, {7.0, false}, nullptr, nullptr);
  EXPECT_DOUBLE_EQ(p.energy, e.values[3]);  // after the three equalities
  EXPECT_DOUBLE_EQ(p.Total(7.0), 7.0 * p.constraint + p.energy);
  ExpectDerivativesMatch(block, x, phi);
}

TEST(Penalty, GaussNewtonHessianIsPositiveSemiDefinite) {
  const CompiledPrior prior = Load("Circular prior");
  const CompiledBlock& block = *prior.block(BlockKind::kSameRegion);
  Rng rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<double> x(6), phi = {-0.4, 0.0, 0.4};
    for (int i = 0; i < 3; ++i) x[static_cast<std::size_t>(i)] = rng.Uniform(1.0, 4.0);
    for (int i = 3; i < 6; ++i) x[static_cast<std::size_t>(i)] = rng.Uniform(-kPi, kPi);
    const Evaluation e = Evaluate(block, x, phi);
    std::vector<double> hessian(36, 0.0);
    (void)AccumulatePenalty(block, e.values.data(), e.gradients.data(), e.hessians.data(),
                            {1.0, true}, nullptr, hessian.data());
    const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> h(hessian.data());
    using Matrix6 = Eigen::Matrix<double, 6, 6>;
    const double smallest =
        Eigen::SelfAdjointEigenSolver<Matrix6>(Matrix6(h)).eigenvalues().minCoeff();
    EXPECT_GE(smallest, -1e-9);
  }
}

}  // namespace
}  // namespace priormap::dsl
