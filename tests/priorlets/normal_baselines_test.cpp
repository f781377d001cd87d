#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <map>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/priorlets/normal_baselines.hpp>

namespace priormap::priorlets {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kNoiseless = 1e-9;  // sigma must be positive; this is far below every tolerance
constexpr LineFitModel kModels[] = {LineFitModel::kOrthogonal, LineFitModel::kRadial};

Scan Simulate(const std::string& scene_name, double sigma, std::uint64_t seed,
              double outlier_probability = 0.0) {
  const Scene scene = *BuiltinScene(scene_name);
  RangeSensor sensor = *RangeSensor::Preset("utm30");
  sensor.sigma = sigma;
  sensor.outlier_probability = outlier_probability;
  Rng rng(seed);
  return SimulateScan(SceneRayCaster(scene), sensor, *scene.default_pose, rng);
}

Scan SimulateSquare(double sigma, std::uint64_t seed) {
  return Simulate("square", sigma, seed);
}

std::vector<int> SquareLabels(const Scan& scan) {
  return StraightRegionLabels(scan, *BuiltinScene("square"));
}

double AbsError(double estimate, double truth) {
  return std::abs(AngleDifference(estimate, truth));
}

// Valid beams by label, as OracleLineFitNormals groups them.
std::map<int, std::vector<std::size_t>> Groups(const Scan& scan, std::span<const int> labels) {
  std::map<int, std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan.IsValid(i) && labels[i] >= 0) groups[labels[i]].push_back(i);
  }
  return groups;
}

// Beams whose whole window i - half .. i + half is valid and on one wall, by wall.
std::map<int, std::vector<std::size_t>> InteriorBeams(const Scan& scan, int half) {
  std::map<int, std::vector<std::size_t>> out;
  const auto h = static_cast<std::size_t>(half);
  for (std::size_t i = h; i + h < scan.size(); ++i) {
    const int region = scan.truth->region[i];
    bool same = region >= 0;
    for (std::size_t j = i - h; same && j <= i + h; ++j) {
      same = scan.IsValid(j) && scan.truth->region[j] == region;
    }
    if (same) out[region].push_back(i);
  }
  return out;
}

// Valid beams whose window i - half .. i + half sees two walls.
std::vector<std::size_t> CornerBeams(const Scan& scan, int half) {
  std::vector<std::size_t> out;
  const auto h = static_cast<std::size_t>(half);
  for (std::size_t i = h; i + h < scan.size(); ++i) {
    if (!scan.IsValid(i)) continue;
    bool mixed = false;
    for (std::size_t j = i - h; j <= i + h; ++j) {
      mixed = mixed || scan.truth->region[j] != scan.truth->region[i];
    }
    if (mixed) out.push_back(i);
  }
  return out;
}

std::vector<std::size_t> Window(std::size_t i, int half) {
  std::vector<std::size_t> window;
  const auto h = static_cast<std::size_t>(half);
  for (std::size_t j = i - h; j <= i + h; ++j) window.push_back(j);
  return window;
}

// Small-noise error of a fitted normal angle, e ~ N(bias, sd^2), rad.
struct ErrorPrediction {
  double bias = 0.0;
  double sd = 0.0;
  // Mean and variance of |e| (folded normal).
  [[nodiscard]] double MeanAbs() const {
    const double z = bias / sd;
    return sd * std::sqrt(2.0 / kPi) * std::exp(-0.5 * z * z) + bias * std::erf(z / std::sqrt(2.0));
  }
  [[nodiscard]] double VarAbs() const { return bias * bias + sd * sd - MeanAbs() * MeanAbs(); }
};

