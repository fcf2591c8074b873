/* circle_plugin_record.h — what the test plug-in (circle_plugin.c) records
 * of one device, read back by tests/haptics_plugin_test.cpp through the
 * plug-in's exported sinew_test_plugin_record_of() (found with dlsym). */
#ifndef SINEW_TEST_CIRCLE_PLUGIN_RECORD_H
#define SINEW_TEST_CIRCLE_PLUGIN_RECORD_H

#include <stdint.h>

typedef struct sinew_test_plugin_record {
  uint32_t open;          /* 1 while opened */
  uint32_t started;       /* 1 while started */
  uint64_t opens, starts, stops, closes;
  uint64_t samples;       /* samples returned */
  uint64_t commands;      /* commands received */
  double last_force[3];   /* [N] */
  double last_torque[3];  /* [N m] */
  int64_t last_command_ns;
  double force_sum[3];    /* sum of the forces commanded [N] */
  double torque_sum[3];   /* [N m] */
} sinew_test_plugin_record;

/* Copies device `index`'s record to `out`: 0, or 1 for an index out of range. */
typedef int (*sinew_test_plugin_record_fn)(uint32_t index, sinew_test_plugin_record* out);
#define SINEW_TEST_PLUGIN_RECORD_NAME "sinew_test_plugin_record_of"

#endif
