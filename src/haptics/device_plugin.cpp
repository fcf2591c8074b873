// src/haptics/device_plugin.cpp — loading haptic device plug-ins (dlopen,
// the C table of sinew/haptics/device_plugin_abi.h checked once) and the
// HapticDevice adapter over an opened plug-in device.
#include "sinew/haptics/device_plugin.h"

#include <dlfcn.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <string>
#include <utility>

namespace sinew::haptics {

// The handle and the table; dlclose when the last owner (the DevicePlugin,
// a PluginDevice) lets go.
struct PluginLibrary {
  void* handle = nullptr;
  const sinew_haptic_plugin_v1* table = nullptr;
  std::string path;
  std::string name;

  PluginLibrary() = default;
  PluginLibrary(const PluginLibrary&) = delete;
  PluginLibrary& operator=(const PluginLibrary&) = delete;
  ~PluginLibrary() {
    if (handle) dlclose(handle);
  }
};

namespace {

// Plug-ins' messages: a fixed buffer, NUL-terminated whatever the plug-in wrote.
constexpr std::size_t kErrorSize = 512;
using ErrorBuffer = std::array<char, kErrorSize>;

std::string message_of(ErrorBuffer& buffer, const char* fallback) {
  buffer.back() = '\0';
  return buffer[0] != '\0' ? std::string(buffer.data()) : std::string(fallback);
}

std::string last_dlerror() {
  const char* e = dlerror();
  return e ? e : "no reason given by dlerror";
}

Error plugin_error(ErrorCode code, const std::string& path, const std::string& what) {
  return Error(code, "haptic plug-in " + path + ": " + what);
}

// The first null function pointer of a version-1 table, or nullptr.
const char* first_null_function(const sinew_haptic_plugin_v1& t) {
  if (!t.device_count) return "device_count";
  if (!t.device_name) return "device_name";
  if (!t.open) return "open";
  if (!t.close) return "close";
  if (!t.start) return "start";
  if (!t.stop) return "stop";
  if (!t.sample) return "sample";
  if (!t.command) return "command";
  if (!t.update_rate_hz) return "update_rate_hz";
  if (!t.degrees_of_freedom) return "degrees_of_freedom";
  return nullptr;
}

// Whether `text` is a decimal number that fits in a uint32_t; [out] value.
bool parse_index(const std::string& text, std::uint32_t& value) {
  if (text.empty() || text.size() > 10) return false;
  std::uint64_t v = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
    v = 10 * v + std::uint64_t(c - '0');
  }
  if (v > 0xffffffffu) return false;
  value = std::uint32_t(v);
  return true;
}

}  // namespace

// ------------------------------------------------------------- DevicePlugin

Result<std::unique_ptr<DevicePlugin>> DevicePlugin::load(const std::string& path) {
  if (path.empty()) return Error(ErrorCode::bad_parameter, "haptic plug-in: the path is empty");
  auto library = std::make_shared<PluginLibrary>();
  library->path = path;
  dlerror();  // clear an earlier, unrelated message
  library->handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!library->handle)
    return plugin_error(ErrorCode::bad_input_file, path, "cannot load the library: " + last_dlerror());

  dlerror();
  void* symbol = dlsym(library->handle, SINEW_HAPTIC_PLUGIN_ENTRY_NAME);
  if (!symbol)
    return plugin_error(ErrorCode::bad_input_file, path,
                        "no entry point " SINEW_HAPTIC_PLUGIN_ENTRY_NAME " (" + last_dlerror() +
                            "); is it a sinew haptic device plug-in, exported with SINEW_HAPTIC_PLUGIN_EXPORT?");
  // POSIX guarantees dlsym's object pointer converts to a function pointer;
  // memcpy says so without a cast ISO C++ calls conditionally supported.
  sinew_haptic_plugin_entry_fn entry = nullptr;
  static_assert(sizeof(entry) == sizeof(symbol));
  std::memcpy(&entry, &symbol, sizeof(entry));

  const sinew_haptic_plugin_v1* table = entry();
  if (!table)
    return plugin_error(ErrorCode::bad_input_file, path,
                        SINEW_HAPTIC_PLUGIN_ENTRY_NAME " returned no table (NULL): the plug-in cannot work here");
  // abi_version comes first in every version: read it before trusting the rest.
  if (table->abi_version != SINEW_HAPTIC_PLUGIN_ABI_VERSION)
    return Error(ErrorCode::bad_input_file, "haptic plug-in " + path + " has ABI version " +
                                                std::to_string(table->abi_version) + "; this sinew reads version " +
                                                std::to_string(SINEW_HAPTIC_PLUGIN_ABI_VERSION));
  if (table->struct_size < sizeof(sinew_haptic_plugin_v1))
    return plugin_error(ErrorCode::bad_input_file, path,
                        "struct_size is " + std::to_string(table->struct_size) +
                            " bytes, smaller than ABI version 1's table (" +
                            std::to_string(sizeof(sinew_haptic_plugin_v1)) + " bytes)");
  if (!table->name || table->name[0] == '\0')
    return plugin_error(ErrorCode::bad_input_file, path, "the table's name is NULL or empty");
  if (const char* missing = first_null_function(*table))
    return plugin_error(ErrorCode::bad_input_file, path,
                        std::string("the table's function pointer '") + missing + "' is NULL");
  library->table = table;
  library->name = table->name;
  return std::unique_ptr<DevicePlugin>(new DevicePlugin(std::move(library)));
}

DevicePlugin::DevicePlugin(std::shared_ptr<const PluginLibrary> library) : library_(std::move(library)) {}
DevicePlugin::~DevicePlugin() = default;

