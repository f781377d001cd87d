#pragma once
// Conversions between priormap's types and Python's: JSON documents become dicts whose numeric
// lists are numpy arrays; numpy arrays of scans become a priormap::Log.

#include <optional>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <nlohmann/json.hpp>

#include <priormap/core/log.hpp>

namespace priormap::python {

namespace py = pybind11;

/// A numpy array of float64 in C order (other dtypes and layouts are converted on the way in).
using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// Objects become dicts, lists of numbers numpy float64 arrays (null entries NaN; of bools, bool
/// arrays; of equal-length number lists, 2-D arrays), other lists Python lists, null None.
py::object JsonToPython(const nlohmann::json& value);

/// Localized scans from arrays: poses (n, 3) of x, y, theta; ranges (n, m); angles (m,) shared by
/// every scan or (n, m). NaN readings are invalid, readings at or above max_range are max-range
/// readings. Throws std::invalid_argument (ValueError in Python) on mismatched shapes.
Log LogFromArrays(const Doubles& poses, const Doubles& ranges, const Doubles& angles,
                  double max_range, double min_range, double sigma);

/// A raster (row 0 at the bottom, as the library keeps them) as a 2-D numpy array.
py::array_t<double> MatrixToNumpy(const Eigen::MatrixXd& matrix);

}  // namespace priormap::python
