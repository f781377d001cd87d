// The outputs of a prior-map SLAM study and of one run (docs/formats.md): JSON summaries, CSV
// tables per frame and per relation, a GeoJSON map of the estimate.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <system_error>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <priormap/core/check.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/slam/study_io.hpp>

#include "../core/json_document.hpp"
#include "csv_table.hpp"

namespace priormap::slam {
namespace {

using priormap::detail::Dump;
using priormap::detail::NumberToJson;
using priormap::detail::OrderedJson;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A CSV cell: the shortest text that reads back to the same double; NaN is an empty cell.
std::string Cell(double value) {
  return std::isnan(value) ? std::string() : detail::FormatNumber(value);
}

std::string OptionalBool(const std::optional<bool>& value) {
  return value ? (*value ? "1" : "0") : "";
}

// The `building` cell: the relation's first building, a number in every row (empty for a
// relation to a single wall), so that a reader infers the same column type with or without a tie.
std::string BuildingCell(const RelationRecord& r) {
  return r.building < 0 ? std::string() : std::to_string(r.building);
}

// The `buildings` cell: every building of the relation (RelationRecord::buildings), joined as the
// walls are; several only on an exact tie.
std::string BuildingsCell(const RelationRecord& r) {
  if (r.building < 0) return std::string();
  return r.buildings.empty() ? std::to_string(r.building)
                             : fmt::format("{}", fmt::join(r.buildings, ";"));
}

OrderedJson Vec3ToJson(const Vec3& v) {
  return {{"x", NumberToJson(v.x())}, {"y", NumberToJson(v.y())}, {"theta", NumberToJson(v.z())}};
}

OrderedJson VariantToJson(const VariantSummary& s) {
  return {{"rms_position_m", NumberToJson(s.rms_position_m)},
          {"rms_heading_rad", NumberToJson(s.rms_heading_rad)},
          {"inside_3sigma_fraction", NumberToJson(s.inside_3sigma_fraction)},
          {"inside_3sigma", Vec3ToJson(s.inside_3sigma)},
          {"mean_nees", NumberToJson(s.mean_nees)},
          {"nees_inside_band_fraction", NumberToJson(s.nees_inside_band_fraction)},
          {"mean_landmarks", NumberToJson(s.mean_landmarks)}};
}

// a / b, NaN when b is 0 (JSON null: "no ratio").
double Ratio(double a, double b) {
  return b != 0.0 ? a / b : kNaN;
}

const char* AssociationName(AssociationMode mode) {
  return mode == AssociationMode::kKnownIds ? "ids" : "nearest";
}

void CreateDirectory(const std::filesystem::path& directory) {
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec)
    throw IoError(fmt::format("cannot create directory {}: {}", directory.string(), ec.message()));
}

std::filesystem::path Write(const std::filesystem::path& path, const std::string& text) {
  WriteTextFileAtomically(path, text);
  return path;
}

OrderedJson PointToJson(const Vec2& p) {
  return {p.x(), p.y()};
}

}  // namespace

// --- a study -------------------------------------------------------------------------------------

std::string StudySummaryJson(const StudyResult& study, const StudyOptions& options) {
  const RelationTotals& r = study.relations;
  OrderedJson json;
  json["format"] = "priormap.slam_study";
  json["version"] = 1;
  json["runs"] = study.with_prior.size();
  json["seed"] = options.seed;
  json["with_prior"] = VariantToJson(study.with_prior_summary);
  json["without_prior"] = VariantToJson(study.without_prior_summary);
  json["constraints"] = {{"correct", r.correct},
                         {"incorrect", r.incorrect},
                         {"from_spurious", r.from_spurious},
                         {"flagged", r.flagged}};
  json["rms_position_ratio"] = NumberToJson(
      Ratio(study.without_prior_summary.rms_position_m, study.with_prior_summary.rms_position_m));
  json["incorrect_per_correct"] =
      NumberToJson(Ratio(static_cast<double>(r.incorrect), static_cast<double>(r.correct)));
  json["nees_band"] = {NumberToJson(study.nees_band_low), NumberToJson(study.nees_band_high)};
  json["frames"] = study.times.size();
  json["path_length_m"] = NumberToJson(study.path_length_m);
  json["duration_s"] = NumberToJson(study.duration_s);
  json["beacons"] = study.beacons;
  json["prior_segments"] = study.prior_segments;
  json["prior_std_m"] = NumberToJson(options.scenario.prior_std);
  json["spurious_fraction"] = NumberToJson(options.scenario.spurious_fraction);
  json["window_s"] = NumberToJson(options.slam.window_s);
  json["p_accept"] = NumberToJson(options.slam.priors.p_accept);
  json["wall_time_s"] = NumberToJson(study.wall_time_s);
  return Dump(json, 2) + "\n";
}

