// Acceptance tests of the priorlets engine (issue 4): normal accuracy against PCA and an oracle,
// outliers and clutter, every prior of the library and priors written here, greedy topology vs
// border refinement, and real logs. The numbers behind the thresholds are printed by
// bench/normal_accuracy_bench.cpp (`normal_accuracy_bench --section all`).
//
// A test the engine does not pass yet keeps asserting its target and is marked with
// GTEST_SKIP() << "known failure: ..." (before its assertions), saying what fails and with
// which numbers; remove the mark when the engine passes.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/log_io.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/dsl/prior_library.hpp>
#include <priormap/priorlets/engine.hpp>
#include <priormap/priorlets/normal_baselines.hpp>

#include "testing/scan_truth.hpp"

namespace priormap::priorlets {
namespace {

using priormap::testing::BorderError;
using priormap::testing::ErrorPool;
using priormap::testing::FoundBorder;
using priormap::testing::FoundBorders;
using priormap::testing::NearestBorder;
using priormap::testing::TrueBorders;
using priormap::testing::TrueCorners;
using priormap::testing::TrueInModel;
using priormap::testing::TruthMask;

RangeSensor Sensor(const std::string& name) {
  return RangeSensor::Preset(name).value();
}

dsl::CompiledPrior Prior(const std::string& name) {
  return dsl::PriorLibrary().Load(name).value();
}

// Expected number of regions: maximal runs of one true region among the genuine valid readings
// in scan order (beams without a genuine reading do not split a run).
std::size_t ExpectedRegions(const Scan& scan) {
  std::size_t runs = 0;
  int previous = -2;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (!scan.IsValid(i) || scan.truth->outlier[i] || scan.truth->region[i] < 0) continue;
    if (scan.truth->region[i] != previous) ++runs;
    previous = scan.truth->region[i];
  }
  return runs;
}

// ---------------------------------------------------------------------------------------------
// 1. Accuracy: square 4 x 4 m room, utm30 at sigma = 1 cm, sensor near (not at) the centre,
// rectangular prior, 20 seeds; the engine against PcaNormals (k = 11, 21, 31) and the oracle
// line fit on the true segmentation.

struct AccuracyResults {
  ErrorPool ours_all, ours_excl, oracle_all, oracle_excl;
  std::map<int, ErrorPool> pca_all, pca_excl;  // by k
  int best_k = 0;
  struct Seed {
    std::uint64_t seed = 0;
    std::size_t true_corners = 0, found_borders = 0, corners_within_one_beam = 0, regions = 0;
    bool feasible = false;
    std::string borders;  // "true a|b ...; found c|d ..."
  };
  std::vector<Seed> seeds;
};

class EngineAcceptanceAccuracy : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (results_) return;
    results_ = new AccuracyResults;
    AccuracyResults& r = *results_;
    const Scene scene = BuiltinScene("square").value();
    RangeSensor sensor = Sensor("utm30");
    sensor.sigma = 0.01;  // the preset's value; set so that the test says what it measures
    const dsl::CompiledPrior prior = Prior("rectangular");
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
      const Scan scan = priormap::testing::SimulateScene(scene, sensor, Se2(0.3, -0.2, 0.4), seed);
      const MapScan map = EstimateMapScan(scan, prior);
      const std::vector<std::uint8_t> all = TruthMask(scan, false), excl = TruthMask(scan, true);
      r.ours_all.Add(map.alpha, scan, all);
      r.ours_excl.Add(map.alpha, scan, excl);
      for (int k : {11, 21, 31}) {
        PcaNormalOptions options;
        options.k = k;
        const std::vector<double> pca = PcaNormals(scan, options);
        r.pca_all[k].Add(pca, scan, all);
        r.pca_excl[k].Add(pca, scan, excl);
      }
      const LineFitResult oracle = OracleLineFitNormals(scan, StraightRegionLabels(scan, scene));
      r.oracle_all.Add(oracle.alpha, scan, all);
      r.oracle_excl.Add(oracle.alpha, scan, excl);
      AccuracyResults::Seed s;
      s.seed = seed;
      const std::vector<std::size_t> truth = TrueBorders(scan);
      const std::vector<FoundBorder> found = FoundBorders(map);
      s.true_corners = truth.size();
      s.found_borders = found.size();
      for (std::size_t c : truth) s.corners_within_one_beam += NearestBorder(c, found) <= 1;
      s.borders = "true";
      for (std::size_t c : truth) s.borders += fmt::format(" {}|{}", c, c + 1);
      s.borders += "; found";
      for (const FoundBorder& b : found) s.borders += fmt::format(" {}|{}", b.last, b.first);
      s.regions = map.regions.size();
      s.feasible = map.feasible;
      r.seeds.push_back(s);
    }
    r.best_k = 11;
    for (const auto& [k, pool] : r.pca_excl) {
      if (pool.Mean() < r.pca_excl[r.best_k].Mean()) r.best_k = k;
    }
    std::cout << fmt::format(
        "[ accuracy ] mean |normal error| deg, all valid beams / without corner beams:\n"
        "  ours {:.4f} / {:.4f}; oracle {:.4f} / {:.4f}; PCA k=11 {:.4f} / {:.4f}, k=21 "
        "{:.4f} / {:.4f}, k=31 {:.4f} / {:.4f} (best k = {}); ours missing {} beams\n",
        r.ours_all.Mean(), r.ours_excl.Mean(), r.oracle_all.Mean(), r.oracle_excl.Mean(),
        r.pca_all[11].Mean(), r.pca_excl[11].Mean(), r.pca_all[21].Mean(), r.pca_excl[21].Mean(),
        r.pca_all[31].Mean(), r.pca_excl[31].Mean(), r.best_k, r.ours_all.missing);
    for (const AccuracyResults::Seed& s : r.seeds) {
      if (s.corners_within_one_beam != s.true_corners || s.found_borders != s.true_corners) {
        std::cout << fmt::format("  seed {}: borders {}\n", s.seed, s.borders);
      }
    }
  }
  static void TearDownTestSuite() {
    delete results_;
    results_ = nullptr;
  }
  static AccuracyResults* results_;
};
AccuracyResults* EngineAcceptanceAccuracy::results_ = nullptr;

