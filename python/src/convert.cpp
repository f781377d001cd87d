#include "convert.hpp"

#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include <priormap/core/world_bounds.hpp>

namespace priormap::python {
namespace {

// Our JSON writes infinities as the strings "inf" and "-inf" (docs/formats.md).
bool IsInfinity(const nlohmann::json& value) {
  return value.is_string() && (value == "inf" || value == "-inf");
}

bool IsNumber(const nlohmann::json& value) {
  return value.is_number() || IsInfinity(value);
}

// Numbers, with nulls (NaN in the array) for what has no value, like an outlier's deviation; an
// array of nulls alone is numbers none of which has a value.
bool AllNumbersOrNull(const nlohmann::json& array) {
  for (const auto& v : array)
    if (!IsNumber(v) && !v.is_null()) return false;
  return !array.empty();
}

// Whole numbers only, as the writer writes indices (a double is always written with a point).
bool AllIntegers(const nlohmann::json& array) {
  for (const auto& v : array)
    if (!v.is_number_integer()) return false;
  return !array.empty();
}

double NumberOrNan(const nlohmann::json& value) {
  if (IsInfinity(value))
    return value == "inf" ? std::numeric_limits<double>::infinity()
                          : -std::numeric_limits<double>::infinity();
  return value.is_number() ? value.get<double>() : std::numeric_limits<double>::quiet_NaN();
}

bool AllBooleans(const nlohmann::json& array) {
  for (const auto& v : array)
    if (!v.is_boolean()) return false;
  return !array.empty();
}

// A list of lists of one length, each passing `row_test`: a matrix.
template <typename RowTest>
bool IsMatrix(const nlohmann::json& array, RowTest row_test) {
  if (array.empty() || !array.front().is_array()) return false;
  const std::size_t columns = array.front().size();
  for (const auto& row : array)
    if (!row.is_array() || row.size() != columns || !row_test(row)) return false;
  return columns > 0;
}

// Members that hold beam indices: int arrays even when empty (then of their usual shape), so that
// they can index the scan's arrays.
std::optional<std::vector<py::ssize_t>> EmptyIndexShape(std::string_view key) {
  if (key == "regions" || key == "surfaces") return std::vector<py::ssize_t>{0, 2};
  if (key == "inmodel_beams") return std::vector<py::ssize_t>{0};
  return std::nullopt;
}

// Members that are text whatever they spell (a prior may be named "inf").
bool IsTextMember(std::string_view key) {
  return key == "format" || key == "input" || key == "prior" || key == "note" ||
         key == "covariance" || key == "name";
}

template <typename T, typename Get>
py::array_t<T> Vector(const nlohmann::json& array, Get get) {
  py::array_t<T> a(static_cast<py::ssize_t>(array.size()));
  auto out = a.template mutable_unchecked<1>();
  for (std::size_t i = 0; i < array.size(); ++i) out(static_cast<py::ssize_t>(i)) = get(array[i]);
  return a;
}

template <typename T, typename Get>
py::array_t<T> Matrix(const nlohmann::json& array, Get get) {
  const auto rows = static_cast<py::ssize_t>(array.size());
  const auto columns = static_cast<py::ssize_t>(array.front().size());
  py::array_t<T> a({rows, columns});
  auto out = a.template mutable_unchecked<2>();
  for (py::ssize_t r = 0; r < rows; ++r)
    for (py::ssize_t c = 0; c < columns; ++c)
      out(r, c) = get(array[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)]);
  return a;
}

std::int64_t Integer(const nlohmann::json& v) {
  return v.get<std::int64_t>();
}

}  // namespace

