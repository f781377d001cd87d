#include <fmt/format.h>

#include <priormap/prf/study_session.hpp>

namespace priormap::prf {

std::string StudyCaseFolder(const std::string& scene, const std::string& sensor) {
  return fmt::format("{}-{}", scene, sensor);
}

std::filesystem::path StudyCaseCheckpoints(const StudySession& session, const std::string& scene,
                                           const std::string& sensor) {
  if (session.directory.empty()) return {};
  return session.directory / StudyCaseFolder(scene, sensor) / "checkpoints";
}

}  // namespace priormap::prf
