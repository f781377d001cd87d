#pragma once
// Conversions between priormap's types and Python's: JSON documents become dicts whose numeric
// lists are numpy arrays; numpy arrays of scans become a priormap::Log.

#include <optional>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <string_view>

#include <nlohmann/json.hpp>

#include <priormap/core/log.hpp>

namespace priormap::python {

namespace py = pybind11;

/// A numpy array of float64 in C order (other dtypes and layouts are converted on the way in).
using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// Objects become dicts; lists of whole numbers int64 arrays, lists of numbers (null entries NaN)
/// float64 arrays, of bools bool arrays, of equal-length such lists 2-D arrays; other lists Python
/// lists, null None. `key` is the member's name: the beam-index members ("regions", "surfaces",
/// "inmodel_beams") are int arrays even when empty, and text members stay text.
py::object JsonToPython(const nlohmann::json& value, std::string_view key = "");

/// Localized scans from arrays: poses (n, 3) of x, y, theta; ranges (n, m); angles (m,) shared by
/// every scan or (n, m). NaN readings are invalid, readings at or above max_range are max-range
/// readings. Throws std::invalid_argument (ValueError in Python) on mismatched shapes and on
/// what the file readers refuse: x or y beyond 1e9 m, angles that are not finite or do not
/// increase, returns (readings below max_range) beyond 1e9 m, min_range not below max_range.
/// `one_scan`: the ranges are the caller's one scan, (m,), and messages index them so.
Log LogFromArrays(const Doubles& poses, const Doubles& ranges, const Doubles& angles,
                  double max_range, double min_range, double sigma, bool one_scan = false);

/// A raster (row 0 at the bottom, as the library keeps them) as a 2-D numpy array.
py::array_t<double> MatrixToNumpy(const Eigen::MatrixXd& matrix);

}  // namespace priormap::python
