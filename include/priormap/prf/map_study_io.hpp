#pragma once
/// The outputs of `priormap prf study` (map_study.hpp): summary.json ("priormap.prf_study": the
/// options, per case and overall the classification scores of each method over the observed
/// area, its sparse part and the rest, with coverage; the MAP map's wall distances; times) and
/// the same numbers as a markdown table for docs/prf.md. NaN is null in JSON and "–" in tables.

#include <string>

#include <nlohmann/json.hpp>

#include <priormap/prf/map_study.hpp>

namespace priormap::prf {

struct SonarStudyOptions;

/// The options of a `prf study` as its summary.json holds them ("options"). A stopped study's
/// record keeps them too, so that a resume with other options is refused naming them.
[[nodiscard]] nlohmann::json MapStudyOptionsJson(const MapStudyOptions& options);

/// The same of a `prf sonar-study` (its summary.json's "options", sonar_study.hpp).
[[nodiscard]] nlohmann::json SonarStudyOptionsJson(const SonarStudyOptions& options);

[[nodiscard]] std::string MapStudySummaryJson(const MapStudyResult& study,
                                              const MapStudyOptions& options);

/// One row per case and one for all cases pooled: accuracy of the grid, the PRF posterior and
/// the MAP map over the observed area and its sparse part (with the grid's coverage), the MAP
/// map's wall distances and recovered fraction, and the times.
[[nodiscard]] std::string MapStudyMarkdownTable(const MapStudyResult& study);

}  // namespace priormap::prf
