// The radial sweep of a sonar cone against brute force: what each direction of the cone sees
// (the first segment along a ray, by testing every segment), which vertices are visible (the
// ray to them crosses nothing), and the faces' distances, angles and the cone's extent, on hand
// cases (a partly hidden wall, a corner behind a face) and on Arak samples in many random cones.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/prf/coloring.hpp>
#include <priormap/prf/sampler.hpp>
#include <priormap/prf/sonar_visibility.hpp>

#include "cone_testing.hpp"

namespace priormap::prf {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();
const Window& kWindow = kConeTestWindow;

// The first segment a ray meets within R (index, distance), by testing all of them.
std::pair<int, double> FirstHitByBruteForce(const std::vector<Segment>& segments,
                                            const Vec2& origin, const Vec2& direction, double r) {
  std::pair<int, double> best{-1, kInf};
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const auto t = RaySegmentHit(origin, direction, segments[i].a, segments[i].b, r);
    if (t && *t < best.second) best = {static_cast<int>(i), *t};
  }
  return best;
}

// The segment a piece of the view sees at angle psi off the axis (-1: nothing).
int SeenAt(const SonarView& view, double psi) {
  for (const VisiblePiece& piece : view.pieces)
    if (psi >= piece.from && psi <= piece.to) return piece.segment;
  ADD_FAILURE() << "no piece at angle " << psi;
  return -2;
}

bool OnBoundary(const Window& w, const Vec2& p) {
  return p.x() == w.min.x() || p.x() == w.max.x() || p.y() == w.min.y() || p.y() == w.max.y();
}

// The vertices (shared or free ends, off the window's boundary) inside the cone that the ray
// from the apex reaches without crossing another segment first.
std::set<std::pair<double, double>> VisibleVerticesByBruteForce(
    const std::vector<Segment>& segments, const SonarCone& cone, const Window& window) {
  std::set<std::pair<double, double>> visible;
  for (const Segment& s : segments) {
    for (const Vec2& v : {s.a, s.b}) {
      const Vec2 d = v - cone.origin;
      const double r = d.norm();
      if (OnBoundary(window, v) || r > cone.max_range) continue;
      if (std::acos(std::clamp(d.dot(cone.axis) / r, -1.0, 1.0)) > cone.half_spread) continue;
      bool blocked = false;
      for (const Segment& t : segments) {
        if (t.a == v || t.b == v) continue;
        const auto hit = RaySegmentHit(cone.origin, d / r, t.a, t.b, r);
        blocked = blocked || (hit && *hit < r * (1.0 - 1e-12));
      }
      if (!blocked) visible.insert({v.x(), v.y()});
    }
  }
  return visible;
}

std::set<std::pair<double, double>> AsSet(const std::vector<Vec2>& points) {
  std::set<std::pair<double, double>> set;
  for (const Vec2& p : points) set.insert({p.x(), p.y()});
  return set;
}

