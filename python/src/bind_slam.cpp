// priormap.slam_study: the Monte Carlo study of EKF-SLAM with and without a prior map.
#include <stdexcept>

#include <fmt/format.h>

#include <priormap/slam/prior_map.hpp>
#include <priormap/slam/study.hpp>
#include <priormap/slam/study_io.hpp>

#include "bindings.hpp"
#include "convert.hpp"

namespace priormap::python {

void BindSlam(py::module_& m) {
  m.def(
      "slam_study",
      [](int runs, std::uint64_t seed, double prior_std) {
        // The bounds of `priormap slam simulate --runs` and `--prior-std`.
        if (runs < 1 || runs > 100000)
          throw std::invalid_argument(fmt::format("runs must be in [1, 100000], got {}", runs));
        if (!slam::IsValidPriorStd(prior_std))
          throw std::invalid_argument(fmt::format("prior_std must be in (0, {:g}] m, got {}",
                                                  slam::kMaxPriorStd, prior_std));
        slam::StudyOptions study;
        study.runs = runs;
        study.seed = seed;
        study.scenario.prior_std = prior_std;
        std::string why;
        if (!study.scenario.IsValid(&why)) throw std::invalid_argument("scenario: " + why);
        std::string json;
        {
          const py::gil_scoped_release release;
          const slam::StudyResult result = slam::RunStudy(study);
          json = slam::StudySummaryJson(result, study);
        }
        return JsonToPython(nlohmann::json::parse(json)).cast<py::dict>();
      },
      py::arg("runs") = 30, py::arg("seed") = 1,
      py::arg("prior_std") = slam::StudyOptions{}.scenario.prior_std,
      "EKF-SLAM with a heterogeneous prior map on the simulated city (Parsley & Julier, Sec. VI): "
      "runs with and without the prior map; the summary of `priormap slam simulate` as a dict "
      "('with_prior', 'without_prior': RMS errors, NEES; 'constraints'; 'rms_position_ratio')");
}

}  // namespace priormap::python
