#pragma once
/// priormap's own JSON formats for scans, logs and scenes (documented in docs/formats.md).
/// Semantic errors are located at file:line:col of the offending JSON value.

#include <filesystem>
#include <string>
#include <string_view>

#include <priormap/core/diagnostic.hpp>
#include <priormap/core/log.hpp>
#include <priormap/core/scene.hpp>

namespace priormap {

/// A scan document {"format": "priormap.scan", ...}. The Format and Write functions throw
/// IoError, writing nothing, for what the readers would refuse: a position beyond the world or
/// a return ending beyond it (Scan/Log/Scene::FirstBeyondWorld, world_bounds.hpp).
[[nodiscard]] std::string FormatJsonScan(const Scan& scan);
/// A log document {"format": "priormap.log", ...}.
[[nodiscard]] std::string FormatJsonLog(const Log& log);

/// Parses a scan or a log document; a scan document gives a log with one scan. Columns of the
/// diagnostics count characters. A scan stamped before the previous stamped scan of its channel
/// is kept in the file's order, with a warning at its "timestamp" (Result::warnings).
[[nodiscard]] Result<Log> ParseJsonLog(std::string_view text, const std::string& name);
[[nodiscard]] Result<Log> ReadJsonLog(const std::filesystem::path& path);

void WriteJsonScan(const Scan& scan, const std::filesystem::path& path);
void WriteJsonLog(const Log& log, const std::filesystem::path& path);

/// A scene document {"format": "priormap.scene", ...}.
[[nodiscard]] std::string FormatJsonScene(const Scene& scene);
[[nodiscard]] Result<Scene> ParseJsonScene(std::string_view text, const std::string& name);
[[nodiscard]] Result<Scene> ReadJsonScene(const std::filesystem::path& path);
void WriteJsonScene(const Scene& scene, const std::filesystem::path& path);

}  // namespace priormap
