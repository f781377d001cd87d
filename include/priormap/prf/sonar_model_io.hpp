#pragma once
/// Sonar models as JSON files (format "priormap.sonar_model", docs/formats.md): what
/// `priormap prf fit-sonar` writes and `--sonar-model` reads. Every parameter of SonarModel may
/// be given; one left out keeps its default, an unknown one is an error (a misspelt name would
/// otherwise be ignored).

#include <filesystem>
#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

#include <priormap/core/diagnostic.hpp>
#include <priormap/prf/sonar_model.hpp>

namespace priormap::prf {

/// The document; `about` (may be null) is stored as its "fit" member, for the record.
[[nodiscard]] std::string FormatSonarModel(const SonarModel& model,
                                           const nlohmann::ordered_json* about = nullptr);
/// Parses a document; problems are reported at file:line:col (`name` is the file).
[[nodiscard]] Result<SonarModel> ParseSonarModel(std::string_view text, const std::string& name);
[[nodiscard]] Result<SonarModel> ReadSonarModel(const std::filesystem::path& path);
/// Written atomically (a temporary file, then renamed).
void WriteSonarModel(const SonarModel& model, const std::filesystem::path& path,
                     const nlohmann::ordered_json* about = nullptr);

}  // namespace priormap::prf
