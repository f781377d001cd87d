// Edge cases of the sonar likelihood found in review, each checked against an independent
// computation:
//   - the cone sweep when another vertex lies on the ray from the apex through a vertex shared
//     by two edges (round coordinates make such collinear triples common, as in the true maps
//     of the built-in offices): what each direction sees, against brute-force rays;
//   - the model's log-likelihood where the outlier weight Π (1 − q_f) and every echo term
//     underflow (many features that nearly always echo), against the same mixture summed in
//     long double, whose exponent range holds it;
//   - logistic coefficients so large that a feature's logit would be inf − inf (NaN): refused,
//     naming the parameter, also in a model file (at the value);
//   - the fit on degenerate data (only max readings, a single reading) gives a usable model.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/prf/coloring.hpp>
#include <priormap/prf/sonar_fit.hpp>
#include <priormap/prf/sonar_model.hpp>
#include <priormap/prf/sonar_model_io.hpp>
#include <priormap/prf/sonar_visibility.hpp>

#include "cone_testing.hpp"
#include "testing/diagnostic_matchers.hpp"

namespace priormap::prf {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using Kind = SonarFeature::Kind;

constexpr double kInf = std::numeric_limits<double>::infinity();

// The segment the ray at angle psi off the cone's axis meets first within R (-1: none).
int FirstHit(const std::vector<Segment>& segments, const SonarCone& cone, double psi) {
  const Vec2 direction = std::cos(psi) * cone.axis + std::sin(psi) * Perp(cone.axis);
  int best = -1;
  double nearest = kInf;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const auto t =
        RaySegmentHit(cone.origin, direction, segments[i].a, segments[i].b, cone.max_range);
    if (t && *t < nearest) {
      nearest = *t;
      best = static_cast<int>(i);
    }
  }
  return best;
}

// The segment each piece of the view sees must be what its middle ray meets first. Pieces an
// ulp or so wide are passed over: between two ends that are on one ray from the apex in reals
// but an ulp apart in doubles the sweep may see nothing, or either segment, through a gap no
// ray can be aimed into.
void ExpectPiecesMatchRays(const std::vector<Segment>& segments, const SonarCone& cone,
                           const SonarView& view) {
  for (const VisiblePiece& piece : view.pieces)
    if (piece.to - piece.from > 1e-12) {
      EXPECT_EQ(piece.segment, FirstHit(segments, cone, 0.5 * (piece.from + piece.to)))
        << "piece [" << piece.from << ", " << piece.to << "]";
    }
}

TEST(ConeSweepCollinearVertices, TwoEdgesFromAVertexAreOrderedWhereTheySeparate) {
  // A wedge of two edges from V = (1.4, 1.4 · 0.05), and a wall ending at W = (0.8, 0.8 · 0.05),
  // on the ray from the apex through V: one slope in reals, an ulp apart in doubles. The sweep used to place the wedge's edges by their distances along a ray between
  // the two events, through V itself, where they tie; the tie-break then put the hidden edge in
  // front for their whole span.
  const SonarCone cone = Cone(Vec2::Zero(), 0.0, 0.3, 6.0);
  const Vec2 v(1.4, 1.4 * 0.05), w(0.8, 0.8 * 0.05);
  ASSERT_NE(v.y() / v.x(), w.y() / w.x()) << "the case needs the two slopes an ulp apart";
  const std::vector<Segment> segments = {{v, Vec2(v.x() + 1.5, v.y() + 1.5 * 1.16)},
                                         {v, Vec2(v.x() + 1.5, v.y() + 1.5 * 0.89)},
                                         {w, Vec2(w.x(), w.y() - 0.5)}};
  ConeSweep sweep;
  SonarView view;
  sweep.Compute(cone, Tagged(segments), kConeTestWindow, &view);
  ExpectPiecesMatchRays(segments, cone, view);
  // Above V the steeper edge (0) hides the other (1) up to the cone's side: only it is seen.
  EXPECT_EQ(FirstHit(segments, cone, 0.2), 0);
  EXPECT_EQ(view.contact_tags, (std::vector<std::int32_t>{0, 2}));
}

