// json_fields.cpp — typed reads with JSON-path errors (json_fields.h).
#include "scene_file/json_fields.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <sstream>

namespace sinew::scene_file {

void Context::fail(ErrorCode code, const std::string& path, const std::string& rule) {
  if (!error_) error_.emplace(code, (path.empty() ? std::string("/") : path) + ": " + rule);
}

std::string type_name(const Json& value) {
  switch (value.type()) {
    case Json::value_t::null: return "null";
    case Json::value_t::object: return "an object";
    case Json::value_t::array: return "an array of " + std::to_string(value.size());
    case Json::value_t::string: return "a string";
    case Json::value_t::boolean: return "a boolean";
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float: return "a number";
    default: return "an unreadable value";
  }
}

namespace {

std::string number_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

bool read_double(const Json& v, const std::string& path, Context& ctx, double& out) {
  if (ctx.failed()) return false;
  if (!v.is_number()) {
    ctx.fail(ErrorCode::bad_input_file, path, "must be a number (got " + type_name(v) + ")");
    return false;
  }
  const double d = v.get<double>();
  // (JSON text cannot hold one: the parser refuses 1e999; checked all the same.)
  if (!std::isfinite(d)) {
    ctx.fail(ErrorCode::bad_parameter, path, "must be finite");
    return false;
  }
  out = d;
  return true;
}

bool read_int(const Json& v, const std::string& path, Context& ctx, long long lo, long long hi, long long& out) {
  if (ctx.failed()) return false;
  if (!v.is_number()) {
    ctx.fail(ErrorCode::bad_input_file, path, "must be a whole number (got " + type_name(v) + ")");
    return false;
  }
  long long value = 0;
  if (v.is_number_unsigned()) {
    const auto u = v.get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(std::numeric_limits<long long>::max())) {
      ctx.fail(ErrorCode::bad_parameter, path, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
      return false;
    }
    value = static_cast<long long>(u);
  } else if (v.is_number_integer()) {
    value = v.get<long long>();
  } else {
    const double d = v.get<double>();
    if (!(std::isfinite(d) && d == std::floor(d) && std::abs(d) < 9e15)) {
      ctx.fail(ErrorCode::bad_input_file, path, "must be a whole number (got " + number_text(d) + ")");
      return false;
    }
    value = static_cast<long long>(d);
  }
  if (value < lo || value > hi) {
    ctx.fail(ErrorCode::bad_parameter, path,
             "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "] (got " + std::to_string(value) + ")");
    return false;
  }
  out = value;
  return true;
}

bool read_uint32(const Json& v, const std::string& path, Context& ctx, std::uint32_t& out) {
  long long value = 0;
  if (!read_int(v, path, ctx, 0, std::numeric_limits<std::uint32_t>::max(), value)) return false;
  out = static_cast<std::uint32_t>(value);
  return true;
}

Object::Object(const Json& value, std::string path, Context& ctx) : path_(std::move(path)), ctx_(&ctx) {
  if (ctx.failed()) return;
  if (!value.is_object()) {
    ctx.fail(ErrorCode::bad_input_file, path_, "must be an object (got " + type_name(value) + ")");
    return;
  }
  object_ = &value;
}

const Json* Object::find(const std::string& key) {
  if (!object_ || ctx_->failed()) return nullptr;
  const auto it = object_->find(key);
  if (it == object_->end()) return nullptr;
  read_.insert(key);
  return &*it;
}

bool Object::has(const std::string& key) const { return object_ && object_->contains(key); }

void Object::finish() {
  if (!object_ || ctx_->failed()) return;
  for (const auto& [key, value] : object_->items())
    if (!read_.count(key)) {
      ctx_->fail(ErrorCode::bad_input_file, path(key), "unknown key (docs/scene_files.md lists the keys)");
      return;
    }
}

namespace {

// The member `key` of `o`, or nullptr; an error when required and absent.
const Json* member(Object& o, const std::string& key, bool required) {
  const Json* v = o.find(key);
  if (!v && required && !o.ctx().failed() && o.valid())
    o.ctx().fail(ErrorCode::bad_input_file, o.path(key), "is required");
  return v;
}

}  // namespace

void Object::read(const std::string& key, double& out, bool required) {
  if (const Json* v = member(*this, key, required)) read_double(*v, path(key), *ctx_, out);
}

void Object::read(const std::string& key, int& out, bool required) {
  long long value = 0;
  if (const Json* v = member(*this, key, required))
    if (read_int(*v, path(key), *ctx_, std::numeric_limits<int>::min(), std::numeric_limits<int>::max(), value))
      out = static_cast<int>(value);
}

void Object::read(const std::string& key, std::uint32_t& out, bool required) {
  if (const Json* v = member(*this, key, required)) read_uint32(*v, path(key), *ctx_, out);
}

void Object::read(const std::string& key, bool& out, bool required) {
  if (const Json* v = member(*this, key, required)) {
    if (v->is_boolean()) out = v->get<bool>();
    else ctx_->fail(ErrorCode::bad_input_file, path(key), "must be true or false (got " + type_name(*v) + ")");
  }
}

void Object::read(const std::string& key, std::string& out, bool required) {
  if (const Json* v = member(*this, key, required)) {
    if (v->is_string()) out = v->get<std::string>();
    else ctx_->fail(ErrorCode::bad_input_file, path(key), "must be a string (got " + type_name(*v) + ")");
  }
}

void Object::read(const std::string& key, std::array<double, 3>& out, bool required) {
  if (const Json* v = member(*this, key, required)) read_doubles(*v, path(key), *ctx_, out);
}

void Object::read(const std::string& key, std::array<double, 4>& out, bool required) {
  if (const Json* v = member(*this, key, required)) read_doubles(*v, path(key), *ctx_, out);
}

const std::initializer_list<std::string_view> kSceneRoots = {
    "gravity",     "solver",           "tet_bodies", "tri_bodies", "line_bodies",    "colliders",
    "targets",     "attachments",      "body_attachments", "tools", "needles",   "graspers",
    "mesh_collision", "external_forces", "topology_changes", "fluid"};

std::pair<std::string, std::string> split_scene_message(const std::string& message,
                                                        std::initializer_list<std::string_view> roots) {
  // The leading name: identifiers joined by '.', each with [index] suffixes.
  std::size_t i = 0;
  std::string path;
  while (i < message.size()) {
    const std::size_t start = i;
    while (i < message.size() && (std::isalnum(static_cast<unsigned char>(message[i])) || message[i] == '_')) ++i;
    if (i == start) break;
    if (path.empty() && std::find(roots.begin(), roots.end(), std::string_view(message).substr(start, i - start)) == roots.end())
      return {"", message};
    path += "/" + message.substr(start, i - start);
    while (i < message.size() && message[i] == '[') {
      const std::size_t close = message.find(']', i);
      if (close == std::string::npos) return {"", message};
      path += "/" + message.substr(i + 1, close - i - 1);
      i = close + 1;
    }
    if (i < message.size() && message[i] == '.') ++i;
    else break;
  }
  if (path.empty() || i >= message.size() || (message[i] != ' ' && message[i] != ':')) return {"", message};
  // The file holds SceneFluidDesc::fluid's keys in "fluid" itself.
  if (path.rfind("/fluid/fluid/", 0) == 0) path.erase(0, 6);
  const std::size_t rule = message.find_first_not_of(": ", i);
  return {path, rule == std::string::npos ? std::string() : message.substr(rule)};
}

}  // namespace sinew::scene_file
