#include <algorithm>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <priormap/core/file_io.hpp>
#include <priormap/prf/sonar_model_io.hpp>

#include "../core/json_document.hpp"

namespace priormap::prf {
namespace {

using detail::JsonNode;
using detail::OrderedJson;

constexpr std::string_view kFormat = "priormap.sonar_model";
constexpr int kVersion = 1;

SonarModel ReadModel(const JsonNode& root) {
  detail::RequireFormat(root, kFormat, kVersion);
  SonarModel model;
  for (const auto& item : root.value.items()) {
    const std::string& key = item.key();
    if (key == "format" || key == "version" || key == "fit") continue;
    const JsonNode node{item.value(), root.pointer / key};
    const auto* known = std::find_if(kSonarModelParameters.begin(), kSonarModelParameters.end(),
                                     [&](const auto& p) { return key == p.name; });
    if (known == kSonarModelParameters.end()) {
      std::string names;
      for (const auto& [name, member] : kSonarModelParameters) names += fmt::format(" {}", name);
      detail::Fail(node, fmt::format("unknown sonar model parameter \"{}\" (expected one of:{})",
                                     key, names));
    }
    model.*(known->member) = detail::FiniteNumber(node, fmt::format("\"{}\"", key));
  }
  if (const std::string problem = model.Problem(); !problem.empty()) {
    // A problem of one parameter (its message starts with its name) is reported at its value;
    // one of several together (weights that must sum to 1), for the document as a whole.
    for (const auto& item : root.value.items())
      if (problem.starts_with(item.key() + " "))
        detail::Fail(JsonNode{item.value(), root.pointer / item.key()},
                     "not a usable sonar model: " + problem);
    detail::Fail(root, "not a usable sonar model: " + problem);
  }
  return model;
}

}  // namespace

std::string FormatSonarModel(const SonarModel& model, const nlohmann::ordered_json* about) {
  OrderedJson j;
  j["format"] = kFormat;
  j["version"] = kVersion;
  for (const auto& [name, member] : kSonarModelParameters) j[name] = model.*member;
  if (about != nullptr) j["fit"] = *about;
  return detail::Dump(j, 2) + "\n";
}

Result<SonarModel> ParseSonarModel(std::string_view text, const std::string& name) {
  Result<detail::JsonDocument> document = detail::JsonDocument::Parse(text, name);
  if (!document) return document.diagnostics();
  try {
    return ReadModel(document.value().root());
  } catch (const detail::JsonSchemaError& error) {
    return document.value().Diagnose(error);
  }
}

Result<SonarModel> ReadSonarModel(const std::filesystem::path& path) {
  Result<std::string> text = ReadFileText(path);
  if (!text) return text.diagnostics();
  return ParseSonarModel(text.value(), path.string());
}

void WriteSonarModel(const SonarModel& model, const std::filesystem::path& path,
                     const nlohmann::ordered_json* about) {
  WriteTextFileAtomically(path, FormatSonarModel(model, about));
}

}  // namespace priormap::prf
