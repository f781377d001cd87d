#pragma once
/// The outputs of `priormap slam simulate` (a Monte Carlo study, study.hpp) and of `priormap slam
/// run` (one filter run on the user's files), as documented in docs/formats.md:
///  - a study: `summary.json` ("priormap.slam_study"), `runs/with_prior_run_NN.csv` and
///    `runs/without_prior_run_NN.csv` (one row per frame) and `relations.csv` (every relation
///    applied in the runs with the prior map);
///  - a run: `trajectory.csv` (pose and its covariance per frame), `map.geojson` (every landmark
///    created, at its last estimate, and the segments in the state at the end), `relations.csv`
///    and `summary.json` ("priormap.slam_run").
/// Numbers are written so that they read back to the same double; NaN is an empty CSV cell and
/// null in JSON. Every file is written atomically (a failure leaves any previous one intact).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <priormap/slam/prior_map_slam.hpp>
#include <priormap/slam/study.hpp>

namespace priormap::slam {

// --- a study -------------------------------------------------------------------------------------

/// summary.json of a study run with `options`: per variant the RMS errors, 3-sigma and NEES
/// consistency, mean landmarks; the relation totals; the acceptance ratios
/// `rms_position_ratio` (without / with the prior map) and `incorrect_per_correct`; the world's
/// size; the wall time.
[[nodiscard]] std::string StudySummaryJson(const StudyResult& study, const StudyOptions& options);

/// One row per frame: time, estimate, error, sigma (x, y, theta), NEES and the frame's counts.
/// Precondition: the trace's error, sigma and nees have one entry per frame of its result.
[[nodiscard]] std::string RunTraceCsv(const RunTrace& trace);

/// Every relation applied in the runs with the prior map: run, landmark, segment, time,
/// correct, spurious_segment, flagged, flagged_time.
[[nodiscard]] std::string StudyRelationsCsv(const StudyResult& study);

/// "with_prior_run_07.csv": runs numbered from 0 with at least two digits (more when `runs`
/// needs them, so that the names sort).
[[nodiscard]] std::string RunFileName(bool with_prior, int run, int runs);

/// Writes summary.json, relations.csv and runs/*.csv into `directory` (created when missing),
/// and removes the run tables of an earlier study there that this one does not write. Returns
/// the files written, summary first. Throws IoError.
std::vector<std::filesystem::path> WriteStudyOutputs(const StudyResult& study,
                                                     const StudyOptions& options,
                                                     const std::filesystem::path& directory);

// --- one run on the user's data ------------------------------------------------------------------

/// Where a run's data came from and how it was filtered, for its summary.
struct SlamRunInfo {
  std::string observations;  ///< input files as given (empty: not recorded)
  std::string odometry;
  std::string prior_map;
  std::size_t prior_segments = 0;
  SlamOptions options{};
  double wall_time_s = 0.0;
};

/// time, x, y, theta, then the pose covariance's unique entries cov_xx, cov_xy, cov_xtheta,
/// cov_yy, cov_ytheta, cov_thetatheta (m^2, m rad, rad^2); one row per frame.
[[nodiscard]] std::string TrajectoryCsv(const SlamResult& result);

/// A GeoJSON FeatureCollection in the prior map's metric frame: each landmark of
/// `result.all_landmarks` as a Point at its last estimate {kind: "landmark", id, covariance [xx,
/// xy, yy], segments: the segments of its applied relations, in_state: still in the state at
/// the end, last_time: the time of that estimate, s}; each segment in the state as a LineString
/// {kind: "segment", segment: its index in the prior map, covariance: the 4x4 of (ax, ay, bx,
/// by), row-major}.
[[nodiscard]] std::string SlamMapGeoJson(const SlamResult& result);

/// landmark, segment, time, flagged, flagged_time, correct, spurious_segment (the last two
/// empty without the truth).
[[nodiscard]] std::string SlamRelationsCsv(const SlamResult& result);

/// summary.json of one run ("priormap.slam_run"): frames, landmarks created and at the end,
/// relations applied and flagged, the inference statistics, rejected updates, wall time.
[[nodiscard]] std::string SlamRunSummaryJson(const SlamResult& result, const SlamRunInfo& info);

/// Writes summary.json, trajectory.csv, map.geojson and relations.csv into `directory`
/// (created when missing). Returns the files written, summary first. Throws IoError.
std::vector<std::filesystem::path> WriteSlamRunOutputs(const SlamResult& result,
                                                       const SlamRunInfo& info,
                                                       const std::filesystem::path& directory);

}  // namespace priormap::slam