py::object JsonToPython(const nlohmann::json& value, std::string_view key) {
  switch (value.type()) {
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (const auto& [k, item] : value.items()) d[py::str(k)] = JsonToPython(item, k);
      return d;
    }
    case nlohmann::json::value_t::array: {
      if (value.empty()) {
        if (const auto shape = EmptyIndexShape(key)) return py::array_t<std::int64_t>(*shape);
        return py::list();
      }
      if (AllIntegers(value)) return Vector<std::int64_t>(value, Integer);
      if (AllNumbersOrNull(value)) return Vector<double>(value, NumberOrNan);
      if (AllBooleans(value))
        return Vector<bool>(value, [](const nlohmann::json& v) { return v.get<bool>(); });
      if (IsMatrix(value, AllIntegers)) return Matrix<std::int64_t>(value, Integer);
      if (IsMatrix(value, AllNumbersOrNull)) return Matrix<double>(value, NumberOrNan);
      py::list l;
      for (const auto& item : value) l.append(JsonToPython(item));
      return l;
    }
    case nlohmann::json::value_t::string:
      if (IsInfinity(value) && !IsTextMember(key)) return py::float_(NumberOrNan(value));
      return py::str(value.get<std::string>());
    case nlohmann::json::value_t::boolean:
      return py::bool_(value.get<bool>());
    case nlohmann::json::value_t::number_integer:
      return py::int_(value.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(value.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float:
      return py::float_(value.get<double>());
    default:
      return py::none();
  }
}

Log LogFromArrays(const Doubles& poses, const Doubles& ranges, const Doubles& angles,
                  double max_range, double min_range, double sigma, bool one_scan) {
  if (poses.ndim() != 2 || poses.shape(1) != 3)
    throw std::invalid_argument("poses must have shape (n, 3): x, y, theta per scan");
  if (ranges.ndim() != 2 || ranges.shape(0) != poses.shape(0))
    throw std::invalid_argument(
        fmt::format("ranges must have shape (n, m) with n = {} scans", poses.shape(0)));
  const py::ssize_t n = ranges.shape(0), m = ranges.shape(1);
  const bool shared_angles = angles.ndim() == 1;
  if ((shared_angles && angles.shape(0) != m) ||
      (!shared_angles && (angles.ndim() != 2 || angles.shape(0) != n || angles.shape(1) != m)))
    throw std::invalid_argument(
        fmt::format("angles must have shape ({},) or ({}, {}), like the ranges", m, n, m));
  if (!(sigma > 0.0)) throw std::invalid_argument("sigma must be positive");
  const auto p = poses.unchecked<2>();
  const auto r = ranges.unchecked<2>();
  // What the file readers refuse (docs/formats.md, "What every reader checks"), said with the
  // arrays' indices: positions beyond the world, headings and angles that are not numbers.
  for (py::ssize_t k = 0; k < n; ++k) {
    for (py::ssize_t c = 0; c < 2; ++c)
      if (!IsWithinWorld(p(k, c)))
        throw std::invalid_argument(fmt::format(
            "poses[{}, {}] = {}: x and y are metres in a local frame, finite and at most {:g} in "
            "magnitude (the bound of world coordinates)",
            k, c, p(k, c), kMaxWorldCoordinate));
    if (!std::isfinite(p(k, 2)))
      throw std::invalid_argument(
          fmt::format("poses[{}, 2] = {}: theta must be finite", k, p(k, 2)));
  }
  for (py::ssize_t k = 0; k < (shared_angles ? 1 : n); ++k)
    for (py::ssize_t i = 0; i < m; ++i)
      if (const double a = shared_angles ? angles.at(i) : angles.at(k, i); !std::isfinite(a))
        throw std::invalid_argument(
            shared_angles || one_scan
                ? fmt::format("angles[{}] = {}: angles must be finite", i, a)
                : fmt::format("angles[{}, {}] = {}: angles must be finite", k, i, a));
  Log log;
  log.pose_source = PoseSource::kUnknown;
  for (py::ssize_t k = 0; k < n; ++k) {
    Scan scan;
    scan.channel = "PYTHON";
    scan.pose = Se2(p(k, 0), p(k, 1), p(k, 2));
    scan.min_range = min_range;
    scan.max_range = max_range;
    for (py::ssize_t i = 0; i < m; ++i) {
      scan.angles.push_back(shared_angles ? angles.at(i) : angles.at(k, i));
      scan.ranges.push_back(r(k, i));
    }
    scan.sigma.assign(static_cast<std::size_t>(m), sigma);
    scan.ClassifyAll();
    if (const auto problems = scan.Problems(); !problems.empty())
      throw std::invalid_argument(one_scan ? problems.front()
                                           : fmt::format("scan {}: {}", k, problems.front()));
    // A return (a reading below max_range) is a distance to a surface: at most the bound too; a
    // no-return reading is kept whatever its value, as the readers keep it.
    for (py::ssize_t i = 0; i < m; ++i)
      if (scan.status[static_cast<std::size_t>(i)] == BeamStatus::kValid &&
          !IsReturnWithinWorld(r(k, i)))
        throw std::invalid_argument(fmt::format(
            "ranges[{}] = {}: a return (below max_range {}) is at most {:g} m, the bound of "
            "world coordinates",
            one_scan ? fmt::format("{}", i) : fmt::format("{}, {}", k, i), r(k, i), max_range,
            kMaxWorldCoordinate));
    log.scans.push_back(std::move(scan));
  }
  return log;
}

py::array_t<double> MatrixToNumpy(const Eigen::MatrixXd& matrix) {
  py::array_t<double> a(
      {static_cast<py::ssize_t>(matrix.rows()), static_cast<py::ssize_t>(matrix.cols())});
  auto out = a.mutable_unchecked<2>();
  for (Eigen::Index r = 0; r < matrix.rows(); ++r)
    for (Eigen::Index c = 0; c < matrix.cols(); ++c) out(r, c) = matrix(r, c);
  return a;
}

}  // namespace priormap::python
