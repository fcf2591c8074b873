/* circle_plugin.c — a haptic device plug-in written in C99 against
 * sinew/haptics/device_plugin_abi.h (tests/haptics_plugin_test.cpp; its
 * code is the example of docs/haptics.md, "Device plug-ins").
 *
 * Two simulated devices: "circle" (6 degrees of freedom) and "circle-3dof"
 * (force only). Each moves its end effector on a circle in the x-z plane,
 *   position = (r cos wt, 0, r sin wt), w = 2 pi hz, t from start(),
 * turning about y with it (rotation (cos wt/2, 0, sin wt/2, 0)), and records
 * the forces commanded; sinew_test_plugin_record_of() reads the record back
 * (the test finds it with dlsym). Config: "radius=R,hz=F" (either, in any
 * order; defaults 0.01 m and 1 Hz).
 *
 * Built several times (tests/CMakeLists.txt), the broken variants chosen
 * by a define: TEST_PLUGIN_ABI_VERSION (a wrong version), TEST_PLUGIN_NO_ENTRY
 * (the entry point misnamed), TEST_PLUGIN_STRUCT_SIZE (too small a table;
 * or a larger one, as from a newer header of the same version, which loads),
 * TEST_PLUGIN_NULL_SAMPLE (a null function pointer), TEST_PLUGIN_OPEN_FAILS
 * (every open fails with the plug-in's own message), TEST_PLUGIN_UNRESOLVED
 * (a symbol no library defines: RTLD_NOW refuses it at load). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sinew/haptics/device_plugin_abi.h"
#include "circle_plugin_record.h"

#if defined(TEST_PLUGIN_ABI_VERSION) || defined(TEST_PLUGIN_STRUCT_SIZE) || defined(TEST_PLUGIN_NULL_SAMPLE) || \
    defined(TEST_PLUGIN_NO_ENTRY)
#define TEST_PLUGIN_BROKEN_TABLE 1
#else
#define TEST_PLUGIN_BROKEN_TABLE 0
#endif

#define DEVICE_COUNT 2u
static const char* const device_names[DEVICE_COUNT] = {"circle", "circle-3dof"};
static const double pi = 3.14159265358979323846;

struct sinew_haptic_device {
  uint32_t index;
  double radius;  /* [m] */
  double omega;   /* [rad/s] */
  int64_t origin_ns;
  sinew_haptic_sample newest;
};

static struct sinew_haptic_device devices[DEVICE_COUNT];
static sinew_test_plugin_record records[DEVICE_COUNT];

#ifdef TEST_PLUGIN_UNRESOLVED
extern uint32_t sinew_test_plugin_nowhere(void);
static uint32_t device_count(void) { return sinew_test_plugin_nowhere(); }
#else
static uint32_t device_count(void) { return DEVICE_COUNT; }
#endif

static const char* device_name(uint32_t index) { return index < DEVICE_COUNT ? device_names[index] : NULL; }

/* "radius=0.02,hz=2": [out] radius [m], hz [Hz]; 0, or 1 with a message. */
static int parse_config(const char* config, double* radius, double* hz, char* error, size_t error_size) {
  const char* p = config;
  while (*p) {
    const char* comma = strchr(p, ',');
    const size_t length = comma ? (size_t)(comma - p) : strlen(p);
    char item[64];
    char* end = NULL;
    double* target = NULL;
    if (length >= sizeof item) {
      snprintf(error, error_size, "circle: config item too long in \"%s\"", config);
      return 1;
    }
    memcpy(item, p, length);
    item[length] = '\0';
    if (strncmp(item, "radius=", 7) == 0) target = radius;
    if (strncmp(item, "hz=", 3) == 0) target = hz;
    if (!target) {
      snprintf(error, error_size, "circle: unknown config item \"%s\" (radius=R, hz=F)", item);
      return 1;
    }
    *target = strtod(strchr(item, '=') + 1, &end);
    if (end == strchr(item, '=') + 1 || *end != '\0' || !(*target > 0.0) || !isfinite(*target)) {
      snprintf(error, error_size, "circle: \"%s\" needs a finite number > 0", item);
      return 1;
    }
    p += length;
    if (*p == ',') ++p;
  }
  return 0;
}

static sinew_haptic_device* open_device(uint32_t index, const char* config, char* error, size_t error_size) {
  double radius = 0.01, hz = 1.0;
#ifdef TEST_PLUGIN_OPEN_FAILS
  snprintf(error, error_size, "no circle attached to this machine (simulated failure)");
  return NULL;
#endif
  if (index >= DEVICE_COUNT) {
    snprintf(error, error_size, "circle: no device %u", (unsigned)index);
    return NULL;
  }
  if (records[index].open) {
    snprintf(error, error_size, "circle: device \"%s\" is already open", device_names[index]);
    return NULL;
  }
  if (parse_config(config, &radius, &hz, error, error_size) != 0) return NULL;
  memset(&devices[index], 0, sizeof devices[index]);
  memset(&records[index], 0, sizeof records[index]);
  devices[index].index = index;
  devices[index].radius = radius;
  devices[index].omega = 2.0 * pi * hz;
  records[index].open = 1;
  records[index].opens = 1;
  return &devices[index];
}

