// Accuracy of the priorlets engine against the baseline normal estimators (issue 4's acceptance
// points), printed as tables. Not a google-benchmark program: it measures errors, not time.
//
//   normal_accuracy_bench [--section accuracy|outliers|greedy|regions|all] [--seeds N] [--cases N]
//                         [--outlier-probability P] [--verbose]
//
// accuracy  square 4 x 4 m room, utm30 (sigma 1 cm), sensor at (0.3, -0.2, 0.4), rectangular
//           prior, seeds 1..N (default 20): mean |normal error| of the engine, of PcaNormals
//           (k = 11, 21, 31) and of the oracle line fit on the true segmentation, over all valid
//           beams and without the two beams at each true region change (a beam within a beam
//           spacing of a corner fits either wall within the noise: the "+-1 beam" the issue
//           grants corner location); corners within +-1 beam and the region count per seed.
//           Also the engine with the polygonal prior, the like-for-like match for the oracle.
// outliers  l-room (walls, box, round bin), utm30 with 5 % spurious short readings, polygonal
//           prior, 5 poses x min(N, 4) seeds: precision and recall of INMODEL against the truth
//           (see TrueInModel in tests/testing/scan_truth.hpp for the definition),
//           wall/box topology errors; --verbose: kept readings per true region, found regions.
// greedy    random poses in square, rectangle (rectangular prior) and l-room (polygonal prior)
//           with utm30 and lms200: how often the greedy topology (refine_borders = false) puts a
//           corner more than one beam from the truth, and how often refinement repairs it
//           (--cases per configuration, default 34: 204 in all); --verbose lists each corner
//           that stays misplaced.
// regions   square, rectangle (rectangular prior), corridor and l-room (Manhattan prior) at their
//           default poses, utm30 with 0, 2 and 5 % spurious short readings, seeds 1..N: the mean
//           region count, the scans with as many regions as true regions of 4 or more beams, and
//           the regions with fewer than 4 beams in the model (none should be left).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <string>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/dsl/prior_library.hpp>
#include <priormap/priorlets/engine.hpp>
#include <priormap/priorlets/normal_baselines.hpp>

#include "testing/scan_truth.hpp"