// Samples `rays` directions across the cone (away from the pieces' ends) and checks what each
// sees against the first hit of every segment; the faces' closest distances and visible widths
// against a dense sampling of each piece; the extent against the farthest ray; the corners
// against the vertices the apex sees.
void ExpectViewMatchesRays(const std::vector<Segment>& segments, const SonarCone& cone,
                           const SonarView& view, int rays, const Window& window = kWindow) {
  const double h = cone.half_spread;
  const auto direction_at = [&](double psi) {
    return Vec2(std::cos(psi) * cone.axis + std::sin(psi) * Perp(cone.axis));
  };
  double farthest = 0.0;
  for (int j = 0; j < rays; ++j) {
    const double psi = -h + 2.0 * h * (j + 0.5) / rays;
    const bool near_an_end =
        std::any_of(view.pieces.begin(), view.pieces.end(), [&](const auto& p) {
          return std::abs(psi - p.from) < 1e-9 || std::abs(psi - p.to) < 1e-9;
        });
    if (near_an_end) continue;
    const auto [hit, t] =
        FirstHitByBruteForce(segments, cone.origin, direction_at(psi), cone.max_range);
    ASSERT_EQ(SeenAt(view, psi), hit) << "at angle " << psi;
    farthest = std::max(farthest, hit < 0 ? cone.max_range : t);
  }
  EXPECT_LE(farthest, view.extent + 1e-9);
  EXPECT_LE(view.extent, cone.max_range);

  std::vector<double> sampled_distances, widths, face_distances, face_widths;
  for (const VisiblePiece& piece : view.pieces) {
    if (piece.segment < 0) continue;
    const Segment& s = segments[static_cast<std::size_t>(piece.segment)];
    const Vec2 along = s.b - s.a;
    double nearest = kInf;
    const int samples = 4000;
    for (int j = 0; j <= samples; ++j) {
      const double psi = piece.from + (piece.to - piece.from) * j / samples;
      // Along the ray to the segment's line.
      nearest =
          std::min(nearest, Cross(s.a - cone.origin, along) / Cross(direction_at(psi), along));
    }
    sampled_distances.push_back(nearest);
    widths.push_back(piece.to - piece.from);
  }
  for (const SonarFeature& f : view.features) {
    if (f.kind != SonarFeature::Kind::kFace) continue;
    face_distances.push_back(f.distance);
    face_widths.push_back(f.subtended);
    EXPECT_GT(f.projection, 0.0);
    EXPECT_LE(f.projection, kPi / 2);
  }
  for (auto* v : {&sampled_distances, &widths, &face_distances, &face_widths})
    std::sort(v->begin(), v->end());
  ASSERT_EQ(face_distances.size(), sampled_distances.size());
  for (std::size_t k = 0; k < face_distances.size(); ++k) {
    EXPECT_NEAR(face_distances[k], sampled_distances[k], 1e-6 * (1.0 + sampled_distances[k]));
    EXPECT_EQ(face_widths[k], widths[k]);
  }
  EXPECT_EQ(AsSet(view.corners), VisibleVerticesByBruteForce(segments, cone, window));
}

TEST(ConeSweep, AWallAcrossTheAxisIsOneFaceAtNormalIncidence) {
  const std::vector<Segment> wall = {{Vec2(2, -3), Vec2(2, 3)}};
  const SonarCone cone = Cone(Vec2::Zero(), 0.0, 0.2, 5.0);
  ConeSweep sweep;
  SonarView view;
  sweep.Compute(cone, Tagged(wall), kWindow, &view);
  ASSERT_EQ(view.pieces.size(), 1u);
  EXPECT_EQ(view.pieces[0].segment, 0);
  ASSERT_EQ(view.features.size(), 1u);
  const SonarFeature& face = view.features[0];
  EXPECT_EQ(face.kind, SonarFeature::Kind::kFace);
  EXPECT_NEAR(face.distance, 2.0, 1e-12);
  EXPECT_NEAR(face.projection, kPi / 2, 1e-12);
  EXPECT_NEAR(face.subtended, 0.4, 1e-12);
  EXPECT_NEAR(view.extent, 2.0 / std::cos(0.2), 1e-12);
  EXPECT_TRUE(view.corners.empty());
  EXPECT_EQ(view.contact_tags, std::vector<std::int32_t>{0});
}

TEST(ConeSweep, AnObliqueWallIsSeenAtItsNearEdgeWithASmallProjectionAngle) {
  // The wall's perpendicular foot is far outside the cone.
  const std::vector<Segment> wall = {{Vec2(1, -3), Vec2(4, 3)}};
  const SonarCone cone = Cone(Vec2::Zero(), 0.0, 0.1, 5.0);
  ConeSweep sweep;
  SonarView view;
  sweep.Compute(cone, Tagged(wall), kWindow, &view);
  ASSERT_EQ(view.features.size(), 1u);
  const SonarFeature& face = view.features[0];
  EXPECT_LT(face.projection, kPi / 2 - 0.2);
  // The closest point lies on one of the cone's bounding rays.
  const Vec2 d = wall[0].b - wall[0].a;
  const double line_distance = std::abs(Cross(wall[0].a, d)) / d.norm();
  EXPECT_NEAR(std::sin(face.projection) * face.distance, line_distance, 1e-12);
}

