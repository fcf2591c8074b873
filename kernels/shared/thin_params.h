/* thin_params.h — the per-constraint data of the thin-body and thread
 * kernels (xpbd_solve_area, xpbd_solve_dihedral, xpbd_solve_line_bending),
 * shared by every kernel language (see sinew_lang.h). The kernels take
 * SolveParams and the standard solve bindings (xpbd_params.h): particle
 * indices `arity` uint per constraint (no padding), data
 * SINEW_*_DATA_STRIDE floats per constraint as laid out below, one lambda
 * per constraint. Constraint functions and gradients: kernels/math/
 * thin_math.h; compliances: include/sinew/scene.h.
 *
 * xpbd_solve_area: arity 3, the triangle (x0, x1, x2) in mesh order.
 *   [0] A0, rest area [m^2];  [1] alpha [m^3/N] = c_a A0 / t.
 *   C = |(x1 - x0) x (x2 - x0)| / 2 - A0 [m^2]; residual / A0.
 *
 * xpbd_solve_dihedral: arity 4, (x0, x1, x2, x3): x0, x1 the shared edge in
 *   the winding order of the triangle (x0, x1, x2), x2 and x3 the vertices
 *   opposite the edge in its two triangles.
 *   [0] theta0, rest angle [rad] in (-pi, pi];  [1] alpha [1/(N m)].
 *   theta = the signed angle between the normals e x (x2 - x0) and
 *   (x3 - x0) x e (e = x1 - x0) about e, 0 for a flat hinge;
 *   C = theta - theta0 wrapped into [-pi, pi] [rad]; residual in radians,
 *   not normalised.
 *
 * xpbd_solve_line_bending: arity 3, (b0, v, b1): the middle vertex v and
 *   its two neighbours along the thread.
 *   [0] h0, rest value of |x_v - c| [m], c = (x_b0 + x_v + x_b1) / 3;
 *   [1] alpha [m/N];
 *   [2] L, the mean rest length of the two segments [m];  [3] zero.
 *   C = |x_v - c| - h0 [m]; residual / L (h0 is often 0: a straight thread). */
#ifndef SINEW_THIN_PARAMS_H
#define SINEW_THIN_PARAMS_H

#define SINEW_AREA_DATA_STRIDE 2
#define SINEW_DIHEDRAL_DATA_STRIDE 2
#define SINEW_LINE_BENDING_DATA_STRIDE 4

#endif /* SINEW_THIN_PARAMS_H */
