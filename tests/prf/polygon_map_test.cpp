// Coloring to vector map: the faces partition the window, each face has the colour of every
// point inside it, closed polygons become holes of the face around them, and the GeoJSON holds
// exactly the black faces.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <priormap/core/rng.hpp>
#include <priormap/prf/polygon_map.hpp>
#include <priormap/prf/sampler.hpp>

namespace priormap::prf {
namespace {

// The face holding q: inside its outer ring and none of its holes (faces are disjoint).
const MapFace* FaceAt(const std::vector<MapFace>& faces, const Vec2& q) {
  const MapFace* found = nullptr;
  for (const MapFace& face : faces) {
    if (!RingContains(face.outer, q)) continue;
    bool in_hole = false;
    for (const auto& hole : face.holes) in_hole = in_hole || RingContains(hole, q);
    if (in_hole) continue;
    EXPECT_EQ(found, nullptr) << "two faces hold a point";
    found = &face;
  }
  return found;
}

TEST(PolygonMap, FacesPartitionTheWindowAndCarryTheirColour) {
  const Window window{Vec2(-1.0, 0.5), Vec2(2.0, 2.5)};
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    SamplerOptions options;
    options.p = 1.5;
    options.birth_scale = 0.6;
    PrfSampler sampler(Coloring(window, 0.25), options, seed);
    sampler.Run(20000);
    const Coloring& coloring = sampler.coloring();
    ASSERT_GT(coloring.stats().edges, 5);
    const auto faces = ExtractFaces(coloring);
    double area = 0.0;
    std::size_t holes = 0;
    for (const MapFace& face : faces) {
      EXPECT_GT(RingSignedArea(face.outer), 0.0);
      area += RingSignedArea(face.outer);
      for (const auto& hole : face.holes) {
        EXPECT_LT(RingSignedArea(hole), 0.0);
        area += RingSignedArea(hole);
        ++holes;
      }
    }
    EXPECT_NEAR(area, window.Area(), 1e-9);
    Rng rng(seed);
    for (int i = 0; i < 500; ++i) {
      const Vec2 q(rng.Uniform(window.min.x(), window.max.x()),
                   rng.Uniform(window.min.y(), window.max.y()));
      const MapFace* face = FaceAt(faces, q);
      ASSERT_NE(face, nullptr);
      EXPECT_EQ(face->colour, coloring.ColourAt(q));
    }
    // GeoJSON: one polygon per black face, rings closed.
    const auto geojson = nlohmann::json::parse(FacesToGeoJson(faces, window));
    std::size_t black = 0;
    for (const MapFace& face : faces) black += face.colour == Colour::kBlack ? 1 : 0;
    ASSERT_EQ(geojson["features"].size(), black);
    for (const auto& feature : geojson["features"]) {
      const auto& outer = feature["geometry"]["coordinates"][0];
      EXPECT_EQ(outer.front(), outer.back());
    }
    EXPECT_GT(CompactMapBytes(coloring), 0u);
  }
}

TEST(PolygonMap, AClosedPolygonIsAHoleOfTheFaceAroundIt) {
  const Window window{Vec2::Zero(), Vec2::Ones()};
  Coloring coloring(window, 0.25);
  Edit edit;
  for (const Vec2& v : {Vec2(0.2, 0.2), Vec2(0.4, 0.2), Vec2(0.3, 0.4)}) {
    edit.new_vertices.push_back({v, kInterior});
    edit.flipped_region.push_back(v);
  }
  for (int i = 0; i < 3; ++i)
    edit.added_edges.push_back({VertexRef::New(i), VertexRef::New((i + 1) % 3)});
  EditEffect effect;
  ASSERT_TRUE(coloring.Evaluate(edit, &effect));
  coloring.Apply(edit, effect);
  const auto faces = ExtractFaces(coloring);
  ASSERT_EQ(faces.size(), 2u);
  EXPECT_EQ(faces[0].colour, Colour::kWhite);
  ASSERT_EQ(faces[0].holes.size(), 1u);
  EXPECT_NEAR(faces[0].area, 1.0, 1e-12);
  EXPECT_EQ(faces[1].colour, Colour::kBlack);
  EXPECT_NEAR(faces[1].area, 0.02, 1e-12);
}

}  // namespace
}  // namespace priormap::prf
