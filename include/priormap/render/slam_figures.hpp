#pragma once
/// The figures of prior-map SLAM (Parsley & Julier, Sec. VI): of a Monte Carlo study, the pose
/// error with its 3-sigma bound (Fig. 4), the run-averaged NEES with its 95 % band, the relations
/// in the state applied correctly and incorrectly (Fig. 5) and a map of the world and one run;
/// of a single run on the user's data, a map of the estimate.

#include <filesystem>
#include <memory>
#include <string>

#include <priormap/render/figure.hpp>
#include <priormap/slam/prior_map.hpp>
#include <priormap/slam/prior_map_slam.hpp>
#include <priormap/slam/study.hpp>
#include <priormap/slam/urban_scenario.hpp>

namespace priormap::render {

enum class StudyPlotKind {
  /// Fig. 4: three panels (x, y, theta) of the RMS over runs of the pose error at each frame and
  /// the 3-sigma bound 3 sqrt(mean sigma^2), with and without the prior map. Heading in degrees.
  kPoseError,
  /// The NEES averaged over runs at each frame, with and without the prior map, and the 95 %
  /// band of that average (log scale; frames without a defined NEES are gaps).
  kNees,
  /// Fig. 5: the run mean of the relations applied to landmarks in the state, correctly (thin),
  /// incorrectly (thick) and, of those, to spurious segments (dotted), on a log scale: zero
  /// counts are missing values, as in the paper.
  kRelations,
};

struct StudyPlotOptions {
  int width_px = 1000;  ///< the height follows the number of panels; not negative
  std::string title{};  ///< over the whole figure (empty: none)
};

/// A plot over time of a study's frames, drawn once and saved as PNG, SVG or PDF.
class StudyPlot {
 public:
  /// Draws the plot of `kind`. Preconditions: every trace of the study has one entry per frame
  /// (study.times); the plot's size fits (figure_size.hpp), checked before anything is drawn.
  StudyPlot(const slam::StudyResult& study, StudyPlotKind kind,
            const StudyPlotOptions& options = {});
  ~StudyPlot();
  StudyPlot(StudyPlot&&) noexcept;
  StudyPlot& operator=(StudyPlot&&) noexcept;

  /// Writes PNG, SVG or PDF according to the extension, atomically. Throws IoError.
  void Save(const std::filesystem::path& path) const;

  [[nodiscard]] int width_px() const;
  [[nodiscard]] int height_px() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct SlamMapOptions {
  int width_px = 1000;
  std::string title{};
};

/// The world of a study and one of its runs: buildings (grey), the run's prior map (segments of
/// true walls dark, spurious ones red), beacons on and off walls, the true trajectory and the
/// trajectories estimated with and without the prior map (`with_prior`, `without_prior`: the
/// traces of the same run; either may be null).
[[nodiscard]] Figure StudyMapFigure(const slam::UrbanWorld& world, const slam::UrbanRun& run,
                                    const slam::RunTrace* with_prior,
                                    const slam::RunTrace* without_prior,
                                    const SlamMapOptions& options = {});

/// One run on the user's data: the prior map (null: none), the estimated trajectory, the
/// landmarks in the state at the end with their 3-sigma ellipses, the segments in the state and
/// the applied relations (a line from each landmark to its segment).
[[nodiscard]] Figure SlamRunMapFigure(const slam::SlamResult& result,
                                      const slam::PriorMap* prior_map,
                                      const SlamMapOptions& options = {});

}  // namespace priormap::render