TEST(ConeSweepCollinearVertices, MatchRaysForManyCollinearTriples) {
  // Vertices at round coordinates on rays from the apex: of these configurations, about a
  // third used to give a view that saw a hidden edge over a wide span.
  std::mt19937_64 random(1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const SonarCone cone = Cone(Vec2::Zero(), 0.0, 0.3, 6.0);
  ConeSweep sweep;
  SonarView view;
  int tested = 0;
  for (int trial = 0; trial < 60000; ++trial) {
    const double slope = std::round((unit(random) * 0.4 - 0.2) * 100) / 100;
    const double far = 1 + std::round(unit(random) * 40) / 10;
    const double near = std::round(unit(random) * 10 * far) / 10;
    if (!(near > 0.05 && near < far)) continue;
    const Vec2 v(far, far * slope), w(near, near * slope);
    if (v.y() / v.x() == w.y() / w.x()) continue;  // one event: never a problem
    const double m1 = slope + 0.05 + unit(random), m2 = m1 + 0.05 + unit(random);
    std::vector<Segment> segments = {{v, Vec2(v.x() + 1.5, v.y() + 1.5 * m1)},
                                     {v, Vec2(v.x() + 1.5, v.y() + 1.5 * m2)},
                                     {w, Vec2(w.x(), w.y() - 0.5)}};
    if (unit(random) < 0.5) std::swap(segments[0], segments[1]);
    sweep.Compute(cone, Tagged(segments), kConeTestWindow, &view);
    ++tested;
    ExpectPiecesMatchRays(segments, cone, view);
    if (HasFailure()) {
      ADD_FAILURE() << "V (" << v.x() << ", " << v.y() << "), W (" << w.x() << ", " << w.y()
                    << "), slopes " << m1 << ", " << m2;
      return;
    }
  }
  EXPECT_GT(tested, 5000);
}

SonarFeature Corner(double distance) {
  return {.kind = Kind::kCorner, .distance = distance};
}

// log p(reading | features) for the model's mixture (no multipath, one outlier mixture), summed
// in long double: its exponent range (to 1e-4951 on x86) holds what underflows in double.
long double ReferenceLogLikelihood(const SonarModel& m, double reading, bool max_reading,
                                   const std::vector<SonarFeature>& features, double max_range) {
  const long double pi = std::numbers::pi_v<long double>;
  long double sum = 0.0L, none_closer = 1.0L;
  for (const SonarFeature& f : features) {
    const long double q = m.IndependentReturn(f);
    const long double sigma = std::max(m.sigma_min, m.sigma_relative * f.distance);
    const long double kept = 0.5L * std::erfc(-f.distance / (sigma * std::sqrt(2.0L)));
    const long double r = q * none_closer;
    none_closer *= 1.0L - q;
    if (max_reading) {
      sum += r * 0.5L * std::erfc((max_range - f.distance) / (sigma * std::sqrt(2.0L))) / kept;
    } else {
      const long double z = (reading - f.distance) / sigma;
      sum += r * std::exp(-0.5L * z * z) / (sigma * std::sqrt(2.0L * pi) * kept);
    }
  }
  long double outlier;
  if (max_reading) {
    outlier = m.max_weight;
  } else {
    const long double rate = m.exponential_rate;
    outlier = m.uniform_weight / max_range +
              m.exponential_weight * rate * std::exp(-rate * reading) /
                  (1.0L - std::exp(-rate * max_range));
  }
  return std::log(sum + none_closer * outlier);
}

TEST(SonarModelUnderflow, ManyCertainEchoesGiveAFiniteLogLikelihood) {
  // Sixty corners that would each echo with probability 0.999999: the outlier weight is
  // (1e-6)^60 = 1e-360, and a reading between the corners is many σ from each of them. Every
  // term of the mixture is positive, but the sum in double used to be 0, its log -inf (and
  // ToFixed(-inf) undefined behaviour in the sampler's total).
  SonarModel model;
  model.max_return = 0.999999;
  model.corner_bias = 50.0;
  ASSERT_EQ(model.Problem(), "");
  std::vector<SonarFeature> features;
  for (int k = 0; k < 60; ++k) features.push_back(Corner(0.5 + 0.07 * k));
  for (const auto& [reading, max_reading] :
       {std::pair{4.9, false}, std::pair{0.1, false}, std::pair{5.0, true}}) {
    SCOPED_TRACE(::testing::Message() << "reading " << reading << (max_reading ? " (max)" : ""));
    const double log_likelihood = model.LogLikelihood(reading, max_reading, features, 5.0);
    ASSERT_TRUE(std::isfinite(log_likelihood));
    const long double reference = ReferenceLogLikelihood(model, reading, max_reading, features, 5.0);
    EXPECT_NEAR(log_likelihood, static_cast<double>(reference),
                1e-9 * std::abs(static_cast<double>(reference)));
    EXPECT_LT(log_likelihood, -700.0);  // truly below what a double holds
  }
  // Near the underflow, with fewer features, the log-space sum agrees with the direct one:
  // no jump where one takes over from the other.
  for (int count = 30; count <= 60; count += 2) {
    const std::vector<SonarFeature> some(features.begin(), features.begin() + count);
    const double log_likelihood = model.LogLikelihood(4.9, false, some, 5.0);
    const long double reference = ReferenceLogLikelihood(model, 4.9, false, some, 5.0);
    EXPECT_NEAR(log_likelihood, static_cast<double>(reference),
                1e-9 * std::abs(static_cast<double>(reference)))
        << count << " features";
  }
}

TEST(SonarModelUnderflow, OrdinaryReadingsAreUnchanged) {
  // Where nothing underflows the log-likelihood is the log of the direct sum, as before (the
  // published fits and studies do not move): it agrees with the long double sum.
  const SonarModel model;
  const std::vector<SonarFeature> features = {
      Corner(1.0), {.kind = Kind::kFace, .distance = 2.0, .projection = 1.5, .subtended = 0.3}};
  for (const double r : {0.0, 1.0, 2.0, 3.7}) {
    const long double reference = ReferenceLogLikelihood(model, r, false, features, 5.0);
    EXPECT_NEAR(model.LogLikelihood(r, false, features, 5.0), static_cast<double>(reference),
                1e-13);
  }
}

TEST(SonarModelCoefficients, HugeCoefficientsAreRefusedByName) {
  // face_per_m · d = -inf and face_per_rad_subtended · subtended = +inf: a NaN logit, q and
  // log-likelihood, which the model used to accept.
  SonarModel model;
  model.face_per_m = -1e308;
  model.face_per_rad_subtended = 1e308;
  EXPECT_THAT(model.Problem(), HasSubstr("face_per_m -1e+308 is not a finite logistic"));
  model.face_per_m = -0.3;
  EXPECT_THAT(model.Problem(), HasSubstr("face_per_rad_subtended 1e+308"));
  model.face_per_rad_subtended = 1e100;  // the bound itself is accepted
  EXPECT_EQ(model.Problem(), "");
  const SonarFeature face{
      .kind = Kind::kFace, .distance = 4.0, .projection = 0.1, .subtended = 0.35};
  EXPECT_TRUE(std::isfinite(model.LogLikelihood(2.0, false, std::vector{face}, 5.0)));
  model.corner_bias = std::nan("");
  EXPECT_THAT(model.Problem(), HasSubstr("corner_bias nan is not a finite"));
  // In a file the problem is reported at the value: "face_per_m" (10 characters) on line 4.
  const std::string text =
      "{\n  \"format\": \"priormap.sonar_model\",\n  \"version\": 1,\n  \"face_per_m\": "
      "-1e308\n}\n";
  const Result<SonarModel> read = ParseSonarModel(text, "m.json");
  ASSERT_FALSE(read.ok());
  EXPECT_THAT(read.diagnostics(),
              ElementsAre(testing::DiagnosticAt("m.json", 4, 17, "face_per_m -1e+308")));
}

std::vector<SonarFitReading> Readings(int count, bool max_reading, bool with_face) {
  std::vector<SonarFitReading> readings;
  for (int i = 0; i < count; ++i) {
    SonarFitReading r;
    r.max_range = 5.0;
    r.max_reading = max_reading;
    r.range = max_reading ? 5.0 : 1.0 + 0.01 * i;
    if (with_face)
      r.features.push_back({.kind = Kind::kFace,
                            .distance = 1.0,
                            .projection = std::numbers::pi / 2,
                            .subtended = 0.3});
    r.seen_fraction = with_face ? 1.0 : 0.0;
    readings.push_back(r);
  }
  return readings;
}

TEST(SonarFitDegenerate, OnlyMaxReadingsOrOneReadingStillGiveAUsableModel) {
  SonarFitOptions options;
  options.rounds = 1;
  options.max_evaluations = 500;
  for (const auto& [count, max_reading, with_face] :
       {std::tuple{40, true, false}, std::tuple{40, true, true}, std::tuple{1, false, true},
        std::tuple{1, true, false}, std::tuple{20, false, false}}) {
    SCOPED_TRACE(::testing::Message() << count << " readings, max " << max_reading << ", face "
                                      << with_face);
    const SonarFitResult fit =
        FitSonarModel(Readings(count, max_reading, with_face), SonarModel{}, options);
    EXPECT_EQ(fit.model.Problem(), "");
    EXPECT_TRUE(std::isfinite(fit.log_likelihood));
    EXPECT_GE(fit.log_likelihood, fit.initial_log_likelihood - 1.0);  // within the prior's pull
  }
  // Only max readings from cones that see nothing: the clear mixture's atom takes them.
  const SonarFitResult clear = FitSonarModel(Readings(40, true, false), SonarModel{}, options);
  EXPECT_GT(clear.model.clear_max_weight, 0.9);
}

}  // namespace
}  // namespace priormap::prf