namespace {

using namespace priormap;
using namespace priormap::priorlets;
using priormap::testing::BorderError;
using priormap::testing::FoundBorder;
using priormap::testing::FoundBorders;
using priormap::testing::NearestBorder;
using priormap::testing::TrueBorders;
using priormap::testing::TrueCorners;
using priormap::testing::TrueInModel;
using priormap::testing::TruthMask;
using Pool = priormap::testing::ErrorPool;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void Accuracy(int seeds) {
  const Scene scene = *BuiltinScene("square");
  RangeSensor sensor = *RangeSensor::Preset("utm30");
  sensor.sigma = 0.01;
  const Se2 pose(0.3, -0.2, 0.4);
  const dsl::CompiledPrior prior = dsl::PriorLibrary().Load("rectangular").value();
  const int ks[] = {11, 21, 31};

  fmt::print("# Normal accuracy: square 4x4 m, utm30 sigma {} m, pose (0.3, -0.2, 0.4), {}\n",
             sensor.sigma, prior.name());
  fmt::print(
      "# mean |normal error| in degrees; 'all' = every valid beam, 'excl' = without the two\n"
      "# beams at each true corner; corners = found within +-1 beam / true\n");
  fmt::print("{:>4} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>7} {:>7} {:>4} {:>8}\n",
             "seed", "ours-all", "ours-exc", "pca11", "pca21", "pca31", "pca31all", "orc-all",
             "orc-excl", "corners", "regions", "feas", "ms");
  Pool ours_all, ours_excl, oracle_all, oracle_excl;
  Pool pca_all[3], pca_excl[3];
  int seeds_all_corners = 0, seeds_four_regions = 0, seeds_feasible = 0;
  double total_ms = 0.0;
  std::string misplaced;
  const dsl::CompiledPrior polygonal = dsl::PriorLibrary().Load("polygonal").value();
  Pool poly_all, poly_excl;
  for (int seed = 1; seed <= seeds; ++seed) {
    const Scan scan =
        priormap::testing::SimulateScene(scene, sensor, pose, static_cast<std::uint64_t>(seed));
    const auto t0 = std::chrono::steady_clock::now();
    const MapScan map = EstimateMapScan(scan, prior);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    total_ms += ms;
    const std::vector<std::uint8_t> all = TruthMask(scan, false), excl = TruthMask(scan, true);
    Pool seed_all, seed_excl;
    seed_all.Add(map.alpha, scan, all);
    seed_excl.Add(map.alpha, scan, excl);
    ours_all.Add(map.alpha, scan, all);
    ours_excl.Add(map.alpha, scan, excl);
    // The same engine with the polygonal prior: the like-for-like comparison with the oracle,
    // which fits each wall on its own (the rectangular prior also ties the walls' directions).
    const MapScan poly = EstimateMapScan(scan, polygonal);
    poly_all.Add(poly.alpha, scan, all);
    poly_excl.Add(poly.alpha, scan, excl);
    double pca_seed[3], pca31_all_seed = kNaN;
    for (int j = 0; j < 3; ++j) {
      PcaNormalOptions options;
      options.k = ks[j];
      const std::vector<double> pca = PcaNormals(scan, options);
      pca_all[j].Add(pca, scan, all);
      pca_excl[j].Add(pca, scan, excl);
      pca_seed[j] = CompareNormals(pca, scan.truth->alpha, excl).mean_deg;
      if (ks[j] == 31) pca31_all_seed = CompareNormals(pca, scan.truth->alpha, all).mean_deg;
    }
    const LineFitResult oracle = OracleLineFitNormals(scan, StraightRegionLabels(scan, scene));
    oracle_all.Add(oracle.alpha, scan, all);
    oracle_excl.Add(oracle.alpha, scan, excl);

    const std::vector<std::size_t> truth = TrueBorders(scan);
    const std::vector<FoundBorder> found = FoundBorders(map);
    std::size_t within = 0;
    for (std::size_t c : truth) within += NearestBorder(c, found) <= 1;
    if (found.size() != truth.size() || within != truth.size()) {
      std::string t, f;
      for (std::size_t b : truth) t += fmt::format(" {}|{}", b, b + 1);
      for (const FoundBorder& b : found) f += fmt::format(" {}|{}", b.last, b.first);
      misplaced += fmt::format("  seed {}: true borders{}; found{}\n", seed, t, f);
    }
    seeds_all_corners += found.size() == truth.size() && within == truth.size();
    seeds_four_regions += map.regions.size() == 4;
    seeds_feasible += map.feasible;
    fmt::print(
        "{:>4} {:>9.4f} {:>9.4f} {:>9.4f} {:>9.4f} {:>9.4f} {:>9.4f} {:>9.4f} {:>9.4f} {:>3}/{:<3} "
        "{:>7} {:>4} {:>8.1f}\n",
        seed, seed_all.Mean(), seed_excl.Mean(), pca_seed[0], pca_seed[1], pca_seed[2],
        pca31_all_seed, CompareNormals(oracle.alpha, scan.truth->alpha, all).mean_deg,
        CompareNormals(oracle.alpha, scan.truth->alpha, excl).mean_deg, within, truth.size(),
        map.regions.size(), map.feasible ? "yes" : "NO", ms);
  }
  fmt::print("\n{:<28} {:>10} {:>10} {:>12} {:>8}\n", "estimator", "mean all", "mean excl",
             "worst seed*", "missing");
  const auto row = [](const std::string& name, const Pool& a, const Pool& e) {
    fmt::print("{:<28} {:>10.4f} {:>10.4f} {:>12.4f} {:>8}\n", name, a.Mean(), e.Mean(),
               e.worst_scan, a.missing);
  };
  row("ours (engine, rectangular)", ours_all, ours_excl);
  row("ours (engine, polygonal)", poly_all, poly_excl);
  int best = 0;
  for (int j = 0; j < 3; ++j) {
    row(fmt::format("PcaNormals k = {}", ks[j]), pca_all[j], pca_excl[j]);
    if (pca_excl[j].Mean() < pca_excl[best].Mean()) best = j;
  }
  row("oracle line fit (radial)", oracle_all, oracle_excl);
  fmt::print("(* worst per-seed mean, excl)\n{}", misplaced);
  fmt::print(
      "seeds with every corner within +-1 beam: {}/{}; with 4 regions: {}/{}; feasible: "
      "{}/{}; mean engine time {:.1f} ms\n",
      seeds_all_corners, seeds, seeds_four_regions, seeds, seeds_feasible, seeds, total_ms / seeds);
  const double ours = ours_excl.Mean(), pca = pca_excl[best].Mean(), oracle = oracle_excl.Mean();
  fmt::print(
      "acceptance (excl): ours {:.4f} <= 0.10: {}; ours < best PCA (k = {}, {:.4f}): {}; "
      "ours <= 1.25 x oracle ({:.4f}): {} (ratio {:.3f})\n",
      ours, ours <= 0.10 ? "PASS" : "FAIL", ks[best], pca, ours < pca ? "PASS" : "FAIL",
      1.25 * oracle, ours <= 1.25 * oracle ? "PASS" : "FAIL", ours / oracle);
  fmt::print(
      "acceptance (all):  ours {:.4f} <= 0.10: {}; ours < best PCA all-beam ({:.4f}): {}; "
      "ratio to oracle {:.3f}\n\n",
      ours_all.Mean(), ours_all.Mean() <= 0.10 ? "PASS" : "FAIL", pca_all[best].Mean(),
      ours_all.Mean() < pca_all[best].Mean() ? "PASS" : "FAIL",
      ours_all.Mean() / oracle_all.Mean());
}

void Outliers(int seeds, double outlier_probability, bool verbose) {
  const Scene scene = *BuiltinScene("l-room");
  RangeSensor sensor = *RangeSensor::Preset("utm30");
  sensor.outlier_probability = outlier_probability;
  const dsl::CompiledPrior prior = dsl::PriorLibrary().Load("polygonal").value();
  const Se2 poses[] = {Se2(-1.5, -1.5, kPi / 4), Se2(0.0, -1.0, 0.4), Se2(-1.5, 1.5, -1.2),
                       Se2(2.0, -1.5, 2.8), Se2(-2.0, -1.8, 0.1)};
  fmt::print("# Outliers: l-room (walls, box, bin), utm30 with {} spurious readings, {}\n",
             sensor.outlier_probability, prior.name());
  fmt::print(
      "{:>22} {:>4} {:>6} {:>6} {:>6} {:>9} {:>9} {:>6} {:>9} {:>5} {:>5} {:>5} {:>7} "
      "{:>6} {:>8}\n",
      "pose", "seed", "true", "est", "tp", "precision", "recall", "bin-in", "bin-beams", "mixed",
      "wrong", "feas", "regions", "rounds", "ms");
  const int wall_surface = 0, box_surface = 1, bin_surface = 2;
  std::size_t tp_total = 0, est_total = 0, true_total = 0, bad_topology = 0, cases = 0;
  double worst_precision = 1.0, worst_recall = 1.0;
  for (const Se2& pose : poses) {
    for (int seed = 1; seed <= seeds; ++seed) {
      const Scan scan =
          priormap::testing::SimulateScene(scene, sensor, pose, static_cast<std::uint64_t>(seed));
      const MapScan map = EstimateMapScan(scan, prior);
      const std::vector<int> label = TrueInModel(scan, bin_surface, 4.0);
      std::size_t tp = 0, est = 0, truth = 0, bin_in = 0, bin_beams = 0;
      for (std::size_t i = 0; i < scan.size(); ++i) {
        if (scan.truth->surface[i] == bin_surface && scan.IsValid(i)) {
          ++bin_beams;
          bin_in += map.inmodel[i];
        }
        if (label[i] < 0) continue;
        truth += label[i] == 1;
        est += map.inmodel[i];
        tp += map.inmodel[i] && label[i] == 1;
      }
      // Regions mixing a wall and the box; wall/box links that are not different_surface.
      std::size_t mixed = 0, wrong_links = 0;
      for (const BeamRange& r : map.regions) {
        bool wall = false, box = false;
        for (std::size_t i = r.first; i <= r.last; ++i) {
          if (!map.inmodel[i] || scan.truth->outlier[i]) continue;
          wall |= scan.truth->surface[i] == wall_surface;
          box |= scan.truth->surface[i] == box_surface;
        }
        mixed += wall && box;
      }
      for (std::size_t j = 0; j < map.links.size(); ++j) {
        const std::size_t a = map.inmodel_beams[j], b = map.inmodel_beams[j + 1];
        if (scan.truth->outlier[a] || scan.truth->outlier[b]) continue;
        const int sa = scan.truth->surface[a], sb = scan.truth->surface[b];
        const bool wall_box =
            (sa == wall_surface && sb == box_surface) || (sa == box_surface && sb == wall_surface);
        const bool wrong = wall_box && map.links[j] != Link::kDifferentSurface;
        wrong_links += wrong;
        if (wrong && verbose) {
          fmt::print(
              "    wall/box link {} between beams {} (surface {}, range {:.3f}) and {} "
              "(surface {}, range {:.3f})\n",
              ToString(map.links[j]), a, sa, scan.ranges[a], b, sb, scan.ranges[b]);
        }
      }
      if (verbose) {
        // Per true region: genuine readings kept / genuine readings; and the found regions.
        std::map<int, std::pair<int, int>> per_region;
        for (std::size_t i = 0; i < scan.size(); ++i) {
          if (label[i] != 1) continue;
          auto& [kept, total] = per_region[scan.truth->region[i]];
          kept += map.inmodel[i];
          ++total;
        }
        std::string line;
        for (const auto& [region, counts] : per_region) {
          line += fmt::format(" r{}:{}/{}", region, counts.first, counts.second);
        }
        std::string regions;
        for (const BeamRange& r : map.regions) regions += fmt::format(" [{},{}]", r.first, r.last);
        fmt::print("    kept per true region:{}\n    found regions:{}\n", line, regions);
      }
      const double precision = est ? static_cast<double>(tp) / static_cast<double>(est) : kNaN;
      const double recall = truth ? static_cast<double>(tp) / static_cast<double>(truth) : kNaN;
      worst_precision = std::min(worst_precision, precision);
      worst_recall = std::min(worst_recall, recall);
      tp_total += tp;
      est_total += est;
      true_total += truth;
      bad_topology += mixed + wrong_links > 0;
      ++cases;
      fmt::print(
          "{:>22} {:>4} {:>6} {:>6} {:>6} {:>9.4f} {:>9.4f} {:>6} {:>9} {:>5} {:>5} {:>5} "
          "{:>7} {:>6} {:>8.1f}\n",
          fmt::format("({:.1f}, {:.1f}, {:.2f})", pose.x(), pose.y(), pose.theta()), seed, truth,
          est, tp, precision, recall, bin_in, bin_beams, mixed, wrong_links,
          map.feasible ? "yes" : "NO", map.regions.size(), map.stats.outer_rounds,
          1e3 * map.stats.seconds_total);
    }
  }
  fmt::print(
      "pooled precision {:.4f}, recall {:.4f}; worst precision {:.4f}, worst recall "
      "{:.4f}; cases with a wall/box topology error: {}/{}\n\n",
      static_cast<double>(tp_total) / static_cast<double>(est_total),
      static_cast<double>(tp_total) / static_cast<double>(true_total), worst_precision,
      worst_recall, bad_topology, cases);
}

// A random pose in the free space of a built-in scene, at least `margin` from every surface.
Se2 RandomPose(const Scene& scene, Rng& rng, double margin) {
  const Box2 box = scene.Bounds();
  for (;;) {
    const Vec2 p(rng.Uniform(box.min().x(), box.max().x()),
                 rng.Uniform(box.min().y(), box.max().y()));
    bool ok = true;
    for (const SceneSurface& s : scene.surfaces) {
      if (const auto* line = std::get_if<Polyline>(&s.shape)) {
        ok &= line->Distance(p) >= margin;
      } else {
        ok &= std::get<Circle>(s.shape).DistanceToBoundary(p) >= margin;
      }
    }
    // Inside the walls (the first surface): a ray to the right crosses them an odd number of times.
    const auto& walls = std::get<Polyline>(scene.surfaces[0].shape);
    int crossings = 0;
    for (std::size_t k = 0; k < walls.NumSegments(); ++k) {
      const Segment s = walls.segment(k);
      const Vec2 a = s.a, b = s.b;
      if ((a.y() > p.y()) != (b.y() > p.y()) &&
          p.x() < a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y())) {
        ++crossings;
      }
    }
    // Not inside a clutter box or bin.
    for (std::size_t k = 1; k < scene.surfaces.size(); ++k) {
      if (const auto* c = std::get_if<Circle>(&scene.surfaces[k].shape)) ok &= !c->Contains(p);
    }
    if (ok && crossings % 2 == 1) return Se2(p.x(), p.y(), rng.Uniform(-kPi, kPi));
  }
}

