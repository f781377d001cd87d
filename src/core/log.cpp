#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/core/log.hpp>
#include <priormap/core/world_bounds.hpp>

namespace priormap {

const char* ToString(PoseSource source) {
  switch (source) {
    case PoseSource::kUnknown:
      return "unknown";
    case PoseSource::kOdometry:
      return "odometry";
    case PoseSource::kCorrected:
      return "corrected";
    case PoseSource::kGroundTruth:
      return "ground_truth";
  }
  return "?";
}

std::optional<PoseSource> PoseSourceFromString(std::string_view name) {
  for (PoseSource s : {PoseSource::kUnknown, PoseSource::kOdometry, PoseSource::kCorrected,
                       PoseSource::kGroundTruth}) {
    if (name == ToString(s)) return s;
  }
  return std::nullopt;
}

std::size_t Log::NumRecords() const {
  return scans.size() + odometry.size() + true_poses.size() + params.size();
}

std::vector<Log::RecordRef> Log::RecordOrder() const {
  if (!order.empty()) {
    PRIORMAP_CHECK(order.size() == NumRecords(), "Log::order does not cover every record");
    return order;
  }
  std::vector<RecordRef> refs;
  refs.reserve(NumRecords());
  for (std::size_t i = 0; i < scans.size(); ++i) refs.push_back({RecordKind::kScan, i});
  for (std::size_t i = 0; i < odometry.size(); ++i) refs.push_back({RecordKind::kOdometry, i});
  for (std::size_t i = 0; i < true_poses.size(); ++i) refs.push_back({RecordKind::kTruePose, i});
  for (std::size_t i = 0; i < params.size(); ++i) refs.push_back({RecordKind::kParam, i});
  return refs;
}

std::optional<std::string> Log::FirstBeyondWorld() const {
  for (std::size_t k = 0; k < scans.size(); ++k)
    if (const auto beyond = scans[k].FirstBeyondWorld())
      return fmt::format("scan {}: {}", k, *beyond);
  for (std::size_t k = 0; k < odometry.size(); ++k) {
    const Se2& p = odometry[k].pose;
    if (const auto beyond = CoordinateBeyondWorld("pose", p.x(), p.y()))
      return fmt::format("odometry record {}: {}", k, *beyond);
  }
  for (std::size_t k = 0; k < true_poses.size(); ++k) {
    for (const auto& [field, p] :
         {std::pair<const char*, const Se2&>{"true_pose", true_poses[k].true_pose},
          {"odom_pose", true_poses[k].odom_pose}})
      if (const auto beyond = CoordinateBeyondWorld(field, p.x(), p.y()))
        return fmt::format("true pose record {}: {}", k, *beyond);
  }
  return std::nullopt;
}

std::vector<std::string> Log::Problems() const {
  std::vector<std::string> problems;
  for (std::size_t k = 0; k < scans.size(); ++k) {
    for (const std::string& p : scans[k].Problems())
      problems.push_back(fmt::format("scan {}: {}", k, p));
  }
  if (!order.empty()) {
    if (order.size() != NumRecords()) {
      problems.push_back(
          fmt::format("order lists {} records, the log has {}", order.size(), NumRecords()));
    }
    const auto count_of = [&](RecordKind kind) -> std::size_t {
      switch (kind) {
        case RecordKind::kScan:
          return scans.size();
        case RecordKind::kOdometry:
          return odometry.size();
        case RecordKind::kTruePose:
          return true_poses.size();
        case RecordKind::kParam:
          return params.size();
      }
      return 0;
    };
    for (const RecordRef& ref : order) {
      if (ref.index >= count_of(ref.kind)) {
        problems.push_back("order refers to a record that does not exist");
        break;
      }
    }
  }
  return problems;
}

}  // namespace priormap
