#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include <Eigen/SVD>
#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/dsl/prior_library.hpp>
#include <priormap/priorlets/posterior.hpp>

#include "testing/scan_truth.hpp"

namespace priormap::priorlets {
namespace {

using testing::SimulateScene;

RangeSensor Sensor(const std::string& name) {
  return RangeSensor::Preset(name).value();
}

dsl::CompiledPrior Prior(const std::string& name) {
  return dsl::PriorLibrary().Load(name).value();
}

// rank of grad_q (range, alpha) of the in-model beams by central differences of the simulator's
// ray caster (the true ranges and normals at body-frame perturbed poses).
std::size_t FiniteDifferenceExtrinsicRank(const Scene& scene, const RangeSensor& sensor,
                                          const Se2& pose, const MapScan& map) {
  const double h = 1e-5;
  Eigen::MatrixXd j(static_cast<Eigen::Index>(2 * map.inmodel_beams.size()), 3);
  for (int c = 0; c < 3; ++c) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    d[c] = h;
    const Scan plus = SimulateScene(scene, sensor, pose.Compose(Se2(d[0], d[1], d[2])), 1);
    const Scan minus = SimulateScene(scene, sensor, pose.Compose(Se2(-d[0], -d[1], -d[2])), 1);
    const ScanTruth& up = plus.truth.value();
    const ScanTruth& down = minus.truth.value();
    for (std::size_t k = 0; k < map.inmodel_beams.size(); ++k) {
      const std::size_t b = map.inmodel_beams[k];
      const auto r = static_cast<Eigen::Index>(2 * k);
      j(r, c) = (up.range[b] - down.range[b]) / (2 * h);
      j(r + 1, c) = WrapAngle(up.alpha[b] - down.alpha[b]) / (2 * h);
    }
  }
  for (Eigen::Index c = 0; c < 3; ++c) j.col(c).normalize();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(j);
  const Eigen::Vector3d s = svd.singularValues();
  return static_cast<std::size_t>((s.array() > 1e-4 * s.x()).count());
}

struct DofCase {
  const char* scene;
  const char* prior;
  std::size_t free, extrinsic, intrinsic;
};

// Sec. V of the paper: the number of intrinsic degrees of freedom is the number of parameters of
// the map the prior leaves free, minus those a sensor motion explains.
void CheckDegreesOfFreedom(const DofCase& c) {
  const Scene scene = BuiltinScene(c.scene).value();
  const RangeSensor sensor = Sensor("utm30");
  const Se2 pose = scene.default_pose.value();  // it sees every surface
  for (std::uint64_t seed : {1, 2}) {
    SCOPED_TRACE(seed);
    const Scan scan = SimulateScene(scene, sensor, pose, seed);
    const dsl::CompiledPrior prior = Prior(c.prior);
    const MapScan map = EstimateMapScan(scan, prior);
    ASSERT_TRUE(map.feasible);
    const Posterior post = AnalysePosterior(scan, prior, map);
    EXPECT_EQ(post.dof.free, c.free) << map.regions.size() << " regions";
    EXPECT_EQ(post.dof.extrinsic, c.extrinsic);
    EXPECT_EQ(post.dof.intrinsic, c.intrinsic);
    EXPECT_EQ(post.dof.extrinsic, FiniteDifferenceExtrinsicRank(scene, sensor, pose, map));
    EXPECT_TRUE(post.dof.pose_independent) << post.dof.min_extrinsic_cosine;
    EXPECT_GT(post.dof.min_extrinsic_cosine, 0.999);
    // The rank decisions are clear-cut: orders of magnitude either side of the tolerance.
    EXPECT_LT(post.dof.kernel.largest_null_singular_value,
              1e-2 * post.dof.kernel.smallest_kept_singular_value);
  }
}

std::string DofName(const ::testing::TestParamInfo<DofCase>& param) {
  std::string name = std::string(param.param.scene) + "_" + param.param.prior;
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
}

class DegreesOfFreedom : public ::testing::TestWithParam<DofCase> {};
TEST_P(DegreesOfFreedom, MatchThePaper) {
  CheckDegreesOfFreedom(GetParam());
}
INSTANTIATE_TEST_SUITE_P(Paper, DegreesOfFreedom,
                         ::testing::Values(DofCase{"rectangle", "rectangular", 5, 3, 2},
                                           DofCase{"rectangle", "polygonal", 8, 3, 5},
                                           DofCase{"two-circles", "circular", 6, 3, 3},
                                           DofCase{"circle", "circular", 3, 2, 1}),
                         DofName);

// The covariance is that of the estimator: over many noise draws, the MAP ranges scatter around
// the truth as posterior_std says (linear-Gaussian on straight walls, so it should be exact up to
// the sampling error of the spread, ~ 1 / sqrt(2 draws) = 6 % here).
TEST(Posterior, StandardDeviationsMatchTheSpreadOfTheEstimate) {
  const Scene scene = BuiltinScene("square").value();
  const RangeSensor sensor = Sensor("lms200");
  const Se2 pose(0.3, -0.2, 0.4);
  const dsl::CompiledPrior prior = Prior("rectangular");
  const int draws = 150;
  const std::size_t n = static_cast<std::size_t>(sensor.num_beams);
  std::vector<double> sum_sq(n, 0.0), predicted(n, 0.0);
  std::vector<int> count(n, 0);
  for (int k = 0; k < draws; ++k) {
    const Scan scan = SimulateScene(scene, sensor, pose, 1000 + static_cast<std::uint64_t>(k));
    const MapScan map = EstimateMapScan(scan, prior);
    ASSERT_TRUE(map.feasible);
    const Posterior post = AnalysePosterior(scan, prior, map);
    ASSERT_TRUE(post.computed);
    for (std::size_t b : map.inmodel_beams) {
      // Only beams clear of the corners, whose wall is the true one in every draw.
      if (b < 3 || b + 3 >= n || scan.truth->region[b - 3] != scan.truth->region[b + 3]) continue;
      sum_sq[b] += std::pow(map.rho[b] - scan.truth->range[b], 2);
      predicted[b] += post.posterior_std_rho[b] * post.posterior_std_rho[b];
      ++count[b];
    }
  }
  double ratio_sum = 0.0;
  int beams = 0;
  for (std::size_t b = 0; b < n; ++b) {
    if (count[b] < draws * 8 / 10) continue;
    ratio_sum += std::sqrt(sum_sq[b] / predicted[b]);
    ++beams;
  }
  ASSERT_GT(beams, 100);
  const double mean_ratio = ratio_sum / beams;
  EXPECT_NEAR(mean_ratio, 1.0, 0.1) << "empirical / predicted std";
}

// Band-correlated range noise (AR(1), correlation 0.3 between neighbours): on a wall of hundreds
// of readings the prior pins each range far better than the sensor does, and the corrected
// readings of one wall move together. (A line fit is least sure at its ends: there the shrink is
// 6-8x; the middle half of every wall seen by >= 250 readings shrinks >= 10x.)
TEST(Posterior, CorrelatedNoiseShrinksAndCorrelatesAlongWalls) {
  const Scene scene = BuiltinScene("square").value();
  RangeSensor sensor = Sensor("utm30");
  sensor.correlation = 0.3;
  const Scan scan = SimulateScene(scene, sensor, Se2(0.3, -0.2, 0.4), 3);
  ASSERT_TRUE(scan.precision.has_value());
  const dsl::CompiledPrior prior = Prior("rectangular");
  const MapScan map = EstimateMapScan(scan, prior);
  ASSERT_TRUE(map.feasible);
  ASSERT_EQ(map.regions.size(), 4u);
  PosteriorOptions options;
  options.keep_range_covariance = true;
  const Posterior post = AnalysePosterior(scan, prior, map, options);
  ASSERT_TRUE(post.computed);
  const auto shrink = [&](std::size_t b) {
    return post.prior_std_rho[b] / post.posterior_std_rho[b];
  };
  std::vector<double> all;
  for (std::size_t b : map.inmodel_beams) {
    EXPECT_NEAR(post.prior_std_rho[b], sensor.sigma, 1e-9) << b;
    all.push_back(shrink(b));
  }
  std::nth_element(all.begin(), all.begin() + static_cast<long>(all.size() / 2), all.end());
  EXPECT_GE(all[all.size() / 2], 10.0) << "median shrink";
  int long_walls = 0;
  for (const BeamRange& wall : map.regions) {
    const std::size_t length = wall.last - wall.first + 1;
    if (length < 250) continue;
    ++long_walls;
    for (std::size_t b = wall.first + length / 4; b < wall.first + 3 * length / 4; ++b) {
      ASSERT_GE(shrink(b), 10.0) << "beam " << b;
    }
  }
  EXPECT_GE(long_walls, 3);

  // Readings a few beams apart on one wall are strongly correlated, readings of two walls less.
  const Eigen::MatrixXd& cov = post.range_covariance;
  const auto index = [&](std::size_t beam) {
    return static_cast<Eigen::Index>(
        std::lower_bound(map.inmodel_beams.begin(), map.inmodel_beams.end(), beam) -
        map.inmodel_beams.begin());
  };
  const auto corr = [&](std::size_t a, std::size_t b) {
    const Eigen::Index i = index(a), j = index(b);
    return cov(i, j) / std::sqrt(cov(i, i) * cov(j, j));
  };
  const std::size_t mid1 = (map.regions[1].first + map.regions[1].last) / 2;
  const std::size_t mid2 = (map.regions[2].first + map.regions[2].last) / 2;
  EXPECT_GT(corr(mid1, mid1 + 5), 0.9);
  EXPECT_LT(std::abs(corr(mid1, mid2)), corr(mid1, mid1 + 5));
  // The prior's own correlation of neighbours five apart is 0.3^5 = 0.002.
}

TEST(Posterior, EigenvariationsAreUnitAndOrderedAndIntrinsicOnesChangeTheMap) {
  const Scene scene = BuiltinScene("rectangle").value();
  const Scan scan = SimulateScene(scene, Sensor("utm30"), Se2(0.3, -0.2, 0.4), 5);
  const dsl::CompiledPrior prior = Prior("rectangular");
  const MapScan map = EstimateMapScan(scan, prior);
  ASSERT_TRUE(map.feasible);
  const Posterior post = AnalysePosterior(scan, prior, map);
  ASSERT_TRUE(post.computed);
  ASSERT_EQ(post.eigenvariations.size(), 5u);  // dim Free = 5
  ASSERT_EQ(post.intrinsic_eigenvariations.size(), 2u);
  for (std::size_t k = 0; k < post.eigenvariations.size(); ++k) {
    const Eigenvariation& ev = post.eigenvariations[k];
    double norm = 0.0;
    for (std::size_t b : map.inmodel_beams)
      norm += ev.rho[b] * ev.rho[b] + ev.alpha[b] * ev.alpha[b];
    EXPECT_NEAR(norm, 1.0, 1e-9);
    if (k > 0) {
      EXPECT_LE(ev.sigma, post.eigenvariations[k - 1].sigma);
    }
  }
  for (const Eigenvariation& ev : post.intrinsic_eigenvariations) {
    EXPECT_NEAR(ev.intrinsic_fraction, 1.0, 1e-9);
    EXPECT_GT(ev.sigma, 0.0);
  }
}

TEST(Posterior, ProjectedFormIsNeverNarrowerOnTheRangesOfStraightWalls) {
  // The paper's P A^-1 P^T is wider than the conditional covariance in general (it mixes
  // metres and radians), and never narrower on the ranges of a straight wall.
  const Scene scene = BuiltinScene("square").value();
  const Scan scan = SimulateScene(scene, Sensor("lms200"), Se2(0.3, -0.2, 0.4), 2);
  const dsl::CompiledPrior prior = Prior("rectangular");
  const MapScan map = EstimateMapScan(scan, prior);
  PosteriorOptions projected;
  projected.form = CovarianceForm::kProjected;
  const Posterior a = AnalysePosterior(scan, prior, map);
  const Posterior b = AnalysePosterior(scan, prior, map, projected);
  ASSERT_TRUE(a.computed && b.computed);
  EXPECT_EQ(a.dof.free, b.dof.free);
  for (std::size_t beam : map.inmodel_beams) {
    EXPECT_GE(b.posterior_std_rho[beam], 0.999 * a.posterior_std_rho[beam]) << beam;
  }
}

TEST(Posterior, APriorOfEnergiesOnlyLeavesEverythingFreeButStillGivesStandardDeviations) {
  const Scene scene = BuiltinScene("circle").value();
  const Scan scan = SimulateScene(scene, Sensor("lms200"), Se2(0.3, -0.2, 0.4), 4);
  // The splines prior as Fig. 2g of the paper writes it: a cost on the normals' turn, nothing
  // else (the library's splines prior also ties the normals to the chords).
  const dsl::CompiledPrior prior = dsl::PriorLibrary()
                                       .CompileText(R"(name: Smooth normals
order: 2
max_curvature: 10
priorlet same_region:
  model_likelihood ( alpha_2 - alpha_1 )^2
)",
                                                    "smooth-normals.prior")
                                       .value();
  const MapScan map = EstimateMapScan(scan, prior);
  PosteriorOptions options;
  options.max_free_dimension = 100;
  const Posterior post = AnalysePosterior(scan, prior, map, options);
  EXPECT_EQ(post.dof.free, 2 * map.inmodel_beams.size());
  EXPECT_FALSE(post.computed);
  EXPECT_TRUE(post.eigenvariations.empty());
  EXPECT_NE(post.note.find("dim Free"), std::string::npos) << post.note;
  for (std::size_t b : map.inmodel_beams) {
    // Nothing constrains the ranges, and the smoothness energy is on the normals only.
    EXPECT_NEAR(post.posterior_std_rho[b], post.prior_std_rho[b], 1e-12) << b;
    EXPECT_LT(post.posterior_std_alpha[b], post.prior_std_alpha[b]) << b;
  }
  // The full computation agrees where it runs.
  const Posterior full = AnalysePosterior(scan, prior, map);
  ASSERT_TRUE(full.computed);
  for (std::size_t b : map.inmodel_beams) {
    EXPECT_NEAR(full.posterior_std_alpha[b], post.posterior_std_alpha[b], 1e-9) << b;
  }
}