void Greedy(int cases_per_config, bool verbose) {
  struct Config {
    const char* scene;
    const char* sensor;
    const char* prior;
  };
  const Config configs[] = {
      {"square", "utm30", "rectangular"},    {"square", "lms200", "rectangular"},
      {"rectangle", "utm30", "rectangular"}, {"rectangle", "lms200", "rectangular"},
      {"l-room", "utm30", "polygonal"},      {"l-room", "lms200", "polygonal"}};
  fmt::print(
      "# Greedy vs refined borders: {} random poses per configuration (pose stream = case)\n",
      cases_per_config);
  fmt::print("{:<10} {:<7} {:<12} {:>6} {:>8} {:>9} {:>9} {:>9} {:>9} {:>8}\n", "scene", "sensor",
             "prior", "cases", "corners", "greedy>1", "refin>1", "repaired", "worsened", "infeas");
  int found_examples = 0;
  for (const Config& c : configs) {
    const Scene scene = *BuiltinScene(c.scene);
    const RangeSensor sensor = *RangeSensor::Preset(c.sensor);
    const dsl::CompiledPrior prior = dsl::PriorLibrary().Load(c.prior).value();
    EngineOptions greedy_options;
    greedy_options.refine_borders = false;
    std::size_t corners = 0, greedy_off = 0, refined_off = 0, repaired = 0, worsened = 0;
    std::size_t infeasible = 0;
    for (int k = 0; k < cases_per_config; ++k) {
      Rng pose_rng = Rng::ForStream(2024, static_cast<std::uint64_t>(k));
      const Se2 pose = RandomPose(scene, pose_rng, 0.4);
      const auto seed = static_cast<std::uint64_t>(k + 1);
      const Scan scan = priormap::testing::SimulateScene(scene, sensor, pose, seed);
      const MapScan greedy = EstimateMapScan(scan, prior, greedy_options);
      const MapScan refined = EstimateMapScan(scan, prior);
      infeasible += !greedy.feasible + !refined.feasible;
      const std::vector<FoundBorder> g = FoundBorders(greedy), r = FoundBorders(refined);
      for (std::size_t corner : TrueCorners(scan)) {
        ++corners;
        const long dg = NearestBorder(corner, g), dr = NearestBorder(corner, r);
        greedy_off += dg > 1;
        refined_off += dr > 1;
        worsened += dg <= 1 && dr > 1;
        if (verbose && dr > 1) {
          const auto nearest = [&](const std::vector<FoundBorder>& borders) {
            if (borders.empty()) return std::string("none");
            FoundBorder best = borders.front();
            for (const FoundBorder& b : borders) {
              if (BorderError(corner, b) < BorderError(corner, best)) best = b;
            }
            return fmt::format("{}|{}", best.last, best.first);
          };
          fmt::print(
              "  off: {} {} {} pose ({:.6f}, {:.6f}, {:.6f}) seed {} corner {}|{}: greedy "
              "{} ({}), refined {} ({}); regions {} -> {}, in model {} -> {} of {}\n",
              c.scene, c.sensor, c.prior, pose.x(), pose.y(), pose.theta(), seed, corner,
              corner + 1, nearest(g), dg, nearest(r), dr, greedy.regions.size(),
              refined.regions.size(), greedy.inmodel_beams.size(), refined.inmodel_beams.size(),
              scan.NumValid());
        }
        if (dg > 1 && dr <= 1) {
          ++repaired;
          if (found_examples++ < 10) {
            fmt::print(
                "  repaired: {} {} {} pose ({:.6f}, {:.6f}, {:.6f}) seed {} corner {}: "
                "greedy {} beams off, refined {}\n",
                c.scene, c.sensor, c.prior, pose.x(), pose.y(), pose.theta(), seed, corner, dg, dr);
          }
        }
      }
    }
    fmt::print("{:<10} {:<7} {:<12} {:>6} {:>8} {:>9} {:>9} {:>9} {:>9} {:>8}\n", c.scene, c.sensor,
               c.prior, cases_per_config, corners, greedy_off, refined_off, repaired, worsened,
               infeasible);
  }
  fmt::print("\n");
}

