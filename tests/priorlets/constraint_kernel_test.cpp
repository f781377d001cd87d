#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <priormap/core/check.hpp>
#include <priormap/priorlets/constraint_kernel.hpp>

#include "testing/numeric_diff.hpp"

namespace priormap::priorlets {
namespace {

using Eigen::Index;
using Eigen::MatrixXd;

Index ToIndex(std::size_t i) {
  return static_cast<Index>(i);
}

MatrixXd DenseJacobian(std::size_t n, const std::vector<ConstraintRow>& rows) {
  MatrixXd j = MatrixXd::Zero(ToIndex(rows.size()), ToIndex(n));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    for (std::size_t c = 0; c < rows[r].coefficients.size(); ++c) {
      j(ToIndex(r), ToIndex(rows[r].first + c)) = rows[r].coefficients[c];
    }
  }
  return j;
}

// The reference: a dense SVD of J with unit rows, null below 1e-9 * sigma_max.
MatrixXd DenseKernel(MatrixXd j) {
  const Index n = j.cols();
  for (Index r = 0; r < j.rows(); ++r) {
    if (j.row(r).norm() > 0.0) j.row(r).normalize();
  }
  if (j.rows() == 0) return MatrixXd::Identity(n, n);
  const Eigen::BDCSVD<MatrixXd> svd(j, Eigen::ComputeFullV);
  const Eigen::VectorXd& s = svd.singularValues();
  const Index rank = (s.array() > 1e-9 * std::max(1.0, s(0))).count();
  return svd.matrixV().rightCols(n - rank);
}

MatrixXd Projector(const MatrixXd& basis) {
  return basis * basis.transpose();
}

double MaxAbs(const MatrixXd& m) {
  return m.size() == 0 ? 0.0 : m.cwiseAbs().maxCoeff();
}

// Free = ker J by both methods: same dimension, same subspace, orthonormal, J N ~ 0.
void ExpectMatchesDense(std::size_t n, const std::vector<ConstraintRow>& rows,
                        const ConstraintKernel& kernel) {
  const MatrixXd j = DenseJacobian(n, rows);
  const MatrixXd reference = DenseKernel(j);
  const MatrixXd basis = kernel.ToDense();
  ASSERT_EQ(basis.rows(), ToIndex(n));
  ASSERT_EQ(basis.cols(), ToIndex(kernel.dimension()));
  EXPECT_EQ(basis.cols(), reference.cols());
  EXPECT_LT((basis.transpose() * basis - MatrixXd::Identity(basis.cols(), basis.cols())).norm(),
            1e-12);
  EXPECT_LT((Projector(basis) - Projector(reference)).norm(), 1e-8);
  MatrixXd unit_rows = j;
  for (Index r = 0; r < j.rows(); ++r) {
    if (j.row(r).norm() > 0.0) unit_rows.row(r).normalize();
  }
  EXPECT_LT(MaxAbs(unit_rows * basis), 1e-10);
}

struct RandomSystemSpec {
  std::size_t points = 10;  // m; n = 2m variables
  std::size_t order = 2;    // k: a window's row touches 2k variables
  std::size_t rows_per_window = 2;
  double zero_probability = 0.0;  // of each coefficient being exactly zero
  bool redundant = false;         // add duplicates and combinations of neighbouring rows
  bool empty_and_gaps = false;    // add empty rows, and skip windows (free variables)
};

// Windows of `order` consecutive points with Gaussian coefficients, sorted by first.
std::vector<ConstraintRow> RandomBanded(const RandomSystemSpec& spec, std::uint64_t seed) {
  std::mt19937_64 engine(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform;
  std::vector<ConstraintRow> rows;
  const std::size_t width = 2 * spec.order;
  for (std::size_t i = 0; i + spec.order <= spec.points; ++i) {
    if (spec.empty_and_gaps && uniform(engine) < 0.15) continue;
    for (std::size_t r = 0; r < spec.rows_per_window; ++r) {
      ConstraintRow row{2 * i, std::vector<double>(width)};
      for (double& c : row.coefficients)
        c = uniform(engine) < spec.zero_probability ? 0.0 : normal(engine);
      rows.push_back(std::move(row));
    }
    if (spec.empty_and_gaps && uniform(engine) < 0.1) {
      rows.push_back(
          {2 * i, uniform(engine) < 0.5 ? std::vector<double>{} : std::vector<double>(width, 0.0)});
    }
  }
  if (spec.redundant) {
    const std::size_t original = rows.size();
    for (std::size_t r = 0; r + 1 < original; ++r) {
      if (uniform(engine) < 0.1) {
        ConstraintRow duplicate = rows[r];
        for (double& c : duplicate.coefficients) c *= -3.0;
        rows.push_back(std::move(duplicate));
      }
      if (uniform(engine) < 0.1 && !rows[r].coefficients.empty() &&
          !rows[r + 1].coefficients.empty()) {
        // a rows[r] + b rows[r + 1] over the union of their runs (rows are sorted by first).
        const ConstraintRow& p = rows[r];
        const ConstraintRow& q = rows[r + 1];
        const std::size_t end =
            std::max(p.first + p.coefficients.size(), q.first + q.coefficients.size());
        ConstraintRow combination{p.first, std::vector<double>(end - p.first, 0.0)};
        const double a = normal(engine);
        const double b = normal(engine);
        for (std::size_t c = 0; c < p.coefficients.size(); ++c) {
          combination.coefficients[c] += a * p.coefficients[c];
        }
        for (std::size_t c = 0; c < q.coefficients.size(); ++c) {
          combination.coefficients[q.first - p.first + c] += b * q.coefficients[c];
        }
        rows.push_back(std::move(combination));
      }
    }
    std::stable_sort(rows.begin(), rows.end(), [](const ConstraintRow& a, const ConstraintRow& b) {
      return a.first < b.first;
    });
  }
  return rows;
}

TEST(ConstraintKernel, MatchesDenseSvdOnRandomBandedSystems) {
  std::uint64_t seed = 1;
  for (std::size_t points : {1, 2, 3, 10, 40, 150}) {
    for (std::size_t order : {1, 2, 3, 5}) {
      for (std::size_t rows_per_window : {1, 2, 3}) {
        const RandomSystemSpec spec{points, order, rows_per_window, 0.0, false, false};
        const auto rows = RandomBanded(spec, ++seed);
        SCOPED_TRACE(::testing::Message()
                     << "m " << points << " k " << order << " rows/window " << rows_per_window);
        ExpectMatchesDense(2 * points, rows, ComputeKernel(2 * points, rows));
      }
    }
  }
}

TEST(ConstraintKernel, FindsRedundantRowsEmptyRowsAndFreeVariables) {
  std::uint64_t seed = 100;
  for (std::size_t points : {8, 60, 120}) {
    for (std::size_t order : {2, 3}) {
      for (std::size_t rows_per_window : {1, 2, 3}) {
        for (double zero_probability : {0.0, 0.3}) {
          const RandomSystemSpec spec{points, order, rows_per_window, zero_probability, true, true};
          const auto rows = RandomBanded(spec, ++seed);
          SCOPED_TRACE(::testing::Message() << "m " << points << " k " << order << " rows/window "
                                            << rows_per_window << " zeros " << zero_probability);
          const ConstraintKernel kernel = ComputeKernel(2 * points, rows);
          ExpectMatchesDense(2 * points, rows, kernel);
          // The decisions had a wide margin (exact redundancy is at rounding level).
          EXPECT_LT(kernel.summary().largest_null_singular_value, 1e-12);
          EXPECT_GT(kernel.summary().smallest_kept_singular_value, 1e-6);
        }
      }
    }
  }
}

TEST(ConstraintKernel, RedundantRowsDoNotChangeTheKernel) {
  const RandomSystemSpec plain{80, 2, 2, 0.0, false, false};
  RandomSystemSpec redundant = plain;
  redundant.redundant = true;
  // Same seed: the redundant system is the plain one plus dependent rows.
  const ConstraintKernel a = ComputeKernel(160, RandomBanded(plain, 7));
  const ConstraintKernel b = ComputeKernel(160, RandomBanded(redundant, 7));
  ASSERT_GT(RandomBanded(redundant, 7).size(), RandomBanded(plain, 7).size());
  EXPECT_EQ(a.dimension(), b.dimension());
  EXPECT_LT((Projector(a.ToDense()) - Projector(b.ToDense())).norm(), 1e-9);
}

TEST(ConstraintKernel, RowScalesDoNotChangeTheKernel) {
  std::mt19937_64 engine(3);
  std::uniform_real_distribution<double> exponent(-6.0, 6.0);
  for (std::size_t order : {2, 3}) {
    const RandomSystemSpec spec{120, order, 2, 0.2, true, true};
    const auto rows = RandomBanded(spec, 11 + order);
    auto scaled = rows;
    for (ConstraintRow& row : scaled) {
      const double s = std::pow(10.0, exponent(engine));
      for (double& c : row.coefficients) c *= s;
    }
    const ConstraintKernel kernel = ComputeKernel(240, scaled);
    ExpectMatchesDense(240, rows, kernel);  // the reference sees the unscaled rows
  }
}

TEST(ConstraintKernel, UntouchedVariablesAndEmptyRowsAreFreeUnitVectors) {
  // 12 variables; rows couple {1, 2, 3} and {6, 8}; 0, 4, 5, 7, 9, 10, 11 are free (7 and 9
  // sit inside runs with zero coefficients, 4 and 5 in an empty and a zero row).
  const std::vector<ConstraintRow> rows = {
      {1, {1.0, -1.0}}, {2, {2.0, 0.5}}, {4, {}}, {4, {0.0, 0.0}}, {6, {1.0, 0.0, 1.0, 0.0}},
  };
  const ConstraintKernel kernel = ComputeKernel(12, rows);
  EXPECT_EQ(kernel.free_variables(), (std::vector<std::size_t>{0, 4, 5, 7, 9, 10, 11}));
  EXPECT_EQ(kernel.summary().num_components, 2u);
  EXPECT_EQ(kernel.summary().num_rows, 3u);
  // {1, 2, 3}: 2 independent rows, kernel 1; {6, 8}: 1 row, kernel 1.
  EXPECT_EQ(kernel.dimension(), 7u + 1u + 1u);
  ExpectMatchesDense(12, rows, kernel);
  for (const KernelBlock& block : kernel.blocks()) {
    EXPECT_TRUE(block.variables == (std::vector<std::size_t>{1, 2, 3}) ||
                block.variables == (std::vector<std::size_t>{6, 8}));
  }
  const MatrixXd dense = kernel.ToDense();
  for (std::size_t j = 0; j < kernel.free_variables().size(); ++j) {
    EXPECT_EQ(dense.col(ToIndex(j)),
              MatrixXd::Identity(12, 12).col(ToIndex(kernel.free_variables()[j])));
  }
}

TEST(ConstraintKernel, NoRowsOrNoVariables) {
  EXPECT_EQ(ComputeKernel(5, {}).dimension(), 5u);
  EXPECT_EQ(ComputeKernel(5, {}).ToDense(), MatrixXd::Identity(5, 5));
  const ConstraintKernel empty = ComputeKernel(0, {});
  EXPECT_EQ(empty.dimension(), 0u);
  EXPECT_EQ(empty.ToDense().size(), 0);
  EXPECT_EQ(ConstraintKernel(4).ToDense(), MatrixXd::Identity(4, 4));
}

TEST(ConstraintKernel, SeparateComponentsGiveSeparateBlocks) {
  // Two chains x_i = x_{i+1} over [0, 50) and [50, 100), and a full-rank block on [100, 110).
  std::vector<ConstraintRow> rows;
  for (std::size_t i = 0; i + 1 < 100; ++i) {
    if (i != 49) rows.push_back({i, {1.0, -1.0}});
  }
  for (std::size_t i = 100; i + 1 < 110; ++i) rows.push_back({i, {1.0, 0.5}});
  rows.push_back({109, {1.0}});
  const ConstraintKernel kernel = ComputeKernel(110, rows);
  EXPECT_EQ(kernel.summary().num_components, 3u);
  EXPECT_EQ(kernel.dimension(), 2u);
  ASSERT_EQ(kernel.blocks().size(), 2u);
  for (const KernelBlock& block : kernel.blocks()) {
    ASSERT_EQ(block.basis.cols(), 1);
    EXPECT_EQ(block.variables.size(), 50u);
    EXPECT_NEAR(std::abs(block.basis(0, 0)), 1.0 / std::sqrt(50.0), 1e-14);
  }
  ExpectMatchesDense(110, rows, kernel);
}

TEST(ConstraintKernel, NearlyDependentRowsAreDecidedBySvd) {
  // x0 - x1 and x0 - (1 + delta) x1 on a chain: singular value ~ delta / 2 near the tolerance.
  for (double delta : {1e-6, 1e-7, 1e-10, 1e-11}) {
    std::vector<ConstraintRow> rows;
    for (std::size_t i = 0; i + 1 < 40; ++i) rows.push_back({i, {1.0, -1.0}});
    rows.push_back({20, {1.0, -(1.0 + delta)}});
    const ConstraintKernel kernel = ComputeKernel(40, rows);
    SCOPED_TRACE(::testing::Message() << "delta " << delta);
    EXPECT_EQ(kernel.dimension(), delta > 1e-9 ? 0u : 1u);
    EXPECT_GT(kernel.summary().num_svd_fallbacks, 0u);
    ExpectMatchesDense(40, rows, kernel);
  }
}

TEST(ConstraintKernel, ResultDoesNotDependOnRowOrderOrThreads) {
  const RandomSystemSpec spec{700, 3, 2, 0.2, true, true};
  const auto rows = RandomBanded(spec, 5);
  const ConstraintKernel sequential = ComputeKernel(1400, rows, {.parallel_grain = 1u << 20});
  const ConstraintKernel parallel = ComputeKernel(1400, rows, {.parallel_grain = 32});
  EXPECT_EQ(sequential.ToDense(), parallel.ToDense());  // bit for bit
  auto shuffled = rows;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937_64(9));
  const ConstraintKernel other = ComputeKernel(1400, shuffled);
  EXPECT_EQ(other.dimension(), sequential.dimension());
  const MatrixXd a = sequential.ToDense();
  const MatrixXd b = other.ToDense();
  EXPECT_LT((a * (a.transpose() * b) - b).norm(), 1e-9);  // same subspace
}

TEST(ConstraintKernel, ProjectionsMatchTheDenseBasis) {
  const RandomSystemSpec spec{90, 2, 2, 0.2, true, true};
  const auto rows = RandomBanded(spec, 21);
  const ConstraintKernel kernel = ComputeKernel(180, rows);
  const MatrixXd n = kernel.ToDense();
  const MatrixXd x = MatrixXd::Random(180, 3);
  const MatrixXd c = MatrixXd::Random(n.cols(), 2);
  EXPECT_TRUE(kernel.Coordinates(x).isApprox(n.transpose() * x, 1e-12));
  EXPECT_TRUE(kernel.Expand(c).isApprox(n * c, 1e-12));
  EXPECT_TRUE(kernel.Project(x).isApprox(n * n.transpose() * x, 1e-12));
  EXPECT_TRUE(kernel.ProjectOntoComplement(x).isApprox(x - n * n.transpose() * x, 1e-12));
  EXPECT_THROW((void)kernel.Project(MatrixXd::Zero(179, 3)), ContractError);
}

// The kernel of one constraint per window over `points` points (2 unknowns each): of full
// dimension, stored in O(n log n), and N^T N = I and J N = 0, probed with random coordinates.
void ExpectCompactKernelOfOneRowPerWindow(const ConstraintKernel& kernel, std::size_t points,
                                          const std::vector<ConstraintRow>& rows) {
  EXPECT_EQ(kernel.dimension(), 2 * points - rows.size());
  std::size_t stored = 0;
  for (const KernelBlock& block : kernel.blocks())
    stored += static_cast<std::size_t>(block.basis.size());
  EXPECT_LT(stored, 2 * points * kernel.dimension() / 20);
  const MatrixXd c = MatrixXd::Random(ToIndex(kernel.dimension()), 8);
  const MatrixXd nc = kernel.Expand(c);
  EXPECT_LT((kernel.Coordinates(nc) - c).norm(), 1e-11 * c.norm());
  EXPECT_LT((DenseJacobian(2 * points, rows) * nc).norm(), 1e-11 * c.norm());
}

TEST(ConstraintKernel, LargeKernelIsStoredCompactly) {
  // One constraint per window over m points: dim Free ~ m, yet storage O(n log n).
  const std::size_t points = 1100;
  const RandomSystemSpec spec{points, 2, 1, 0.0, false, false};
  const auto rows = RandomBanded(spec, 31);
  ExpectCompactKernelOfOneRowPerWindow(ComputeKernel(2 * points, rows), points, rows);
}

// Variable scales S: the rank is decided on J S^-1 (the reference: a dense SVD of those rows),
// the basis spans ker J = S^-1 ker(J S^-1) and is orthonormal in the variables as given, block
// by block (the blocks of a large kernel keep their supports).
void ExpectMatchesScaledDense(std::size_t n, const std::vector<ConstraintRow>& rows,
                              const std::vector<double>& scales, const ConstraintKernel& kernel) {
  const MatrixXd j = DenseJacobian(n, rows);
  const Eigen::VectorXd inverse =
      Eigen::Map<const Eigen::VectorXd>(scales.data(), ToIndex(n)).cwiseInverse();
  const MatrixXd reference_z = DenseKernel(j * inverse.asDiagonal());
  const MatrixXd basis = kernel.ToDense();
  ASSERT_EQ(basis.cols(), reference_z.cols());
  EXPECT_LT((basis.transpose() * basis - MatrixXd::Identity(basis.cols(), basis.cols())).norm(),
            1e-12);
  // Same subspace: S^-1 N_z, orthonormalised, has the projector of the basis.
  if (basis.cols() > 0) {
    const Eigen::HouseholderQR<MatrixXd> qr(inverse.asDiagonal() * reference_z);
    const MatrixXd reference =
        qr.householderQ() * MatrixXd::Identity(ToIndex(n), reference_z.cols());
    EXPECT_LT((Projector(basis) - Projector(reference)).norm(), 1e-8);
  }
  for (const KernelBlock& block : kernel.blocks()) {
    EXPECT_LT((block.basis.transpose() * block.basis -
               MatrixXd::Identity(block.basis.cols(), block.basis.cols()))
                  .norm(),
              1e-12);
  }
}

TEST(ConstraintKernel, VariableScalesDecideTheRankInCommonUnits) {
  std::mt19937_64 engine(41);
  std::uniform_real_distribution<double> exponent(-3.0, 3.0);
  std::uint64_t seed = 400;
  for (std::size_t points : {3, 40, 150}) {
    for (std::size_t order : {2, 3}) {
      for (std::size_t rows_per_window : {1, 2}) {
        const RandomSystemSpec spec{points, order, rows_per_window, 0.2, true, true};
        const auto rows = RandomBanded(spec, ++seed);
        std::vector<double> scales(2 * points);
        for (double& s : scales) s = std::pow(10.0, exponent(engine));
        SCOPED_TRACE(::testing::Message()
                     << "m " << points << " k " << order << " rows/window " << rows_per_window);
        ExpectMatchesScaledDense(2 * points, rows, scales,
                                 ComputeKernel(2 * points, rows, {}, scales));
      }
    }
  }
}

TEST(ConstraintKernel, UnitVariableScalesChangeNothing) {
  const RandomSystemSpec spec{300, 3, 2, 0.2, true, true};
  const auto rows = RandomBanded(spec, 17);
  const ConstraintKernel plain = ComputeKernel(600, rows);
  const ConstraintKernel unit = ComputeKernel(600, rows, {}, std::vector<double>(600, 1.0));
  ASSERT_EQ(plain.dimension(), unit.dimension());
  EXPECT_LT((Projector(plain.ToDense()) - Projector(unit.ToDense())).norm(), 1e-12);
  EXPECT_EQ(plain.summary().smallest_kept_singular_value,
            unit.summary().smallest_kept_singular_value);
}

// Where the units hide coefficients: x_{2i} are ranges of a wall 1e8 m away and x_{2i+1} its
// normals, seen every 0.01 rad: rows tie each normal to the next and each range to the next
// through a coefficient of rho dphi = 1e6 on the normal. Free is the common normal with the
// ranges that follow it, plus one range (2 directions). Without scales the ranges' coefficients,
// 1e-6 of a unit row, are lost below the tolerance the posterior uses at a solution feasible to
// 1e-8 (100 v = 1e-6), and most ranges look free.
TEST(ConstraintKernel, VariableScalesKeepRowsWithHugeCoefficientsFromHidingTheOthers) {
  const std::size_t points = 200;
  const double rho = 1e8;
  std::vector<ConstraintRow> rows;
  for (std::size_t i = 0; i + 1 < points; ++i) {
    rows.push_back({2 * i, {0.0, 1.0, 0.0, -1.0}});
    rows.push_back({2 * i, {-1.0, 0.01 * rho, 1.0, 0.0}});
  }
  std::vector<double> scales(2 * points, 1.0);
  for (std::size_t i = 0; i < points; ++i) scales[2 * i + 1] = rho;
  const KernelOptions options{.relative_tolerance = 1e-6};
  EXPECT_GT(ComputeKernel(2 * points, rows, options).dimension(), 10u);
  const ConstraintKernel kernel = ComputeKernel(2 * points, rows, options, scales);
  EXPECT_EQ(kernel.dimension(), 2u);
  ExpectMatchesScaledDense(2 * points, rows, scales, kernel);
  EXPECT_LT((DenseJacobian(2 * points, rows) * kernel.ToDense()).norm(), 1e-6);
}

TEST(ConstraintKernel, LargeKernelWithVariableScalesKeepsItsBlocksCompact) {
  const std::size_t points = 1100;
  const RandomSystemSpec spec{points, 2, 1, 0.0, false, false};
  const auto rows = RandomBanded(spec, 31);
  std::vector<double> scales(2 * points, 1.0);
  for (std::size_t i = 0; i < points; ++i) scales[2 * i + 1] = 2.0 + std::sin(0.01 * i);
  ExpectCompactKernelOfOneRowPerWindow(ComputeKernel(2 * points, rows, {}, scales), points, rows);
}

TEST(ConstraintKernel, RejectsMalformedInput) {
  EXPECT_THROW((void)ComputeKernel(4, std::vector<ConstraintRow>{{3, {1.0, 1.0}}}), ContractError);
  // A row that is not finite comes from a prior's term outside its domain: the user's to fix.
  EXPECT_THROW((void)ComputeKernel(4, std::vector<ConstraintRow>{{0, {NAN}}}), std::domain_error);
  EXPECT_THROW((void)ComputeKernel(4, {}, {.relative_tolerance = 0.0}), ContractError);
  EXPECT_THROW((void)ComputeKernel(4, {}, {}, std::vector<double>(3, 1.0)), ContractError);
  EXPECT_THROW((void)ComputeKernel(2, {}, {}, std::vector<double>{1.0, 0.0}), ContractError);
  EXPECT_THROW((void)ComputeKernel(2, {}, {}, std::vector<double>{1.0, INFINITY}), ContractError);
}

// A rectangular room [-3, 5] x [-2, 4] scanned from the origin, m beams starting at the corner
// (5, 4), so that each wall is one run of beams. x interleaves (rho_i, alpha_i); alpha is the
// normal pointing back at the sensor, in the sensor frame.
struct Room {
  std::vector<double> phi, rho, alpha;
  std::vector<int> wall;
};

// The readings from a sensor at body-frame pose q = (dx, dy, dtheta); alpha is not wrapped, so
// that it is differentiable.
Room ScanRoom(std::size_t m, const Eigen::Vector3d& q) {
  constexpr double kX[2] = {-3.0, 5.0};
  constexpr double kY[2] = {-2.0, 4.0};
  const double phi0 = std::atan2(4.0, 5.0);
  Room room;
  for (std::size_t i = 0; i < m; ++i) {
    const double phi =
        phi0 + 2.0 * std::numbers::pi * (static_cast<double>(i) + 0.5) / static_cast<double>(m);
    const Eigen::Vector2d u(std::cos(phi + q.z()), std::sin(phi + q.z()));
    double best = INFINITY;
    int wall = -1;
    double normal = 0.0;  // world angle of the inward normal
    const double candidates[4][3] = {{(kY[1] - q.y()) / u.y(), 0, -std::numbers::pi / 2},
                                     {(kX[0] - q.x()) / u.x(), 1, 0.0},
                                     {(kY[0] - q.y()) / u.y(), 2, std::numbers::pi / 2},
                                     {(kX[1] - q.x()) / u.x(), 3, std::numbers::pi}};
    for (const auto& c : candidates) {
      if (c[0] > 0.0 && c[0] < best) {
        best = c[0];
        wall = static_cast<int>(c[1]);
        normal = c[2];
      }
    }
    room.phi.push_back(phi);
    room.rho.push_back(best);
    room.alpha.push_back(normal - q.z());
    room.wall.push_back(wall);
  }
  return room;
}

Eigen::VectorXd Readings(const Room& room) {
  Eigen::VectorXd x(ToIndex(2 * room.rho.size()));
  for (std::size_t i = 0; i < room.rho.size(); ++i) {
    x(ToIndex(2 * i)) = room.rho[i];
    x(ToIndex(2 * i + 1)) = room.alpha[i];
  }
  return x;
}

// g = (p_b - p_a) . n(alpha_a) over (rho_a, alpha_a, rho_b, alpha_b): zero when b lies on a's line.
Eigen::Vector4d OnLineGradient(const Room& room, std::size_t a, std::size_t b) {
  const Eigen::Vector2d ua(std::cos(room.phi[a]), std::sin(room.phi[a]));
  const Eigen::Vector2d ub(std::cos(room.phi[b]), std::sin(room.phi[b]));
  const Eigen::Vector2d n(std::cos(room.alpha[a]), std::sin(room.alpha[a]));
  const Eigen::Vector2d dn(-std::sin(room.alpha[a]), std::cos(room.alpha[a]));
  return {-ua.dot(n), (room.rho[b] * ub - room.rho[a] * ua).dot(dn), ub.dot(n), 0.0};
}

// Rows of a polygonal prior with windows of `order` (2 or 3) points, each window inside one wall:
// equal normals and points on the first point's line. With `corners` > 0, the first `corners`
// wall changes also get alpha_i - alpha_{i+1} -/+ pi/2 = 0 (rectangular prior); the 4th couples
// the last beam to the first, a row across all variables.
std::vector<ConstraintRow> PolygonRows(const Room& room, std::size_t order, int corners) {
  const std::size_t m = room.rho.size();
  std::vector<ConstraintRow> rows;
  int corner = 0;
  for (std::size_t i = 0; i + 1 < m; ++i) {
    if (room.wall[i] != room.wall[i + 1]) {
      if (corner++ < corners) rows.push_back({2 * i, {0.0, 1.0, 0.0, -1.0}});
      continue;
    }
    if (i + order > m || room.wall[i + order - 1] != room.wall[i]) continue;
    for (std::size_t j = 1; j < order; ++j) {
      ConstraintRow equal{2 * i, std::vector<double>(2 * order, 0.0)};
      equal.coefficients[2 * j - 1] = 1.0;
      equal.coefficients[2 * j + 1] = -1.0;
      rows.push_back(std::move(equal));
      const Eigen::Vector4d g = OnLineGradient(room, i, i + j);
      std::vector<double> on_line = {g(0), g(1)};  // (rho_i, alpha_i), then rho_{i+j}
      on_line.resize(2 * order, 0.0);
      on_line[2 * j] = g(2);
      rows.push_back({2 * i, std::move(on_line)});
    }
  }
  if (corners >= 4) {
    ConstraintRow wrap{1, std::vector<double>(2 * m - 1, 0.0)};  // alpha_0 .. alpha_{m-1}
    wrap.coefficients.front() = -1.0;
    wrap.coefficients.back() = 1.0;
    rows.push_back(std::move(wrap));
  }
  return rows;
}

TEST(ConstraintKernel, PolygonRowGradientsMatchNumeric) {
  const Room room = ScanRoom(40, Eigen::Vector3d::Zero());
  const Eigen::Vector4d at(room.rho[3], room.alpha[3], room.rho[5], room.alpha[5]);
  const auto g = [&](const Eigen::VectorXd& v) {
    const Eigen::Vector2d pa = v(0) * Eigen::Vector2d(std::cos(room.phi[3]), std::sin(room.phi[3]));
    const Eigen::Vector2d pb = v(2) * Eigen::Vector2d(std::cos(room.phi[5]), std::sin(room.phi[5]));
    return Eigen::VectorXd::Constant(
        1, (pb - pa).dot(Eigen::Vector2d(std::cos(v(1)), std::sin(v(1)))));
  };
  EXPECT_NEAR(g(at)(0), 0.0, 1e-12);  // the room's points are exactly on their walls
  EXPECT_TRUE(priormap::testing::JacobiansMatch(OnLineGradient(room, 3, 5).transpose(),
                                                priormap::testing::NumericJacobian(g, at)));
}

// Extr = d x / d q by central differences of the ray casting (Sec. IV-B, eq. (8)).
MatrixXd ExtrinsicJacobian(std::size_t m) {
  return priormap::testing::NumericJacobian(
      [m](const Eigen::VectorXd& q) { return Readings(ScanRoom(m, q)); }, Eigen::Vector3d::Zero());
}

TEST(ConstraintKernel, RectangleRoomDegreesOfFreedom) {
  // Polygonal prior: 2 per wall (Free 8), Intr 5; right angles at 3 or all 4 corners (the 4th is
  // redundant): a rectangle, Free 5 (pose 3 + width, height), Intr 2 (Sec. V, Fig. 6b).
  const std::size_t m = 160;
  const Room room = ScanRoom(m, Eigen::Vector3d::Zero());
  const MatrixXd extrinsic = ExtrinsicJacobian(m);
  struct Case {
    std::size_t order;
    int corners;
    std::size_t free, intrinsic;
  };
  for (const Case& c : {Case{2, 0, 8, 5}, Case{3, 0, 8, 5}, Case{2, 3, 5, 2}, Case{3, 4, 5, 2}}) {
    SCOPED_TRACE(::testing::Message() << "order " << c.order << " corners " << c.corners);
    const auto rows = PolygonRows(room, c.order, c.corners);
    const ConstraintKernel kernel = ComputeKernel(2 * m, rows);
    EXPECT_EQ(kernel.dimension(), c.free);
    EXPECT_EQ(kernel.summary().num_components, c.corners == 0 ? 4u : 1u);
    ExpectMatchesDense(2 * m, rows, kernel);
    EXPECT_LT(kernel.summary().largest_null_singular_value, 1e-12);
    EXPECT_GT(kernel.summary().smallest_kept_singular_value, 1e-6);

    // Prop. 2: Extr is inside Free (the prior is pose-independent) ...
    EXPECT_LT(kernel.ProjectOntoComplement(extrinsic).norm(), 1e-6 * extrinsic.norm());
    const IntrinsicSubspace intr(kernel, extrinsic);
    ASSERT_EQ(intr.cosines().size(), 3);
    EXPECT_GT(intr.cosines().minCoeff(), 1.0 - 1e-8);
    EXPECT_EQ(intr.dimension(), c.intrinsic);
    // ... and Intr = Free ∩ Extr^perp, checked densely.
    const MatrixXd basis = intr.ToDense();
    ASSERT_EQ(basis.cols(), ToIndex(c.intrinsic));
    EXPECT_LT((basis.transpose() * basis - MatrixXd::Identity(basis.cols(), basis.cols())).norm(),
              1e-12);
    EXPECT_LT((basis.transpose() * extrinsic).norm(), 1e-6 * extrinsic.norm());
    const MatrixXd free = kernel.ToDense();
    EXPECT_LT((free * (free.transpose() * basis) - basis).norm(), 1e-10);
    const MatrixXd x = MatrixXd::Random(ToIndex(2 * m), 2);
    EXPECT_TRUE(intr.Project(x).isApprox(basis * (basis.transpose() * x), 1e-10));
  }
}

TEST(ConstraintKernel, IntrinsicSubspaceOfExtrinsicOutsideFree) {
  // Free = span(e0, e1, e2) in R^4 (one row on x3); Extr = span(e0 + e3, e1): Free ∩ Extr^perp
  // = span(e2), and the cosines are 1/sqrt(2) and 1.
  const ConstraintKernel kernel = ComputeKernel(4, std::vector<ConstraintRow>{{3, {2.0}}});
  MatrixXd extrinsic = MatrixXd::Zero(4, 2);
  extrinsic(0, 0) = extrinsic(3, 0) = 5.0;
  extrinsic(1, 1) = 1e-3;
  const IntrinsicSubspace intr(kernel, extrinsic);
  EXPECT_EQ(intr.dimension(), 1u);
  EXPECT_NEAR(intr.cosines()(0), 1.0, 1e-14);
  EXPECT_NEAR(intr.cosines()(1), std::sqrt(0.5), 1e-14);
  const MatrixXd basis = intr.ToDense();
  EXPECT_NEAR(std::abs(basis(2, 0)), 1.0, 1e-14);
  EXPECT_EQ(IntrinsicSubspace(kernel, MatrixXd::Zero(4, 3)).dimension(), 3u);
}

}  // namespace
}  // namespace priormap::priorlets
