#pragma once
/// The files of `priormap slam run` (documented in docs/formats.md):
///  - observations CSV: `time,id,range,bearing`, one measurement per row, consecutive rows of
///    one time form a frame (`time,,,`: a frame without observations); ids are all given
///    (>= 0) or all unknown (empty, -1, or no `id` column);
///  - odometry CSV: `time,speed,steer` (bicycle controls, each held until the next row's time)
///    or `time,dx,dy,dtheta[,sx,sy,stheta]` (SE(2) increments since the previous row; the first
///    row marks the start and must be zero);
///  - prior map GeoJSON: a FeatureCollection of LineString, MultiLineString, Polygon or
///    MultiPolygon features in a local metric frame (x east, y north, m; longitude/latitude is
///    not reprojected); each feature is one building whose edges are its wall segments; the
///    endpoint 1-sigma comes from the feature's `segment_std` (one per segment) or `std`
///    property, else the collection's `std`, else the caller's default.
/// CSV files: a header row names the columns (in any order), '#' lines and blank lines are
/// skipped. Readers stop at the first problem and report it at file:line:col with what was
/// expected; writers produce what the readers accept at full precision, so a simulated run can
/// be exported and read back bit for bit. A writer given what no file can hold (a bug of the
/// caller) throws ContractError.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <priormap/core/diagnostic.hpp>
#include <priormap/slam/prior_map.hpp>
#include <priormap/slam/slam_input.hpp>

namespace priormap::slam {

/// Frames in time order. Errors: missing or unknown columns, non-numbers, NaN/inf,
/// range <= 0 or above 1e9 m (kMaxWorldCoordinate), bearing outside [-pi, pi], time going
/// backwards, the same id twice in one frame, known and unknown ids mixed in one file, an id that
/// is not an integer in [-1, 2^31 - 1]. A header without rows is no error (no frames).
[[nodiscard]] Result<std::vector<ObservationFrame>> ParseObservationsCsv(std::string_view text,
                                                                         const std::string& name);
/// A frame without observations is written as a row with empty id, range and bearing. The
/// frames' times must increase strictly, their ids be all known or all unknown, and each
/// observation be one the reader accepts.
[[nodiscard]] std::string FormatObservationsCsv(const std::vector<ObservationFrame>& frames);

/// Motion steps (MotionStep::time is each interval's end) and the start time (the first row's).
struct Odometry {
  double start_time = 0.0;
  std::vector<MotionStep> steps;
};
/// Errors: missing or unknown columns, bicycle and increment columns mixed, non-numbers,
/// NaN/inf, times not strictly increasing, a first increment that is not zero, |dx| or |dy|
/// above 1e9 m (kMaxWorldCoordinate), dtheta outside [-pi, pi], a speed above 1e9 m/s in
/// magnitude, a steering angle outside [-pi, pi], a speed held for so long that the step is
/// longer than 1e9 m (|speed| dt, as |dx| for an increment), negative standard deviations, fewer
/// than two rows. Bicycle: N rows give N - 1 steps, the last row's controls are not used.
/// Increments: an empty sx/sy/stheta cell (or a missing column) is NaN, "use MotionNoise".
/// Each step keeps the line and column of its speed or dx cell (MotionStep::line, col).
/// Each row is bounded on its own; where the rows take the vehicle together depends on the start
/// pose, which the file does not hold: FirstPoseBeyondWorld checks that.
[[nodiscard]] Result<Odometry> ParseOdometryCsv(std::string_view text, const std::string& name);
/// Bicycle steps or increments (all steps must be of one kind; ContractError otherwise). Only
/// times are written, so the steps must be contiguous (each starts where the previous ended,
/// the first at start_time); reading gives dt back as the difference of the times.
[[nodiscard]] std::string FormatOdometryCsv(const Odometry& odometry);

/// The odometry dead-reckoned from `initial_pose` (the steps' mean motion; bicycle steps with
/// `wheelbase`): where it first takes the pose beyond kMaxWorldCoordinate in x or y, a Diagnostic
/// at that step's row (MotionStep::line, col) in `name`; nullopt when every pose stays within the
/// world. Rows of 9e8 m each pass the readers one by one, but two of them leave a world whose
/// positions every reader bounds at 1e9 m, and the trajectory and map written from them could not
/// be read back as positions. A pose that stops being finite (a heading made infinite by a tiny
/// wheelbase) is left to the filter, which stops with SlamDiverged.
[[nodiscard]] std::optional<Diagnostic> FirstPoseBeyondWorld(const Se2& initial_pose,
                                                             const Odometry& odometry,
                                                             double wheelbase,
                                                             const std::string& name);

/// Segments in file order, grouped by feature; building k is feature k, named by its
/// properties' `name`, else their `id`, else the feature's `id`, else "feature k". Null
/// `properties`, `name`, `id` or `std` count as absent. Errors: invalid JSON, not a
/// FeatureCollection, a feature without a supported geometry (Point, MultiPoint,
/// GeometryCollection or null are named as such), fewer than two positions in a line, a
/// Polygon ring that is not closed or has fewer than four positions, non-finite coordinates,
/// zero-length segments, a std that is not finite, > 0 and at most 1e9 m (IsValidPriorStd), no
/// segments at all. `default_std` must be a valid std.
[[nodiscard]] Result<PriorMap> ParsePriorMapGeoJson(std::string_view text, const std::string& name,
                                                    double default_std);
/// One Feature per building, in building order (a MultiLineString of its segments, consecutive
/// segments that meet exactly joined into one line, so that noisy endpoints of neighbouring
/// walls need not coincide) with properties {name, std}, or {name, segment_std} when its
/// segments' std differ. Every segment must belong to a building; segments are written grouped
/// by building, so a map whose buildings' segments are interleaved reads back reordered. A
/// segment shared with other buildings (`shared_with`, a merged map's) is written in the feature
/// of each, as GeoJSON holds a shared wall once per footprint: read back, it is one segment per
/// building again, and MergeSameWalls makes it the one shared wall it was.
[[nodiscard]] std::string FormatPriorMapGeoJson(const PriorMap& map);

/// File wrappers (plain or gzip text); writers are atomic and throw IoError.
[[nodiscard]] Result<std::vector<ObservationFrame>> ReadObservationsCsv(
    const std::filesystem::path& path);
[[nodiscard]] Result<Odometry> ReadOdometryCsv(const std::filesystem::path& path);
[[nodiscard]] Result<PriorMap> ReadPriorMapGeoJson(const std::filesystem::path& path,
                                                   double default_std);
void WriteObservationsCsv(const std::vector<ObservationFrame>& frames,
                          const std::filesystem::path& path);
void WriteOdometryCsv(const Odometry& odometry, const std::filesystem::path& path);
void WritePriorMapGeoJson(const PriorMap& map, const std::filesystem::path& path);

}  // namespace priormap::slam