static void close_device(sinew_haptic_device* d) {
  records[d->index].open = 0;
  records[d->index].closes += 1;
}

static int start(sinew_haptic_device* d, int64_t now_ns, char* error, size_t error_size) {
  (void)error;
  (void)error_size;
  d->origin_ns = now_ns;
  records[d->index].started = 1;
  records[d->index].starts += 1;
  return 0;
}

static void stop(sinew_haptic_device* d) {
  records[d->index].started = 0;
  records[d->index].stops += 1;
}

/* Real-time: arithmetic only. No sample before start(). */
static int sample(sinew_haptic_device* d, int64_t now_ns, sinew_haptic_sample* out) {
  const double t = 1e-9 * (double)(now_ns - d->origin_ns);
  const double a = d->omega * t, r = d->radius;
  if (!records[d->index].started) return 0;
  d->newest.sequence += 1;
  d->newest.time_ns = now_ns;
  d->newest.position[0] = r * cos(a);
  d->newest.position[1] = 0.0;
  d->newest.position[2] = r * sin(a);
  d->newest.rotation[0] = cos(0.5 * a);
  d->newest.rotation[1] = 0.0;
  d->newest.rotation[2] = sin(0.5 * a);
  d->newest.rotation[3] = 0.0;
  d->newest.velocity[0] = -r * d->omega * sin(a);
  d->newest.velocity[1] = 0.0;
  d->newest.velocity[2] = r * d->omega * cos(a);
  d->newest.angular_velocity[0] = 0.0;
  d->newest.angular_velocity[1] = d->omega;
  d->newest.angular_velocity[2] = 0.0;
  d->newest.buttons = t >= 0.5 ? 1u : 0u; /* the button goes down half a second in */
  *out = d->newest;
  records[d->index].samples += 1;
  return 1;
}

/* Real-time: records the command. */
static void command(sinew_haptic_device* d, const double force[3], const double torque[3], int64_t now_ns) {
  sinew_test_plugin_record* rec = &records[d->index];
  int k;
  for (k = 0; k < 3; ++k) {
    rec->last_force[k] = force[k];
    rec->last_torque[k] = torque[k];
    rec->force_sum[k] += force[k];
    rec->torque_sum[k] += torque[k];
  }
  rec->last_command_ns = now_ns;
  rec->commands += 1;
}

static double update_rate_hz(const sinew_haptic_device* d) {
  (void)d;
  return 1000.0;
}

static uint32_t degrees_of_freedom(const sinew_haptic_device* d) { return d->index == 0 ? 6u : 3u; }

/* The table sinew reads: every call set, and this header's version and size. */
static const sinew_haptic_plugin_v1 table = {
    .abi_version = SINEW_HAPTIC_PLUGIN_ABI_VERSION,
    .struct_size = sizeof(sinew_haptic_plugin_v1),
    .name = "circle",
    .device_count = device_count,
    .device_name = device_name,
    .open = open_device,
    .close = close_device,
    .start = start,
    .stop = stop,
    .sample = sample,
    .command = command,
    .update_rate_hz = update_rate_hz,
    .degrees_of_freedom = degrees_of_freedom,
};

#if !TEST_PLUGIN_BROKEN_TABLE
SINEW_HAPTIC_PLUGIN_EXPORT const sinew_haptic_plugin_v1* sinew_haptic_plugin_entry(void) { return &table; }
#else
/* The variants: the table above, altered as the define says. */
static sinew_haptic_plugin_v1 broken;
static const sinew_haptic_plugin_v1* broken_table(void) {
  broken = table;
#ifdef TEST_PLUGIN_ABI_VERSION
  broken.abi_version = TEST_PLUGIN_ABI_VERSION;
#endif
#ifdef TEST_PLUGIN_STRUCT_SIZE
  broken.struct_size = TEST_PLUGIN_STRUCT_SIZE;
#endif
#ifdef TEST_PLUGIN_NULL_SAMPLE
  broken.sample = NULL;
#endif
  return &broken;
}
#ifdef TEST_PLUGIN_NO_ENTRY
/* Misnamed: sinew finds no sinew_haptic_plugin_entry. */
SINEW_HAPTIC_PLUGIN_EXPORT const sinew_haptic_plugin_v1* sinew_haptic_plugin_entry_misnamed(void);
SINEW_HAPTIC_PLUGIN_EXPORT const sinew_haptic_plugin_v1* sinew_haptic_plugin_entry_misnamed(void) {
  return broken_table();
}
#else
SINEW_HAPTIC_PLUGIN_EXPORT const sinew_haptic_plugin_v1* sinew_haptic_plugin_entry(void) { return broken_table(); }
#endif
#endif

/* The test's window into the plug-in: device `index`'s record. 0, or 1 for
 * an index out of range. */
SINEW_HAPTIC_PLUGIN_EXPORT int sinew_test_plugin_record_of(uint32_t index, sinew_test_plugin_record* out);
SINEW_HAPTIC_PLUGIN_EXPORT int sinew_test_plugin_record_of(uint32_t index, sinew_test_plugin_record* out) {
  if (index >= DEVICE_COUNT) return 1;
  *out = records[index];
  return 0;
}