TEST(ConeSweep, APartlyHiddenWallIsTwoFacesAndTheBlockersEndsAreCorners) {
  const std::vector<Segment> segments = {{Vec2(4, -3), Vec2(4, 3)},         // far wall
                                         {Vec2(2, -0.1), Vec2(2.1, 0.1)}};  // a post in front
  const SonarCone cone = Cone(Vec2::Zero(), 0.0, 0.2, 5.0);
  ConeSweep sweep;
  SonarView view;
  sweep.Compute(cone, Tagged(segments), kWindow, &view);
  ASSERT_EQ(view.pieces.size(), 3u);
  EXPECT_EQ(view.pieces[0].segment, 0);
  EXPECT_EQ(view.pieces[1].segment, 1);
  EXPECT_EQ(view.pieces[2].segment, 0);
  EXPECT_EQ(AsSet(view.corners), AsSet({Vec2(2, -0.1), Vec2(2.1, 0.1)}));
  // Two faces of the wall (one at normal incidence: the foot (4, 0) is hidden, so neither),
  // one of the post, two corners.
  int faces = 0, corners = 0;
  for (const SonarFeature& f : view.features)
    (f.kind == SonarFeature::Kind::kFace ? faces : corners) += 1;
  EXPECT_EQ(faces, 3);
  EXPECT_EQ(corners, 2);
  ExpectViewMatchesRays(segments, cone, view, 4001);
}

TEST(ConeSweep, ACornerBehindAFaceIsNotSeenAndOneInFrontIs) {
  // A room corner at (3, 0.2) and, in front of it, a wall hiding it.
  const std::vector<Segment> segments = {{Vec2(3, 0.2), Vec2(3, 3)},
                                         {Vec2(3, 0.2), Vec2(4.5, 0.2)},
                                         {Vec2(1.5, -0.3), Vec2(1.5, 0.3)}};
  const SonarCone cone = Cone(Vec2::Zero(), 0.0, 0.3, 5.0);
  ConeSweep sweep;
  SonarView view;
  sweep.Compute(cone, Tagged(segments), kWindow, &view);
  EXPECT_EQ(AsSet(view.corners), AsSet({Vec2(1.5, -0.3), Vec2(1.5, 0.3)}));
  ExpectViewMatchesRays(segments, cone, view, 4001);
  // Without the wall in front, the corner is seen (and the far end of the wall it joins,
  // grazed from below).
  const std::vector<Segment> open(segments.begin(), segments.begin() + 2);
  sweep.Compute(cone, Tagged(open), kWindow, &view);
  EXPECT_EQ(AsSet(view.corners), AsSet({Vec2(3, 0.2), Vec2(4.5, 0.2)}));
  ExpectViewMatchesRays(open, cone, view, 4001);
}

TEST(ConeSweep, EndsOnTheWindowBoundaryAreNotCornersAndFarPartsAreClippedAtR) {
  const Window window{Vec2(-1, -1), Vec2(3, 1)};
  // A boundary vertex at (3, 0.5) inside the cone.
  const std::vector<Segment> segments = {{Vec2(2, 0.0), Vec2(3, 0.5)}};
  ConeSweep sweep;
  SonarView view;
  const SonarCone cone = Cone(Vec2::Zero(), 0.0, 0.3, 4.0);
  sweep.Compute(cone, Tagged(segments), window, &view);
  EXPECT_EQ(AsSet(view.corners), AsSet({Vec2(2, 0.0)}));
  EXPECT_EQ(view.extent, 4.0);  // directions that see nothing within R
  ExpectViewMatchesRays(segments, cone, view, 4001, window);
  // Within R = 2.5 only a part of the edge, whose far end is no vertex.
  const SonarCone short_cone = Cone(Vec2::Zero(), 0.0, 0.3, 2.5);
  sweep.Compute(short_cone, Tagged(segments), window, &view);
  EXPECT_EQ(AsSet(view.corners), AsSet({Vec2(2, 0.0)}));
  EXPECT_EQ(view.extent, 2.5);
  ExpectViewMatchesRays(segments, short_cone, view, 4001, window);
}

TEST(ConeSweep, TheViewDoesNotDependOnTheOrderOfSegmentsOrOfTheirEnds) {
  std::vector<Segment> segments = {
      {Vec2(4, -3), Vec2(4, 3)}, {Vec2(2, -0.1), Vec2(2.1, 0.1)}, {Vec2(2.1, 0.1), Vec2(2.5, 0.6)}};
  const SonarCone cone = Cone(Vec2(0.1, 0.05), 0.05, 0.25, 5.0);
  ConeSweep sweep;
  SonarView first, second;
  sweep.Compute(cone, Tagged(segments), kWindow, &first);
  std::reverse(segments.begin(), segments.end());
  for (Segment& s : segments) std::swap(s.a, s.b);
  sweep.Compute(cone, Tagged(segments), kWindow, &second);
  ASSERT_EQ(first.features.size(), second.features.size());
  for (std::size_t i = 0; i < first.features.size(); ++i) {
    EXPECT_EQ(first.features[i].distance, second.features[i].distance);
    EXPECT_EQ(first.features[i].projection, second.features[i].projection);
    EXPECT_EQ(first.features[i].subtended, second.features[i].subtended);
  }
  EXPECT_EQ(first.extent, second.extent);
  EXPECT_EQ(first.corners, second.corners);
}

