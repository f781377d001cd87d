// Line segments from MAP-scan regions: the fitted polar line against the true one, and the
// propagated covariance against the spread of fits over many noisy scans.
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <priormap/core/angles.hpp>
#include <priormap/priorlets/line_segments.hpp>

namespace priormap::priorlets {
namespace {

// The wall whose normal from the sensor has direction `angle` at distance `radius`, seen by
// beams over [-0.5, 0.5] rad around the normal, with Gaussian range noise: a scan and the MAP
// scan that keeps the readings as they are, all in one region.
struct WallScan {
  Scan scan;
  MapScan map;
};

WallScan MakeWallScan(double radius, double angle, double sigma, std::mt19937_64* rng) {
  std::normal_distribution<double> noise(0.0, sigma);
  WallScan w;
  const int n = 101;
  for (int i = 0; i < n; ++i) {
    const double bearing = angle - 0.5 + i * (1.0 / (n - 1));
    w.scan.angles.push_back(bearing);
    w.scan.ranges.push_back(radius / std::cos(bearing - angle) + noise(*rng));
    w.scan.sigma.push_back(sigma);
    w.scan.status.push_back(BeamStatus::kValid);
    w.map.inmodel.push_back(1);
    w.map.inmodel_beams.push_back(static_cast<std::size_t>(i));
  }
  w.map.rho = w.scan.ranges;
  w.map.regions = {{0, static_cast<std::size_t>(n - 1)}};
  return w;
}

TEST(LineSegments, FitsTheTrueLineWithinItsCovarianceAndTheSpreadMatchesIt) {
  const double radius = 2.5, angle = 2.9, sigma = 0.01;
  std::mt19937_64 rng(11);
  const int trials = 400;
  std::vector<Vec2> errors;
  Mat2 predicted = Mat2::Zero();
  for (int t = 0; t < trials; ++t) {
    const WallScan w = MakeWallScan(radius, angle, sigma, &rng);
    const LineSegments lines = ExtractLineSegments(w.scan, w.map, nullptr);
    ASSERT_EQ(lines.segments.size(), 1u);
    EXPECT_EQ(lines.covariance_source, SegmentCovarianceSource::kSensor);
    const LineSegment& s = lines.segments.front();
    errors.emplace_back(s.radius - radius, WrapAngle(s.angle - angle));
    predicted += s.covariance / trials;
  }
  Vec2 mean = Vec2::Zero();
  for (const Vec2& e : errors) mean += e / trials;
  Mat2 empirical = Mat2::Zero();
  for (const Vec2& e : errors) empirical += (e - mean) * (e - mean).transpose() / (trials - 1);
  // Unbiased: the mean error within 4 standard errors.
  EXPECT_LT(std::abs(mean.x()), 4.0 * std::sqrt(predicted(0, 0) / trials));
  EXPECT_LT(std::abs(mean.y()), 4.0 * std::sqrt(predicted(1, 1) / trials));
  // The propagated covariance is the spread of the fits (variances within 20 %, from 400
  // samples their relative standard error is 7 %; the correlation within 0.15).
  EXPECT_NEAR(empirical(0, 0) / predicted(0, 0), 1.0, 0.2);
  EXPECT_NEAR(empirical(1, 1) / predicted(1, 1), 1.0, 0.2);
  const double rho_empirical = empirical(0, 1) / std::sqrt(empirical(0, 0) * empirical(1, 1));
  const double rho_predicted = predicted(0, 1) / std::sqrt(predicted(0, 0) * predicted(1, 1));
  EXPECT_NEAR(rho_empirical, rho_predicted, 0.15);
}

TEST(LineSegments, EndpointsLieOnTheLineAndTheConventionIsPositiveRadius) {
  std::mt19937_64 rng(3);
  const WallScan w = MakeWallScan(1.5, -2.0, 0.005, &rng);
  const LineSegments lines = ExtractLineSegments(w.scan, w.map, nullptr);
  ASSERT_EQ(lines.segments.size(), 1u);
  const LineSegment& s = lines.segments.front();
  EXPECT_GT(s.radius, 0.0);
  EXPECT_NEAR(s.angle, -2.0, 0.01);
  const Vec2 normal(std::cos(s.angle), std::sin(s.angle));
  EXPECT_NEAR(normal.dot(s.start), s.radius, 1e-12);
  EXPECT_NEAR(normal.dot(s.end), s.radius, 1e-12);
  // The first beam is at the smaller bearing: the start is there.
  EXPECT_LT(std::atan2(s.start.y(), s.start.x()), std::atan2(s.end.y(), s.end.x()));
  const nlohmann::json j = nlohmann::json::parse(LineSegmentsToJson(lines, "laser", 12.5));
  EXPECT_EQ(j.at("header").at("frame_id"), "laser");
  EXPECT_EQ(j.at("line_segments").at(0).at("covariance").size(), 4u);
  EXPECT_EQ(j.at("line_segments").at(0).at("start").size(), 2u);
}

TEST(LineSegments, CurvedAndTinyRegionsGiveNoSegment) {
  WallScan arc;
  for (int i = 0; i < 60; ++i) {  // points of a circle of radius 1 around (2, 0)
    const double t = 2.0 + i * 0.04;
    const Vec2 p(2.0 + std::cos(t), std::sin(t));
    arc.scan.angles.push_back(std::atan2(p.y(), p.x()));
    arc.scan.ranges.push_back(p.norm());
    arc.scan.sigma.push_back(0.01);
    arc.scan.status.push_back(BeamStatus::kValid);
    arc.map.inmodel.push_back(1);
    arc.map.inmodel_beams.push_back(static_cast<std::size_t>(i));
  }
  arc.map.rho = arc.scan.ranges;
  arc.map.regions = {{0, 59}, {0, 3}};  // the arc, and a region of 4 points
  EXPECT_TRUE(ExtractLineSegments(arc.scan, arc.map, nullptr).segments.empty());
}

}  // namespace
}  // namespace priormap::priorlets