TEST_F(EngineAcceptanceAccuracy, MeanNormalErrorWithoutCornerBeamsIsAtMostATenthOfADegree) {
  EXPECT_EQ(results_->ours_excl.missing, 0u) << "valid beams without a normal";
  EXPECT_LE(results_->ours_excl.Mean(), 0.10);
}

TEST_F(EngineAcceptanceAccuracy, MeanNormalErrorOverAllBeamsIsAtMostATenthOfADegree) {
  EXPECT_EQ(results_->ours_all.missing, 0u) << "valid beams without a normal";
  EXPECT_LE(results_->ours_all.Mean(), 0.10);
}

TEST_F(EngineAcceptanceAccuracy, BeatsPcaWithItsBestWindow) {
  const AccuracyResults& r = *results_;
  EXPECT_LT(r.ours_excl.Mean(), r.pca_excl.at(r.best_k).Mean()) << "best k = " << r.best_k;
  for (const auto& [k, pool] : r.pca_all) {
    EXPECT_LT(r.ours_all.Mean(), pool.Mean()) << "all beams, k = " << k;
  }
}

TEST_F(EngineAcceptanceAccuracy, IsWithinAQuarterOfTheOracleLineFit) {
  EXPECT_LE(results_->ours_excl.Mean(), 1.25 * results_->oracle_excl.Mean());
}

TEST_F(EngineAcceptanceAccuracy, FindsFourRegionsAndEveryCornerWithinOneBeamForEverySeed) {
  for (const AccuracyResults::Seed& s : results_->seeds) {
    SCOPED_TRACE(fmt::format("seed {}: borders {}", s.seed, s.borders));
    EXPECT_TRUE(s.feasible);
    EXPECT_EQ(s.regions, 4u);
    EXPECT_EQ(s.found_borders, s.true_corners);
    EXPECT_EQ(s.corners_within_one_beam, s.true_corners);
  }
}

