/* contact_params.h — the GPU layouts of the collider and target buffers and
 * the per-constraint data of the contact and attachment kernels, shared by
 * every kernel language (see sinew_lang.h). Both kernels take SolveParams and
 * the standard solve bindings (xpbd_params.h), then extra ones.
 *
 * Units: SI (metres, kilograms, seconds); compliances [m/N].
 *
 * ---------------------------------------------------------------- colliders
 * The collider buffer is one ColliderHeader followed by `colliders + tools`
 * ColliderEntry: the scene's colliders first (SceneDesc::colliders order),
 * then the tools (SceneDesc::tools order) as capsules. Each entry holds its
 * pose at the start and at the end of the frame; a kernel interpolates the
 * pose at a fraction t of the frame (position linearly, rotation by
 * normalised lerp on the shorter arc) — t = substep_end for the end of the
 * substep and substep_end - substep_fraction for its start. The host writes
 * the end pose before each frame (Simulation::set_collider_pose, or the
 * tool's integrated motion) and the start pose is the previous end pose.
 *
 * Shapes, in the collider's frame (include/sinew/scene.h):
 *   plane   y = 0, solid below (normal +y);
 *   sphere  centre 0, `radius`;
 *   capsule segment (0, -half_height, 0)..(0, +half_height, 0) swollen by `radius`;
 *   box     |x| <= half_x, |y| <= half_y, |z| <= half_z;
 *   cylinder x^2 + z^2 <= radius^2, |y| <= half_height (flat caps);
 *   implicit the signed distance of a CSG expression (include/sinew/scene.h,
 *            ImplicitNode): `implicit_count` ImplicitEntry nodes from
 *            `implicit_first`, in postfix order, stored after the last
 *            ColliderEntry. A kernel runs them as a stack machine: a
 *            primitive (SINEW_IMPLICIT_*: the shapes above in the node's own
 *            pose, plus a torus; distance minus `rounding`) pushes
 *            (distance, normal), an operation pops b then a and pushes
 *            min(a, b) (unite), max(a, b) (intersect) or max(a, -b)
 *            (subtract, b's normal negated), keeping the normal of the
 *            value chosen (a on ties). At most SINEW_IMPLICIT_STACK values
 *            and SINEW_IMPLICIT_MAX_NODES nodes (checked on the host);
 *   level set a LevelSet's NanoVDB grid (sinew/level_set.h) in binding 8, at
 *            byte `implicit_first` of it; half_x = 1 / h, half_y = 1 / 2h
 *            (h its voxel). The distance is its trilinear value, the normal
 *            its gradient (kernels/shared/level_set_params.h) normalised; a
 *            zero gradient (beyond the grid's bands) gives a zero normal,
 *            along which nothing moves.
 *
 * ------------------------------------------------------------ xpbd_solve_contacts
 * arity 1: one constraint per movable particle, all in one colour (a particle
 * meets only static or kinematic colliders, never another particle here).
 * bindings: 0-4 standard, then
 *   5 previous position float4 per particle (start of the substep) [in]
 *   6 colliders: ColliderHeader + ColliderEntry[] [in]
 *   7 contact impulses, float4 [in/out]: SINEW_CONTACT_IMPULSE_FLOAT4S per
 *     (particle, tool), slot (particle * tools + tool) * SINEW_CONTACT_IMPULSE_FLOAT4S:
 *       +0 xyz: impulse the particle gave the tool over the frame [N s]
 *       +1 xyz: its moment about the tool's centre (at each substep's end) [N m s]
 *       +2 xyz: impulse over the frame's last substep only [N s]
 *       +3 xyz: its moment [N m s]
 *       +4 if the particle touches the tool after the frame's last sweep:
 *          xyz its offset from the tool's centre [m], w its mass [kg];
 *          else all 0
 *     A work item resets its particle's frame sums in the frame's first
 *     sweep (and the last-substep ones in the last substep's first sweep)
 *     and adds every correction it applies, so the buffer holds the sums
 *     when the frame ends; w unused in +0..+3. (The host couples the tool
 *     with the last substep's force, the one at the tool's end-of-frame
 *     pose, its rotation stabilised by the inertia of the particles it
 *     touches, and reports the frame average; see
 *     src/runtime/simulation_contacts.cpp.)
 *   8 level-set grids uint [in]: every level-set collider's grid, each at
 *     its byte offset (a placeholder when the scene has none).
 * data: SINEW_CONTACT_DATA_STRIDE floats per constraint: [0] margin [m], a
 *   distance the particle keeps from every surface (0 for mesh vertices).
 * lambda: SINEW_CONTACT_LAMBDA_PER_COLLIDER floats per (constraint,
 *   collider): [0] lambda_n >= 0 (normal), [1..3] lambda_t, the accumulated
 *   friction multiplier as a world vector in the tangent plane; both [kg m]
 *   (the position correction is w * lambda, the impulse lambda / h).
 *
 * Per collider: C = signed distance - margin >= 0, gradient n (the outward
 * normal); xPBD for an inequality (Macklin et al. 2016):
 *   dlambda_n = (-C - alpha~ lambda_n) / (w + alpha~), clamped so that
 *   lambda_n stays >= 0; x += w dlambda_n n.
 * Friction (Macklin et al., "Unified Particle Physics for Real-Time
 * Applications", 2014, eq. 24-25, with the normal correction of the substep
 * w lambda_n as the depth d): the particle's displacement over the substep
 * relative to the collider's surface point under it, tangential part d_t;
 * cancelling it needs lambda_t' = lambda_t - d_t / w; if |lambda_t'| <=
 * mu_s lambda_n (static cone) that is applied, else lambda_t' is scaled to
 * length mu_k lambda_n (kinetic); x += w (lambda_t' - lambda_t). Accumulating
 * lambda_t makes repeated iterations converge to these rules rather than
 * apply the kinetic reduction once per iteration.
 * Residual (measuring pass): the largest over colliders of |C + alpha~
 * lambda_n| where lambda_n > 0, else max(-C, 0): metres, not normalised
 * (there is no rest value); 0 when not in contact.
 *
 * ------------------------------------------------------------ xpbd_solve_attachment
 * arity 1 (the attached particle); several attachments of one particle get
 * different colours. bindings: 0-4 standard, then
 *   5 targets: TargetEntry per target [in].
 * data: SINEW_ATTACHMENT_DATA_STRIDE floats: [0] target index, as an exactly
 *   representable float (< 2^24), [1] compliance alpha [m/N].
 * C = |x - target(substep_end)| (zero rest length), gradient (x - target) / C,
 * nothing done where C == 0; residual |C + alpha~ lambda| in metres.
 *
 * ------------------------------------------------------------ xpbd_solve_point_attachment
 * A point inside a triangle held at a target (a grasper's jaws closed on a
 * surface between vertices; iMSTK's barycentric point-to-point
 * constraint): arity 3 (the triangle's particles); no two in one colour
 * share a movable particle. bindings: 0-4 standard (data as float4), then
 *   5 targets: TargetEntry per target [in].
 * data: SINEW_POINT_ATTACHMENT_DATA_STRIDE floats: [0-2] the point's
 *   barycentric weights w_k (sum 1), [3] compliance alpha [m/N], [4] target
 *   index, as an exactly representable float (< 2^24), [5-7] 0.
 * C = |p - target(substep_end)| with p = sum w_k x_k (zero rest length),
 * gradient w_k n for particle k, n = (p - target) / C; Delta lambda =
 * (-C - alpha~ lambda) / (sum w_k^2 w(x_k) + alpha~), x_k += w(x_k) w_k
 * Delta lambda n (w(x_k) the inverse mass); nothing done where C == 0 or
 * every particle is immovable; residual |C + alpha~ lambda| in metres.
 *
 * ------------------------------------------------------------ xpbd_solve_body_attachment
 * Two bodies attached two ways (BodyAttachmentDesc): a barycentric point of
 * each, p_a = sum_k wa_k x(a_k), p_b = sum_k wb_k x(b_k), up to 4 particles
 * each: arity 8 (a_0..a_3, b_0..b_3; an unused slot repeats the side's
 * first particle with weight 0 and is never written); no two in one colour
 * share a movable particle. bindings: 0-4 standard (data as float4).
 * data: SINEW_BODY_ATTACHMENT_DATA_STRIDE floats: [0-3] wa, [4-7] wb,
 *   [8] compliance alpha [m/N], [9] break force [N] (0: never breaks),
 *   [10] broken flag (0 or 1; the kernel sets it [in/out]), [11] rest length L [m].
 * C = |p_a - p_b| - L, n = (p_a - p_b) / |p_a - p_b|, gradient wa_k n
 * for a_k and -wb_k n for b_k; Delta lambda = (-C - alpha~ lambda) /
 * (sum wa_k^2 w(a_k) + sum wb_k^2 w(b_k) + alpha~), a_k += w(a_k) wa_k
 * Delta lambda n, b_k -= w(b_k) wb_k Delta lambda n. Then, when the break
 * force is not 0 and |lambda| / h^2 > break force, the flag is set: from
 * the next solve on, a broken attachment does nothing (lambda 0, residual
 * 0). Nothing moves where C == 0 or every particle is immovable; residual
 * |C + alpha~ lambda| in metres. */
