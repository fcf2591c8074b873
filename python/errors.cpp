// errors.cpp — sinew.Error: the Python exception every library error becomes.
#include "errors.h"

namespace py = pybind11;

namespace sinew::python {

void register_errors(py::module_& m) {
  // Kept for the life of the process: the translator may run until the
  // interpreter ends, after the module's own references are gone.
  static py::handle error_type;
  error_type = py::exception<PythonError>(m, "Error", PyExc_RuntimeError).release();
  error_type.attr("__doc__") =
      "A sinew error: the message names the parameter, file or JSON path at fault; `code` says its kind "
      "(bad_parameter, bad_input_file, backend_unavailable, device_lost, out_of_memory, capacity_exceeded, "
      "internal, diverged).";
  // Instances raised from Python itself have no code of their own.
  error_type.attr("code") = py::none();
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const PythonError& e) {
      py::object instance = error_type(e.error.message());
      instance.attr("code") = error_code_name(e.error.code());
      PyErr_SetObject(error_type.ptr(), instance.ptr());
    }
  });
}

}  // namespace sinew::python