void Regions(int seeds) {
  constexpr std::size_t kMinPoints = 4;  // EngineOptions::min_region_points
  fmt::print("# Regions: default poses, utm30, seeds 1..{}; exact = scans with the true count\n",
             seeds);
  fmt::print("{:<10} {:<12} {:>9} {:>12} {:>6} {:>14}\n", "scene", "prior", "spurious",
             "mean regions", "exact", "regions < 4");
  for (const auto& [name, prior_name] :
       std::vector<std::pair<std::string, std::string>>{{"square", "rectangular"},
                                                        {"rectangle", "rectangular"},
                                                        {"corridor", "manhattan"},
                                                        {"l-room", "manhattan"}}) {
    const dsl::CompiledPrior prior = dsl::PriorLibrary().Load(prior_name).value();
    const Scene scene = BuiltinScene(name).value();
    for (const double rate : {0.0, 0.02, 0.05}) {
      RangeSensor sensor = RangeSensor::Preset("utm30").value();
      sensor.outlier_probability = rate;
      std::size_t regions = 0, exact = 0, small = 0;
      for (int seed = 1; seed <= seeds; ++seed) {
        const Scan scan = priormap::testing::SimulateScene(
            scene, sensor, scene.default_pose.value(), static_cast<std::uint64_t>(seed));
        const MapScan map = EstimateMapScan(scan, prior);
        regions += map.regions.size();
        exact += map.regions.size() == priormap::testing::TrueRegionCount(scan, kMinPoints) ? 1 : 0;
        for (const BeamRange& r : map.regions) {
          std::size_t in_model = 0;
          for (std::size_t b = r.first; b <= r.last; ++b) in_model += map.inmodel[b] ? 1 : 0;
          small += in_model < kMinPoints ? 1 : 0;
        }
      }
      fmt::print("{:<10} {:<12} {:>8.0f}% {:>12.2f} {:>6} {:>14}\n", name, prior_name, 100 * rate,
                 static_cast<double>(regions) / seeds, exact, small);
    }
  }
  fmt::print("\n");
}

}  // namespace

