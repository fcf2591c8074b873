// sinew/result.h — error values instead of exceptions or aborts.
//
// Every fallible sinew call returns Status (success or an Error) or Result<T>
// (a T or an Error). The library never exits, aborts or throws on bad input,
// missing devices or failed kernel builds: the caller decides what to do.
#pragma once

#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace sinew {

/// What kind of failure an Error is, for callers that react to some kinds
/// (retry on another backend, grow a capacity, report a bad file) and not others.
enum class ErrorCode {
  bad_parameter,        ///< a value given to sinew is out of its range, non-finite or inconsistent
  bad_input_file,       ///< a file could not be read (or written) or is malformed
  backend_unavailable,  ///< the backend is not built, or has no device or driver here
  device_lost,          ///< the device stopped working (driver reset, hang, crash)
  out_of_memory,        ///< host or device memory ran out
  capacity_exceeded,    ///< data-dependent work outgrew a declared capacity (results were kept within it)
  internal,             ///< a bug in sinew, or a device failure with no better description
  diverged,             ///< a frame diverged and DivergenceSettings::on_divergence is stop (sinew/divergence.h)
};

/// The code's name, e.g. "capacity_exceeded".
constexpr const char* error_code_name(ErrorCode code) {
  switch (code) {
    case ErrorCode::bad_parameter: return "bad_parameter";
    case ErrorCode::bad_input_file: return "bad_input_file";
    case ErrorCode::backend_unavailable: return "backend_unavailable";
    case ErrorCode::device_lost: return "device_lost";
    case ErrorCode::out_of_memory: return "out_of_memory";
    case ErrorCode::capacity_exceeded: return "capacity_exceeded";
    case ErrorCode::internal: return "internal";
    case ErrorCode::diverged: return "diverged";
  }
  return "unknown";
}

/// A human-readable description of what went wrong, with its kind. Messages
/// name the file and line, or the parameter, that caused the problem.
class Error {
 public:
  /// An error of kind `code` described by `message`.
  Error(ErrorCode code, std::string message) : code_(code), message_(std::move(message)) {}
  /// The kind of failure.
  [[nodiscard]] ErrorCode code() const { return code_; }
  /// What went wrong, naming the file and line or the parameter.
  [[nodiscard]] const std::string& message() const { return message_; }

 private:
  ErrorCode code_;
  std::string message_;
};

/// Success, or an Error. Check with `if (!status)` and read `status.error()`.
class [[nodiscard]] Status {
 public:
  /// Success.
  Status() = default;
  /// Failure with `error` (implicit, so a function returning Status can `return Error{...}`).
  Status(Error error) : error_(std::move(error)), ok_(false) {}  // NOLINT: implicit by design
  /// Whether it succeeded.
  ///@{
  [[nodiscard]] bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  ///@}
  /// [pre] !ok()
  [[nodiscard]] const Error& error() const { assert(!ok_); return error_; }

 private:
  Error error_{ErrorCode::internal, ""};
  bool ok_ = true;
};

/// A value of type T, or an Error.
template <class T>
class [[nodiscard]] Result {
 public:
  /// A value (implicit, so a function returning Result<T> can `return value;`).
  Result(T value) : v_(std::in_place_index<0>, std::move(value)) {}  // NOLINT: implicit by design
  /// An error (implicit, so a function returning Result<T> can `return Error{...}`).
  Result(Error error) : v_(std::in_place_index<1>, std::move(error)) {}  // NOLINT
  /// Whether it holds a value.
  ///@{
  [[nodiscard]] bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  ///@}
  /// The value. [pre] ok()
  ///@{
  [[nodiscard]] T& value() & { assert(ok()); return std::get<0>(v_); }
  [[nodiscard]] const T& value() const& { assert(ok()); return std::get<0>(v_); }
  [[nodiscard]] T&& value() && { assert(ok()); return std::get<0>(std::move(v_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  ///@}
  /// [pre] !ok()
  [[nodiscard]] const Error& error() const { assert(!ok()); return std::get<1>(v_); }
  /// The error as a Status (for forwarding); [pre] !ok()
  [[nodiscard]] Status status() const { return ok() ? Status() : Status(error()); }

 private:
  std::variant<T, Error> v_;
};

}  // namespace sinew
