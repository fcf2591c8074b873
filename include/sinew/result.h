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

/// A human-readable description of what went wrong. Messages name the file
/// and line, or the parameter, that caused the problem.
class Error {
 public:
  explicit Error(std::string message) : message_(std::move(message)) {}
  [[nodiscard]] const std::string& message() const { return message_; }

 private:
  std::string message_;
};

/// Success, or an Error. Check with `if (!status)` and read `status.error()`.
class [[nodiscard]] Status {
 public:
  Status() = default;  // success
  Status(Error error) : error_(std::move(error)), ok_(false) {}  // NOLINT: implicit by design
  [[nodiscard]] bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  /// [pre] !ok()
  [[nodiscard]] const Error& error() const { assert(!ok_); return error_; }

 private:
  Error error_{""};
  bool ok_ = true;
};

/// A value of type T, or an Error.
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::in_place_index<0>, std::move(value)) {}  // NOLINT: implicit by design
  Result(Error error) : v_(std::in_place_index<1>, std::move(error)) {}  // NOLINT
  [[nodiscard]] bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  /// [pre] ok()
  [[nodiscard]] T& value() & { assert(ok()); return std::get<0>(v_); }
  [[nodiscard]] const T& value() const& { assert(ok()); return std::get<0>(v_); }
  [[nodiscard]] T&& value() && { assert(ok()); return std::get<0>(std::move(v_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  /// [pre] !ok()
  [[nodiscard]] const Error& error() const { assert(!ok()); return std::get<1>(v_); }
  /// The error as a Status (for forwarding); [pre] !ok()
  [[nodiscard]] Status status() const { return ok() ? Status() : Status(error()); }

 private:
  std::variant<T, Error> v_;
};

}  // namespace sinew
