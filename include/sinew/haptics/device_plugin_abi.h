/* sinew/haptics/device_plugin_abi.h — the C ABI of haptic device plug-ins.
 *
 * A plug-in is a shared library (built outside sinew, e.g. around a vendor
 * SDK: OpenHaptics, Force Dimension's dhd, libnifalcon) that sinew loads at
 * run time with dlopen (sinew/haptics/device_plugin.h). It exports one
 * function, sinew_haptic_plugin_entry(), which returns a table: the
 * plug-in's name, its devices, and the calls sinew makes on an opened
 * device. The header is plain C99 so a plug-in may be written in C; it
 * includes nothing of sinew's C++ and links against nothing of sinew's.
 *
 * Units and frames (the same as sinew::haptics::HapticDevice's): positions
 * in metres [m], velocities [m/s], angular velocities [rad/s], orientation
 * a unit quaternion (w, x, y, z), force [N], torque [N m], all in the
 * simulation's world frame (the plug-in applies its workspace offset and
 * scale; a scale s on positions means a scale s on forces, so power is
 * preserved). Times are nanoseconds [ns] on the haptic loop's clock, which
 * sinew passes in (now_ns): a sample is stamped with that clock, not with
 * the SDK's own.
 *
 * Threading. device_count, device_name, open, close, start, stop,
 * update_rate_hz and degrees_of_freedom are called outside the real-time
 * loop and may allocate, block, log or do I/O. sample and command are
 * called from the real-time tick (1 kHz by default): they must not block,
 * take a lock that a non-real-time thread may hold, allocate, log or do
 * I/O (copy what the SDK's own servo callback left in a lock-free buffer,
 * or read the SDK's non-blocking state). The calls on one device never
 * overlap one another; two devices may be driven from two threads at once.
 *
 * ABI rules. abi_version and struct_size are the table's first two fields
 * and stay there in every version. Within ABI version 1 the table only
 * grows: new fields are appended at its end, a plug-in reports in
 * struct_size how much of it it fills, and sinew reads an appended field
 * only when struct_size covers it (an older plug-in's table is shorter and
 * still loads). Fields are never removed, reordered or retyped within a
 * version; such a change raises SINEW_HAPTIC_PLUGIN_ABI_VERSION, and sinew
 * refuses a plug-in of a version it does not read. sinew_haptic_sample is
 * frozen for version 1: a richer sample would come with a new struct type
 * and a new, appended, call.
 */
#ifndef SINEW_HAPTICS_DEVICE_PLUGIN_ABI_H
#define SINEW_HAPTICS_DEVICE_PLUGIN_ABI_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** The table layout this header describes (sinew_haptic_plugin_v1). */
#define SINEW_HAPTIC_PLUGIN_ABI_VERSION 1u
/** The name of the exported entry point, for dlsym. */
#define SINEW_HAPTIC_PLUGIN_ENTRY_NAME "sinew_haptic_plugin_entry"

/** Marks the entry point as exported (also when the plug-in is built with
 *  -fvisibility=hidden). */
#if defined(__GNUC__) || defined(__clang__)
#define SINEW_HAPTIC_PLUGIN_EXPORT __attribute__((visibility("default")))
#else
#define SINEW_HAPTIC_PLUGIN_EXPORT
#endif

/** One device reading (sinew::haptics::DeviceSample in C). */
typedef struct sinew_haptic_sample {
  uint64_t sequence;           /**< increases by one per new reading */
  int64_t time_ns;             /**< when it was taken, on the loop's clock [ns] */
  double position[3];          /**< end effector [m] */
  double rotation[4];          /**< end-effector orientation, unit quaternion (w, x, y, z) */
  double velocity[3];          /**< [m/s] */
  double angular_velocity[3];  /**< world frame [rad/s] */
  uint32_t buttons;            /**< bit i: button i pressed */
} sinew_haptic_sample;

