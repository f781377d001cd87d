// The priormap Python module (pybind11): thin wrappers over the C++ library; see
// python/priormap/__init__.py for the package and docs/python.md for the API.
#include "bindings.hpp"

PYBIND11_MODULE(_priormap, m) {
  m.doc() = "priormap: 2D mapping with structural prior knowledge (C++ core)";
  priormap::python::BindPriorlets(m);
  priormap::python::BindSlam(m);
  priormap::python::BindMapping(m);
}