const std::string& DevicePlugin::path() const { return library_->path; }
const std::string& DevicePlugin::name() const { return library_->name; }
std::uint32_t DevicePlugin::abi_version() const { return library_->table->abi_version; }
std::uint32_t DevicePlugin::struct_size() const { return library_->table->struct_size; }

Result<std::vector<std::string>> DevicePlugin::devices() const {
  const sinew_haptic_plugin_v1& t = *library_->table;
  const std::uint32_t count = t.device_count();
  if (count > kMaxPluginDevices)
    return plugin_error(ErrorCode::bad_input_file, library_->path,
                        "device_count() says " + std::to_string(count) + " devices, more than the " +
                            std::to_string(kMaxPluginDevices) + " sinew accepts");
  std::vector<std::string> names;
  names.reserve(count);
  for (std::uint32_t i = 0; i < count; ++i) {
    const char* n = t.device_name(i);
    if (!n || n[0] == '\0')
      return plugin_error(ErrorCode::bad_input_file, library_->path,
                          "device_name(" + std::to_string(i) + ") is NULL or empty, of " + std::to_string(count) +
                              " devices");
    names.emplace_back(n);
  }
  return names;
}

Result<std::unique_ptr<PluginDevice>> DevicePlugin::open(const std::string& name_or_index,
                                                        const std::string& config) const {
  auto listed = devices();
  if (!listed) return listed.error();
  const std::vector<std::string>& names = *listed;
  // A name first (a device may be called "1"), then an index.
  std::uint32_t index = std::uint32_t(names.size());
  for (std::uint32_t i = 0; i < names.size(); ++i)
    if (names[i] == name_or_index) { index = i; break; }
  if (index == names.size()) {
    std::uint32_t parsed = 0;
    if (parse_index(name_or_index, parsed) && parsed < names.size()) index = parsed;
  }
  if (index == names.size()) {
    std::string known;
    for (std::uint32_t i = 0; i < names.size(); ++i)
      known += (i ? ", " : "") + std::to_string(i) + " \"" + names[i] + "\"";
    return plugin_error(ErrorCode::bad_parameter, library_->path,
                        "no device \"" + name_or_index + "\" (by name or index); it has " +
                            (names.empty() ? std::string("no devices") : "devices: " + known));
  }

  const sinew_haptic_plugin_v1& t = *library_->table;
  ErrorBuffer error{};
  sinew_haptic_device* handle = t.open(index, config.c_str(), error.data(), error.size());
  const std::string device_name = library_->name + ": " + names[index];
  if (!handle)
    return Error(ErrorCode::backend_unavailable, "haptic plug-in " + library_->path + ": cannot open device \"" +
                                                     names[index] + "\": " +
                                                     message_of(error, "(the plug-in gave no reason)"));
  const double rate = t.update_rate_hz(handle);
  const std::uint32_t dof = t.degrees_of_freedom(handle);
  if (!(rate > 0.0) || !std::isfinite(rate) || (dof != 3 && dof != 6)) {
    t.close(handle);
    return plugin_error(ErrorCode::bad_input_file, library_->path,
                        "device \"" + names[index] + "\" reports " +
                            (dof != 3 && dof != 6 ? std::to_string(dof) + " degrees of freedom (3 or 6 expected)"
                                                  : "update rate " + std::to_string(rate) +
                                                        " Hz (finite and > 0 expected)"));
  }
  return std::unique_ptr<PluginDevice>(new PluginDevice(library_, handle, device_name, rate, dof));
}

// ------------------------------------------------------------- PluginDevice

PluginDevice::PluginDevice(std::shared_ptr<const PluginLibrary> library, sinew_haptic_device* handle,
                           std::string name, double rate_hz, std::uint32_t dof)
    : library_(std::move(library)),
      table_(library_->table),
      handle_(handle),
      name_(std::move(name)),
      rate_hz_(rate_hz),
      dof_(dof) {}

PluginDevice::~PluginDevice() {
  stop();
  table_->close(handle_);
  // library_ goes last (declared first): the last device's dlclose.
}

Status PluginDevice::start(std::int64_t now_ns) {
  if (started_) return Error(ErrorCode::bad_parameter, "haptic device " + name_ + ": already started");
  ErrorBuffer error{};
  if (table_->start(handle_, now_ns, error.data(), error.size()) != 0)
    return Error(ErrorCode::backend_unavailable,
                 "haptic device " + name_ + ": cannot start: " + message_of(error, "(the plug-in gave no reason)"));
  started_ = true;
  return {};
}

void PluginDevice::stop() noexcept {
  if (!started_) return;
  table_->stop(handle_);
  started_ = false;
}

bool PluginDevice::sample(std::int64_t now_ns, DeviceSample& out) noexcept {
  sinew_haptic_sample s{};
  if (table_->sample(handle_, now_ns, &s) == 0) return false;
  out.sequence = s.sequence;
  out.time_ns = s.time_ns;
  for (int k = 0; k < 3; ++k) {
    out.position[k] = s.position[k];
    out.velocity[k] = s.velocity[k];
    out.angular_velocity[k] = s.angular_velocity[k];
  }
  for (int k = 0; k < 4; ++k) out.rotation[k] = s.rotation[k];
  out.buttons = s.buttons;
  return true;
}

void PluginDevice::command(const Vec3& force, const Vec3& torque, std::int64_t now_ns) noexcept {
  const double f[3] = {force[0], force[1], force[2]};
  const double m[3] = {dof_ == 6 ? torque[0] : 0.0, dof_ == 6 ? torque[1] : 0.0, dof_ == 6 ? torque[2] : 0.0};
  table_->command(handle_, f, m, now_ns);
}

}  // namespace sinew::haptics
