/* ccd_params.h — continuous collision queries in a kernel (issue 13): the
 * inclusion-based root finder of src/ccd/inclusion_ccd.cpp (Wang et al.,
 * "A Large Scale Benchmark and an Inclusion-Based Algorithm for Continuous
 * Collision Detection", TOG 2021) in single precision, with its error
 * bound redone for float, so that it never misses on any device: every
 * operation it relies on is an IEEE-754 single-precision add, subtract or
 * multiply, correctly rounded on every GPU (divisions and square roots,
 * which some drivers round loosely, only choose split sizes and directions,
 * where any value is sound). Shared by every kernel language (sinew_lang.h).
 *
 * The bound (eps = 2^-24, M_k the largest |coordinate k| of the query's
 * eight float points; the double version's derivation with eps = 2^-24):
 * every corner value of F is within 64 eps M_k of F's exact value for the
 * float points, and those points are within eps |x| of the caller's
 * doubles, which moves F by at most 4 eps M_k (F is a combination of the
 * points with coefficients of absolute sum <= 4); a box is dropped only
 * beyond min_separation + 68 eps M_k (+ a margin for M's own rounding), or
 * along a direction n beyond min_separation |n|_1 + 92 eps sum |n_k| M_k.
 * Box corners are dyadic fractions of at most 23 bits, exact in float.
 *
 * ------------------------------------------------------------ ccd_queries
 * One item per query q < count. A query is 8 points (float4 each, xyz [m],
 * w unused) in the order of sinew::ccd: vertex-face p, a, b, c at the
 * step's start, then at its end; edge-edge a0, a1, b0, b1, then at the end;
 * its kind in `kinds` (0 vertex-face, 1 edge-edge). Depth-first search with
 * a stack of SINEW_CCD_STACK boxes and at most max_boxes boxes; a query that
 * would outgrow either reports a touch (gave up: never a miss), and so does
 * a search the device itself cuts short (lavapipe breaks every loop of an
 * invocation after 65,535 iterations in all: the search loop's body has no
 * loop of its own, so only the search loop is cut, and it ends with boxes
 * still open, which the kernel reports as a touch).
 * bindings: 0 points float4, 8 per query [in]
 *           1 kinds uint, 1 per query [in]
 *           2 hits uint, 4 per query [out]: touch (0/1), the time (float
 *             bits, never later than the first touch; 1 without a touch),
 *             gave up (0/1), boxes examined */
#ifndef SINEW_CCD_PARAMS_H
#define SINEW_CCD_PARAMS_H

#include "sinew_lang.h"

#define SINEW_CCD_STACK 96u

#ifdef __cplusplus
namespace sinew::kernels {
#endif

SINEW_STRUCT_BEGIN(CcdParams)
  uint count;           /* queries */
  uint max_boxes;       /* per query, > 0 */
  float min_separation; /* [m], >= 0 */
  float tolerance;      /* [m], > 0 */
SINEW_STRUCT_END(CcdParams)

#ifdef __cplusplus
}  // namespace sinew::kernels
#endif

#endif /* SINEW_CCD_PARAMS_H */
