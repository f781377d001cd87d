#include "convert.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

namespace priormap::python {
namespace {

// Our JSON writes infinities as the strings "inf" and "-inf" (docs/formats.md).
bool IsInfinity(const nlohmann::json& value) {
  return value.is_string() && (value == "inf" || value == "-inf");
}

bool IsNumber(const nlohmann::json& value) {
  return value.is_number() || IsInfinity(value);
}

// Numbers, with nulls (NaN in the array) for what has no value, like an outlier's deviation.
bool AllNumbers(const nlohmann::json& array) {
  bool any_number = false;
  for (const auto& v : array) {
    if (!IsNumber(v) && !v.is_null()) return false;
    any_number = any_number || IsNumber(v);
  }
  return any_number;
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

// A list of number lists of one length: a matrix.
bool IsMatrix(const nlohmann::json& array) {
  if (array.empty() || !array.front().is_array()) return false;
  const std::size_t columns = array.front().size();
  for (const auto& row : array)
    if (!row.is_array() || row.size() != columns || !AllNumbers(row)) return false;
  return columns > 0;
}

}  // namespace

py::object JsonToPython(const nlohmann::json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (const auto& [key, item] : value.items()) d[py::str(key)] = JsonToPython(item);
      return d;
    }
    case nlohmann::json::value_t::array: {
      if (AllNumbers(value)) {
        py::array_t<double> a(static_cast<py::ssize_t>(value.size()));
        auto out = a.mutable_unchecked<1>();
        for (std::size_t i = 0; i < value.size(); ++i)
          out(static_cast<py::ssize_t>(i)) = NumberOrNan(value[i]);
        return a;
      }
      if (AllBooleans(value)) {
        py::array_t<bool> a(static_cast<py::ssize_t>(value.size()));
        auto out = a.mutable_unchecked<1>();
        for (std::size_t i = 0; i < value.size(); ++i)
          out(static_cast<py::ssize_t>(i)) = value[i].get<bool>();
        return a;
      }
      if (IsMatrix(value)) {
        const auto rows = static_cast<py::ssize_t>(value.size());
        const auto columns = static_cast<py::ssize_t>(value.front().size());
        py::array_t<double> a({rows, columns});
        auto out = a.mutable_unchecked<2>();
        for (py::ssize_t r = 0; r < rows; ++r)
          for (py::ssize_t c = 0; c < columns; ++c)
            out(r, c) =
                NumberOrNan(value[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)]);
        return a;
      }
      py::list l;
      for (const auto& item : value) l.append(JsonToPython(item));
      return l;
    }
    case nlohmann::json::value_t::string:
      if (IsInfinity(value)) return py::float_(NumberOrNan(value));
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
                  double max_range, double min_range, double sigma) {
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
      throw std::invalid_argument(fmt::format("scan {}: {}", k, problems.front()));
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