int main(int argc, char** argv) {
  std::string section = "accuracy";
  int seeds = 20, cases = 34;
  double outlier_probability = 0.05;
  bool verbose = false;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    const bool has_value = a + 1 < argc;
    if (arg == "--section" && has_value) {
      section = argv[++a];
    } else if (arg == "--seeds" && has_value) {
      seeds = std::atoi(argv[++a]);
    } else if (arg == "--verbose") {
      verbose = true;
    } else if (arg == "--outlier-probability" && has_value) {
      outlier_probability = std::atof(argv[++a]);
    } else if (arg == "--cases" && has_value) {
      cases = std::atoi(argv[++a]);
    } else {
      std::fprintf(
          stderr,
          "usage: %s [--section accuracy|outliers|greedy|regions|all] [--seeds N] [--cases N] "
          "[--outlier-probability P] [--verbose]\n",
          argv[0]);
      return 2;
    }
  }
  if (seeds < 1 || cases < 1) {
    std::fprintf(stderr, "--seeds and --cases must be positive\n");
    return 2;
  }
  const bool all = section == "all";
  if (!all && section != "accuracy" && section != "outliers" && section != "greedy" &&
      section != "regions") {
    std::fprintf(stderr, "unknown section '%s'\n", section.c_str());
    return 2;
  }
  if (all || section == "accuracy") Accuracy(seeds);
  if (all || section == "outliers") Outliers(std::min(seeds, 4), outlier_probability, verbose);
  if (all || section == "greedy") Greedy(cases, verbose);
  if (all || section == "regions") Regions(seeds);
  return 0;
}