// Linearised error of a line fitted to `beams` (one straight wall) under the simulator's radial
// noise, around the true line p . n(alpha_out) = rho. kRadial is maximum likelihood, so its
// covariance is the inverse Fisher information of the range residuals. kOrthogonal minimises
// orthogonal distances d_i = n . p_i - rho whose noise is sigma_i cos(x_i) (x_i: incidence), so
// its covariance is the sandwich H^-1 M H^-1; its bias is the minor axis of the expected
// scatter, which the noise inflates by sum_i w_i (1 - w_i / W) sigma_i^2 u_i u_i^T (not
// isotropic). This is the closed form that sigma / (L sqrt(N / 12)) approximates for evenly
// spaced points and isotropic noise.
ErrorPrediction PredictError(const Scan& scan, std::span<const std::size_t> beams,
                             LineFitModel model) {
  const ScanTruth& truth = *scan.truth;
  const std::size_t i0 = beams.front();
  const double alpha_out = truth.alpha[i0] + kPi;
  const double rho = truth.range[i0] * std::cos(scan.angles[i0] - alpha_out);
  const Vec2 n = UnitVector(alpha_out);
  double total_weight = 0.0;
  Vec2 centroid = Vec2::Zero();
  for (std::size_t i : beams) {
    total_weight += 1.0 / (scan.sigma[i] * scan.sigma[i]);
    centroid += truth.range[i] * UnitVector(scan.angles[i]) / (scan.sigma[i] * scan.sigma[i]);
  }
  centroid /= total_weight;
  Mat2 h = Mat2::Zero(), meat = Mat2::Zero(), scatter = Mat2::Zero();
  for (std::size_t i : beams) {
    const double sigma2 = scan.sigma[i] * scan.sigma[i];
    const double w = 1.0 / sigma2;
    const Vec2 u = UnitVector(scan.angles[i]);
    const Vec2 p = truth.range[i] * u;
    const double x = scan.angles[i] - alpha_out;
    const double c = std::cos(x);
    if (model == LineFitModel::kRadial) {
      const Row2 J_range_line(-rho * std::sin(x) / (c * c), 1.0 / c);
      h += w * J_range_line.transpose() * J_range_line;
      meat += w * J_range_line.transpose() * J_range_line;
    } else {
      const Row2 J_distance_line(Perp(n).dot(p), -1.0);
      h += w * J_distance_line.transpose() * J_distance_line;
      meat += w * w * sigma2 * c * c * J_distance_line.transpose() * J_distance_line;
      scatter += w * (p - centroid) * (p - centroid).transpose() +
                 w * (1.0 - w / total_weight) * sigma2 * u * u.transpose();
    }
  }
  const Mat2 h_inv = h.inverse();
  ErrorPrediction prediction;
  prediction.sd = std::sqrt((h_inv * meat * h_inv)(0, 0));
  if (model == LineFitModel::kOrthogonal) {
    const double minor_axis =
        0.5 * std::atan2(2.0 * scatter(0, 1), scatter(0, 0) - scatter(1, 1)) + kPi / 2;
    prediction.bias = std::asin(std::sin(AngleDifference(minor_axis, alpha_out)));  // mod pi
  }
  return prediction;
}

TEST(NormalBaselineOptions, RejectsEvenOrTooSmallWindows) {
  std::string why;
  EXPECT_TRUE(PcaNormalOptions{}.IsValid(&why)) << why;
  EXPECT_FALSE(PcaNormalOptions{.k = 10}.IsValid(&why));
  EXPECT_NE(why.find("k must be odd"), std::string::npos);
  EXPECT_FALSE(PcaNormalOptions{.k = 1}.IsValid(&why));
  EXPECT_FALSE(PcaNormalOptions{.max_neighbour_distance = 0.0}.IsValid(&why));
  EXPECT_NE(why.find("max_neighbour_distance"), std::string::npos);
  EXPECT_THROW((void)PcaNormals(SimulateSquare(0.01, 1), {.k = 4}), ContractError);
}

TEST(NormalBaselinePca, RecoversTruthOnNoiselessWallsAwayFromCorners) {
  const Scan scan = SimulateSquare(kNoiseless, 1);
  for (int k : {3, 11, PcaNormalOptions{}.k}) {
    for (LineFitModel model : kModels) {
      const std::vector<double> alpha = PcaNormals(scan, {.k = k, .model = model});
      std::size_t checked = 0;
      for (const auto& [region, beams] : InteriorBeams(scan, k / 2)) {
        for (std::size_t i : beams) {
          EXPECT_LT(AbsError(alpha[i], scan.truth->alpha[i]), 1e-6)
              << "k " << k << " model " << ToString(model) << " beam " << i;
          ++checked;
        }
      }
      EXPECT_GT(checked, scan.size() / 2);
    }
  }
}

TEST(NormalBaselineOracle, RecoversTruthLinesOnNoiselessScan) {
  const Scan scan = SimulateSquare(kNoiseless, 1);
  const std::vector<int> labels = SquareLabels(scan);
  EXPECT_EQ(Groups(scan, labels).size(), 4u);  // the sensor sees all four walls
  for (LineFitModel model : kModels) {
    const LineFitResult fit = OracleLineFitNormals(scan, labels, {model});
    for (std::size_t i = 0; i < scan.size(); ++i) {
      ASSERT_TRUE(scan.IsValid(i) && labels[i] >= 0);
      const double true_rho =
          -scan.truth->range[i] * std::cos(scan.angles[i] - scan.truth->alpha[i]);
      EXPECT_LT(AbsError(fit.alpha[i], scan.truth->alpha[i]), 1e-6) << "beam " << i;
      EXPECT_NEAR(fit.rho[i], true_rho, 1e-6) << "beam " << i;
      EXPECT_NEAR(fit.range[i], scan.truth->range[i], 1e-6) << "beam " << i;
    }
  }
}