// ---------------------------------------------------------------------------------------------
// 2. Outliers and clutter: the l-room (walls; a box and a round bin, both marked clutter in the
// scene), utm30 with 5 % spurious short readings, polygonal prior, several poses and seeds.
//
// Ground truth of INMODEL in the l-room: see testing::TrueInModel; the round bin (radius
// 0.15 m) is the surface not scored.
constexpr int kWallSurface = 0, kBoxSurface = 1, kBinSurface = 2;

struct OutlierCase {
  Se2 pose;
  std::uint64_t seed = 0;
  std::size_t true_inmodel = 0, estimated = 0, true_positives = 0;
  std::size_t mixed_regions = 0;  // regions holding genuine readings of both a wall and the box
  std::size_t wall_box_links_not_different_surface = 0;
  bool feasible = false;
  [[nodiscard]] std::string Name() const {
    return fmt::format("pose ({}, {}, {}) seed {}", pose.x(), pose.y(), pose.theta(), seed);
  }
};

class EngineAcceptanceOutliers : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (cases_) return;
    cases_ = new std::vector<OutlierCase>;
    const Scene scene = BuiltinScene("l-room").value();
    RangeSensor sensor = Sensor("utm30");
    sensor.outlier_probability = 0.05;  // the preset has none
    const dsl::CompiledPrior prior = Prior("polygonal");
    const EngineOptions options;
    for (const Se2& pose : {Se2(-1.5, -1.5, kPi / 4), Se2(0.0, -1.0, 0.4), Se2(-1.5, 1.5, -1.2),
                            Se2(2.0, -1.5, 2.8), Se2(-2.0, -1.8, 0.1)}) {
      for (std::uint64_t seed : {1, 2}) {
        OutlierCase c;
        c.pose = pose;
        c.seed = seed;
        const Scan scan = priormap::testing::SimulateScene(scene, sensor, pose, seed);
        const MapScan map = EstimateMapScan(scan, prior, options);
        const std::vector<int> label = TrueInModel(scan, kBinSurface, options.rho_bound_sigmas);
        for (std::size_t i = 0; i < scan.size(); ++i) {
          if (label[i] < 0) continue;
          c.true_inmodel += label[i] == 1;
          c.estimated += map.inmodel[i];
          c.true_positives += map.inmodel[i] && label[i] == 1;
        }
        const ScanTruth& t = *scan.truth;
        for (const BeamRange& r : map.regions) {
          bool wall = false, box = false;
          for (std::size_t i = r.first; i <= r.last; ++i) {
            if (!map.inmodel[i] || t.outlier[i]) continue;
            wall |= t.surface[i] == kWallSurface;
            box |= t.surface[i] == kBoxSurface;
          }
          c.mixed_regions += wall && box;
        }
        // Consecutive in-model beams, also across beams left out of the model between them.
        for (std::size_t j = 0; j < map.links.size(); ++j) {
          const std::size_t a = map.inmodel_beams[j], b = map.inmodel_beams[j + 1];
          if (t.outlier[a] || t.outlier[b]) continue;
          const bool wall_box = (t.surface[a] == kWallSurface && t.surface[b] == kBoxSurface) ||
                                (t.surface[a] == kBoxSurface && t.surface[b] == kWallSurface);
          c.wall_box_links_not_different_surface +=
              wall_box && map.links[j] != Link::kDifferentSurface;
        }
        c.feasible = map.feasible;
        cases_->push_back(c);
      }
    }
    for (const OutlierCase& c : *cases_) {
      std::cout << fmt::format(
          "[ outliers ] {}: true {} estimated {} tp {}: precision {:.4f} recall {:.4f}; mixed "
          "regions {}, wall/box links not different_surface {}\n",
          c.Name(), c.true_inmodel, c.estimated, c.true_positives,
          static_cast<double>(c.true_positives) / static_cast<double>(c.estimated),
          static_cast<double>(c.true_positives) / static_cast<double>(c.true_inmodel),
          c.mixed_regions, c.wall_box_links_not_different_surface);
    }
  }
  static void TearDownTestSuite() {
    delete cases_;
    cases_ = nullptr;
  }
  static std::vector<OutlierCase>* cases_;
};
std::vector<OutlierCase>* EngineAcceptanceOutliers::cases_ = nullptr;