std::string RunTraceCsv(const RunTrace& trace) {
  const std::vector<FrameRecord>& frames = trace.result.frames;
  PRIORMAP_CHECK(trace.error.size() == frames.size() && trace.sigma.size() == frames.size() &&
                     trace.nees.size() == frames.size(),
                 "a run trace has one error, sigma and NEES per frame");
  std::string out =
      "time,x,y,theta,error_x,error_y,error_theta,sigma_x,sigma_y,sigma_theta,nees,landmarks,"
      "segments,relations_in_state,relations_correct,relations_incorrect,relations_spurious,"
      "accepted\n";
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const FrameRecord& frame = frames[f];
    const Vec3& e = trace.error[f];
    const Vec3& s = trace.sigma[f];
    out += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", Cell(frame.time),
                       Cell(frame.estimate.x()), Cell(frame.estimate.y()),
                       Cell(frame.estimate.theta()), Cell(e.x()), Cell(e.y()), Cell(e.z()),
                       Cell(s.x()), Cell(s.y()), Cell(s.z()), Cell(trace.nees[f]), frame.landmarks,
                       frame.segments, frame.relations_in_state, frame.relations_correct,
                       frame.relations_incorrect, frame.relations_spurious, frame.accepted);
  }
  return out;
}

std::string StudyRelationsCsv(const StudyResult& study) {
  std::string out =
      "run,landmark,segment,time,correct,spurious_segment,flagged,flagged_time,building,walls,"
      "buildings\n";
  for (std::size_t run = 0; run < study.with_prior.size(); ++run) {
    for (const RelationRecord& r : study.with_prior[run].result.relations) {
      out += fmt::format("{},{},{},{},{},{},{},{},{},{},{}\n", run, r.landmark, r.segment,
                         Cell(r.time), OptionalBool(r.correct), r.spurious_segment ? 1 : 0,
                         r.flagged ? 1 : 0, r.flagged ? Cell(r.flagged_time) : std::string(),
                         BuildingCell(r), fmt::join(r.walls, ";"), BuildingsCell(r));
    }
  }
  return out;
}

std::string RunFileName(bool with_prior, int run, int runs) {
  const int digits = std::max(2, static_cast<int>(fmt::format("{}", std::max(runs - 1, 0)).size()));
  return fmt::format("{}_run_{:0{}}.csv", with_prior ? "with_prior" : "without_prior", run, digits);
}

std::vector<std::filesystem::path> WriteStudyOutputs(const StudyResult& study,
                                                     const StudyOptions& options,
                                                     const std::filesystem::path& directory) {
  const std::filesystem::path runs_directory = directory / "runs";
  CreateDirectory(runs_directory);
  std::vector<std::filesystem::path> written;
  written.push_back(Write(directory / "summary.json", StudySummaryJson(study, options)));
  written.push_back(Write(directory / "relations.csv", StudyRelationsCsv(study)));
  const int runs = static_cast<int>(study.with_prior.size());
  for (const bool with_prior : {true, false}) {
    const std::vector<RunTrace>& traces = with_prior ? study.with_prior : study.without_prior;
    for (int run = 0; run < static_cast<int>(traces.size()); ++run) {
      written.push_back(Write(runs_directory / RunFileName(with_prior, run, runs),
                              RunTraceCsv(traces[static_cast<std::size_t>(run)])));
    }
  }
  // An earlier study with more runs (or another number of digits) left tables that summary.json
  // no longer counts; they go, matched by name alone.
  const std::set<std::filesystem::path> kept(written.begin(), written.end());
  std::vector<std::filesystem::path> stale;
  for (const auto& entry : std::filesystem::directory_iterator(runs_directory)) {
    const std::string name = entry.path().filename().string();
    if ((IsNumberedName(name, "with_prior_run_", ".csv", true) ||
         IsNumberedName(name, "without_prior_run_", ".csv", true)) &&
        !kept.contains(entry.path()))
      stale.push_back(entry.path());
  }
  for (const auto& file : stale) std::filesystem::remove(file);
  return written;
}

// --- one run on the user's data ------------------------------------------------------------------

std::string TrajectoryCsv(const SlamResult& result) {
  std::string out = "time,x,y,theta,cov_xx,cov_xy,cov_xtheta,cov_yy,cov_ytheta,cov_thetatheta\n";
  for (const FrameRecord& frame : result.frames) {
    const Mat3& P = frame.covariance;
    out +=
        fmt::format("{},{},{},{},{},{},{},{},{},{}\n", Cell(frame.time), Cell(frame.estimate.x()),
                    Cell(frame.estimate.y()), Cell(frame.estimate.theta()), Cell(P(0, 0)),
                    Cell(P(0, 1)), Cell(P(0, 2)), Cell(P(1, 1)), Cell(P(1, 2)), Cell(P(2, 2)));
  }
  return out;
}