// Same representative as the truth (towards the sensor, wrapped to (-pi, pi]), not merely the
// same direction: no wall normal of this view is near +-pi, so plain differences are small.
TEST(NormalBaselineConvention, AlphaIsRepresentedLikeTruthAlpha) {
  const Scan scan = SimulateSquare(kNoiseless, 1);
  const std::vector<double> pca = PcaNormals(scan);
  const std::vector<double> oracle = OracleLineFitNormals(scan, SquareLabels(scan)).alpha;
  for (const auto& [region, beams] : InteriorBeams(scan, PcaNormalOptions{}.k / 2)) {
    for (std::size_t i : beams) {
      EXPECT_NEAR(pca[i], scan.truth->alpha[i], 1e-6);
      EXPECT_NEAR(oracle[i], scan.truth->alpha[i], 1e-6);
      EXPECT_LT(std::cos(pca[i] - scan.angles[i]), 0.0);  // points back at the sensor
    }
  }
}

TEST(NormalBaselineInput, InvalidBeamsAreSkipped) {
  Scan scan = SimulateSquare(kNoiseless, 1);
  for (std::size_t i = 0; i < scan.size(); i += 7) {
    scan.ranges[i] = 1e3;  // would wreck any fit that used it
    scan.status[i] = i % 2 == 0 ? BeamStatus::kInvalid : BeamStatus::kMaxRange;
  }
  const int k = PcaNormalOptions{}.k;
  const std::vector<double> pca = PcaNormals(scan, {.k = k});
  const std::vector<int> labels = SquareLabels(scan);
  const LineFitResult oracle = OracleLineFitNormals(scan, labels);
  // Interior with respect to the truth regions: the invalid beams are inside these windows.
  Scan truth_view = scan;
  std::fill(truth_view.status.begin(), truth_view.status.end(), BeamStatus::kValid);
  for (const auto& [region, beams] : InteriorBeams(truth_view, k / 2)) {
    for (std::size_t i : beams) {
      if (scan.IsValid(i)) {
        EXPECT_LT(AbsError(pca[i], scan.truth->alpha[i]), 1e-6) << "beam " << i;
        EXPECT_LT(AbsError(oracle.alpha[i], scan.truth->alpha[i]), 1e-6) << "beam " << i;
      }
    }
  }
  for (std::size_t i = 0; i < scan.size(); i += 7) {
    EXPECT_TRUE(std::isnan(pca[i]));
    EXPECT_TRUE(std::isnan(oracle.alpha[i]) && std::isnan(oracle.rho[i]) &&
                std::isnan(oracle.range[i]));
  }
}

// Two walls seen one behind the other, with a 2 m jump between beams 50 and 51.
TEST(NormalBaselinePca, WindowsStopAtJumps) {
  Scan scan;
  scan.angles = EvenlySpacedAngles(101, -0.5, 0.5);
  scan.max_range = 10.0;
  const double near_alpha_out = 0.0, near_rho = 1.0, far_alpha_out = 0.5, far_rho = 3.0;
  for (std::size_t i = 0; i < scan.angles.size(); ++i) {
    const bool near = i <= 50;
    const double a = near ? near_alpha_out : far_alpha_out;
    scan.ranges.push_back((near ? near_rho : far_rho) / std::cos(scan.angles[i] - a));
  }
  scan.sigma.assign(scan.angles.size(), 0.01);
  scan.ClassifyAll();
  ASSERT_TRUE(scan.Problems().empty());
  const std::vector<double> stopped = PcaNormals(scan, {.k = 11});
  EXPECT_NEAR(AngleDifference(stopped[50], near_alpha_out + kPi), 0.0, 1e-9);
  EXPECT_NEAR(AngleDifference(stopped[51], far_alpha_out + kPi), 0.0, 1e-9);
  const std::vector<double> joined = PcaNormals(scan, {.k = 11, .max_neighbour_distance = 10.0});
  EXPECT_GT(std::abs(AngleDifference(joined[50], near_alpha_out + kPi)), 0.01);
}

