/* suture_params.h — needles and sutures in the solver (issue 13, part 4):
 * the rows the host keeps (src/runtime/sutures.cpp) and the kernel that
 * solves them, shared by every kernel language (see sinew_lang.h).
 * Units: SI (metres, kilograms, seconds); compliance [m/N].
 *
 * After Moore, Scheirich et al., "The interactive medical simulation toolkit
 * (iMSTK): an open source platform for surgical simulation", Frontiers in
 * Virtual Reality 4, 2023, section 2.5 (needle puncture and suture thread
 * constraints), written as xPBD constraints (Macklin, Müller,
 * Chentanez, "XPBD", MIG 2016) with position-level Coulomb friction
 * (Macklin et al., "Unified Particle Physics for Real-Time Applications",
 * SIGGRAPH 2014, eq. 24-25).
 *
 * A needle is a rigid polyline, kinematic: the host writes each of its
 * points in world space at the frame's start and end, and the kernel takes
 * the point at fraction t = substep_end of the frame as the lerp of the two
 * (a rotation's arc replaced by its chord: for a needle of radius R turning
 * by theta in a frame, at most R theta^2 / 8 off, 0.015 mm for 8 mm and 7
 * degrees). Its tail is its first point, its tip its last; d_tip is the unit
 * direction of its last segment, d_tail of its first.
 *
 * A row joins the tissue point p = wa x_a + wb x_b + wc x_c (a surface
 * triangle, barycentric weights) to the needle or its thread. Kinds:
 *   1 tie          the thread's first vertex x_a held at the needle's
 *                  tail q: C = |x_a - q| = 0;
 *   2 tip contact  the tip pushing a surface before it punctures it:
 *                  C = m . (p - tip) >= 0 with m the triangle's unit
 *                  normal turned the way the tip goes (d_tip . m > 0):
 *                  the tissue kept ahead of the tip across the surface;
 *                  while it pushes (lambda > 0) the tip also catches the
 *                  tissue: C_t = |(p - tip) across m| = 0
 *                  with |lambda_t| <= tan(max_puncture_angle) lambda
 *                  (beyond, the point slides at that bound). The host
 *                  turns it into a puncture when its force passes
 *                  puncture_force;
 *   3 puncture     the tissue point held on the needle's curve: q its
 *                  closest point on the polyline, C = |p - q| = 0, gradient
 *                  (p - q) / |p - q| (the iMSTK paper's); the needle slides
 *                  through it freely. When q is the tip and p lies ahead
 *                  of it, only p's offset across d_tip counts (a needle
 *                  pulled back leaves the point; the host ends the row
 *                  once it is 0.5 mm ahead). When q is the tail and p lies behind
 *                  it (d_tail . (p - tail) < 0) the needle has passed: with
 *                  a thread the row becomes a thread puncture on the
 *                  thread's first segment, without one it ends (kind 0);
 *                  With NeedleDesc::shaft_friction and the others set
 *                  (binding 3's 2nd and 3rd float4), friction along the
 *                  shaft (Karnopp, "Computer simulation of stick-slip
 *                  friction in mechanical dynamic systems", J. Dyn. Sys.
 *                  Meas. Control 107(1), 1985, as Okamura, Simone and
 *                  O'Leary, IEEE TBME 51(10), 2004, used it for needles):
 *                  along the needle's tangent, the tissue point's slide
 *                  relative to the needle's own point (segment, u) over the
 *                  substep; L the row's inserted shaft length (weights.w)
 *                  [m]; v the slide speed at the end of the last substep
 *                  (lambda.z, carried over substeps and frames). With
 *                  |v| <= v_band the multiplier that stops the slide is
 *                  kept up to (f_s L + cut) h^2 (stick; beyond, it breaks
 *                  away at that level); else Coulomb (f_c L + cut) h^2
 *                  plus the viscous b L v h^2 taken implicitly (of the
 *                  multiplier m that would stop it, (coulomb + k m) /
 *                  (1 + k) with k = b L h W), never reversing the slide.
 *                  cut is the cutting force while the needle advances
 *                  (m > 0), on the row of the body the tip is inside
 *                  (word 7 = 1);
 *   5 blunt        one surface vertex x_a (weights (1, 0, 0)) kept ahead
 *                  of a blunt tip's rounded end (a hemisphere of radius R
 *                  = NeedleDesc::tip_radius, binding 3's 3rd float4 .y)
 *                  along the tip's axis: C = d_tip . (x_a - tip) + R -
 *                  sqrt(R^2 - r^2) >= 0, r the vertex's distance from the
 *                  axis; no catch. The host adds one for every surface
 *                  vertex within R of the tip's axis while a tip contact
 *                  (kind 2) pushes, sums their push with its own for the
 *                  puncture, and drops them every frame;
 *   4 thread       the tissue point held on the thread: q = (1 - s) x_i +
 *                  s x_{i+1} on segment i (s its closest point, the
 *                  segment followed to a neighbour when s leaves [0, 1],
 *                  at most SINEW_SUTURE_MAX_MOVES segments per solve;
 *                  lambda_t carries over: neighbouring tangents are
 *                  nearly parallel),
 *                  C = |p - q| = 0, with friction along the segment's
 *                  tangent: the relative slide over the substep is held
 *                  while its multiplier stays within mu_s |lambda|, else
 *                  limited to mu_k |lambda|. The thread's last vertex is a
 *                  knot: it stops at the puncture (s <= 1 on the last
 *                  segment).
 * With W = sum_k w_k c_k^2 (c_k the coefficients of the gradient) and
 * alpha~ = compliance / h^2 every row steps lambda by (-C - alpha~ lambda)
 * / (W + alpha~) (kind 2 keeping lambda >= 0).
 *
 * ------------------------------------------------------------ xpbd_sutures
 * One work item does every row in order (Gauss-Seidel: rows share
 * particles through threads that slide, so they are not coloured; a scene
 * has a few dozen at most). Dispatched after the bodies' constraints and
 * the mesh contacts in every sweep.
 * bindings:
 *   0 position float4 (xyz, w = inverse mass) [in/out]
 *   1 previous position float4 (the substep's start) [in]
 *   2 table uint [in]: word 0 the rows; then per needle (first point, points)
 *   3 needles float4 [in]: 3 per needle: (compliance, mu_s, mu_k,
 *     tan(max_puncture_angle), at most 1e6), the shaft's (f_c [N/m], f_s
 *     [N/m], b [N s/m^2], v_band [m/s]), (cut [N], 0, 0, 0)
 *   4 curve float4 [in]: per needle point, its world position at the
 *     frame's start and at its end (2 per point)
 *   5 thread slots uint [in]: the device slots of the threads' vertices
 *   6 rows uint4 [in/out]: 2 per row, (kind, needle, a, b), (c, first
 *     thread slot, thread vertices, segment)
 *   7 weights float4 [in/out]: per row (wa, wb, wc, s); a puncture's w
 *     is its inserted shaft length L [m] (the host's)
 *   8 lambda float4 [in/out]: 3 per row: (lambda, lambda_t, v, 0), v a
 *     puncture's slide speed along the shaft (kept by the host); the
 *     impulse vector the row gave the tissue (or the tied thread vertex)
 *     in this substep [kg m], the sum of each sweep's steps dlambda n +
 *     dlambda_t t (n and t turn between sweeps); the sum of the frame's
 *     earlier substeps' (reset like mesh_contact_params.h's lambda sum).
 *     (sum + last) / h is the frame's impulse [N s]; the needle feels the
 *     opposite (runtime/sutures.h). */
