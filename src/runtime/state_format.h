// state_format.h — the bytes of a SavedState (sinew/saved_state.h): a fixed
// header (magic, version, byte order, payload size, payload hash) and a
// payload written and read field by field in one order. The writer appends
// plain values and arrays; the reader checks every length against what is
// left, so a truncated or damaged payload is an error, never a read past
// the end.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "sinew/result.h"
#include "sinew/saved_state.h"

namespace sinew::state_format {

inline constexpr char kMagic[8] = {'s', 'i', 'n', 'e', 'w', 's', 't', '\x1a'};
inline constexpr std::uint32_t kByteOrder = 0x01020304u;
inline constexpr std::size_t kHeaderBytes = 8 + 4 + 4 + 8 + 8;

/// Appends to a state's bytes (the header is left room for by begin(), completed by finish()).
class Writer {
 public:
  explicit Writer(std::vector<std::byte>& out) : out_(out) {}
  /// Clears the bytes and leaves room for the header.
  void begin() { out_.assign(kHeaderBytes, std::byte{0}); }
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    raw(&v, sizeof v);
  }
  /// An array with its length first (elements, uint64).
  template <class T>
  void array(std::span<const T> values) {
    value(static_cast<std::uint64_t>(values.size()));
    raw(values.data(), values.size_bytes());
  }
  /// Room for `bytes` more bytes appended at once (a buffer read straight into it); with its length first.
  std::byte* reserve_array(std::size_t bytes) {
    value(static_cast<std::uint64_t>(bytes));
    const std::size_t at = out_.size();
    out_.resize(at + bytes);
    return out_.data() + at;
  }
  /// Writes the header over the room begin() left.
  void finish();

 private:
  void raw(const void* data, std::size_t bytes) {
    const std::size_t at = out_.size();
    out_.resize(at + bytes);
    if (bytes) std::memcpy(out_.data() + at, data, bytes);
  }
  std::vector<std::byte>& out_;
};

/// Reads a payload in the order it was written; every call checks the bytes left.
class Reader {
 public:
  Reader(std::span<const std::byte> payload, std::string what) : left_(payload), what_(std::move(what)) {}
  template <class T>
  Status value(T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (left_.size() < sizeof v) return truncated();
    std::memcpy(&v, left_.data(), sizeof v);
    left_ = left_.subspan(sizeof v);
    return {};
  }
  /// An array of exactly `expected` bytes (what this scene holds there); `name` names it in the error.
  Status array_into(void* into, std::size_t expected, const char* name);
  /// An array of T into a vector, at most `limit` elements.
  template <class T>
  Status array(std::vector<T>& into, std::size_t limit, const char* name) {
    std::uint64_t n = 0;
    if (Status s = value(n); !s) return s;
    if (n > limit || n * sizeof(T) > left_.size()) return mismatch(name, n, limit);
    into.resize(n);
    if (n) std::memcpy(into.data(), left_.data(), n * sizeof(T));
    left_ = left_.subspan(n * sizeof(T));
    return {};
  }
  [[nodiscard]] bool done() const { return left_.empty(); }
  Status truncated() const;
  Status mismatch(const char* name, std::uint64_t got, std::uint64_t want) const;

 private:
  std::span<const std::byte> left_;
  std::string what_;
};

/// Checks a state's header; [out] payload: the bytes after it; version: the
/// format version it was written in (when not null). `what` names the state
/// in errors ("restore_state", or the file's path).
Status open(std::span<const std::byte> bytes, const std::string& what, std::span<const std::byte>& payload,
            std::uint32_t* version = nullptr);

}  // namespace sinew::state_format