#ifndef SINEW_CONTACT_PARAMS_H
#define SINEW_CONTACT_PARAMS_H

#include "sinew_lang.h"

#define SINEW_SHAPE_PLANE 0u
#define SINEW_SHAPE_SPHERE 1u
#define SINEW_SHAPE_CAPSULE 2u
#define SINEW_SHAPE_BOX 3u
#define SINEW_SHAPE_CYLINDER 4u
#define SINEW_SHAPE_IMPLICIT 5u
#define SINEW_SHAPE_LEVEL_SET 6u

/* ImplicitEntry::op: primitives (their shape in the node's frame), then operations. */
#define SINEW_IMPLICIT_HALF_SPACE 0u
#define SINEW_IMPLICIT_SPHERE 1u
#define SINEW_IMPLICIT_CAPSULE 2u
#define SINEW_IMPLICIT_BOX 3u
#define SINEW_IMPLICIT_CYLINDER 4u
#define SINEW_IMPLICIT_TORUS 5u
#define SINEW_IMPLICIT_UNITE 6u
#define SINEW_IMPLICIT_INTERSECT 7u
#define SINEW_IMPLICIT_SUBTRACT 8u
#define SINEW_IMPLICIT_STACK 8
#define SINEW_IMPLICIT_MAX_NODES 64u