TEST(NormalBaselineOracle, UngroupedBeamsAndSingletonsGiveNaN) {
  const Scan scan = SimulateSquare(kNoiseless, 1);
  std::vector<int> labels = SquareLabels(scan);
  const std::size_t singleton = 300;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (labels[i] == labels[singleton] && i != singleton) labels[i] = -1 - static_cast<int>(i % 3);
  }
  const LineFitResult fit = OracleLineFitNormals(scan, labels);
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const bool grouped = labels[i] >= 0 && i != singleton;
    EXPECT_EQ(std::isfinite(fit.alpha[i]), grouped) << "beam " << i;
    EXPECT_EQ(std::isfinite(fit.rho[i]), grouped) << "beam " << i;
  }
  EXPECT_THROW((void)OracleLineFitNormals(scan, std::span(labels).first(10)), ContractError);
}

TEST(NormalBaselineLabels, StraightRegionLabelsDropCirclesAndOutliers) {
  const Scene scene = *BuiltinScene("l-room");
  const Scan scan = Simulate("l-room", 0.01, 3, 0.05);
  const std::vector<int> labels = StraightRegionLabels(scan, scene);
  const std::vector<ScenePrimitive> primitives = scene.Primitives();
  std::size_t circles = 0, outliers = 0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const int region = scan.truth->region[i];
    ASSERT_GE(region, 0);
    const bool circle =
        std::holds_alternative<Circle>(primitives[static_cast<std::size_t>(region)].shape);
    const bool outlier = scan.truth->outlier[i] != 0;
    circles += circle ? 1 : 0;
    outliers += outlier ? 1 : 0;
    EXPECT_EQ(labels[i], circle || outlier ? -1 : region) << "beam " << i;
  }
  EXPECT_GT(circles, 0u);
  EXPECT_GT(outliers, 0u);
}

TEST(NormalBaselineCompare, UsesTheSmallestAngleAndSkipsNonFiniteAndMasked) {
  const std::vector<double> estimate = {kPi - 0.01, 0.3, kNaN, 1.0, 2.0};
  const std::vector<double> truth = {-kPi + 0.01, 0.1, 0.0, kNaN, 2.0 + kTwoPi};
  NormalErrorStats stats = CompareNormals(estimate, truth);
  EXPECT_EQ(stats.count, 3u);
  EXPECT_NEAR(stats.max_deg, RadToDeg(0.2), 1e-9);
  EXPECT_NEAR(stats.mean_deg, RadToDeg(0.22 / 3), 1e-9);
  const std::vector<std::uint8_t> mask = {1, 0, 1, 1, 0};
  stats = CompareNormals(estimate, truth, mask);
  EXPECT_EQ(stats.count, 1u);
  EXPECT_NEAR(stats.mean_deg, RadToDeg(0.02), 1e-9);
  stats = CompareNormals(estimate, truth, std::vector<std::uint8_t>(5, 0));
  EXPECT_EQ(stats.count, 0u);
  EXPECT_TRUE(std::isnan(stats.mean_deg) && std::isnan(stats.max_deg));
}

// One error per wall and seed, independent: the mean |error| is within 4 standard deviations
// of the linearised prediction (walls of 250-290 points, sd ~ 5e-4 rad: well in the linear
// regime).
TEST(NormalBaselineOracle, ErrorMatchesLinearisedPrediction) {
  for (LineFitModel model : kModels) {
    double measured = 0.0, predicted = 0.0, variance = 0.0;
    for (std::uint64_t seed = 1; seed <= 50; ++seed) {
      const Scan scan = SimulateSquare(0.01, seed);
      const std::vector<int> labels = SquareLabels(scan);
      const LineFitResult fit = OracleLineFitNormals(scan, labels, {model});
      for (const auto& [label, beams] : Groups(scan, labels)) {
        const ErrorPrediction p = PredictError(scan, beams, model);
        measured += AbsError(fit.alpha[beams.front()], scan.truth->alpha[beams.front()]);
        predicted += p.MeanAbs();
        variance += p.VarAbs();
      }
    }
    EXPECT_NEAR(measured, predicted, 4.0 * std::sqrt(variance)) << ToString(model);
  }
}

