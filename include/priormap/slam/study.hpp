#pragma once
/// The Monte Carlo study of Parsley & Julier, Sec. VI: the same urban world and true run, N runs
/// of fresh noise, each filtered with and without the prior map; errors against the truth,
/// their 3-sigma bounds, the average NEES with its 95 % chi-square band, and the relations
/// applied correctly and incorrectly (paper Figs. 4 and 5).

#include <cstdint>
#include <functional>
#include <vector>

#include <priormap/slam/prior_map_slam.hpp>
#include <priormap/slam/urban_scenario.hpp>

namespace priormap::slam {

struct StudyOptions {
  int runs = 30;
  std::uint64_t seed = 1;
  UrbanScenarioOptions scenario{};
  SlamOptions slam{};
  /// Called after each finished filter run (from worker threads, serialised) with (done, total).
  std::function<void(int, int)> progress{};
};

/// Per frame of one filter run: the pose error (estimate - truth, heading wrapped), its
/// standard deviations and the NEES (NaN while the pose covariance is singular, at the start).
struct RunTrace {
  std::vector<Vec3> error;
  std::vector<Vec3> sigma;
  std::vector<double> nees;
  SlamResult result;
};

struct VariantSummary {
  double rms_position_m = 0.0;
  double rms_heading_rad = 0.0;
  Vec3 inside_3sigma = Vec3::Zero();    ///< fraction of (run, frame) inside 3 sigma in x, y, theta
  double inside_3sigma_fraction = 0.0;  ///< the smallest of the three
  double mean_nees = 0.0;               ///< time average of the run-averaged NEES
  double nees_inside_band_fraction = 0.0;  ///< frames whose run-averaged NEES is in the band
  double mean_landmarks = 0.0;             ///< in the state, per frame
};

struct RelationTotals {
  std::size_t correct = 0;
  std::size_t incorrect = 0;
  std::size_t from_spurious = 0;  ///< of the incorrect ones, to spurious segments
  std::size_t flagged = 0;        ///< applied, then found implausible
};

struct StudyResult {
  std::vector<double> times;         ///< frame times, s
  std::vector<RunTrace> with_prior;  ///< one per run
  std::vector<RunTrace> without_prior;
  VariantSummary with_prior_summary;
  VariantSummary without_prior_summary;
  RelationTotals relations;                          ///< summed over the runs with the prior map
  double nees_band_low = 0.0, nees_band_high = 0.0;  ///< 95 % band of the run-averaged NEES
  double path_length_m = 0.0;
  double duration_s = 0.0;
  std::size_t beacons = 0, prior_segments = 0;
  double wall_time_s = 0.0;  ///< whole study
};

/// Runs the study in parallel (oneTBB), each filter run on its own; results do not depend on
/// the number of threads.
[[nodiscard]] StudyResult RunStudy(const StudyOptions& options);

/// Scores one filter run against the true poses of its frames.
[[nodiscard]] RunTrace ScoreRun(SlamResult result, const std::vector<Se2>& frame_truth);

/// Summary over runs; `band` is the 95 % band of the average NEES over those runs.
[[nodiscard]] VariantSummary Summarise(const std::vector<RunTrace>& runs, double band_low,
                                       double band_high);

/// The p-quantile of the chi-square distribution with k degrees of freedom.
[[nodiscard]] double ChiSquareQuantile(double p, double k);

/// The relation truth of an urban world and run, for RunSlam.
[[nodiscard]] RelationTruth TruthOf(const UrbanWorld& world, const UrbanRun& run);

}  // namespace priormap::slam
