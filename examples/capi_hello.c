/* capi_hello.c: a scene file run from C through sinew/sinew.h (docs/c_api.md).
 *   capi_hello [SCENE.json [BACKEND [FRAMES]]]
 * Steps the scene (its script played), then prints the last frame's
 * figures, the lowest particle and the surface it would render. Exits 1
 * on an error, and when nothing moved down (a tissue_sag block must sag). */
#include <stdio.h>
#include <stdlib.h>

#include <sinew/sinew.h>

static int fail(sinew_simulation* sim, const char* what, sinew_status status) {
  fprintf(stderr, "%s: %s: %s\n", what, sinew_status_name(status), sinew_last_error());
  sinew_destroy(sim);
  return 1;
}

int main(int argc, char** argv) {
  const char* scene = argc > 1 ? argv[1] : "scenes/tissue_sag.json";
  const char* backend = argc > 2 ? argv[2] : "auto";
  const int frames = argc > 3 ? atoi(argv[3]) : 60;
  sinew_simulation* sim = NULL;
  sinew_frame_stats stats = {.struct_size = sizeof(sinew_frame_stats)};
  sinew_status s;
  size_t particles = 0, triangles = 0, i;
  float *xyzw, lowest = 1e30f, start_lowest = 1e30f;
  int f;

  if ((s = sinew_create_from_file(scene, backend, 0, &sim)) != SINEW_OK) return fail(sim, scene, s);
  sinew_read_positions(sim, NULL, 0, &particles); /* the count only */
  xyzw = malloc(16 * particles);
  if (!xyzw) return fail(sim, "malloc", SINEW_OUT_OF_MEMORY);
  if ((s = sinew_read_positions(sim, xyzw, particles, &particles)) != SINEW_OK) return fail(sim, "read", s);
  for (i = 0; i < particles; ++i) start_lowest = xyzw[4 * i + 1] < start_lowest ? xyzw[4 * i + 1] : start_lowest;

  for (f = 1; f <= frames; ++f)
    if ((s = sinew_step(sim)) != SINEW_OK) return fail(sim, "step", s);

  sinew_get_frame_stats(sim, &stats);
  printf("frame %llu, t = %.3f s: %.3f ms, residual %.3e, kinetic energy %.3e J, %llu sweeps\n",
         (unsigned long long)stats.frame, stats.time, stats.wall_ms, stats.residual_rms, stats.kinetic_energy,
         (unsigned long long)stats.sweeps);
  if ((s = sinew_read_positions(sim, xyzw, particles, &particles)) != SINEW_OK) return fail(sim, "read", s);
  for (i = 0; i < particles; ++i) lowest = xyzw[4 * i + 1] < lowest ? xyzw[4 * i + 1] : lowest;
  sinew_read_surface_triangles(sim, NULL, 0, &triangles);
  printf("%lu particles, the lowest from y = %.4f m to %.4f m; %lu surface triangles\n",
         (unsigned long)particles, start_lowest, lowest, (unsigned long)triangles);
  free(xyzw);
  sinew_destroy(sim);
  return lowest < start_lowest ? 0 : 1;
}