#define SINEW_CONTACT_DATA_STRIDE 1
#define SINEW_CONTACT_LAMBDA_PER_COLLIDER 4
#define SINEW_CONTACT_IMPULSE_FLOAT4S 5
#define SINEW_ATTACHMENT_DATA_STRIDE 2
#define SINEW_POINT_ATTACHMENT_DATA_STRIDE 8
#define SINEW_BODY_ATTACHMENT_DATA_STRIDE 12

#ifdef __cplusplus
namespace sinew::kernels {
#endif

/* The first 16 bytes of the collider buffer. */
SINEW_STRUCT_BEGIN(ColliderHeader)
  uint colliders;          /* scene colliders: entries [0, colliders) */
  uint tools;              /* tools: entries [colliders, colliders + tools) */
  float substep_fraction;  /* h / time_step: the share of the frame one substep spans */
  uint pad0;
SINEW_STRUCT_END(ColliderHeader)

SINEW_STRUCT_BEGIN(ColliderEntry)
  uint shape;              /* SINEW_SHAPE_* */
  float radius;            /* sphere, capsule, cylinder [m] */
  float half_height;       /* capsule, cylinder [m] */
  float compliance;        /* alpha of its contacts [m/N] */
  float half_x;            /* box half extents [m] */
  float half_y;
  float half_z;
  float static_friction;   /* mu_s */
  float dynamic_friction;  /* mu_k <= mu_s */
  uint implicit_first;     /* implicit: its first node, counted from the first ImplicitEntry */
  uint implicit_count;     /* implicit: its node count (0 for the other shapes) */
  float pad2;
  float start_px;          /* pose at the start of the frame: position [m] */
  float start_py;
  float start_pz;
  float pad3;
  float start_qw;          /* and unit quaternion (w, x, y, z) */
  float start_qx;
  float start_qy;
  float start_qz;
  float end_px;            /* pose at the end of the frame */
  float end_py;
  float end_pz;
  float pad4;
  float end_qw;
  float end_qx;
  float end_qy;
  float end_qz;
SINEW_STRUCT_END(ColliderEntry)

/* One node of an implicit shape (64 bytes): an operation (only `op` used)
 * or a primitive with its dimensions and its pose in the collider's frame. */
SINEW_STRUCT_BEGIN(ImplicitEntry)
  uint op;                 /* SINEW_IMPLICIT_* */
  float radius;            /* sphere, capsule, cylinder; torus: major [m] */
  float half_height;       /* capsule, cylinder [m] */
  float rounding;          /* subtracted from the primitive's distance [m] */
  float half_x;            /* box half extents [m] */
  float half_y;
  float half_z;
  float minor_radius;      /* torus tube [m] */
  float px;                /* position in the collider's frame [m] */
  float py;
  float pz;
  float pad0;
  float qw;                /* rotation in the collider's frame (w, x, y, z) */
  float qx;
  float qy;
  float qz;
SINEW_STRUCT_END(ImplicitEntry)

/* A kinematic target: its position at the start and at the end of the
 * frame [m]; the attachment kernel interpolates linearly at substep_end. */
SINEW_STRUCT_BEGIN(TargetEntry)
  float start_x;
  float start_y;
  float start_z;
  float pad0;
  float end_x;
  float end_y;
  float end_z;
  float pad1;
SINEW_STRUCT_END(TargetEntry)

#ifdef __cplusplus
}  /* namespace sinew::kernels */
#endif

#endif /* SINEW_CONTACT_PARAMS_H */