TEST_F(EngineAcceptanceOutliers, InModelPrecisionAndRecallAreAtLeast95Percent) {
  for (const OutlierCase& c : *cases_) {
    SCOPED_TRACE(c.Name());
    EXPECT_TRUE(c.feasible);
    ASSERT_GT(c.estimated, 0u);
    EXPECT_GE(static_cast<double>(c.true_positives) / static_cast<double>(c.estimated), 0.95)
        << "precision";
    EXPECT_GE(static_cast<double>(c.true_positives) / static_cast<double>(c.true_inmodel), 0.95)
        << "recall";
  }
}

TEST_F(EngineAcceptanceOutliers, TopologySeparatesTheBoxFromTheWalls) {
  for (const OutlierCase& c : *cases_) {
    SCOPED_TRACE(c.Name());
    EXPECT_EQ(c.mixed_regions, 0u) << "regions with beams of both a wall and the box";
    EXPECT_EQ(c.wall_box_links_not_different_surface, 0u)
        << "wall/box transitions that are not different_surface links";
  }
}

// ---------------------------------------------------------------------------------------------
// 3. Generality: every prior of priors/ on a scene it describes, and priors written here.

SceneSurface Walls(std::vector<Vec2> points, bool closed = true) {
  return {Polyline{std::move(points), closed}, false, "walls"};
}

// A regular polygon of `sides` walls around the origin, circumradius `radius`.
Scene RegularPolygonRoom(int sides, double radius, double phase) {
  std::vector<Vec2> points;
  for (int k = 0; k < sides; ++k) {
    const double a = phase + 2.0 * kPi * k / sides;
    points.emplace_back(radius * std::cos(a), radius * std::sin(a));
  }
  Scene scene;
  scene.name = fmt::format("{}-gon", sides);
  scene.surfaces.push_back(Walls(points));
  return scene;
}

// A 6 x 4 m room with its corners cut at 45 degrees: walls meeting at 135 degrees.
Scene CutCornerRoom() {
  const double w = 3.0, h = 2.0, c = 0.8;
  Scene scene;
  scene.name = "cut-corner room";
  scene.surfaces.push_back(Walls({{-w + c, -h},
                                  {w - c, -h},
                                  {w, -h + c},
                                  {w, h - c},
                                  {w - c, h},
                                  {-w + c, h},
                                  {-w, h - c},
                                  {-w, -h + c}}));
  return scene;
}

// A 6 x 4 m quadrilateral whose corners are 88 and 92 degrees (a 2-degree shear).
Scene SkewedRoom() {
  const double s = 4.0 * std::tan(DegToRad(2.0));
  Scene scene;
  scene.name = "skewed room";
  scene.surfaces.push_back(Walls({{-3, -2}, {3, -2}, {3 + s, 2}, {-3 + s, 2}}));
  return scene;
}

// The l-room without its round bin: walls and the box.
Scene LRoomWithBox() {
  Scene scene = BuiltinScene("l-room").value();
  scene.surfaces.pop_back();
  return scene;
}

// A 6 x 4 m room with a round pillar: straight and circular walls.
Scene RoomWithPillar() {
  Scene scene = BuiltinScene("rectangle").value();
  scene.name = "room with pillar";
  scene.surfaces.push_back({Circle{{1.2, 0.6}, 0.5}, false, "pillar"});
  return scene;
}

// Two parallel walls 2 m apart, open at both ends (a corridor seen from inside).
Scene ParallelWalls() {
  Scene scene;
  scene.name = "parallel walls";
  scene.surfaces.push_back(Walls({{-6, 1}, {6, 1}}, false));
  scene.surfaces.push_back(Walls({{-6, -1}, {6, -1}}, false));
  return scene;
}