std::string SlamMapGeoJson(const SlamResult& result) {
  // The segments of each landmark's applied relations.
  std::map<int, std::vector<int>> related;
  for (const RelationRecord& r : result.relations) {
    if (r.building < 0) {
      related[r.landmark].push_back(r.segment);
    } else {
      related[r.landmark].insert(related[r.landmark].end(), r.walls.begin(), r.walls.end());
    }
  }
  OrderedJson features = OrderedJson::array();
  // The whole map, not only the window's landmarks: a run's map is what the drive saw.
  for (const MappedLandmark& mapped : result.all_landmarks) {
    const LandmarkEstimate& landmark = mapped.estimate;
    const Mat2& P = landmark.covariance;
    const auto it = related.find(landmark.id);
    OrderedJson properties = {
        {"kind", "landmark"},
        {"id", landmark.id},
        {"covariance", {NumberToJson(P(0, 0)), NumberToJson(P(0, 1)), NumberToJson(P(1, 1))}},
        {"segments", it == related.end() ? std::vector<int>() : it->second},
        {"in_state", mapped.in_state},
        {"last_time", NumberToJson(mapped.last_time)}};
    features.push_back(
        {{"type", "Feature"},
         {"geometry", {{"type", "Point"}, {"coordinates", PointToJson(landmark.position)}}},
         {"properties", std::move(properties)}});
  }
  for (const SegmentEstimate& segment : result.segments) {
    OrderedJson covariance = OrderedJson::array();
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) covariance.push_back(NumberToJson(segment.covariance(r, c)));
    }
    features.push_back(
        {{"type", "Feature"},
         {"geometry",
          {{"type", "LineString"},
           {"coordinates", {PointToJson(segment.a), PointToJson(segment.b)}}}},
         {"properties",
          {{"kind", "segment"}, {"segment", segment.segment}, {"covariance", covariance}}}});
  }
  OrderedJson json = {{"type", "FeatureCollection"}, {"features", std::move(features)}};
  // One feature per line: readable, diffable and still small.
  std::string out = "{\"type\": \"FeatureCollection\", \"features\": [";
  for (std::size_t i = 0; i < json["features"].size(); ++i)
    out += (i == 0 ? "\n" : ",\n") + Dump(json["features"][i]);
  return out + "\n]}\n";
}

std::string SlamRelationsCsv(const SlamResult& result) {
  std::string out =
      "landmark,segment,time,flagged,flagged_time,correct,spurious_segment,building,walls,"
      "buildings\n";
  for (const RelationRecord& r : result.relations) {
    out += fmt::format("{},{},{},{},{},{},{},{},{},{}\n", r.landmark, r.segment, Cell(r.time),
                       r.flagged ? 1 : 0, r.flagged ? Cell(r.flagged_time) : std::string(),
                       OptionalBool(r.correct),
                       r.correct ? std::string(r.spurious_segment ? "1" : "0") : std::string(),
                       BuildingCell(r), fmt::join(r.walls, ";"), BuildingsCell(r));
  }
  return out;
}

std::string SlamRunSummaryJson(const SlamResult& result, const SlamRunInfo& info) {
  const std::size_t flagged =
      static_cast<std::size_t>(std::count_if(result.relations.begin(), result.relations.end(),
                                             [](const RelationRecord& r) { return r.flagged; }));
  OrderedJson json;
  json["format"] = "priormap.slam_run";
  json["version"] = 1;
  json["inputs"] = {{"observations", info.observations},
                    {"odometry", info.odometry},
                    {"prior_map", info.prior_map}};
  json["use_prior_map"] = info.options.use_prior_map;
  json["association"] = AssociationName(info.options.association);
  json["window_s"] = NumberToJson(info.options.window_s);
  json["prior_segments"] = info.prior_segments;
  json["frames"] = result.frames.size();
  json["start_time"] = NumberToJson(result.frames.empty() ? kNaN : result.frames.front().time);
  json["end_time"] = NumberToJson(result.frames.empty() ? kNaN : result.frames.back().time);
  json["landmarks_created"] = result.landmarks_created;
  json["landmarks_at_end"] = result.landmarks.size();
  json["segments_at_end"] = result.segments.size();
  json["relations"] = {{"applied", result.relations.size()},
                       {"to_buildings", result.building_relations},
                       {"flagged", flagged}};
  json["inference"] = {{"clusters", result.inference.clusters},
                       {"deferred_points", result.inference.deferred_points},
                       {"largest_cluster", result.inference.largest_cluster},
                       {"hypotheses", result.inference.hypotheses}};
  json["rejected_updates"] = result.rejected_updates;
  json["wall_time_s"] = NumberToJson(info.wall_time_s);
  return Dump(json, 2) + "\n";
}

std::vector<std::filesystem::path> WriteSlamRunOutputs(const SlamResult& result,
                                                       const SlamRunInfo& info,
                                                       const std::filesystem::path& directory) {
  CreateDirectory(directory);
  return {Write(directory / "summary.json", SlamRunSummaryJson(result, info)),
          Write(directory / "trajectory.csv", TrajectoryCsv(result)),
          Write(directory / "map.geojson", SlamMapGeoJson(result)),
          Write(directory / "relations.csv", SlamRelationsCsv(result))};
}

}  // namespace priormap::slam