// Errors of overlapping windows are correlated, so the tolerance comes from batch means with one
// batch per wall and seed (independent noise). The linearisation needs the window to be long
// compared with sigma; with k = 31 the shortest window spans ~14 cm against sigma = 1 cm.
TEST(NormalBaselinePca, InteriorErrorMatchesLinearisedPrediction) {
  const int k = PcaNormalOptions{}.k;
  ASSERT_GE(k, 21) << "the prediction is not valid for short windows";
  for (LineFitModel model : kModels) {
    double excess = 0.0, sum_sq_batches = 0.0, predicted = 0.0;
    for (std::uint64_t seed = 1; seed <= 10; ++seed) {
      const Scan scan = SimulateSquare(0.01, seed);
      const std::vector<double> alpha = PcaNormals(scan, {.k = k, .model = model});
      for (const auto& [region, beams] : InteriorBeams(scan, k / 2)) {
        double batch = 0.0;
        for (std::size_t i : beams) {
          const double expected = PredictError(scan, Window(i, k / 2), model).MeanAbs();
          batch += AbsError(alpha[i], scan.truth->alpha[i]) - expected;
          predicted += expected;
        }
        excess += batch;
        sum_sq_batches += batch * batch;
      }
    }
    EXPECT_LT(std::abs(excess), 4.0 * std::sqrt(sum_sq_batches))
        << ToString(model) << ": excess " << excess << " of " << predicted;
  }
}

TEST(NormalBaselinePca, DegradesNearCorners) {
  const int k = PcaNormalOptions{}.k;
  double corner_sum = 0.0, interior_sum = 0.0;
  std::size_t corner_count = 0, interior_count = 0;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const Scan scan = SimulateSquare(0.01, seed);
    const std::vector<double> alpha = PcaNormals(scan, {.k = k});
    for (std::size_t i : CornerBeams(scan, k / 2)) {
      corner_sum += AbsError(alpha[i], scan.truth->alpha[i]);
      ++corner_count;
    }
    for (const auto& [region, beams] : InteriorBeams(scan, k / 2)) {
      for (std::size_t i : beams) interior_sum += AbsError(alpha[i], scan.truth->alpha[i]);
      interior_count += beams.size();
    }
  }
  ASSERT_GT(corner_count, 0u);
  const double corner_mean = corner_sum / static_cast<double>(corner_count);
  const double interior_mean = interior_sum / static_cast<double>(interior_count);
  RecordProperty("corner_mean_deg", fmt::format("{:.3f}", RadToDeg(corner_mean)));
  RecordProperty("interior_mean_deg", fmt::format("{:.3f}", RadToDeg(interior_mean)));
  // Corner windows mix two normals 90 degrees apart, a bias of tens of degrees at the corner.
  EXPECT_GT(corner_mean, 3.0 * interior_mean);
}

// The benchmark setting (square, utm30, sigma = 1 cm), seeds 1..5. Prints the table the default
// k was chosen from.
TEST(NormalBaselineAccuracy, OracleBeatsPcaOnTheSquareRoom) {
  constexpr std::uint64_t kSeeds = 5;
  std::vector<Scan> scans;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) scans.push_back(SimulateSquare(0.01, seed));
  const auto mean_error = [&](const auto& estimator) {
    double sum = 0.0;
    for (const Scan& scan : scans)
      sum += CompareNormals(estimator(scan), scan.truth->alpha).mean_deg;
    return sum / static_cast<double>(kSeeds);
  };
  std::map<LineFitModel, double> oracle;
  for (LineFitModel model : kModels) {
    oracle[model] = mean_error([&](const Scan& scan) {
      return OracleLineFitNormals(scan, SquareLabels(scan), {model}).alpha;
    });
    const std::string line = fmt::format("oracle {}: {:.4f} deg", ToString(model), oracle[model]);
    std::cout << "[ measured ] " << line << "\n";
    RecordProperty(fmt::format("oracle_{}_deg", ToString(model)),
                   fmt::format("{:.4f}", oracle[model]));
  }
  for (int k : {5, 11, 21, 31}) {
    for (LineFitModel model : kModels) {
      const double pca =
          mean_error([&](const Scan& scan) { return PcaNormals(scan, {.k = k, .model = model}); });
      std::cout << fmt::format("[ measured ] pca k={} {}: {:.3f} deg\n", k, ToString(model), pca);
      RecordProperty(fmt::format("pca_k{}_{}_deg", k, ToString(model)), fmt::format("{:.3f}", pca));
      EXPECT_LT(oracle[LineFitModel::kRadial], pca);
      EXPECT_LT(oracle[LineFitModel::kOrthogonal], pca);
    }
  }
}

}  // namespace
}  // namespace priormap::priorlets