struct GeneralityCase {
  std::string name;   // test name
  std::string prior;  // built-in name, or the text of a prior
  bool prior_is_text = false;
  Scene scene;
  Se2 pose;
  // Without corner beams. A quarter of a degree: the paper reports 0.26 deg for its method on a
  // simulated square room; the engine reaches 0.01-0.03 deg on rectangular rooms.
  double max_mean_error_deg = 0.25;
  std::string known_failure;  // non-empty: skipped with this message (after printing the numbers)
};

GeneralityCase Case(std::string name, std::string prior, bool prior_is_text, Scene scene,
                    const Se2& pose, std::string known_failure = {}) {
  GeneralityCase c;
  c.name = std::move(name);
  c.prior = std::move(prior);
  c.prior_is_text = prior_is_text;
  c.scene = std::move(scene);
  c.pose = pose;
  c.known_failure = std::move(known_failure);
  return c;
}

// A smoothness prior knows no shape: its normals are as good as the noise over the length it
// smooths (about 0.35 deg on the circle, where the circular prior, a shape model, reaches 0.01).
// Half a degree, and better than local PCA with its best window (asserted for every case).
GeneralityCase Splines(const Se2& pose) {
  GeneralityCase c = Case("Splines", "splines", false, BuiltinScene("circle").value(), pose);
  c.max_mean_error_deg = 0.5;
  return c;
}

std::vector<GeneralityCase> GeneralityCases() {
  const Se2 off_centre(0.3, -0.2, 0.4);
  // Neighbouring walls of a regular hexagon turn by 60 degrees (120-degree corners).
  const std::string hexagonal = R"(name: Regular hexagon prior
specializes: Polygonal prior
priorlet different_region:
  cos(alpha_2 - alpha_1) == cos(pi / 3)
)";
  // Every wall, across corners and occlusions, is parallel to every other: a corridor.
  const std::string parallel = R"(name: Parallel walls prior
specializes: Polygonal prior
priorlet different_region:
  sin(alpha_2 - alpha_1) == 0
priorlet different_surface:
  sin(alpha_2 - alpha_1) == 0
)";
  return {
      Case("Polygonal", "polygonal", false, LRoomWithBox(), Se2(-1.5, -1.5, kPi / 4)),
      Case("Rectangular", "rectangular", false, BuiltinScene("rectangle").value(), off_centre),
      Case("RectangularRelaxed", "rectangular-relaxed", false, SkewedRoom(), off_centre),
      Case("RectangularRelaxedAlternative", "rectangular-relaxed-alternative", false,
           BuiltinScene("rectangle").value(), off_centre),
      Case("Manhattan", "manhattan", false, LRoomWithBox(), Se2(-1.5, -1.5, kPi / 4)),
      Case("Octagonal", "octagonal", false, CutCornerRoom(), Se2(0.3, -0.2, 1.0)),
      Case("Circular", "circular", false, BuiltinScene("circle").value(), off_centre),
      Case("CircularRadius", "circular-radius", false, BuiltinScene("circle").value(), off_centre),
      Splines(off_centre),
      Case("StraightOrCircular", "straight-or-circular", false, RoomWithPillar(),
           Se2(-1.0, -0.5, 0.3)),
      Case("TextHexagonal", hexagonal, true, RegularPolygonRoom(6, 3.0, 0.0), off_centre),
      Case("TextParallelWalls", parallel, true, ParallelWalls(), Se2(0.0, 0.2, 0.3)),
  };
}

void PrintTo(const GeneralityCase& c, std::ostream* os) {
  *os << c.name;
}

class EngineAcceptanceGenerality : public ::testing::TestWithParam<GeneralityCase> {};

