// json_fields.h — reading typed values out of a parsed JSON document with
// errors that name the JSON path (RFC 6901 pointer) and the rule broken.
// The first error wins: once one is recorded, every later read is a no-op,
// so the readers can be written as straight sequences of reads and check
// `ctx.failed()` at the points where going on would make no sense.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "sinew/result.h"

namespace sinew::scene_file {

using Json = nlohmann::json;

/// The first error met while reading a document.
class Context {
 public:
  [[nodiscard]] bool failed() const { return error_.has_value(); }
  /// Records "<path>: <rule>" unless an error is recorded already.
  void fail(ErrorCode code, const std::string& path, const std::string& rule);
  [[nodiscard]] const std::optional<Error>& error() const { return error_; }

 private:
  std::optional<Error> error_;
};

/// A JSON value's type in words ("a number", "an object").
std::string type_name(const Json& value);

/// An object being read: every key read is marked, and finish() names a
/// key never read (a typo, or a setting that does not exist).
class Object {
 public:
  /// Records an error unless `value` is an object.
  Object(const Json& value, std::string path, Context& ctx);
  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] std::string path(const std::string& key) const { return path_ + "/" + key; }
  [[nodiscard]] Context& ctx() const { return *ctx_; }
  [[nodiscard]] bool valid() const { return object_ != nullptr; }
  /// The member, marked as read, or nullptr when absent.
  const Json* find(const std::string& key);
  [[nodiscard]] bool has(const std::string& key) const;
  /// Records an error for the first key that was never read.
  void finish();

  // Each reads the member if present (leaving `out` as it is otherwise),
  // or requires it (`required`), checking its type and that a number is
  // finite and, for integers, whole and in range.
  void read(const std::string& key, double& out, bool required = false);
  void read(const std::string& key, int& out, bool required = false);
  void read(const std::string& key, std::uint32_t& out, bool required = false);
  void read(const std::string& key, bool& out, bool required = false);
  void read(const std::string& key, std::string& out, bool required = false);
  void read(const std::string& key, std::array<double, 3>& out, bool required = false);
  void read(const std::string& key, std::array<double, 4>& out, bool required = false);

 private:
  const Json* object_ = nullptr;
  std::string path_;
  Context* ctx_;
  std::set<std::string> read_;
};

// Free readers of one value at `path` (the same rules as Object::read).
bool read_double(const Json& v, const std::string& path, Context& ctx, double& out);
bool read_int(const Json& v, const std::string& path, Context& ctx, long long lo, long long hi, long long& out);
bool read_uint32(const Json& v, const std::string& path, Context& ctx, std::uint32_t& out);
template <std::size_t N>
bool read_doubles(const Json& v, const std::string& path, Context& ctx, std::array<double, N>& out) {
  if (ctx.failed()) return false;
  if (!v.is_array() || v.size() != N) {
    ctx.fail(ErrorCode::bad_input_file, path,
             "must be an array of " + std::to_string(N) + " numbers (got " + type_name(v) + ")");
    return false;
  }
  for (std::size_t i = 0; i < N; ++i)
    if (!read_double(v[i], path + "/" + std::to_string(i), ctx, out[i])) return false;
  return true;
}
template <std::size_t N>
bool read_uint32s(const Json& v, const std::string& path, Context& ctx, std::array<std::uint32_t, N>& out) {
  if (ctx.failed()) return false;
  if (!v.is_array() || v.size() != N) {
    ctx.fail(ErrorCode::bad_input_file, path,
             "must be an array of " + std::to_string(N) + " indices (got " + type_name(v) + ")");
    return false;
  }
  for (std::size_t i = 0; i < N; ++i)
    if (!read_uint32(v[i], path + "/" + std::to_string(i), ctx, out[i])) return false;
  return true;
}

/// Reads an array, calling `each(element, element_path)` for every element.
template <class F>
bool read_array(const Json& v, const std::string& path, Context& ctx, F&& each) {
  if (ctx.failed()) return false;
  if (!v.is_array()) {
    ctx.fail(ErrorCode::bad_input_file, path, "must be an array (got " + type_name(v) + ")");
    return false;
  }
  for (std::size_t i = 0; i < v.size() && !ctx.failed(); ++i) each(v[i], path + "/" + std::to_string(i));
  return !ctx.failed();
}

/// Reads a string naming one of `names` into the matching enumerator.
template <class E>
bool read_enum(const Json& v, const std::string& path, Context& ctx,
               std::initializer_list<std::pair<const char*, E>> names, E& out) {
  if (ctx.failed()) return false;
  std::string all;
  for (const auto& [name, value] : names) {
    if (v.is_string() && v.get_ref<const std::string&>() == name) {
      out = value;
      return true;
    }
    all += all.empty() ? std::string("\"") + name + "\"" : std::string(", \"") + name + "\"";
  }
  ctx.fail(ErrorCode::bad_input_file, path, "must be one of " + all + " (got " + (v.is_string() ? "\"" + v.get<std::string>() + "\"" : type_name(v)) + ")");
  return false;
}

/// check_scene's "tet_bodies[0].density must be > 0 (got -1)" as the path
/// "/tet_bodies/0/density" and the rule "must be > 0 (got -1)": the file's
/// keys are the SceneDesc's field names, so its names are the file's
/// paths. Only a name starting with one of `roots` is a path ("the scene
/// has no bodies" is not); otherwise: an empty path and the message.
std::pair<std::string, std::string> split_scene_message(const std::string& message,
                                                        std::initializer_list<std::string_view> roots);
/// The SceneDesc's fields: the roots of check_scene's names.
extern const std::initializer_list<std::string_view> kSceneRoots;

}  // namespace sinew::scene_file