#ifndef SINEW_SUTURE_PARAMS_H
#define SINEW_SUTURE_PARAMS_H

#include "sinew_lang.h"

#define SINEW_SUTURE_DEAD 0u
#define SINEW_SUTURE_TIE 1u
#define SINEW_SUTURE_TIP 2u
#define SINEW_SUTURE_PUNCTURE 3u
#define SINEW_SUTURE_THREAD 4u
#define SINEW_SUTURE_BLUNT 5u
/* How many segments a thread puncture may move along its thread per solve. */
#define SINEW_SUTURE_MAX_MOVES 4u

#ifdef __cplusplus
namespace sinew::kernels {
#endif

SINEW_STRUCT_BEGIN(SutureParams)
  float inv_h2;       /* 1 / h^2 [1/s^2] */
  uint reset_lambda;  /* a substep's first sweep: 1, the frame's first: 2; else 0 */
  float substep_end;  /* fraction of the frame done at the end of this substep, in (0, 1] */
  float substep_begin; /* ... and at its start, in [0, 1) (the shaft's friction) */
  float h;            /* the substep [s] (the shaft's friction) */
  uint pad0, pad1, pad2;  /* 16-byte size */
SINEW_STRUCT_END(SutureParams)

#ifdef __cplusplus
}  /* namespace sinew::kernels */
#endif

#endif /* SINEW_SUTURE_PARAMS_H */
