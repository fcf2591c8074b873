/* mesh_contact_params.h — contacts between deformable meshes in the solver
 * (issue 12, part 3): the layout the host writes every frame and the kernel
 * that solves them, shared by every kernel language (see sinew_lang.h).
 * Units: SI (metres, kilograms, seconds); compliance [m/N].
 *
 * A mesh contact joins up to four particles: a vertex and a triangle
 * (vertex-triangle) or two edges (edge-edge), found by the host at the start
 * of the frame (src/runtime/mesh_collision.cpp) and kept for the whole
 * frame. Each has fixed coefficients c_k and a fixed unit normal n, both
 * from the closest points at the frame's start:
 *   vertex-triangle  c = (1, -wa, -wb, -wc): the vertex minus its closest
 *                    point on the triangle (barycentric wa, wb, wc);
 *   edge-edge        c = (1 - s, s, -(1 - t), -t): the first edge's closest
 *                    point minus the second's;
 *   triangle-shape   c = (0, wa, wb, wc) on particles (a, a, b, c): the
 *                    triangle's point deepest in a collider's shape (its
 *                    first vertex repeated with c = 0: the kernels read all
 *                    four and write them in order, so the repeat's
 *                    unchanged value is overwritten by the real one);
 *   segment-shape    c = (0, 1 - s, 0, s) on particles (a, a, b, b) alike;
 * n points from the second primitive to the first (from the shape). With
 * o = normal.w (0 between meshes; thickness - n . s for a shape's surface
 * point s at the frame's end, so the triangle touches the shape like a
 * vertex does) and m the plane's motion (binding 8: 0 but for a rigid
 * tool's faces, o_start - o_end, so that the plane moves with the tool
 * across the frame instead of jumping to where it ends: t = substep_end)
 * the constraint is
 *   C = n . sum_k c_k x_k + o + m (1 - t) - thickness >= 0
 * keeps the first primitive on its side of the plane through the second's
 * closest point (a separating plane at the frame's start: conservative),
 * at least `thickness` away. Gradient for particle k: c_k n; with
 * W = sum_k w_k c_k^2 the xPBD step for an inequality (Macklin, Müller,
 * Chentanez, "XPBD", MIG 2016) is
 *   lambda_n' = max(lambda_n + (-C - alpha~ lambda_n) / (W + alpha~), 0),
 *   x_k += w_k c_k (lambda_n' - lambda_n) n.
 * Friction (Macklin, Müller, Chentanez, Kim, "Unified Particle Physics for
 * Real-Time Applications", SIGGRAPH 2014, eq. 24-25), as for the colliders
 * (contact_params.h) with the relative motion of the two closest points:
 * d = sum_k c_k (x_k - prev_k), tangential part d_t; lambda_t' =
 * lambda_t - d_t / W, kept if |lambda_t'| <= mu_s lambda_n', else scaled to
 * mu_k lambda_n'; x_k += w_k c_k (lambda_t' - lambda_t).
 * Contacts that are apart (C > 0) and were not pushed in this substep
 * (lambda_n = 0) do nothing: they are speculative, found within the
 * frame's motion margin, and act only if the surfaces come closer.
 *
 * --------------------------------------------------- xpbd_solve_mesh_contacts
 * One work item per contact of one colour (no two contacts of a colour
 * share a movable particle), an indirect dispatch whose count is
 * table[color]; the colour's contacts are [table[colors + color], + count).
 * bindings:
 *   0 position float4 (xyz, w = inverse mass) [in/out]
 *   1 previous position float4 (the substep's start) [in]
 *   2 table uint [in]: colors counts, then colors firsts
 *   3 particles uint4 per contact [in]
 *   4 coefficients float4 per contact (c_0..c_3) [in]
 *   5 normal float4 per contact (xyz unit, w the offset o) [in]
 *   6 lambda float4 per contact [in/out]: (lambda_n, lambda_t xyz), [kg m],
 *     reset to 0 in a substep's first sweep (reset_lambda)
 *   7 lambda sum float4 per contact [in/out]: the final lambda of each of
 *     the frame's earlier substeps, summed: set to 0 in the frame's first
 *     sweep (reset_lambda 2), lambda added to it before the reset of every
 *     later substep (reset_lambda 1). At the frame's end, (sum + lambda) /
 *     h is the impulse the contact gave its first primitive over the frame,
 *     lambda / h over its last substep [N s] as vectors lambda_n n +
 *     lambda_t: the host reads them back for the contacts of triangles and
 *     segments with a rigid tool, whose reaction they are
 *     (src/runtime/mesh_collision.h, add_tool_reactions).
 *   8 motion float per contact [in]: m above [m].
 *   9 order uint per slot [in], read when `ordered`: the contact at each
 *     slot of the table's colours (the device's colouring,
 *     src/coloring/device_contact_coloring.h: the contacts stay where the
 *     host wrote them, in any order, and slot s solves contact order[s];
 *     their lambdas are the contacts', not the slots').
 * With `serial`, one work item solves the colour's contacts one after
 * another in slot order (the device colouring's overflow set, whose
 * contacts may share particles: a Gauss-Seidel pass over them; launched
 * for one item, the count from the table). On lavapipe a shader
 * invocation's loops stop after 65,535 iterations in all: keep the
 * overflow set well below that.
 * xpbd_mesh_contacts_jacobi takes the same bindings 0-6, its corrections
 * at 7, the lambda sum at 8 and the motion at 9. */
#ifndef SINEW_MESH_CONTACT_PARAMS_H
#define SINEW_MESH_CONTACT_PARAMS_H

#include "sinew_lang.h"

#ifdef __cplusplus
namespace sinew::kernels {
#endif

SINEW_STRUCT_BEGIN(MeshContactParams)
  uint color;              /* this dispatch's colour */
  uint colors;             /* colours in the table */
  float inv_h2;            /* 1 / h^2 [1/s^2] */
  uint reset_lambda;       /* a substep's first sweep: 1, the frame's first: 2; else 0 (the lambda sum) */
  float thickness;         /* [m], > 0: the distance the surfaces keep */
  float compliance;        /* alpha [m/N], >= 0 */
  float static_friction;   /* mu_s */
  float dynamic_friction;  /* mu_k <= mu_s */
  float substep_end;       /* fraction of the frame done at the end of this substep, in (0, 1] (the motion) */
  uint ordered;            /* 1: slot s solves contact order[s] (binding 9); 0: contact s */
  uint serial;             /* 1: one item solves the colour's contacts in order (xpbd_solve_mesh_contacts) */
  uint pad0;               /* 16-byte size */
SINEW_STRUCT_END(MeshContactParams)

#ifdef __cplusplus
}  /* namespace sinew::kernels */
#endif

#endif /* SINEW_MESH_CONTACT_PARAMS_H */
