/* capi_test.c — the C API (sinew/sinew.h) driven from C99.
 *
 *   capi_test BACKEND SCENES_DIR TISSUE_SAG_REFERENCE [GRASP_AND_CUT_REFERENCE]
 *
 * Runs scenes/tissue_sag.json for 5 frames on BACKEND through the C API and
 * compares the positions bitwise with TISSUE_SAG_REFERENCE, the raw float32
 * xyzw file `sinew run scenes/tissue_sag.json --backend BACKEND --frames 5
 * --quiet --positions FILE` wrote. With GRASP_AND_CUT_REFERENCE (the cpu
 * run) it also plays scenes/grasp_and_cut.json for 75 frames and compares
 * likewise, reads its events, frame statistics and surface, drives a tool
 * in a scene given as a JSON string, checks the errors (codes and
 * messages), and runs two simulations on two threads at once, each with
 * its own last error. Exit 77 (ctest's SKIP_RETURN_CODE) when BACKEND has no device
 * here; 1 on the first failed check. */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <sinew/sinew.h>

static int failures = 0;

#define CHECK(cond)                                                            \
  do {                                                                         \
    if (!(cond)) {                                                             \
      fprintf(stderr, "%s:%d: check failed: %s (last error: %s)\n", __FILE__, \
              __LINE__, #cond, sinew_last_error());                            \
      ++failures;                                                              \
    }                                                                          \
  } while (0)

/* A call that must succeed; the test stops when it does not. */
#define MUST(call)                                                                     \
  do {                                                                                 \
    sinew_status must_status_ = (call);                                                \
    if (must_status_ != SINEW_OK) {                                                    \
      fprintf(stderr, "%s:%d: %s returned %s: %s\n", __FILE__, __LINE__, #call,         \
              sinew_status_name(must_status_), sinew_last_error());                    \
      exit(1);                                                                         \
    }                                                                                  \
  } while (0)

/* A call that must fail with `expected` and leave a message. */
#define EXPECT_STATUS(call, expected)                                                       \
  do {                                                                                      \
    sinew_status got_ = (call);                                                             \
    if (got_ != (expected) || sinew_last_error()[0] == '\0') {                              \
      fprintf(stderr, "%s:%d: %s returned %s, expected %s (message: '%s')\n", __FILE__,    \
              __LINE__, #call, sinew_status_name(got_), sinew_status_name(expected),       \
              sinew_last_error());                                                          \
      ++failures;                                                                           \
    }                                                                                       \
  } while (0)

/* The whole file at `path` (malloc'd), its size in *size; NULL when unreadable. */
static unsigned char* read_file(const char* path, size_t* size) {
  FILE* f = fopen(path, "rb");
  unsigned char* data = NULL;
  long length;
  if (!f) return NULL;
  if (fseek(f, 0, SEEK_END) == 0 && (length = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0) {
    data = (unsigned char*)malloc((size_t)length + 1);
    if (data && fread(data, 1, (size_t)length, f) != (size_t)length) {
      free(data);
      data = NULL;
    }
    *size = (size_t)length;
  }
  fclose(f);
  return data;
}

/* The simulation's positions (malloc'd, 4 floats per particle), their particles in *count. */
static float* positions(sinew_simulation* sim, size_t* count) {
  float* xyzw;
  MUST(sinew_read_positions(sim, NULL, 0, count));
  xyzw = (float*)malloc(16 * *count);
  if (!xyzw) exit(1);
  MUST(sinew_read_positions(sim, xyzw, *count, count));
  return xyzw;
}

/* Steps `frames` frames, then compares the positions bitwise with the file `reference`. */
static void compare_with_runner(sinew_simulation* sim, int frames, const char* reference, const char* what) {
  size_t particles = 0, bytes = 0;
  unsigned char* expected = read_file(reference, &bytes);
  float* xyzw;
  int f;
  for (f = 0; f < frames; ++f) MUST(sinew_step(sim));
  xyzw = positions(sim, &particles);
  if (!expected) {
    fprintf(stderr, "%s: the runner's positions %s cannot be read\n", what, reference);
    ++failures;
  } else if (bytes != 16 * particles) {
    fprintf(stderr, "%s: %s has %lu bytes, the C API read %lu particles\n", what, reference,
            (unsigned long)bytes, (unsigned long)particles);
    ++failures;
  } else if (memcmp(expected, xyzw, bytes) != 0) {
    fprintf(stderr, "%s: the C API's positions differ from the runner's\n", what);
    ++failures;
  } else {
    printf("%s: %lu particles after %d frames, bitwise equal to the runner's\n", what, (unsigned long)particles,
           frames);
  }
  free(expected);
  free(xyzw);
}

/* Errors: each failing call gives its code and a message naming the problem. */
static void check_errors(const char* scenes, sinew_simulation* sim) {
  sinew_simulation* none = NULL;
  sinew_frame_stats small;
  sinew_tool_state tool;
  size_t count = 0;
  float one[4];
  char path[4096];

  EXPECT_STATUS(sinew_create_from_file("/nonexistent/scene.json", "cpu", 0, &none), SINEW_BAD_INPUT_FILE);
  CHECK(strstr(sinew_last_error(), "/nonexistent/scene.json") != NULL);
  CHECK(none == NULL);
  EXPECT_STATUS(sinew_create_from_json("{ \"tet_bodies\": [ ", NULL, "cpu", 0, &none), SINEW_BAD_INPUT_FILE);
  EXPECT_STATUS(sinew_create_from_json("{\"tet_bodies\": [{\"mesh\": {\"grid\": {\"cells\": [1, 1, 1], "
                                       "\"size\": [0.01, 0.01, 0.01]}}, \"density\": -1}]}",
                                       NULL, "cpu", 0, &none),
                SINEW_BAD_PARAMETER);
  CHECK(strstr(sinew_last_error(), "/tet_bodies/0/density") != NULL);
  snprintf(path, sizeof path, "%s/tissue_sag.json", scenes);
  EXPECT_STATUS(sinew_create_from_file(path, "no-such-backend", 0, &none), SINEW_BAD_PARAMETER);
  CHECK(strstr(sinew_last_error(), "no-such-backend") != NULL);
  EXPECT_STATUS(sinew_create_from_file(path, "cpu", -1, &none), SINEW_BAD_PARAMETER);
  EXPECT_STATUS(sinew_create_from_file(NULL, "cpu", 0, &none), SINEW_NULL_ARGUMENT);
  EXPECT_STATUS(sinew_create_from_file(path, "cpu", 0, NULL), SINEW_NULL_ARGUMENT);
  CHECK(none == NULL);

  /* A null handle, for every kind of call. */
  EXPECT_STATUS(sinew_step(NULL), SINEW_NULL_ARGUMENT);
  CHECK(strstr(sinew_last_error(), "sinew_step") != NULL);
  EXPECT_STATUS(sinew_read_positions(NULL, one, 1, &count), SINEW_NULL_ARGUMENT);
  EXPECT_STATUS(sinew_read_events(NULL, NULL, 0, sizeof(sinew_event), &count), SINEW_NULL_ARGUMENT);
  CHECK(sinew_destroy(NULL) == SINEW_OK);

  /* Too small a buffer: the count needed comes back. */
  MUST(sinew_read_positions(sim, NULL, 0, &count));
  CHECK(count > 1);
  {
    size_t needed = count, got = 0;
    float* short_buffer = (float*)malloc(16 * (needed - 1));
    EXPECT_STATUS(sinew_read_positions(sim, short_buffer, needed - 1, &got), SINEW_BUFFER_TOO_SMALL);
    CHECK(got == needed);
    free(short_buffer);
  }
  EXPECT_STATUS(sinew_read_positions(sim, one, 1, NULL), SINEW_NULL_ARGUMENT);

  /* A struct from a header older than the library's first version. */
  memset(&small, 0, sizeof small);
  small.struct_size = 8;
  EXPECT_STATUS(sinew_get_frame_stats(sim, &small), SINEW_BAD_PARAMETER);
  /* An object the scene does not have (tissue_sag has no tools). */
  memset(&tool, 0, sizeof tool);
  tool.struct_size = sizeof tool;
  EXPECT_STATUS(sinew_get_tool_state(sim, 0, &tool), SINEW_BAD_PARAMETER);
  {
    const double zero[3] = {0.0, 0.0, 0.0}, identity[4] = {1.0, 0.0, 0.0, 0.0};
    EXPECT_STATUS(sinew_set_collider_pose(sim, 3, zero, identity), SINEW_BAD_PARAMETER);
    EXPECT_STATUS(sinew_set_collider_pose(sim, 0, NULL, identity), SINEW_NULL_ARGUMENT);
  }
  /* Particle forces need the scene's external_forces. */
  {
    float* forces = (float*)calloc(3 * count, sizeof(float));
    EXPECT_STATUS(sinew_set_particle_forces(sim, forces, count), SINEW_BAD_PARAMETER);
    free(forces);
  }
  CHECK(strcmp(sinew_status_name(SINEW_BUFFER_TOO_SMALL), "buffer_too_small") == 0);
  CHECK(strcmp(sinew_status_name(SINEW_BAD_INPUT_FILE), "bad_input_file") == 0);
}

/* The frame's figures after 5 frames of tissue_sag. */
static void check_frame_stats(sinew_simulation* sim) {
  sinew_frame_stats st;
  double solve_ms = -1.0;
  memset(&st, 0, sizeof st);
  st.struct_size = sizeof st;
  MUST(sinew_get_frame_stats(sim, &st));
  CHECK(st.struct_size == sizeof st);
  CHECK(st.frame == 5);
  CHECK(st.time > 0.08 && st.time < 0.09); /* 5 frames of 1/60 s */
  CHECK(st.sweeps > 0);
  CHECK(st.kinetic_energy > 0.0);
  CHECK(st.residual_rms > 0.0);
  CHECK(st.wall_ms > 0.0);
  CHECK(st.read_back_bytes > 0);
  CHECK(st.stop == SINEW_SOLVE_FIXED);
  MUST(sinew_get_stage_ms(sim, "solve", &solve_ms));
  CHECK(solve_ms > 0.0 && solve_ms <= st.wall_ms);
}

/* grasp_and_cut: the script's grasp, release, cut and cautery come back as
 * events of their frames; the surface changes with the cut; a collider pose
 * set from C; the positions equal the runner's. */
static void check_grasp_and_cut(const char* scenes, const char* reference) {
  sinew_simulation* sim = NULL;
  sinew_event events[16];
  sinew_scene_info info;
  sinew_body_info body;
  size_t count = 0, before_cut = 0, after_cut = 0, particles = 0;
  int f, grasps = 0, releases = 0, cuts = 0, cauteries = 0;
  char path[4096];
  const double collider_at[3] = {0.06, -0.05, 0.01}, identity[4] = {1.0, 0.0, 0.0, 0.0};

  snprintf(path, sizeof path, "%s/grasp_and_cut.json", scenes);
  MUST(sinew_create_from_file(path, "cpu", 0, &sim));
  memset(&info, 0, sizeof info);
  info.struct_size = sizeof info;
  MUST(sinew_get_scene_info(sim, &info));
  CHECK(info.tet_bodies == 1 && info.graspers == 1 && info.colliders == 1 && info.script_frames == 90);
  for (f = 1; f <= 75; ++f) {
    size_t i;
    /* The collider where the file puts it: set from C each frame, it stays there. */
    MUST(sinew_set_collider_pose(sim, 0, collider_at, identity));
    if (f == 60) MUST(sinew_read_surface_triangles(sim, NULL, 0, &before_cut));
    MUST(sinew_step(sim));
    if (f == 60) MUST(sinew_read_surface_triangles(sim, NULL, 0, &after_cut));
    MUST(sinew_read_events(sim, events, 16, sizeof(sinew_event), &count));
    for (i = 0; i < count; ++i) {
      const sinew_event* e = &events[i];
      CHECK(e->frame == (uint64_t)f);
      if (e->kind == SINEW_EVENT_GRASP) { CHECK(f == 1 && e->count > 0 && e->object == 0); ++grasps; }
      if (e->kind == SINEW_EVENT_RELEASE) { CHECK(f == 50 && e->count > 0); ++releases; }
      if (e->kind == SINEW_EVENT_CUT) {
        CHECK(f == 60 && e->count > 0 && e->body_kind == SINEW_BODY_TET && e->body == 0 && e->constraints_removed > 0);
        ++cuts;
      }
      if (e->kind == SINEW_EVENT_CAUTERY) { CHECK(f == 70 && e->mass_removed >= 0.0); ++cauteries; }
    }
  }
  CHECK(grasps == 1 && releases == 1 && cuts == 1 && cauteries == 1);
  CHECK(before_cut > 0 && after_cut > before_cut); /* the cut opens faces inside the strip */

  /* The surface: every index a particle of the strip, as body 0 says. */
  memset(&body, 0, sizeof body);
  body.struct_size = sizeof body;
  MUST(sinew_get_body_info(sim, 0, &body));
  MUST(sinew_read_surface_triangles(sim, NULL, 0, &count));
  CHECK(body.kind == SINEW_BODY_TET && body.first_triangle == 0 && body.triangle_count == count);
  {
    uint32_t* triangles = (uint32_t*)malloc(12 * count);
    size_t i;
    MUST(sinew_read_surface_triangles(sim, triangles, count, &count));
    MUST(sinew_read_positions(sim, NULL, 0, &particles));
    for (i = 0; i < 3 * count; ++i) CHECK(triangles[i] >= body.first_particle && triangles[i] < particles);
    free(triangles);
  }
  EXPECT_STATUS(sinew_get_body_info(sim, 1, &body), SINEW_BAD_PARAMETER);
  sinew_destroy(sim);

  /* The same scene from its text, played for 75 frames, against the runner. */
  {
    size_t size = 0;
    char* json = (char*)read_file(path, &size);
    CHECK(json != NULL);
    if (!json) return;
    json[size] = '\0';
    MUST(sinew_create_from_json(json, scenes, "cpu", 0, &sim));
    free(json);
    compare_with_runner(sim, 75, reference, "grasp_and_cut (from JSON text)");
    sinew_destroy(sim);
  }
}

/* A rigid capsule tool pushed down on a block pinned at its base: the
 * tissue pushes back, and particle forces move the block. */
static void check_tool(void) {
  static const char* scene =
      "{\"solver\": {\"time_step\": 0.016666666666666666, \"substeps\": 8, \"iterations\": 2},"
      " \"external_forces\": true,"
      " \"tet_bodies\": [{\"mesh\": {\"grid\": {\"cells\": [8, 4, 4], \"size\": [0.04, 0.02, 0.02]}},"
      "   \"density\": 1000, \"elastic\": {\"youngs_modulus\": 30000, \"poisson_ratio\": 0.45},"
      "   \"pinned\": [{\"min\": [-1, -1, -1], \"max\": [1, 0.0, 1]}]}],"
      " \"tools\": [{\"shape\": \"capsule\", \"radius\": 0.004, \"half_height\": 0.01, \"gravity\": false,"
      "   \"mass\": 0.02, \"inertia\": [8.8e-7, 1.6e-7, 8.8e-7],"
      "   \"position\": [0.025, 0.0245, 0.01], \"rotation\": [0.7071067811865476, 0.7071067811865476, 0, 0]}]}";
  const double down[3] = {0.0, -0.05, 0.0}, no_torque[3] = {0.0, 0.0, 0.0};
  sinew_simulation* sim = NULL;
  sinew_tool_state tool;
  size_t particles = 0, i;
  float *forces, *before, *after;
  int f;

  MUST(sinew_create_from_json(scene, NULL, "cpu", 0, &sim));
  memset(&tool, 0, sizeof tool);
  tool.struct_size = sizeof tool;
  for (f = 0; f < 20; ++f) {
    MUST(sinew_apply_tool_force(sim, 0, down, no_torque));
    MUST(sinew_step(sim));
  }
  MUST(sinew_get_tool_state(sim, 0, &tool));
  printf("tool: at y = %.5f m, contact force (%.4f, %.4f, %.4f) N\n", tool.position[1], tool.contact_force[0],
         tool.contact_force[1], tool.contact_force[2]);
  CHECK(tool.contact_force[1] > 0.0); /* the tissue pushes the tool up */
  CHECK(tool.position[1] < 0.0245 && tool.position[1] > 0.02); /* pressed in, resting on the surface */
  CHECK(tool.rotation[0] != 0.0);

  /* Particle forces: +x on every particle moves the free ones along +x. */
  before = positions(sim, &particles);
  forces = (float*)calloc(3 * particles, sizeof(float));
  for (i = 0; i < particles; ++i) forces[3 * i] = 0.01f;
  MUST(sinew_set_particle_forces(sim, forces, particles));
  EXPECT_STATUS(sinew_set_particle_forces(sim, forces, particles - 1), SINEW_BAD_PARAMETER);
  MUST(sinew_step(sim));
  after = positions(sim, &particles);
  {
    double moved = 0.0;
    for (i = 0; i < particles; ++i) moved += (double)after[4 * i] - (double)before[4 * i];
    CHECK(moved > 0.0);
  }
  free(forces);
  free(before);
  free(after);
  EXPECT_STATUS(sinew_apply_tool_force(sim, 1, down, no_torque), SINEW_BAD_PARAMETER);
  sinew_destroy(sim);
}

/* One thread's run: tissue_sag for 5 frames, its positions compared with
 * the runner's, then a failing call whose message must be this thread's. */
struct thread_run {
  const char* scene;
  const char* reference;
  const char* bad_path; /* a missing file only this thread names */
  int equal;            /* [out] the positions equal the reference's */
  int own_message;      /* [out] the last error names this thread's file */
};

static void* run_on_thread(void* arg) {
  struct thread_run* run = (struct thread_run*)arg;
  sinew_simulation* sim = NULL;
  sinew_simulation* none = NULL;
  size_t particles = 0, bytes = 0;
  unsigned char* expected = read_file(run->reference, &bytes);
  float* xyzw;
  int f;
  if (sinew_create_from_file(run->scene, "cpu", 1, &sim) != SINEW_OK) return NULL;
  for (f = 0; f < 5; ++f)
    if (sinew_step(sim) != SINEW_OK) return NULL;
  xyzw = positions(sim, &particles);
  run->equal = expected && bytes == 16 * particles && memcmp(expected, xyzw, bytes) == 0;
  sinew_create_from_file(run->bad_path, "cpu", 0, &none);
  run->own_message = strstr(sinew_last_error(), run->bad_path) != NULL;
  free(xyzw);
  free(expected);
  sinew_destroy(sim);
  return NULL;
}

/* Two simulations stepped at the same time on two threads give the
 * runner's positions, and each thread reads its own last error. */
static void check_threads(const char* scenes, const char* reference) {
  char scene[4096];
  struct thread_run runs[2];
  pthread_t threads[2];
  int t;
  snprintf(scene, sizeof scene, "%s/tissue_sag.json", scenes);
  for (t = 0; t < 2; ++t) {
    runs[t].scene = scene;
    runs[t].reference = reference;
    runs[t].bad_path = t == 0 ? "/nonexistent/first.json" : "/nonexistent/second.json";
    runs[t].equal = runs[t].own_message = 0;
  }
  for (t = 0; t < 2; ++t) CHECK(pthread_create(&threads[t], NULL, run_on_thread, &runs[t]) == 0);
  for (t = 0; t < 2; ++t) pthread_join(threads[t], NULL);
  for (t = 0; t < 2; ++t) {
    CHECK(runs[t].equal);
    CHECK(runs[t].own_message);
  }
}

int main(int argc, char** argv) {
  const char* backend;
  sinew_simulation* sim = NULL;
  sinew_status created;
  char path[4096], name[32];
  size_t length = 0;

  if (argc < 4) {
    fprintf(stderr, "usage: capi_test BACKEND SCENES_DIR TISSUE_SAG_REFERENCE [GRASP_AND_CUT_REFERENCE]\n");
    return 1;
  }
  backend = argv[1];
  printf("sinew %s (header %s)\n", sinew_version_string(), SINEW_VERSION_STRING);
  CHECK(sinew_version() == SINEW_VERSION);
  CHECK(strcmp(sinew_version_string(), SINEW_VERSION_STRING) == 0);

  snprintf(path, sizeof path, "%s/tissue_sag.json", argv[2]);
  created = sinew_create_from_file(path, backend, 0, &sim);
  if (created == SINEW_BACKEND_UNAVAILABLE) {
    printf("skipped: %s\n", sinew_last_error());
    return 77;
  }
  MUST(created);
  MUST(sinew_get_backend_name(sim, name, sizeof name, &length));
  CHECK(strcmp(name, backend) == 0 && length == strlen(backend) + 1);
  EXPECT_STATUS(sinew_get_backend_name(sim, name, 2, &length), SINEW_BUFFER_TOO_SMALL);
  compare_with_runner(sim, 5, argv[3], "tissue_sag");
  if (argc > 4) {
    check_frame_stats(sim);
    check_errors(argv[2], sim);
    check_grasp_and_cut(argv[2], argv[4]);
    check_tool();
    check_threads(argv[2], argv[3]);
  }
  MUST(sinew_destroy(sim));
  if (failures) fprintf(stderr, "%d checks failed\n", failures);
  return failures ? 1 : 0;
}