TEST_P(EngineAcceptanceGenerality, FeasibleAccurateAndFindsTheRegions) {
  const GeneralityCase& c = GetParam();
  const dsl::PriorLibrary library;
  Result<dsl::CompiledPrior> compiled =
      c.prior_is_text ? library.CompileText(c.prior, c.name + ".prior") : library.Load(c.prior);
  ASSERT_TRUE(compiled.ok()) << compiled.error();
  const dsl::CompiledPrior& prior = compiled.value();
  const Scan scan = priormap::testing::SimulateScene(c.scene, Sensor("utm30"), c.pose, 1);
  const MapScan map = EstimateMapScan(scan, prior);
  ErrorPool excl, all;
  excl.Add(map.alpha, scan, TruthMask(scan, true));
  all.Add(map.alpha, scan, TruthMask(scan, false));
  std::cout << fmt::format(
      "[ generality ] {} on {}: feasible {}, violation {:.2e}, regions {} (expected {}), mean "
      "error {:.4f} deg without corner beams ({:.4f} all; {} beams without a normal), {:.1f} "
      "ms\n",
      prior.name(), c.scene.name, map.feasible, map.max_violation, map.regions.size(),
      ExpectedRegions(scan), excl.Mean(), all.Mean(), all.missing, 1e3 * map.stats.seconds_total);
  // (The numbers above are printed either way, to follow a known failure.)
  if (!c.known_failure.empty()) GTEST_SKIP() << "known failure: " << c.known_failure;
  EXPECT_TRUE(map.feasible);
  EXPECT_EQ(map.regions.size(), ExpectedRegions(scan));
  // No outliers are simulated here: at most 1 % of the genuine readings may leave the model.
  EXPECT_LE(static_cast<double>(all.missing), 0.01 * static_cast<double>(all.count + all.missing))
      << "genuine readings left out of the model";
  EXPECT_LE(excl.Mean(), c.max_mean_error_deg);
  double best_pca = std::numeric_limits<double>::infinity();
  for (int k : {11, 21, 31}) {
    PcaNormalOptions pca_options;
    pca_options.k = k;
    ErrorPool pca;
    pca.Add(PcaNormals(scan, pca_options), scan, TruthMask(scan, true));
    best_pca = std::min(best_pca, pca.Mean());
  }
  EXPECT_LT(excl.Mean(), best_pca) << "local PCA with its best window of 11, 21, 31";
}

INSTANTIATE_TEST_SUITE_P(Priors, EngineAcceptanceGenerality, ::testing::ValuesIn(GeneralityCases()),
                         [](const ::testing::TestParamInfo<GeneralityCase>& param_info) {
                           return param_info.param.name;
                         });

TEST(EngineAcceptanceLibrary, EveryBuiltinPriorHasAGeneralityCase) {
  std::vector<std::string> covered;
  for (const GeneralityCase& c : GeneralityCases()) {
    if (!c.prior_is_text) covered.push_back(Prior(c.prior).name());
  }
  for (const dsl::PriorListing& listing : dsl::PriorLibrary().List()) {
    if (!listing.builtin) continue;
    EXPECT_NE(std::find(covered.begin(), covered.end(), listing.name), covered.end())
        << listing.name << " (" << listing.path << ")";
  }
}

// ---------------------------------------------------------------------------------------------
// 4. Greedy order vs border refinement. Found by `normal_accuracy_bench --section greedy` (random
// poses in square, rectangle and l-room, utm30 and lms200): in the rectangle seen with the utm30
// from this pose, the greedy relaxation (refine_borders = false) puts the corner between beams
// 863 and 864 two beams late (after beam 865), which tilts the whole wall that gets the two
// extra beams by about half a degree; moving the border back lowers the objective and stays
// feasible, so refinement puts every corner where it is.

