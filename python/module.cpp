// module.cpp — the `sinew` Python module (docs/python.md): scenes, the
// Simulation, its features, statistics and errors.
#include <pybind11/stl.h>

#include "bindings.h"
#include "errors.h"
#include "sinew/device.h"
#include "sinew/version.h"

namespace py = pybind11;

PYBIND11_MODULE(sinew, m) {
  m.doc() = "sinew: physics for interactive surgical simulation (docs/python.md)";
  m.attr("__version__") = SINEW_VERSION_STRING;
  sinew::python::register_errors(m);
  sinew::python::bind_stats(m);
  sinew::python::bind_states(m);
  sinew::python::bind_scene(m);
  sinew::python::bind_simulation(m);
  sinew::python::bind_features(m);
  m.def("built_backends", &sinew::built_backends, "The backends built into this module ('cpu' always).");
}
