// sinew/haptics/device_plugin.h — haptic devices from plug-ins loaded at
// run time: a vendor's driver (OpenHaptics, Force Dimension, libnifalcon,
// ...) built as a shared library against the C ABI of
// sinew/haptics/device_plugin_abi.h, not into sinew (docs/haptics.md,
// "Device plug-ins").
//
//   auto plugin = sinew::haptics::DevicePlugin::load("/opt/vendor/libsinew_touch.so");
//   if (!plugin) ... plugin.error().message() ...;
//   auto devices = (*plugin)->devices();           // names, index order
//   auto device = (*plugin)->open("Touch 1", "");   // or "0": the index
//   auto loop = sinew::haptics::HapticLoop::create({}, **device, snapshots, feedback, clock);
//
// The library stays loaded while the DevicePlugin or any device opened from
// it lives (they share its handle); the last one to go unloads it (dlclose).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sinew/haptics/device_plugin_abi.h"
#include "sinew/haptics/haptic_device.h"
#include "sinew/result.h"

namespace sinew::haptics {

/// The loaded library: its handle and checked table, shared by the plug-in
/// and every device opened from it (defined in device_plugin.cpp).
struct PluginLibrary;

/// A device opened from a plug-in: HapticDevice calls forwarded to the
/// plug-in's table. sample() and command() allocate nothing, take no lock
/// and add no I/O of their own (the plug-in's code must not either). The
/// destructor stops the device if it runs and closes it.
class PluginDevice final : public HapticDevice {
 public:
  ~PluginDevice() override;
  PluginDevice(const PluginDevice&) = delete;
  PluginDevice& operator=(const PluginDevice&) = delete;

  /// "<plug-in name>: <device name>".
  [[nodiscard]] std::string name() const override { return name_; }
  /// The plug-in's nominal rate for this device [Hz] (checked finite and > 0 at open).
  [[nodiscard]] double update_rate_hz() const override { return rate_hz_; }
  /// 3 (force only: command() hands the plug-in zero torque) or 6 (force and torque).
  [[nodiscard]] std::uint32_t degrees_of_freedom() const { return dof_; }
  /// Starts the device. [in] now_ns: the loop clock [ns]. Errors carry the
  /// plug-in's message (backend_unavailable); already started: bad_parameter.
  Status start(std::int64_t now_ns) override;
  /// Stops the device if it runs (idempotent).
  void stop() noexcept override;
  /// Real-time: the plug-in's newest sample, converted. [in] now_ns [ns]; [out] out.
  bool sample(std::int64_t now_ns, DeviceSample& out) noexcept override;
  /// Real-time: force [N] and torque [N m] to the plug-in (torque zeroed for 3 DOF).
  void command(const Vec3& force, const Vec3& torque, std::int64_t now_ns) noexcept override;

 private:
  friend class DevicePlugin;
  PluginDevice(std::shared_ptr<const PluginLibrary> library, sinew_haptic_device* handle, std::string name,
               double rate_hz, std::uint32_t dof);

  // Declared first, destroyed last: the library outlives the close() call.
  std::shared_ptr<const PluginLibrary> library_;
  const sinew_haptic_plugin_v1* table_;
  sinew_haptic_device* handle_;
  std::string name_;
  double rate_hz_;
  std::uint32_t dof_;
  bool started_ = false;
};

/// A plug-in library loaded with dlopen (RTLD_NOW | RTLD_LOCAL): its entry
/// point's table checked once, then its devices listed and opened.
class DevicePlugin {
 public:
  /// Loads the plug-in at `path` (a path with a '/', or a file name looked
  /// up as dlopen does: LD_LIBRARY_PATH, the cache, the default folders).
  /// Errors (bad_input_file, each naming the path): the library cannot be
  /// loaded (with dlerror's text: missing file, not a shared library, an
  /// undefined symbol); it has no sinew_haptic_plugin_entry; the entry
  /// returned NULL; "plug-in X has ABI version N; this sinew reads version
  /// 1"; struct_size smaller than version 1's table; a null name or
  /// function pointer (named). Loading one file twice gives the same
  /// library (dlopen counts references): the plug-in's global state is
  /// shared. DevicePlugin's calls are for the application's threads, not
  /// the real-time tick (they allocate and call the plug-in's non-real-time
  /// functions).
  static Result<std::unique_ptr<DevicePlugin>> load(const std::string& path);
  ~DevicePlugin();
  DevicePlugin(const DevicePlugin&) = delete;
  DevicePlugin& operator=(const DevicePlugin&) = delete;

  /// The path it was loaded from.
  [[nodiscard]] const std::string& path() const;
  /// The plug-in's own name (its table's `name`).
  [[nodiscard]] const std::string& name() const;
  /// The ABI version and table size the plug-in reports.
  [[nodiscard]] std::uint32_t abi_version() const;
  [[nodiscard]] std::uint32_t struct_size() const;

  /// The devices the plug-in can open now, in index order (asked afresh on
  /// each call: devices may be plugged in or out). Errors: the plug-in
  /// names a device NULL or "" (bad_input_file), or reports more than
  /// kMaxPluginDevices (bad_input_file).
  [[nodiscard]] Result<std::vector<std::string>> devices() const;

  /// Opens a device. [in] name_or_index: a device's name as devices() lists
  /// it, or else its index in decimal ("0" is the first); [in] config: the
  /// plug-in's own settings string ("" for its defaults). Errors: no device
  /// of that name or index (bad_parameter, listing the devices); the
  /// plug-in's open failed (backend_unavailable, with its message); it
  /// reports an update rate that is not finite and > 0 or degrees of
  /// freedom other than 3 or 6 (bad_input_file; the device is closed again).
  [[nodiscard]] Result<std::unique_ptr<PluginDevice>> open(const std::string& name_or_index,
                                                          const std::string& config = "") const;

 private:
  explicit DevicePlugin(std::shared_ptr<const PluginLibrary> library);
  std::shared_ptr<const PluginLibrary> library_;
};

/// The most devices one plug-in may list (a larger count is taken for garbage).
inline constexpr std::uint32_t kMaxPluginDevices = 4096;

}  // namespace sinew::haptics
