// Fitting the sonar model: on readings drawn from a known model the fit finds its parameters
// again (within a few standard errors) and a likelihood at least the truth's, the same bits on
// every run; and the readings of a simulated log come with their views of the scene's true map.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/check.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/core/sonar_simulate.hpp>
#include <priormap/prf/coloring.hpp>
#include <priormap/prf/sonar_data.hpp>
#include <priormap/prf/sonar_fit.hpp>

namespace priormap::prf {
namespace {

constexpr double kMaxRange = 5.0;

// Inside the fit's bounds, with slopes moderate enough that each is seen across the features'
// range (none saturates the logistic); sigma_min is the default's, which the fit keeps.
SonarModel TrueModel() {
  SonarModel m;
  m.corner_bias = 0.5;
  m.corner_per_m = -0.3;
  m.concave_corner_bias = 1.0;
  m.face_bias = 0.5;
  m.face_per_m = -0.4;
  m.face_per_rad_projection = 20.0;
  m.face_per_rad_subtended = 8.0;
  m.max_return = 0.9;
  m.sigma_relative = 0.02;
  m.uniform_weight = 0.3;
  m.exponential_weight = 0.2;
  m.max_weight = 0.5;
  m.exponential_rate = 1.5;
  m.clear_uniform_weight = 0.1;
  m.clear_exponential_weight = 0.1;
  m.clear_max_weight = 0.8;
  return m;
}

// A start far from TrueModel: every parameter at least one of the recovery test's tolerances
// away (most of them two or more), so that no parameter passes by being left where it started.
SonarModel FarStart() {
  SonarModel m;
  m.corner_bias = -2.0;
  m.corner_per_m = -1.0;
  m.concave_corner_bias = -0.5;
  m.face_bias = -2.5;
  m.face_per_m = -1.2;
  m.face_per_rad_projection = 60.0;
  m.face_per_rad_subtended = 25.0;
  m.max_return = 0.5;
  m.sigma_relative = 0.01;
  m.uniform_weight = 0.05;
  m.exponential_weight = 0.6;
  m.max_weight = 0.35;
  m.exponential_rate = 4.0;
  m.clear_uniform_weight = 0.4;
  m.clear_exponential_weight = 0.3;
  m.clear_max_weight = 0.3;
  return m;
}

// Views as a cone might see them: up to three features in depth order, faces near normal
// incidence or oblique, corners concave or not, and any share of the cone seen; each reading
// drawn from `model`.
std::vector<SonarFitReading> SyntheticReadings(const SonarModel& model, int count,
                                               std::uint64_t seed, bool with_multipath = false) {
  Rng rng(seed);
  std::vector<SonarFitReading> readings;
  for (int i = 0; i < count; ++i) {
    SonarFitReading r;
    r.max_range = kMaxRange;
    const auto features = static_cast<int>(rng.UniformIndex(4));
    for (int k = 0; k < features; ++k) {
      SonarFeature f;
      f.distance = rng.Uniform(0.5, 4.5);
      if (rng.Bernoulli(0.5)) {
        f.kind = SonarFeature::Kind::kFace;
        f.projection = rng.Bernoulli(0.5) ? std::numbers::pi / 2 - rng.Uniform(0.0, 0.05)
                                          : rng.Uniform(1.0, 1.5);
        f.subtended = rng.Uniform(0.05, 0.35);
      } else {
        f.kind = SonarFeature::Kind::kCorner;
        f.concave = rng.Bernoulli(0.5);
      }
      r.features.push_back(f);
    }
    std::sort(r.features.begin(), r.features.end(),
              [](const SonarFeature& a, const SonarFeature& b) { return a.distance < b.distance; });
    r.seen_fraction = features == 0 ? rng.Uniform(0.0, 0.3) : rng.Uniform(0.3, 1.0);
    // A mirrored path for most cones that see a face: within R, or beyond it (not heard).
    if (with_multipath && features > 0 && rng.Bernoulli(0.8)) {
      const double path = rng.Uniform(1.0, 7.0);
      r.multipath = path < kMaxRange ? path : std::numeric_limits<double>::infinity();
    }
    const SonarModel::Draw draw =
        model.Sample(r.features, r.seen_fraction, kMaxRange, rng, r.multipath);
    r.range = draw.range;
    r.max_reading = draw.max_reading;
    readings.push_back(std::move(r));
  }
  return readings;
}

void ExpectSameBits(const SonarModel& a, const SonarModel& b) {
  for (const auto& [name, member] : kSonarModelParameters)
    EXPECT_EQ(std::bit_cast<std::uint64_t>(a.*member), std::bit_cast<std::uint64_t>(b.*member))
        << name;
}

TEST(SonarFit, FindsTheParametersOfTheModelThatMadeTheReadings) {
  const SonarModel truth = TrueModel();
  ASSERT_EQ(truth.Problem(), "");
  const std::vector<SonarFitReading> readings = SyntheticReadings(truth, 3000, 5);
  const SonarModel start = FarStart();
  ASSERT_EQ(start.Problem(), "");
  const SonarFitResult fit = FitSonarModel(readings, start);
  const SonarModel& m = fit.model;
  EXPECT_EQ(fit.readings, readings.size());
  EXPECT_GT(fit.evaluations, 0);
  EXPECT_EQ(m.sigma_min, SonarModel{}.sigma_min);
  EXPECT_EQ(m.Problem(), "");
  // The fit maximizes the likelihood plus a weak prior on the mixtures' weights (well under a
  // nat between the truth and the fit), so it can fall short of the truth's likelihood by no
  // more than that prior's difference; in fact the maximum of 3000 readings' likelihood was 4
  // to 11 nats above the truth's over ten data seeds (about half the chi-square with 16
  // degrees of freedom).
  const double true_log_likelihood = FitLogLikelihood(readings, truth);
  EXPECT_GE(fit.log_likelihood, true_log_likelihood - 1.0);
  EXPECT_EQ(fit.log_likelihood, FitLogLikelihood(readings, m));
  EXPECT_EQ(fit.initial_log_likelihood, FitLogLikelihood(readings, start));
  EXPECT_GT(fit.log_likelihood, fit.initial_log_likelihood + 100.0);
  // Tolerances of four standard errors, the standard deviation of each fitted value over fits
  // to ten sets of 3000 readings drawn with other seeds (e.g. 0.24 for corner_bias, 0.05 for
  // corner_per_m, 4 for face_per_rad_projection, 0.06 for max_return, 0.05 for uniform_weight;
  // the biases and max_return trade off against each other, hence their spread).
  EXPECT_NEAR(m.corner_bias, truth.corner_bias, 1.0);
  EXPECT_NEAR(m.corner_per_m, truth.corner_per_m, 0.2);
  EXPECT_NEAR(m.concave_corner_bias, truth.concave_corner_bias, 0.7);
  EXPECT_NEAR(m.face_bias, truth.face_bias, 1.2);
  EXPECT_NEAR(m.face_per_m, truth.face_per_m, 0.35);
  EXPECT_NEAR(m.face_per_rad_projection, truth.face_per_rad_projection, 16.0);
  EXPECT_NEAR(m.face_per_rad_subtended, truth.face_per_rad_subtended, 6.0);
  EXPECT_NEAR(m.max_return, truth.max_return, 0.24);
  EXPECT_NEAR(m.sigma_relative, truth.sigma_relative, 0.002);
  EXPECT_NEAR(m.uniform_weight, truth.uniform_weight, 0.2);
  EXPECT_NEAR(m.exponential_weight, truth.exponential_weight, 0.14);
  EXPECT_NEAR(m.max_weight, truth.max_weight, 0.12);
  EXPECT_NEAR(m.exponential_rate, truth.exponential_rate, 0.7);
  EXPECT_NEAR(m.clear_uniform_weight, truth.clear_uniform_weight, 0.08);
  EXPECT_NEAR(m.clear_exponential_weight, truth.clear_exponential_weight, 0.06);
  EXPECT_NEAR(m.clear_max_weight, truth.clear_max_weight, 0.06);
  // The two mixtures are told apart: the clear one has the larger max-range weight.
  EXPECT_GT(m.clear_max_weight, m.max_weight + 0.15);
}

TEST(SonarFit, FindsTheMultipathWeightAndSpread) {
  SonarModel truth = TrueModel();
  truth.multipath_weight = 0.35;
  truth.multipath_sigma_relative = 0.03;
  ASSERT_EQ(truth.Problem(), "");
  const std::vector<SonarFitReading> readings = SyntheticReadings(truth, 3000, 15, true);
  const SonarFitResult fit = FitSonarModel(readings, SonarModel{});
  EXPECT_GE(fit.log_likelihood, FitLogLikelihood(readings, truth) - 1.0);
  // About 2000 readings have a path and about a third of them are outliers, a third of those
  // multipath: the weight is known to a few hundredths, the spread to a few thousandths.
  EXPECT_NEAR(fit.model.multipath_weight, truth.multipath_weight, 0.08);
  EXPECT_NEAR(fit.model.multipath_sigma_relative, truth.multipath_sigma_relative, 0.008);
  // Without the component the same readings are much less likely.
  SonarFitOptions without;
  without.fit_multipath = false;
  EXPECT_GT(fit.log_likelihood,
            FitSonarModel(readings, SonarModel{}, without).log_likelihood + 50.0);
}

TEST(SonarFit, IsDeterministic) {
  const std::vector<SonarFitReading> readings = SyntheticReadings(TrueModel(), 1000, 6);
  SonarFitOptions options;
  options.rounds = 2;
  const SonarFitResult first = FitSonarModel(readings, SonarModel{}, options);
  const SonarFitResult second = FitSonarModel(readings, SonarModel{}, options);
  ExpectSameBits(first.model, second.model);
  EXPECT_EQ(std::bit_cast<std::uint64_t>(first.log_likelihood),
            std::bit_cast<std::uint64_t>(second.log_likelihood));
  EXPECT_EQ(first.evaluations, second.evaluations);
}

TEST(SonarFit, OptionsLeavingPartsOutKeepThePapersModel) {
  const std::vector<SonarFitReading> readings = SyntheticReadings(TrueModel(), 1000, 7);
  SonarFitOptions options;
  options.fit_clear_mixture = false;
  options.fit_concave_corners = false;
  options.fit_multipath = false;
  options.rounds = 1;
  // From a start that has both components (as a fitted model file given to --start).
  SonarModel start;
  start.concave_corner_bias = 2.9;
  start.multipath_weight = 0.375;
  const SonarFitResult fit = FitSonarModel(readings, start, options);
  EXPECT_EQ(fit.model.concave_corner_bias, 0.0);
  EXPECT_EQ(fit.model.multipath_weight, 0.0);
  EXPECT_EQ(fit.model.clear_uniform_weight, fit.model.uniform_weight);
  EXPECT_EQ(fit.model.clear_exponential_weight, fit.model.exponential_weight);
  EXPECT_EQ(fit.model.clear_max_weight, fit.model.max_weight);
  // ... and fit the rest: the distance slope moves from the start's towards the truth's.
  EXPECT_NE(fit.model.face_per_m, SonarModel{}.face_per_m);
  EXPECT_GT(fit.log_likelihood, fit.initial_log_likelihood);
}

// A coloring of the window [0, 4] x [0, 3] black beyond the wall x = 3 (which ends on the
// bottom and top sides), and one cone from `sensor` along +x.
struct WallCase {
  Coloring truth;
  std::shared_ptr<const SonarData> data;
};
WallCase Wall(const Vec2& sensor) {
  const Window window{Vec2::Zero(), Vec2(4, 3)};
  const std::vector<NewVertex> vertices = {{Vec2(3, 0), 0}, {Vec2(3, 3), 2}};
  const std::vector<std::array<int, 2>> edges = {{0, 1}};
  auto truth = Coloring::FromGraph(window, 0.5, vertices, edges, Colour::kWhite);
  auto data = std::make_shared<SonarData>();
  data->sensors = {sensor};
  data->max_range = kMaxRange;
  data->readings.push_back({.cone = {.origin = sensor,
                                     .axis = Vec2::UnitX(),
                                     .half_spread = 0.2,
                                     .max_range = kMaxRange},
                            .range = 2.05,
                            .max_reading = false,
                            .sensor = 0});
  return {std::get<Coloring>(std::move(truth)), std::move(data)};
}

TEST(SonarFit, ViewsOfPairEachReadingWithWhatTheTrueMapShowsItsCone) {
  const WallCase wall = Wall(Vec2(1, 1.5));
  ASSERT_EQ(wall.truth.ColourAt(Vec2(3.5, 1.5)), Colour::kBlack);
  const std::vector<SonarFitReading> readings = ViewsOf(wall.data, wall.truth);
  ASSERT_EQ(readings.size(), 1u);
  EXPECT_EQ(readings[0].range, 2.05);
  EXPECT_FALSE(readings[0].max_reading);
  EXPECT_EQ(readings[0].max_range, kMaxRange);
  EXPECT_EQ(readings[0].seen_fraction, 1.0);
  // One face at normal incidence 2 m away; the wall's ends are on the window's sides, so no
  // corner.
  ASSERT_EQ(readings[0].features.size(), 1u);
  const SonarFeature& face = readings[0].features[0];
  EXPECT_EQ(face.kind, SonarFeature::Kind::kFace);
  EXPECT_NEAR(face.distance, 2.0, 1e-12);
  EXPECT_NEAR(face.projection, std::numbers::pi / 2, 1e-12);
  EXPECT_NEAR(face.subtended, 0.4, 1e-12);
  // Mirrored head-on, the axis's path goes back out through the window's left side: nothing
  // heard within R.
  ASSERT_TRUE(readings[0].multipath);
  EXPECT_EQ(*readings[0].multipath, std::numeric_limits<double>::infinity());
  // A sensor inside black is a broken precondition.
  const WallCase inside = Wall(Vec2(3.5, 1.5));
  EXPECT_THROW((void)ViewsOf(inside.data, inside.truth), ContractError);
}

TEST(SonarFit, ViewsOfASimulatedOfficeLogPairEachReadingWithWhatItsConeSees) {
  const Scene scene = *BuiltinScene("office");
  const SonarSensor sensor = *SonarSensor::Preset("pioneer16");
  // Every 12th pose of the path: eight or nine rings along the corridor and into a room.
  const auto path = TrajectoryFromWaypoints(scene.waypoints, 0.5, 2.0);
  std::vector<TimedPose> poses;
  for (std::size_t i = 0; i < path.size(); i += 12) poses.push_back(path[i]);
  const Log log = SimulateSonarLog(scene, sensor, poses, 3);
  const auto views = ViewsOfScene(log, scene, kMaxRange);
  ASSERT_TRUE(std::holds_alternative<std::vector<SonarFitReading>>(views))
      << std::get<std::string>(views);
  const auto& readings = std::get<std::vector<SonarFitReading>>(views);
  const auto selected =
      SelectSonarReadings(log, {.first_scan = 0, .end_scan = std::nullopt, .max_range = kMaxRange});
  ASSERT_TRUE(selected.ok()) << selected.error();
  const SonarData& data = selected.value();
  ASSERT_EQ(readings.size(), data.readings.size());
  ASSERT_GT(readings.size(), 100u);
  std::size_t with_features = 0;
  for (std::size_t i = 0; i < readings.size(); ++i) {
    const SonarFitReading& r = readings[i];
    EXPECT_EQ(r.range, data.readings[i].range);
    EXPECT_EQ(r.max_reading, data.readings[i].max_reading);
    EXPECT_EQ(r.max_range, data.max_range);
    EXPECT_GE(r.seen_fraction, 0.0);
    EXPECT_LE(r.seen_fraction, 1.0);
    const bool has_face = std::any_of(r.features.begin(), r.features.end(), [](const auto& f) {
      return f.kind == SonarFeature::Kind::kFace;
    });
    // A share of the cone sees a face exactly when some face is a feature.
    EXPECT_EQ(has_face, r.seen_fraction > 0.0) << "reading " << i;
    EXPECT_TRUE(
        std::is_sorted(r.features.begin(), r.features.end(),
                       [](const auto& a, const auto& b) { return a.distance < b.distance; }));
    with_features += r.features.empty() ? 0 : 1;
  }
  // In a 2 m corridor and its rooms most cones meet a wall within 5 m.
  EXPECT_GT(with_features, readings.size() * 3 / 4);
  // A fit to them runs and improves on the start.
  SonarFitOptions options;
  options.rounds = 1;
  options.max_evaluations = 2000;
  const SonarFitResult fit = FitSonarModel(readings, SonarModel{}, options);
  EXPECT_GE(fit.log_likelihood, fit.initial_log_likelihood);
}

TEST(SonarFit, ViewsOfSceneExplainWhatIsMissing) {
  const Scene corridor = *BuiltinScene("corridor");  // an open wall polyline: no true coloring
  const SonarSensor sensor = *SonarSensor::Preset("pioneer16");
  const auto path = TrajectoryFromWaypoints(corridor.waypoints, 0.5, 2.0);
  const Log log = SimulateSonarLog(corridor, sensor, {path.begin(), path.begin() + 2}, 3);
  const auto views = ViewsOfScene(log, corridor, kMaxRange);
  ASSERT_TRUE(std::holds_alternative<std::string>(views));
  EXPECT_NE(std::get<std::string>(views).find("scene corridor"), std::string::npos)
      << std::get<std::string>(views);
  // A log without sonar.
  const auto none = ViewsOfScene(Log{}, *BuiltinScene("office"), kMaxRange);
  EXPECT_TRUE(std::holds_alternative<std::string>(none));
}

}  // namespace
}  // namespace priormap::prf
