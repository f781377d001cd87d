#include <chrono>
#include <cmath>
#include <mutex>

#include <Eigen/Cholesky>
#include <tbb/parallel_for.h>

#include <priormap/core/angles.hpp>
#include <priormap/slam/study.hpp>

namespace priormap::slam {

RelationTruth TruthOf(const UrbanWorld& world, const UrbanRun& run) {
  RelationTruth truth;
  for (const Beacon& beacon : world.beacons) {
    truth.landmark_wall.push_back(beacon.wall);
    truth.landmark_on_wall.push_back(beacon.on_wall);
  }
  truth.segment_wall = run.segment_wall;
  return truth;
}

RunTrace ScoreRun(SlamResult result, const std::vector<Se2>& frame_truth) {
  RunTrace trace;
  const std::size_t n = std::min(result.frames.size(), frame_truth.size());
  for (std::size_t f = 0; f < n; ++f) {
    const FrameRecord& frame = result.frames[f];
    const Se2& truth = frame_truth[f];
    const Vec3 e(frame.estimate.x() - truth.x(), frame.estimate.y() - truth.y(),
                 WrapAngle(frame.estimate.theta() - truth.theta()));
    trace.error.push_back(e);
    trace.sigma.push_back(frame.covariance.diagonal().cwiseMax(0.0).cwiseSqrt());
    const Eigen::LLT<Mat3> chol(frame.covariance);
    const bool definite =
        chol.info() == Eigen::Success && frame.covariance.diagonal().minCoeff() > 0;
    trace.nees.push_back(definite ? chol.matrixL().solve(e).squaredNorm()
                                  : std::numeric_limits<double>::quiet_NaN());
  }
  trace.result = std::move(result);
  return trace;
}

VariantSummary Summarise(const std::vector<RunTrace>& runs, double band_low, double band_high) {
  VariantSummary s;
  if (runs.empty()) return s;
  double sum_position = 0.0, sum_heading = 0.0, landmarks = 0.0;
  Vec3 inside = Vec3::Zero();
  std::size_t samples = 0;
  for (const RunTrace& run : runs) {
    for (std::size_t f = 0; f < run.error.size(); ++f) {
      const Vec3& e = run.error[f];
      sum_position += e.head<2>().squaredNorm();
      sum_heading += e.z() * e.z();
      for (int k = 0; k < 3; ++k) {
        // A tolerance for the start, where the pose is known exactly and both are zero.
        if (std::abs(e[k]) <= 3.0 * run.sigma[f][k] + 1e-9) inside[k] += 1.0;
      }
      landmarks += run.result.frames[f].landmarks;
      ++samples;
    }
  }
  if (samples == 0) return s;
  s.rms_position_m = std::sqrt(sum_position / static_cast<double>(samples));
  s.rms_heading_rad = std::sqrt(sum_heading / static_cast<double>(samples));
  s.inside_3sigma = inside / static_cast<double>(samples);
  s.inside_3sigma_fraction = s.inside_3sigma.minCoeff();
  s.mean_landmarks = landmarks / static_cast<double>(samples);
  // The NEES averaged over runs at each frame, then over the frames where it is defined.
  const std::size_t frames = runs.front().nees.size();
  double nees_sum = 0.0;
  std::size_t defined = 0, in_band = 0;
  for (std::size_t f = 0; f < frames; ++f) {
    double sum = 0.0;
    std::size_t count = 0;
    for (const RunTrace& run : runs) {
      if (f < run.nees.size() && std::isfinite(run.nees[f])) {
        sum += run.nees[f];
        ++count;
      }
    }
    if (count == 0) continue;
    const double average = sum / static_cast<double>(count);
    nees_sum += average;
    ++defined;
    if (average >= band_low && average <= band_high) ++in_band;
  }
  if (defined > 0) {
    s.mean_nees = nees_sum / static_cast<double>(defined);
    s.nees_inside_band_fraction = static_cast<double>(in_band) / static_cast<double>(defined);
  }
  return s;
}

StudyResult RunStudy(const StudyOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  StudyResult study;
  const UrbanWorld world = MakeUrbanWorld(options.scenario, options.seed);
  const int runs = std::max(0, options.runs);
  study.with_prior.resize(runs);
  study.without_prior.resize(runs);
  std::mutex progress_mutex;
  int done = 0;
  std::size_t prior_segments = 0;  // written by task 0 only
  // Task 2r filters run r with the prior map, task 2r + 1 without; each simulates its run from
  // (seed, r), so both see the same noise and no task depends on another.
  tbb::parallel_for(0, 2 * runs, [&](int task) {
    const int r = task / 2;
    const bool with_prior = task % 2 == 0;
    const UrbanRun run = SimulateUrbanRun(world, options.scenario, options.seed, r);
    const RelationTruth truth = TruthOf(world, run);
    if (task == 0) prior_segments = run.prior_map.segments.size();
    SlamOptions slam = options.slam;
    slam.use_prior_map = with_prior;
    RunTrace trace = ScoreRun(RunSlam(run.input, &run.prior_map, slam, &truth), run.frame_truth);
    (with_prior ? study.with_prior : study.without_prior)[r] = std::move(trace);
    if (options.progress) {
      const std::lock_guard lock(progress_mutex);
      options.progress(++done, 2 * runs);
    }
  });

  if (runs > 0) {
    for (const FrameRecord& frame : study.with_prior.front().result.frames)
      study.times.push_back(frame.time);
  }
  const double dof = 3.0 * runs;
  study.nees_band_low = runs > 0 ? ChiSquareQuantile(0.025, dof) / runs : 0.0;
  study.nees_band_high = runs > 0 ? ChiSquareQuantile(0.975, dof) / runs : 0.0;
  study.with_prior_summary = Summarise(study.with_prior, study.nees_band_low, study.nees_band_high);
  study.without_prior_summary =
      Summarise(study.without_prior, study.nees_band_low, study.nees_band_high);
  for (const RunTrace& run : study.with_prior) {
    for (const RelationRecord& r : run.result.relations) {
      if (r.correct.value_or(false)) {
        ++study.relations.correct;
      } else {
        ++study.relations.incorrect;
        if (r.spurious_segment) ++study.relations.from_spurious;
      }
      if (r.flagged) ++study.relations.flagged;
    }
  }
  study.path_length_m = world.PathLength();
  study.duration_s = world.Duration();
  study.beacons = world.beacons.size();
  study.prior_segments = prior_segments;
  study.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return study;
}

}  // namespace priormap::slam
