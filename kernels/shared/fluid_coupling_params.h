/* fluid_coupling_params.h — a fluid and the tissue of one scene on one
 * device: the tissue's surfaces carried to the fluid's boundary particles,
 * and the fluid's push carried back to the tissue as forces, without the
 * host (Akinci et al., "Versatile rigid-fluid coupling for incompressible
 * SPH", ACM TOG 31(4), 2012: boundary particles that sample a moving
 * surface and take the fluid's pressure and friction forces).
 *
 * A coupled boundary particle s (a sample) lies on a tissue triangle at
 * barycentric weights w0, w1, w2 of its three particles p0, p1, p2 (device
 * slots of the Simulation's particle buffers). The fluid's boundary
 * particles are [0, first) fixed, then [first, first + samples) coupled.
 *
 * ------------------------------------------------------ fluid_boundary_follow
 * One item per boundary particle b < boundary: impulse[b] = 0 (the frame's
 * impulses start from zero); a coupled one (b >= first) takes
 *   position = ((0 + w0 x[p0]) + w1 x[p1]) + w2 x[p2]   per axis, in float
 * and likewise its velocity from v (w written 0): the order of operations
 * of SurfaceSamples::positions_on.
 * bindings: 0 sample_particles uint4 per sample [in]: p0, p1, p2, unused
 *           1 sample_weights float4 per sample [in]: w0, w1, w2, unused
 *           2 position float4 per tissue particle [in] [m]
 *           3 velocity float4 per tissue particle [in] [m/s]
 *           4 boundary_position float4 per boundary particle [out] [m]
 *           5 boundary_velocity float4 per boundary particle [out] [m/s]
 *           6 impulse float4 per boundary particle [out] [N s]
 * ------------------------------------------------------ fluid_forces_on_tissue
 * One item per coupled tissue particle i < vertices: the force of the
 * fluid over the frame on particle vertex_particle[i],
 *   f = sum over its entries e in [offsets[i], offsets[i + 1]) of
 *       weight[e] (impulse[first + sample[e]] inv_frame)
 * added in the entries' order (the samples' order, then the triangle's
 * corners: SurfaceSamples::spread_to_vertices's order), starting from 0;
 * written to external_force (add = 0) or added to what the host set for
 * the frame (add = 1). w is kept.
 * bindings: 0 vertex_particle uint per coupled particle [in]
 *           1 offsets uint (vertices + 1) [in]
 *           2 entry_sample uint per entry [in]
 *           3 entry_weight float per entry [in]
 *           4 impulse float4 per boundary particle [in] [N s]
 *           5 external_force float4 per tissue particle [in/out] [N] */
#ifndef SINEW_FLUID_COUPLING_PARAMS_H
#define SINEW_FLUID_COUPLING_PARAMS_H

#include "sinew_lang.h"

#ifdef __cplusplus
namespace sinew::kernels {
#endif

SINEW_STRUCT_BEGIN(FluidCouplingParams)
  uint boundary;    /* the fluid's boundary particles, fixed and coupled */
  uint first;       /* the first coupled one */
  uint vertices;    /* fluid_forces_on_tissue: coupled tissue particles */
  uint add;         /* fluid_forces_on_tissue: 1 adds to the host's forces, 0 replaces them */
  float inv_frame;  /* 1 / the tissue's frame [1/s], in float */
  uint pad0;
  uint pad1;
  uint pad2;
SINEW_STRUCT_END(FluidCouplingParams)

#ifdef __cplusplus
}  // namespace sinew::kernels
#endif

#endif /* SINEW_FLUID_COUPLING_PARAMS_H */