TEST(EngineAcceptanceGreedy, RefinementRepairsACornerThatTheGreedyOrderMisplaces) {
  const Scan scan = priormap::testing::SimulateScene(
      BuiltinScene("rectangle").value(), Sensor("utm30"), Se2(-0.402812, -0.568978, -1.810382), 14);
  const dsl::CompiledPrior prior = Prior("rectangular");
  EngineOptions greedy_options;
  greedy_options.refine_borders = false;
  const MapScan greedy = EstimateMapScan(scan, prior, greedy_options);
  const MapScan refined = EstimateMapScan(scan, prior);
  ASSERT_TRUE(greedy.feasible);
  ASSERT_TRUE(refined.feasible);
  const std::vector<std::size_t> corners = TrueCorners(scan);
  ASSERT_EQ(corners.size(), 3u);
  const std::vector<FoundBorder> g = FoundBorders(greedy), r = FoundBorders(refined);
  long worst_greedy = 0;
  for (std::size_t c : corners) {
    worst_greedy = std::max(worst_greedy, NearestBorder(c, g));
    EXPECT_LE(NearestBorder(c, r), 1) << "refined, corner after beam " << c;
  }
  EXPECT_GT(worst_greedy, 1) << "the greedy order no longer misplaces a corner here";
  EXPECT_EQ(refined.regions.size(), 4u);
  EXPECT_LE(refined.objective, greedy.objective);
  ErrorPool greedy_error, refined_error;
  greedy_error.Add(greedy.alpha, scan, TruthMask(scan, true));
  refined_error.Add(refined.alpha, scan, TruthMask(scan, true));
  std::cout << fmt::format(
      "[ greedy ] worst greedy corner {} beams off; mean error without corner beams: greedy "
      "{:.4f} deg, refined {:.4f} deg; objective {:.3f} -> {:.3f}\n",
      worst_greedy, greedy_error.Mean(), refined_error.Mean(), greedy.objective, refined.objective);
  EXPECT_LT(refined_error.Mean(), greedy_error.Mean());
}

// ---------------------------------------------------------------------------------------------
// 5. Real data: every 25th scan of two logs of ../shared/data, polygonal prior: no exception,
// and finite ranges and normals for every in-model beam.

TEST(EngineAcceptanceRealData, EveryTwentyFifthScanOfTwoLogsHasFiniteInModelEstimates) {
  const std::filesystem::path data = PRIORMAP_SHARED_DATA_DIR;
  if (!std::filesystem::is_directory(data)) {
    GTEST_SKIP() << "shared data directory " << data << " not found";
  }
  const dsl::CompiledPrior prior = Prior("polygonal");
  for (const char* name :
       {"laser-corrected/intel-corrected.log.gz", "laser-raw-mbicp/laserazosSM3.log.gz"}) {
    SCOPED_TRACE(name);
    const std::filesystem::path path = data / name;
    if (!std::filesystem::exists(path)) {
      ADD_FAILURE() << path << " is missing from the shared data";
      continue;
    }
    Result<Log> read = ReadLog(path);
    ASSERT_TRUE(read.ok()) << read.error();
    const Log& log = read.value();
    std::size_t solved = 0, inmodel = 0, valid = 0, infeasible = 0;
    double seconds = 0.0;
    for (std::size_t k = 0; k < log.scans.size(); k += 25) {
      SCOPED_TRACE(fmt::format("scan {}", k));
      const Scan& scan = log.scans[k];
      ASSERT_TRUE(scan.Problems().empty());
      MapScan map;
      ASSERT_NO_THROW(map = EstimateMapScan(scan, prior));
      ASSERT_EQ(map.rho.size(), scan.size());
      ASSERT_EQ(map.alpha.size(), scan.size());
      for (std::size_t i : map.inmodel_beams) {
        EXPECT_TRUE(std::isfinite(map.rho[i])) << "rho, beam " << i;
        EXPECT_TRUE(std::isfinite(map.alpha[i])) << "alpha, beam " << i;
      }
      ++solved;
      inmodel += map.inmodel_beams.size();
      valid += scan.NumValid();
      infeasible += !map.feasible;
      seconds += map.stats.seconds_total;
    }
    std::cout << fmt::format(
        "[ real data ] {}: {} scans, {:.1f} ms per scan, {:.3f} of valid readings in the model, "
        "{} infeasible\n",
        name, solved, 1e3 * seconds / static_cast<double>(solved),
        static_cast<double>(inmodel) / static_cast<double>(valid), infeasible);
  }
}

}  // namespace
}  // namespace priormap::priorlets
