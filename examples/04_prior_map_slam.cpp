// EKF-SLAM of point landmarks with a noisy, partly wrong prior map of building walls (Parsley &
// Julier): the same simulated drive filtered with and without the map, scored against the truth.
//   example_04_prior_map_slam [spurious_fraction] [seed]
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <priormap/slam/prior_map_slam.hpp>
#include <priormap/slam/study.hpp>
#include <priormap/slam/urban_scenario.hpp>

namespace slam = priormap::slam;

namespace {

// The whole argument as a number, or nothing: "abc", "0.3x" or a seed of "-1" is refused
// rather than read as 0 or as a huge number.
template <typename T>
std::optional<T> Parse(std::string_view text) {
  T value{};
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

struct Outcome {
  double rms_position = 0.0;  ///< of the pose, over the frames, m
  double rms_landmark = 0.0;  ///< of every landmark's last estimate, m
  std::size_t landmarks = 0;
  slam::SlamResult result;
};

Outcome Filter(const slam::UrbanWorld& world, const slam::UrbanRun& run, bool use_prior_map) {
  slam::SlamOptions options;
  options.use_prior_map = use_prior_map;
  // The truth only labels the relations as right or wrong; the filter does not look at it.
  const slam::RelationTruth truth = slam::TruthOf(world, run);
  Outcome out;
  out.result = slam::RunSlam(run.input, &run.prior_map, options, &truth);
  const std::vector<slam::FrameRecord>& frames = out.result.frames;
  double pose_sq = 0.0;
  for (std::size_t f = 0; f < frames.size(); ++f)
    pose_sq += (frames[f].estimate.translation() - run.frame_truth[f].translation()).squaredNorm();
  out.rms_position = std::sqrt(pose_sq / static_cast<double>(frames.size()));
  // The sliding window drops landmarks a few seconds after they were last seen; the map keeps
  // each at its last estimate, by its observation id (the beacon's index).
  const std::vector<slam::MappedLandmark>& map = out.result.all_landmarks;
  double landmark_sq = 0.0;
  for (const slam::MappedLandmark& landmark : map) {
    const auto beacon = static_cast<std::size_t>(landmark.estimate.id);
    landmark_sq += (landmark.estimate.position - world.beacons[beacon].position).squaredNorm();
  }
  out.landmarks = map.size();
  out.rms_landmark = std::sqrt(landmark_sq / static_cast<double>(map.size()));
  return out;
}

}  // namespace

// A filter that diverges (slam::SlamDiverged, e.g. when nearly every wall of the map is
// invented) throws: say why, and exit 1.
int main(int argc, char** argv) try {
  slam::UrbanScenarioOptions scenario;  // the paper's city, drive, sensor and 1 m map noise
  // More invented walls than the paper's 11 %: the filter must tell them from real ones.
  const std::optional<double> fraction = argc > 1 ? Parse<double>(argv[1]) : 0.25;
  const std::optional<std::uint64_t> seed = argc > 2 ? Parse<std::uint64_t>(argv[2]) : 1;
  if (fraction) scenario.spurious_fraction = *fraction;
  if (std::string why; argc > 3 || !fraction || !seed || !scenario.IsValid(&why)) {
    std::fprintf(stderr, "usage: %s [spurious_fraction in [0, 0.9]] [seed: a whole number >= 0]\n",
                 argv[0]);
    if (!why.empty()) std::fprintf(stderr, "scenario: %s\n", why.c_str());
    return 2;
  }
  // The world (city, true drive, visibility) is fixed by the seed; the run draws the noise of
  // the controls, observations and prior map.
  const slam::UrbanWorld world = slam::MakeUrbanWorld(scenario, *seed);
  const slam::UrbanRun run = slam::SimulateUrbanRun(world, scenario, *seed, /*run=*/0);
  std::size_t spurious = 0;
  for (const int wall : run.segment_wall) spurious += wall < 0;
  std::printf("%.0f m drive, %zu beacons; prior map: %zu walls, %zu of them invented\n",
              world.PathLength(), world.beacons.size(), run.prior_map.segments.size(), spurious);

  const Outcome with = Filter(world, run, true);
  const Outcome without = Filter(world, run, false);
  std::size_t correct = 0, wrong = 0, to_invented = 0;
  for (const slam::RelationRecord& r : with.result.relations) {
    correct += r.correct.value_or(false);
    wrong += !r.correct.value_or(true);
    to_invented += r.spurious_segment;
  }
  std::printf("%-26s%14s%14s\n", "", "with map", "without");
  std::printf("%-26s%14.3f%14.3f\n", "RMS position error (m)", with.rms_position,
              without.rms_position);
  std::printf("%-26s%14.3f%14.3f\n", "RMS landmark error (m)", with.rms_landmark,
              without.rms_landmark);
  std::printf("%-26s%14zu%14zu\n", "landmarks mapped", with.landmarks, without.landmarks);
  std::printf("landmark-on-wall relations: %zu right, %zu wrong (%zu to invented walls)\n", correct,
              wrong, to_invented);

  // What the example claims: the map helps despite its errors, and most relations are right.
  const bool ok = with.rms_position < without.rms_position &&
                  with.rms_landmark < without.rms_landmark && correct > 10 * wrong;
  if (!ok) std::fprintf(stderr, "unexpected result: see the numbers above\n");
  return ok ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "error: %s\n", e.what());
  return 1;
}
