#pragma once
/// PRF mapping from localized sonar rings (Paskin & Thrun, Sec. 2.3 and 3, Fig. 5): the data a
/// mapping run (mapping.hpp) needs, with the sonar likelihood as its data term.

#include <cstdint>
#include <memory>

#include <priormap/prf/mapping.hpp>
#include <priormap/prf/sonar_data.hpp>
#include <priormap/prf/sonar_model.hpp>

namespace priormap::prf {

/// The window around the rings and their arcs (options.margin); as trace points, for evenly
/// spread readings that echoed, the point midway along the axis (seen free) and one 0.1 m
/// beyond the arc; as guide points, where each echo's axis meets its arc; a SonarLikelihood
/// of `model` per chain. The fingerprint covers the readings, the model and the options.
[[nodiscard]] MappingData SonarMappingData(std::shared_ptr<const SonarData> data,
                                           const SonarModel& model, const MappingOptions& options);

/// Hash of the readings and the sonar model (the options are hashed by the caller).
[[nodiscard]] std::uint64_t SonarDataFingerprint(const SonarData& data, const SonarModel& model);
/// The readings a thinned burn-in stage (or a delayed acceptance's screen) of `stride` keeps in
/// its share `phase` (KeptByThinning), with every sensor position.
[[nodiscard]] std::shared_ptr<const SonarData> ThinnedSonarData(const SonarData& data, int stride,
                                                                int phase = 0);

}  // namespace priormap::prf
