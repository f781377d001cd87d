#pragma once
// The parts of the priormap Python module, one per engine; module.cpp puts them together.

#include <pybind11/pybind11.h>

namespace priormap::python {

void BindPriorlets(pybind11::module_& m);
void BindSlam(pybind11::module_& m);
void BindMapping(pybind11::module_& m);

}  // namespace priormap::python
