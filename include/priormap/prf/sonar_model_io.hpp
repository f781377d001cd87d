#pragma once
/// Sonar models as JSON files (format "priormap.sonar_model", docs/formats.md): what
/// `priormap prf fit-sonar` writes and `--sonar-model` reads. Every parameter of SonarModel may
/// be given; one left out keeps its default, an unknown one is an error (a misspelt name would
/// otherwise be ignored).

#include <array>
#include <filesystem>
#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

#include <priormap/core/diagnostic.hpp>
#include <priormap/prf/sonar_model.hpp>

namespace priormap::prf {

/// A parameter of SonarModel and its name in the file.
struct SonarModelParameter {
  const char* name;
  double SonarModel::*member;
};
/// Every parameter of SonarModel, in the file's order.
inline constexpr std::array<SonarModelParameter, 17> kSonarModelParameters = {{
    {"corner_bias", &SonarModel::corner_bias},
    {"corner_per_m", &SonarModel::corner_per_m},
    {"concave_corner_bias", &SonarModel::concave_corner_bias},
    {"face_bias", &SonarModel::face_bias},
    {"face_per_m", &SonarModel::face_per_m},
    {"face_per_rad_projection", &SonarModel::face_per_rad_projection},
    {"face_per_rad_subtended", &SonarModel::face_per_rad_subtended},
    {"max_return", &SonarModel::max_return},
    {"sigma_relative", &SonarModel::sigma_relative},
    {"sigma_min", &SonarModel::sigma_min},
    {"uniform_weight", &SonarModel::uniform_weight},
    {"exponential_weight", &SonarModel::exponential_weight},
    {"max_weight", &SonarModel::max_weight},
    {"exponential_rate", &SonarModel::exponential_rate},
    {"clear_uniform_weight", &SonarModel::clear_uniform_weight},
    {"clear_exponential_weight", &SonarModel::clear_exponential_weight},
    {"clear_max_weight", &SonarModel::clear_max_weight},
}};

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