TEST(Posterior, WithoutInModelPointsReportsWhy) {
  Scan scan;
  scan.angles = {0.0, 0.1};
  scan.ranges = {1.0, 1.0};
  scan.sigma = {0.01, 0.01};
  scan.status = {BeamStatus::kMaxRange, BeamStatus::kMaxRange};
  const dsl::CompiledPrior prior = Prior("polygonal");
  const MapScan map = EstimateMapScan(scan, prior);
  const Posterior post = AnalysePosterior(scan, prior, map);
  EXPECT_FALSE(post.computed);
  EXPECT_EQ(post.dof.free, 0u);
  EXPECT_FALSE(post.note.empty());
}

// A noise-free scan of `count` beams over [first, last] with ranges range(phi).
template <typename Range>
Scan ExactScan(std::size_t count, double first, double last, Range range) {
  Scan scan;
  scan.angles = EvenlySpacedAngles(count, first, last);
  for (double phi : scan.angles) scan.ranges.push_back(range(phi));
  scan.sigma.assign(count, 0.01);
  scan.status.assign(count, BeamStatus::kValid);
  scan.min_range = 0.1;
  scan.max_range = 30.0;
  return scan;
}

// A straight wall leaves two parameters, both of which a sensor motion changes; the motion along
// the wall changes no reading. That holds however the wall is turned, also when it faces the
// sensor exactly and the motion along it is the sensor's y (a Jacobian column of rounding).
TEST(Posterior, AStraightWallHasTwoExtrinsicDegreesOfFreedomHoweverItIsTurned) {
  const dsl::CompiledPrior prior = Prior("polygonal");
  for (const double normal : {0.0, 0.3, 0.5 * std::numbers::pi}) {
    SCOPED_TRACE(normal);
    const Scan scan = ExactScan(200, normal - 0.5, normal + 0.5,
                                [&](double phi) { return 2.0 / std::cos(phi - normal); });
    const MapScan map = EstimateMapScan(scan, prior);
    ASSERT_TRUE(map.feasible);
    ASSERT_EQ(map.regions.size(), 1u);
    const Posterior post = AnalysePosterior(scan, prior, map);
    EXPECT_EQ(post.dof.free, 2u);
    EXPECT_EQ(post.dof.extrinsic, 2u);
    EXPECT_EQ(post.dof.intrinsic, 0u);
    EXPECT_TRUE(post.dof.pose_independent) << post.note;
  }
}

// From the centre of a circular room a rotation changes no reading: Extr is the two
// translations, inside Free (centre and radius), and the radius is the one intrinsic freedom.
TEST(Posterior, AtTheCentreOfACircularRoomTheRotationIsNoExtrinsicDirection) {
  const dsl::CompiledPrior prior = Prior("circular");
  const Scan scan = ExactScan(200, -1.5, 1.5, [](double) { return 2.0; });
  const MapScan map = EstimateMapScan(scan, prior);
  ASSERT_TRUE(map.feasible);
  ASSERT_EQ(map.regions.size(), 1u);
  const Posterior post = AnalysePosterior(scan, prior, map);
  EXPECT_EQ(post.dof.free, 3u);
  EXPECT_EQ(post.dof.extrinsic, 2u);
  EXPECT_EQ(post.dof.intrinsic, 1u);
  EXPECT_TRUE(post.dof.pose_independent) << post.note;
}

}  // namespace
}  // namespace priormap::priorlets