/** An opened device: the plug-in's own type, opaque to sinew. */
typedef struct sinew_haptic_device sinew_haptic_device;

/** The table a plug-in returns from sinew_haptic_plugin_entry(). Every
 *  function pointer must be set (sinew refuses a table with a null one).
 *  Strings returned (name, device_name) are the plug-in's, NUL-terminated,
 *  and must stay valid until the library is unloaded. Error buffers
 *  ([out] error, error_size bytes, at least 1) receive a NUL-terminated
 *  message saying why a call failed; sinew shows it to the user as is. */
typedef struct sinew_haptic_plugin_v1 {
  /** SINEW_HAPTIC_PLUGIN_ABI_VERSION of the header the plug-in was built with. */
  uint32_t abi_version;
  /** sizeof(sinew_haptic_plugin_v1) of the header the plug-in was built with. */
  uint32_t struct_size;
  /** The plug-in's name, e.g. "openhaptics" (not empty). */
  const char* name;

  /** How many devices the plug-in can open now (0 when none is attached). */
  uint32_t (*device_count)(void);
  /** [in] index: 0..device_count()-1. The device's name, unique within the
   *  plug-in (e.g. "Touch 1"); NULL for an index out of range. */
  const char* (*device_name)(uint32_t index);

  /** Opens device `index` with `config` (the plug-in's own settings, e.g.
   *  "radius=0.01"; "" for the defaults; never NULL). Returns the device,
   *  or NULL with the reason in `error`. The device does not move the
   *  user's hand until start(). */
  sinew_haptic_device* (*open)(uint32_t index, const char* config, char* error, size_t error_size);
  /** Releases a device from open() (stopped first by sinew when started). */
  void (*close)(sinew_haptic_device* device);
  /** Starts the device (servo on, forces enabled). [in] now_ns: the loop
   *  clock's time [ns]. Returns 0 on success, else nonzero with the reason
   *  in `error`. */
  int (*start)(sinew_haptic_device* device, int64_t now_ns, char* error, size_t error_size);
  /** Stops the device: forces off. Called once per successful start(). */
  void (*stop)(sinew_haptic_device* device);

  /** Real-time. [in] now_ns: the tick's time on the loop clock [ns].
   *  [out] out: the newest reading. Returns 1 when `out` was filled, 0 when
   *  there is none (the loop keeps its previous one and its watchdog sees
   *  it age; `out` is then ignored). */
  int (*sample)(sinew_haptic_device* device, int64_t now_ns, sinew_haptic_sample* out);
  /** Real-time. Commands force[3] [N] and torque[3] [N m] (world frame),
   *  applied to the user's hand until the next command. [in] now_ns: the
   *  tick's time [ns]. A 3-degree-of-freedom device is handed zero torque. */
  void (*command)(sinew_haptic_device* device, const double force[3], const double torque[3], int64_t now_ns);

  /** Nominal rate at which the device produces new samples [Hz], finite and > 0. */
  double (*update_rate_hz)(const sinew_haptic_device* device);
  /** Actuated degrees of freedom: 3 (force only) or 6 (force and torque). */
  uint32_t (*degrees_of_freedom)(const sinew_haptic_device* device);
} sinew_haptic_plugin_v1;

/** The entry point's type. */
typedef const sinew_haptic_plugin_v1* (*sinew_haptic_plugin_entry_fn)(void);

/** Defined by the plug-in (with SINEW_HAPTIC_PLUGIN_EXPORT): returns its
 *  table, a pointer that stays valid until the library is unloaded, or
 *  NULL when the plug-in cannot work at all. Called once per load. */
SINEW_HAPTIC_PLUGIN_EXPORT const sinew_haptic_plugin_v1* sinew_haptic_plugin_entry(void);

#ifdef __cplusplus
}  /* extern "C" */
#endif

#endif /* SINEW_HAPTICS_DEVICE_PLUGIN_ABI_H */
