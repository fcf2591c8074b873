// errors.h — sinew's Status and Result as Python exceptions: every error the
// library returns becomes `sinew.Error` (a RuntimeError) with the message
// and a `.code` attribute ("bad_parameter", "bad_input_file", ...), so a
// Python caller never sees a crash or a silently ignored failure.
#pragma once

#include <pybind11/pybind11.h>

#include <string>
#include <utility>

#include "sinew/result.h"

namespace sinew::python {

/// A sinew Error on its way to Python (translated by register_errors).
struct PythonError {
  Error error;
};

/// Throws `error` as sinew.Error.
[[noreturn]] inline void raise(Error error) { throw PythonError{std::move(error)}; }
/// Throws a bad_parameter sinew.Error with `message` (a binding's own check
/// of its arguments: an array of the wrong shape or type).
[[noreturn]] inline void raise_bad_parameter(std::string message) {
  raise(Error{ErrorCode::bad_parameter, std::move(message)});
}

/// Throws the status's error, if any.
inline void check(const Status& status) {
  if (!status) raise(status.error());
}

/// The result's value, or throws its error.
template <class T>
T take(Result<T>&& result) {
  if (!result) raise(result.error());
  return std::move(result).value();
}

/// Adds `Error` (a subclass of RuntimeError) to module `m` and translates
/// PythonError into it with its `.code`.
void register_errors(pybind11::module_& m);

}  // namespace sinew::python