TEST(ConeSweep, MatchesBruteForceRaysOnArakSamplesInRandomCones) {
  // Dense samples of the Arak process: many edges, vertices and partial occlusions.
  const Window& window = kArakSampleWindow;
  const Coloring coloring = DenseArakSample(11);
  std::vector<Segment> segments;
  for (EdgeId e : coloring.edge_ids()) segments.push_back(coloring.EdgeSegment(e));
  ASSERT_GT(segments.size(), 100u);
  std::mt19937_64 random(5);
  ConeSweep sweep;
  SonarView view;
  int corners_seen = 0, pieces_seen = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const SonarCone cone = RandomCone(random, 0.03, 0.5);
    sweep.Compute(cone, Tagged(segments), window, &view);
    ExpectViewMatchesRays(segments, cone, view, 3001, window);
    if (HasFatalFailure()) return;
    corners_seen += static_cast<int>(view.corners.size());
    pieces_seen += static_cast<int>(view.pieces.size());
  }
  // The trials exercised occlusion: several pieces per cone and many corners.
  EXPECT_GT(pieces_seen, 4 * 60);
  EXPECT_GT(corners_seen, 60);
}

TEST(ConeSweep, SegmentsBeyondTheExtentDoNotChangeTheView) {
  // What lies wholly beyond the farthest point seen is hidden: leaving it out of the sweep
  // must give the same view, bit for bit (the likelihood's incremental updates rely on views
  // depending only on what they could see).
  const Window& window = kArakSampleWindow;
  const Coloring coloring = DenseArakSample(12);
  std::vector<Segment> segments;
  for (EdgeId e : coloring.edge_ids()) segments.push_back(coloring.EdgeSegment(e));
  std::mt19937_64 random(6);
  ConeSweep sweep;
  SonarView all, near;
  int trimmed = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const SonarCone cone = RandomCone(random, 0.03, 0.5);
    sweep.Compute(cone, Tagged(segments), window, &all);
    if (all.extent >= cone.max_range) continue;
    std::vector<TaggedSegment> kept;
    for (std::size_t i = 0; i < segments.size(); ++i)
      if (SegmentMeetsCone(segments[i], cone, all.extent))
        kept.push_back({segments[i], static_cast<std::int32_t>(i)});
    trimmed += static_cast<int>(segments.size() - kept.size());
    sweep.Compute(cone, kept, window, &near);
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    EXPECT_EQ(near.extent, all.extent);
    EXPECT_EQ(near.contact_tags, all.contact_tags);
    ASSERT_EQ(near.features.size(), all.features.size());
    for (std::size_t f = 0; f < all.features.size(); ++f) {
      EXPECT_EQ(near.features[f].kind, all.features[f].kind);
      EXPECT_EQ(near.features[f].distance, all.features[f].distance);
      EXPECT_EQ(near.features[f].projection, all.features[f].projection);
      EXPECT_EQ(near.features[f].subtended, all.features[f].subtended);
    }
    if (HasFailure()) return;
  }
  EXPECT_GT(trimmed, 0);
}

TEST(SegmentMeetsCone, IsTrueForWhatTheSweepCanSeeAndFalseFarAway) {
  const SonarCone cone = Cone(Vec2::Zero(), 0.0, 0.2, 5.0);
  EXPECT_TRUE(SegmentMeetsCone({Vec2(2, -1), Vec2(2, 1)}, cone, 3.0));
  EXPECT_FALSE(SegmentMeetsCone({Vec2(4, -1), Vec2(4, 1)}, cone, 3.0));    // beyond the radius
  EXPECT_FALSE(SegmentMeetsCone({Vec2(2, 1), Vec2(2, 3)}, cone, 3.0));     // beside the cone
  EXPECT_FALSE(SegmentMeetsCone({Vec2(-2, -1), Vec2(-2, 1)}, cone, 3.0));  // behind the apex
}

}  // namespace
}  // namespace priormap::prf
