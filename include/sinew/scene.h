// sinew/scene.h — describing a scene: bodies, materials, gravity and solver
// settings. A SceneDesc is plain data; Simulation::create checks it, compiles
// it into device buffers and a frame program, and runs it.
//
// Units are SI throughout: metres, kilograms, seconds, pascals, newtons.
#pragma once

#include <array>
#include <optional>
#include <cstdint>
#include <limits>
#include <vector>

#include "sinew/fluid.h"
#include "sinew/level_set.h"
#include "sinew/mesh.h"
#include "sinew/result.h"

namespace sinew {

/// FEM materials for tet bodies, each solved as two xPBD constraints per
/// tet on the deformation gradient F (a deviatoric and a hydrostatic one),
/// from Young's modulus E and Poisson's ratio nu (Lame mu, lambda):
///  - neo_hookean: stable Neo-Hookean (Macklin & Müller, "A Constraint-based
///    Formulation of Stable Neo-Hookean Materials", MIG 2021):
///    C_D = |F|_F, alpha = 1/(mu V); C_H = det F - gamma, alpha = 1/(lambda' V),
///    gamma = 1 + mu/lambda', lambda' = lambda + mu (so small-strain E, nu hold).
///  - stvk: St. Venant-Kirchhoff, energy mu |E|^2 + lambda/2 (tr E)^2 with the
///    Green strain E: C_D = |E|_F, alpha = 1/(2 mu V); the hydrostatic term
///    uses det F - 1 (equal to tr E to first order), alpha = 1/(lambda V),
///    because pure StVK has zero energy for a tet turned inside out and so
///    could not recover inverted elements.
///  - corotational: corotational linear, energy mu |F - R|^2 +
///    lambda/2 tr(R^T F - I)^2 with R the rotation of F's polar decomposition
///    (det R = +1, so inverted tets are pushed back): C_D = |F - R|_F,
///    alpha = 1/(2 mu V); C_H = tr(R^T F) - 3, alpha = 1/(lambda V).
/// Every model is invertible: its hydrostatic constraint pushes det F > 0.
/// stvk and corotational need nu > 0 (lambda > 0; Simulation::create names
/// poisson_ratio otherwise). neo_hookean needs small steps: its shear acts
/// explicitly, so keep h sqrt(mu / rho) / (edge length) below ~0.2 (above
/// ~0.75 it is unstable); see docs/tissue.md, "FEM materials".
enum class TetMaterial { none, neo_hookean, stvk, corotational };

/// A volumetric body simulated on a tet mesh with xPBD constraints.
///
/// Distance constraints (one per mesh edge) resist stretch; volume
/// constraints (one per tet) resist volume change. Two ways to set their
/// compliances:
///  - set_elastic(E, nu) (calibrated_network): each tet's six edge springs
///    and its volume stiffness are fitted to that tet's linear-elastic
///    (constant-strain) stiffness for E and nu, and an edge's spring is the
///    sum of its tets' (docs/materials.md: the fit, the nu it can reach,
///    the accuracy measured against a linear-elastic solve of the same
///    mesh). effective_moduli() reports the E and nu a body got.
///  - distance_compliance and volume_compliance [1/Pa] by hand, scaled per
///    element so the response does not depend on how finely it is meshed:
///    edge e of rest length L with a share V_e of the volumes of its tets
///    (each tet gives V/6 to each of its 6 edges): alpha_e = c_d * L^2 / V_e
///    [m/N]; tet of rest volume V: alpha = c_v * V [m^3/Pa], the energy
///    (K/2) (dV/V)^2 V with K = 1 / c_v. Such a network is not a material
///    of modulus 1/c_d: on a regular grid its Young's modulus is about a
///    quarter of 1/c_d (docs/materials.md).
/// Compliance 0 makes a constraint rigid (solved as a hard constraint).
struct TetBodyDesc {
  TetMesh mesh;                         ///< rest shape [m]; must pass check_tet_mesh
  std::vector<Vec3d> initial_vertices;  ///< start positions [m] if not the rest shape (empty: rest)
  double density = 1000.0;              ///< [kg/m^3], > 0; mass is lumped to vertices (V/4 each)
  bool distance_constraints = true;     ///< one distance constraint per edge
  double distance_compliance = 1e-5;    ///< c_d [1/Pa], >= 0 (1/E of the edge network)
  bool volume_constraints = true;       ///< one volume constraint per tet
  double volume_compliance = 1e-6;      ///< c_v [1/Pa], >= 0 (1/K, the bulk compliance)
  std::vector<std::uint32_t> pinned;    ///< vertices held fixed (inverse mass 0)
  TetMaterial material = TetMaterial::none;  ///< FEM constraints per tet (with E and nu below)
  /// Tearing, >= 0 (0: never tears): after each frame, a tet with an edge
  /// stretched past (1 + tear_strain) times its rest length is removed
  /// (Simulation::last_tears lists them). Needs SceneDesc::topology_changes.
  double tear_strain = 0.0;
  /// Velocity damping k [1/s], >= 0: every substep multiplies the velocity
  /// of the body's particles by exp(-k h), so free motion decays as
  /// exp(-k t) whatever the substeps (like a drag through a viscous medium:
  /// it also slows rigid motion and falls, to a terminal speed g / k).
  double velocity_damping = 0.0;
  /// Constraint damping time tau [s], >= 0, of the distance and volume
  /// constraints (Macklin et al., "XPBD", MIG 2016, eq. 26 with beta = tau
  /// times the constraint's stiffness): stiffness-proportional (Rayleigh)
  /// damping that resists the rate of stretch and volume change, not rigid
  /// motion. A mode of angular frequency omega decays at tau omega^2 / 2
  /// [1/s] (damping ratio tau omega / 2). Not applied to the FEM materials
  /// (use velocity_damping there). Bodies with different taus get separate
  /// constraint blocks (more dispatches per sweep).
  double stiffness_damping = 0.0;
  double youngs_modulus = 0.0;          ///< E [Pa], > 0 when material != none or calibrated_network
  double poisson_ratio = 0.0;           ///< nu, in (-1, 0.5) when material != none or calibrated_network
  /// true (set by set_elastic): the distance and volume compliances come
  /// from youngs_modulus and poisson_ratio, fitted per tet, and
  /// distance_compliance and volume_compliance are ignored.
  bool calibrated_network = false;

  /// Makes the distance + volume network approximate the linear material
  /// of Young's modulus E [Pa] (> 0) and Poisson's ratio nu (in [0.2, 0.5))
  /// in small strain: sets youngs_modulus, poisson_ratio and
  /// calibrated_network. Each tet's springs and volume term are fitted to
  /// its constant-strain stiffness, towards a target chosen so that the
  /// body's mean stiffness has E, nu and the shear modulus along the axes
  /// (effective_moduli reports them). An edge network is not isotropic, so
  /// a body's response still differs from linear elasticity's on the same
  /// mesh by up to about 30% depending on the load (docs/materials.md has
  /// the measurements). nu below 0.2 is an error naming poisson_ratio:
  /// springs are central forces (use set_material). Errors name the
  /// parameter.
  Status set_elastic(double young, double poisson);

  /// Makes this an FEM body: sets material, E [Pa] and nu, and turns the
  /// distance and volume constraints off. Errors name the parameter.
  Status set_material(TetMaterial model, double young, double poisson);
};

/// Small-strain isotropic moduli.
struct ElasticModuli {
  double young = 0.0;    ///< Young's modulus E [Pa]
  double poisson = 0.0;  ///< Poisson's ratio nu
  double shear = 0.0;    ///< shear modulus G [Pa]
  double bulk = 0.0;     ///< bulk modulus K [Pa]
};

/// What a tet body's distance + volume constraints amount to as a linear
/// material along the coordinate axes: from the mean over its tets of the
/// network's small-strain stiffness (springs and volume terms under a
/// uniform strain, inverted to a compliance S), E = 1 / S_xxxx, nu =
/// -E S_xxyy and G = 1 / (4 S_xyxy), each averaged over the three axes,
/// and K. For set_elastic(E, nu) this is E, nu and E / (2 (1 + nu)) to
/// within the fit (about 1e-3); for compliances set by hand it says what
/// they mean (on a regular grid, E about a quarter of 1 / c_d). It is the
/// mean of a uniform strain: a mesh whose nodes relax non-uniformly (not a
/// regular grid) is softer (docs/materials.md). [in] body: a body with
/// distance or volume constraints and a valid mesh. Errors name the
/// parameter.
Result<ElasticModuli> effective_moduli(const TetBodyDesc& body);

/// Particles joined by distance constraints: a chain, or a suture thread.
///
/// Bending (when bending_compliance >= 0): every vertex joined to exactly two
/// segments gets a bending constraint on the triangle it forms with its two
/// neighbours (Kelager, Niebe, Erleben, "A Triangle Bending Constraint Model
/// for Position-Based Dynamics", VRIPHYS 2010): C = |x_mid - centroid| - h0,
/// with h0 its rest value, alpha = bending_compliance [m/N].
struct LineBodyDesc {
  std::vector<Vec3d> vertices;                          ///< rest positions [m]
  std::vector<Vec3d> initial_vertices;                  ///< start positions [m] if not the rest ones (empty: rest)
  std::vector<double> masses;                           ///< per vertex [kg], > 0
  std::vector<std::array<std::uint32_t, 2>> segments;   ///< vertex pairs, rest length > 0
  double compliance = 0.0;                              ///< per segment [m/N], >= 0
  double bending_compliance = -1.0;                     ///< [m/N], >= 0; < 0: no bending constraints
  std::vector<std::uint32_t> pinned;                    ///< vertices held fixed
  /// Tearing, >= 0 (0: never): after each frame, a segment stretched past
  /// (1 + tear_strain) times its rest length breaks, with the bending
  /// constraints across it (Simulation::last_tears). Needs
  /// SceneDesc::topology_changes.
  double tear_strain = 0.0;
  /// Velocity damping k [1/s], >= 0: every substep multiplies the velocity
  /// of the body's particles by exp(-k h), so free motion decays as
  /// exp(-k t) whatever the substeps (like a drag through a viscous medium:
  /// it also slows rigid motion and falls, to a terminal speed g / k).
  double velocity_damping = 0.0;
  /// Constraint damping time tau [s], >= 0, of the segments (as TetBodyDesc).
  double stiffness_damping = 0.0;
};

/// A thin body on a triangle mesh: a membrane, a vessel wall, a ligament.
/// Mass: density * thickness * area, lumped a third to each vertex.
///  - distance constraints on the edges: alpha_e = c_d * L^2 / (A_e * t)
///    [m/N], A_e the edge's share of its triangles' areas (A/3 each), t the
///    thickness: the membrane analogue of TetBodyDesc's edges;
///  - area constraints: C = A - A0 [m^2], alpha = c_a A0 / t [m^3/N], i.e.
///    the energy (K/2) (dA/A0)^2 A0 t with K = 1/c_a;
///  - dihedral bending on every interior edge (exactly two triangles; an
///    edge of three or more gets none): C = angle - rest angle [rad], the
///    signed angle between the two normals (0 flat) wrapped to [-pi, pi],
///    alpha = bending_compliance [1/(N m)] per hinge (Müller et al.,
///    "Position Based Dynamics", 2007, section 4.2; gradients of Bridson
///    et al., SCA 2003).
struct TriBodyDesc {
  TriMesh mesh;                           ///< rest shape [m]
  std::vector<Vec3d> initial_vertices;    ///< start positions [m] if not the rest shape (empty: rest)
  double thickness = 1e-3;                ///< [m], > 0
  double density = 1000.0;                ///< [kg/m^3], > 0
  bool distance_constraints = true;       ///< stretch: one distance constraint per edge
  double distance_compliance = 1e-5;      ///< c_d [1/Pa], >= 0
  bool area_constraints = true;           ///< one area constraint per triangle
  double area_compliance = 1e-5;          ///< c_a [1/Pa], >= 0
  double bending_compliance = -1.0;       ///< [1/(N m)], >= 0; < 0: no bending constraints
  std::vector<std::uint32_t> pinned;      ///< vertices held fixed
  /// Tearing, >= 0 (0: never tears): after each frame, a triangle with an
  /// edge stretched past (1 + tear_strain) times its rest length is
  /// removed, with the hinges it was part of (Simulation::last_tears).
  /// Needs SceneDesc::topology_changes.
  double tear_strain = 0.0;
  /// Velocity damping k [1/s], >= 0: every substep multiplies the velocity
  /// of the body's particles by exp(-k h), so free motion decays as
  /// exp(-k t) whatever the substeps (like a drag through a viscous medium:
  /// it also slows rigid motion and falls, to a terminal speed g / k).
  double velocity_damping = 0.0;
  /// Constraint damping time tau [s], >= 0, of the edges (as TetBodyDesc;
  /// not of the area and bending constraints).
  double stiffness_damping = 0.0;
};

/// Analytic collider shapes. Pose: `position` [m] and unit quaternion
/// `rotation` (w, x, y, z). In the collider's frame: a plane is y = 0 with
/// solid below (normal +y); a sphere has `radius`; a capsule is the segment
/// from (0, -half_height, 0) to (0, +half_height, 0) swollen by `radius`; a
/// box has `half_extents`; a cylinder has flat caps at y = +-half_height and
/// `radius` about the y axis; an implicit shape is the signed distance
/// function its `implicit` nodes compute (ImplicitNode).
enum class ColliderShape { plane, sphere, capsule, box, cylinder, implicit, level_set };

/// One node of an implicit shape (ColliderShape::implicit), an analytic
/// signed distance function written as a CSG expression in postfix order:
/// a primitive pushes its signed distance, an operation pops two (a, then
/// b on top) and pushes the result. {box, sphere, subtract} is a box with
/// a spherical bite; {a, b, unite, c, intersect} is (a u b) n c.
///
/// Primitives, in their own frame (`position` [m] and unit quaternion
/// `rotation` (w, x, y, z) within the collider's frame): half_space (y <= 0,
/// solid below, like a plane collider), sphere (`radius`), capsule (the
/// segment +-half_height along y swollen by `radius`), box (`half_extents`),
/// cylinder (`radius`, caps at +-half_height), torus (a tube of
/// `minor_radius` around the circle of `radius` in the y = 0 plane). Each
/// primitive's distance is reduced by `rounding` [m] >= 0 (rounded edges,
/// grown by that much).
/// Operations: unite min(a, b), intersect max(a, b), subtract max(a, -b)
/// (a without b). These are exact distances outside a union and bounds
/// elsewhere (the sign, the zero set and the normal on it are exact; the
/// normal is the gradient of the primitive that decides the value).
/// At most 64 nodes, at most 8 values on the stack at once.
enum class ImplicitOp { half_space, sphere, capsule, box, cylinder, torus, unite, intersect, subtract };
/// One node of an implicit collider's postfix expression: a primitive with
/// its pose and size, or an operation on the two values before it.
struct ImplicitNode {
  ImplicitOp op = ImplicitOp::sphere;  ///< the primitive, or the operation
  std::array<double, 3> position{0.0, 0.0, 0.0};       ///< primitive's origin in the collider's frame [m]
  std::array<double, 4> rotation{1.0, 0.0, 0.0, 0.0};  ///< unit quaternion (w, x, y, z)
  double radius = 0.0;                                  ///< sphere, capsule, cylinder, torus (major) [m], > 0
  double half_height = 0.0;                             ///< capsule [m] >= 0; cylinder [m] > 0
  std::array<double, 3> half_extents{0.0, 0.0, 0.0};    ///< box [m], > 0
  double minor_radius = 0.0;                            ///< torus tube [m], > 0
  double rounding = 0.0;                                ///< [m], >= 0
};

/// A static or kinematic collider that every body's particles collide with,
/// as xPBD contact constraints C = signed distance >= 0 with `compliance`
/// [m/N] and Coulomb friction (static and dynamic coefficients). Move it
/// between frames with Simulation::set_collider_pose; it is interpolated
/// across the frame's substeps.
struct ColliderDesc {
  ColliderShape shape = ColliderShape::plane;  ///< which shape; the fields below it uses
  std::array<double, 3> position{0.0, 0.0, 0.0};       ///< [m]
  std::array<double, 4> rotation{1.0, 0.0, 0.0, 0.0};  ///< unit quaternion (w, x, y, z)
  double radius = 0.0;                                  ///< sphere, capsule, cylinder [m], > 0
  double half_height = 0.0;                             ///< capsule [m], >= 0; cylinder [m], > 0
  std::array<double, 3> half_extents{0.0, 0.0, 0.0};    ///< box [m], > 0
  double static_friction = 0.5;                         ///< >= 0
  double dynamic_friction = 0.4;                        ///< >= 0, <= static_friction
  double compliance = 0.0;                              ///< [m/N], >= 0
  std::vector<ImplicitNode> implicit;                   ///< implicit shape's nodes (only with ColliderShape::implicit)
  /// ColliderShape::level_set: the signed distance field (sinew/level_set.h)
  /// in the collider's frame. Particles are pushed out along its gradient;
  /// one deeper inside than its interior band (where the gradient is zero)
  /// is not (build it with the inside filled for a solid). The simulation
  /// shares the grid: Simulation::cut_collider cuts it.
  std::optional<LevelSet> level_set;
};

/// Which body a vertex belongs to.
enum class BodyKind { tet, tri, line };
/// One vertex of one body of the scene.
struct VertexRef {
  BodyKind body_kind = BodyKind::tet;  ///< the kind of body
  std::uint32_t body = 0;    ///< index into the scene's bodies of that kind
  std::uint32_t vertex = 0;  ///< vertex of that body
};

/// A vertex attached to a kinematic target (a grasper jaw) by a zero-length
/// xPBD distance constraint of `compliance` [m/N]. Targets are scene-wide
/// points moved between frames with Simulation::set_target and interpolated
/// across the substeps; several attachments may share one target.
struct AttachmentDesc {
  VertexRef vertex;           ///< the vertex held
  std::uint32_t target = 0;   ///< index into SceneDesc::targets
  double compliance = 0.0;    ///< [m/N], >= 0
};

/// A point of a body given by barycentric weights over up to four of its
/// vertices: p = sum_k weights[k] x(vertices[k]). A point inside a tet uses
/// its 4 vertices, inside a triangle 3, on a segment 2, on a vertex 1.
struct BarycentricPoint {
  BodyKind body_kind = BodyKind::tet;   ///< the kind of body
  std::uint32_t body = 0;               ///< index into the scene's bodies of that kind
  std::vector<std::uint32_t> vertices;  ///< 1 to 4 distinct vertices of that body
  std::vector<double> weights;          ///< one per vertex, finite, summing to 1 (within 1e-6)
};

/// Two bodies attached to each other, two ways: an xPBD distance
/// constraint C = |p_a - p_b| - rest_length between a barycentric point of
/// each (Macklin, Mueller and Chentanez, "XPBD", MIG 2016; rest_length 0
/// holds the points together), solved in every sweep after the
/// bodies' own constraints. Each side feels the other's pull: a membrane
/// attached to an organ lifts it when pulled, and the organ's weight hangs
/// on the membrane. Connective tissue, vessels on organs and mesentery are
/// many such attachments (docs/attachments.md).
///
/// The attachment breaks, for good, in the first iteration whose constraint
/// force |lambda| / h^2 [N] (lambda the multiplier accumulated in the
/// substep, h the substep) exceeds `break_force`. The device detects it:
/// a flag word in the attachment's data is set by the solve kernel and the
/// attachment is skipped from then on; the host reads nothing back.
struct BodyAttachmentDesc {
  BarycentricPoint a;        ///< the point on the first body
  BarycentricPoint b;        ///< the point on the second (no vertex shared with a)
  /// [m/N], >= 0: the attachment stretches by compliance x force; 0 is rigid.
  double compliance = 0.0;
  /// [N], > 0; infinity (the default) never breaks.
  double break_force = std::numeric_limits<double>::infinity();
  /// [m], >= 0: the distance the attachment holds the two points at (0:
  /// together). Give two points that lie apart at rest their distance then:
  /// connective tissue that bridges a gap. With a rest length the
  /// attachment pushes as well as pulls (a strut, not a string).
  double rest_length = 0.0;
};

/// A rigid tool's shape (ToolDesc::shape).
enum class ToolShape {
  /// The segment +-half_height along its y swollen by `radius`: meets the
  /// colliders and the other tools as a rigid body (positional contacts,
  /// tool_contacts.h).
  capsule,
  /// ToolDesc::level_set in its frame (a burr, a drill bit, any closed
  /// surface): meets the colliders and the other tools by a penalty on its
  /// surface points (penalty_stiffness).
  level_set,
};

/// A trocar (laparoscopic port) a tool's shaft passes through
/// (ToolDesc::trocar): a point fixed in the world that the tool's shaft
/// line, centre + R axis s for every s, always passes through. The tool
/// stays free to turn about the pivot (all three axes, including the roll
/// about its shaft) and to slide along its shaft (insertion); motion of the
/// shaft sideways at the pivot is removed.
struct TrocarDesc {
  std::array<double, 3> pivot{0.0, 0.0, 0.0};  ///< the port, world frame [m], finite
  /// The shaft's direction in the tool's frame, through its centre; finite
  /// and non-zero (normalised when the scene is created). A capsule's
  /// shaft is its y axis, {0, 1, 0} (the default).
  std::array<double, 3> axis{0.0, 1.0, 0.0};
};

/// How far a tool's initial shaft line may pass from its trocar's pivot
/// [m]: within it, the initial pose is projected onto the constraint when
/// the scene is created; beyond it, a named error.
inline constexpr double kTrocarPoseTolerance = 1e-5;

/// A rigid tool with mass and inertia, driven by a force and torque
/// (Simulation::apply_tool_force) and pushed back by what it touches. Its
/// contacts with particles are solved like a collider's of its shape; the
/// reaction of the tissue acts on the tool at the end of each frame.
///
/// A level-set tool (shape = level_set) against a collider or another tool
/// feels a penalty (voxmap-pointshell; McNeely, Neff and Troy, SIGGRAPH
/// 1999): each point of its surface (LevelSet::surface(), a third of its
/// triangles' area each) at depth d > 0 inside the other shape is pushed
/// along that shape's normal by area * (penalty_stiffness d +
/// penalty_damping d'), never pulled (d' is the point's speed into the
/// shape). A sphere of radius R pressed delta into a flat face feels
/// penalty_stiffness pi R delta^2. The penalty at the start of a frame
/// drives the frame (explicit): stable while sqrt(k / M) time_step < 2 for
/// the contact's stiffness k = dF/d delta (2 penalty_stiffness pi R delta
/// for that sphere) and the tool's mass M; docs/level_sets.md sizes it.
/// Particles deeper in the tool than its level set's interior band (zero
/// gradient) are not pushed out: build a tool's level set with the inside
/// filled. Continuous collision (MeshCollisionDesc::continuous) sweeps
/// capsule tools only: a level-set tool meets particles and faces at the
/// substeps' poses.
///
/// A tool with a trocar (a laparoscopic instrument through its port) has
/// its shaft held through the pivot every frame, after its motion is
/// integrated (Cline and Pai, "Post-stabilization for rigid body
/// simulation with contact and constraints", ICRA 2003): first an impulse
/// at the pivot removes the sideways velocity of the tool's point there,
/// including the part the angular velocity makes, through the tool's
/// mass and inertia, so a sideways push on the tool turns it about the
/// port as a real instrument turns (the tip swings the other way) instead
/// of being cancelled; then the pose is moved straight across the shaft
/// by the small drift the rotation's integration left, so the shaft line
/// passes through the pivot to rounding, and the impulse is applied again
/// at the new pose, so the tool does not fight the constraint next frame.
/// After the tools are pushed out of the colliders (which may move them
/// sideways), the pose and velocity are held to the port again: the port
/// wins over a collider. What the port pushed the tool with is reported
/// (ToolState::trocar_force, trocar_torque); a hand coupled to the tool
/// (haptics/tool_bridge.h) feels it through the coupling, whose spring
/// stretches as the port holds the tool back. The initial pose must put
/// the shaft line within kTrocarPoseTolerance of the pivot (a named
/// error otherwise); the rest is projected when the scene is created.
/// A tool that removes a level-set collider's material as it moves (a
/// burr, a drill, a saw; ToolDesc::cuts): after each frame the collider is
/// cut (Tools::cut) by `cutter`, swept from the tool's pose at the frame's
/// start to its pose at the end, the cutter in the tool's frame (centred at
/// its origin; a capsule along its y). A cutter a little smaller than the
/// tool's own shape removes only what the tool presses deeper than the
/// difference, so the tool's penalty against the bone is the force felt
/// while cutting. The collider must be a level set with its inside stored
/// (LevelSet::cut); the cut is done on the host and the changed leaves
/// uploaded, as Tools::cut does (a saved state holds the grid's values:
/// restoring one from before the cut puts the grid back).
struct ToolCutDesc {
  std::uint32_t collider = 0;  ///< the level-set collider it cuts (SceneDesc::colliders index)
  CutterShape cutter;          ///< its shape [m], in the tool's frame
};

struct ToolDesc {
  ToolShape shape = ToolShape::capsule;  ///< a capsule, or a level set's shape
  double radius = 0.005;                                ///< capsule [m], > 0
  double half_height = 0.05;                            ///< capsule [m], >= 0
  /// ToolShape::level_set: the signed distance field in the tool's frame
  /// (its origin is the tool's centre of mass). Shared with the caller.
  std::optional<LevelSet> level_set;
  double penalty_stiffness = 0.0;  ///< level_set: pressure per depth [N/m^3], > 0 (no default: it depends on M and dt)
  double penalty_damping = 0.0;    ///< level_set: pressure per speed into the shape [N s/m^3], >= 0
  double mass = 0.1;                                    ///< [kg], > 0
  std::array<double, 3> inertia{1e-4, 1e-5, 1e-4};      ///< principal moments in the tool frame [kg m^2], > 0
  std::array<double, 3> position{0.0, 0.0, 0.0};       ///< initial [m]
  std::array<double, 4> rotation{1.0, 0.0, 0.0, 0.0};  ///< initial unit quaternion (w, x, y, z)
  bool gravity = true;                                  ///< whether gravity acts on the tool
  double static_friction = 0.3;                         ///< of its contacts, >= 0
  double dynamic_friction = 0.2;                        ///< of its contacts, >= 0, <= static_friction
  double compliance = 0.0;                              ///< of its contacts [m/N]
  /// A trocar its shaft passes through (see above); none by default.
  std::optional<TrocarDesc> trocar;
  /// A collider it cuts as it moves (ToolCutDesc); none by default.
  std::optional<ToolCutDesc> cuts;
};

/// How a needle moves (NeedleDesc::drive).
enum class NeedleDrive {
  /// Posed by the user every frame (Simulation::set_needle_pose); it feels
  /// the tissue's reaction (NeedleState::reaction_force) but is not moved by it.
  kinematic,
  /// A rigid body with mass and inertia, driven by a force and torque
  /// (Simulation::apply_needle_force) and pushed back by the tissue and
  /// pulled by its thread, coupled as a rigid tool is (ToolDesc): the
  /// reaction of one frame acts on it in the next. Drive it through a
  /// virtual coupling that also holds its orientation (a needle pushed
  /// along its axis balances on its tip like a pencil); the gains' bounds
  /// are in docs/needles.md.
  force,
};

/// A suture needle (docs/needles.md): a rigid curve, a polyline in its own
/// frame from its tail (curve.front()) to its tip (curve.back()), moved
/// kinematically (Simulation::set_needle_pose) or by force
/// (Simulation::apply_needle_force; `drive`), its substeps interpolating
/// each point linearly, and optionally pulling a thread tied to its tail.
///
/// The tip punctures the surfaces of the tet bodies (their boundary) and
/// the tri bodies: when its path in a frame meets a surface triangle from
/// outside, a contact pushes the tissue ahead of the tip; once the frame's
/// average push passes `puncture_force` with the tip within
/// `max_puncture_angle` of the surface's inward normal, the tissue point
/// it pushed (triangle and barycentric weights) is held on the needle's
/// curve, the closest point of the curve to it, as the needle slides
/// through (Moore et al., "The interactive medical simulation toolkit
/// (iMSTK)", Frontiers in Virtual Reality 2023, section 2.5). Leaving a tet
/// body's surface from inside makes an exit puncture (no force needed).
/// Once the needle's tail has passed a puncture, the puncture holds the
/// thread instead, which slides through it with friction; the thread's last
/// vertex is a knot that stops at the puncture. Punctures of a triangle
/// that is degenerate or inverted (its tet turned inside out) are refused
/// (NeedleState::refused). Details and limits: docs/needles.md.
struct NeedleDesc {
  std::vector<std::array<double, 3>> curve;             ///< [m] in the needle's frame, tail to tip, >= 2 points, no zero-length segment
  std::array<double, 3> position{0.0, 0.0, 0.0};       ///< initial [m]
  std::array<double, 4> rotation{1.0, 0.0, 0.0, 0.0};  ///< initial unit quaternion (w, x, y, z)
  double puncture_force = 0.5;                          ///< [N], > 0: the push that punctures a surface
  double max_puncture_angle = 1.0;                      ///< [rad], in (0, pi/2]
  /// Of the punctures and the tie to the thread [m/N], >= 0 (0: rigid).
  double compliance = 0.0;
  /// A line body whose vertex 0 is tied to the needle's tail, or -1 for none.
  int thread = -1;
  double thread_static_friction = 0.3;   ///< of the thread sliding through a puncture, >= 0
  double thread_dynamic_friction = 0.2;  ///< >= 0, <= thread_static_friction
  // ---- Needle forces (docs/needles.md, "Needle forces"; all off by default:
  // a point tip and a frictionless shaft, as before they existed).
  /// A blunt tip: its end a flat disc of this radius [m], >= 0, finite (0:
  /// a point). While it pushes an unpunctured surface, every surface vertex
  /// of that body within this radius of the tip's axis is kept ahead of the
  /// disc, so the push is shared by the tissue around the tip instead of one
  /// point (which turns its tets inside out long before a puncture force of
  /// 0.1-2 N). Set it to at least one element's edge; the rows it adds count
  /// towards a needle's 64 (step() fails naming the needle past that).
  double tip_radius = 0.0;
  /// Friction along the shaft, a Karnopp stick-slip law acting where the
  /// shaft passes through a punctured tet body, scaled by the length of
  /// shaft inside it (Okamura, Simone and O'Leary, IEEE TBME 51(10), 2004).
  /// Slipping (relative speed above shaft_stick_velocity): a Coulomb force
  /// of this [N per m of inserted shaft], >= 0, plus shaft_viscous_friction
  /// times the speed.
  double shaft_friction = 0.0;
  /// Sticking (relative speed within shaft_stick_velocity): holds the
  /// tissue on the shaft up to this [N per m of inserted shaft], >=
  /// shaft_friction.
  double shaft_static_friction = 0.0;
  double shaft_viscous_friction = 0.0;  ///< [N s/m per m of inserted shaft], >= 0
  double shaft_stick_velocity = 1e-3;   ///< Karnopp's band [m/s], > 0: below it the shaft sticks
  /// The force [N], >= 0, the tip needs to cut its way on through a tet
  /// body it is inside (added to the shaft's friction while it advances).
  double cutting_force = 0.0;
  NeedleDrive drive = NeedleDrive::kinematic;  ///< posed by the caller, or moved by force
  // ---- A force-driven needle's body (drive = force; ignored otherwise).
  // The needle's frame has its origin at the centre of mass and its axes
  // along the principal axes of inertia; the defaults are those of a needle
  // held in its needle holder (the hand moves both).
  double mass = 0.02;                                ///< [kg], > 0
  std::array<double, 3> inertia{4e-5, 4e-5, 4e-6};   ///< principal moments in the needle frame [kg m^2], > 0
  bool gravity = true;                               ///< whether gravity acts on it
};

/// Which solver integrates the tissue (SolverSettings::method).
///  - xpbd: constraints solved by xPBD (Macklin et al., 2016, 2019), every
///    feature of the scene description.
///  - vbd: Vertex Block Descent (Chen, Liu, Yang, Yuksel, "Vertex Block
///    Descent", ACM TOG 43(4), SIGGRAPH 2024): each substep minimises the
///    implicit-Euler energy  sum_i m_i / (2 h^2) |x_i - y_i|^2 + E_elastic(x)
///    (y = x + h v + h^2 g, the inertia target) by sweeps of one 3x3 Newton
///    step per vertex over its tets' energy, vertices coloured so that a
///    colour's vertices share no tet. The stiffness is the material's at any
///    sweep count (no compliance is softened by unconverged sweeps); too few
///    sweeps show as extra damping instead. For tet bodies with
///    TetMaterial::corotational or neo_hookean only, pinned vertices, on
///    every backend (the GPU kernels agree bitwise with the CPU reference);
///    every other feature is an error naming it
///    (docs/materials.md, "Vertex Block Descent").
enum class SolverMethod { xpbd, vbd };

/// How each frame is solved: a frame of length time_step is split into
/// `substeps` substeps of h = time_step / substeps; each substep predicts,
/// runs `iterations` Gauss-Seidel sweeps over all constraints (colour by
/// colour) and updates velocities (Macklin et al., "Small Steps", 2019).
/// With method = vbd a sweep is one pass of Vertex Block Descent over the
/// vertex colours instead (SolverMethod).
struct SolverSettings {
  /// The solver (SolverMethod): xpbd (the default) or vbd. With vbd,
  /// `iterations` counts VBD sweeps per substep, chebyshev_rho/gamma/delay
  /// accelerate them (the paper's Chebyshev acceleration, positions only), and the
  /// residual mode, warm_start and every constraint other than a tet
  /// body's corotational or neo_hookean material are errors. FrameStats::
  /// residual_rms and max_residual are 0 with vbd (it has no constraint
  /// multipliers whose residual they measure); the kinetic energy, volume
  /// change and inverted tets are measured as with xpbd.
  SolverMethod method = SolverMethod::xpbd;
  /// Frame length [s], > 0. The device computes in float32: h =
  /// time_step / substeps, 1/h and 1/h^2 must be finite, non-zero floats
  /// (e.g. 1e300 or 1e-300 is an error naming solver.time_step), and so
  /// must every compliance alpha the device stores (after scaling by its
  /// element, e.g. c L^2 / V) and alpha / h^2, each stiffness_damping over
  /// h, gravity and h g (and a frame's move dt^2 g at most 1e12 m), and
  /// every particle's inverse mass (a density so large that it rounds to
  /// 0, which would pin the particle, is an error naming the body).
  double time_step = 1.0 / 60.0;
  int substeps = 1;               ///< >= 1, <= 10,000 (a bound on a frame's work)
  int iterations = 5;             ///< >= 1, <= 10,000; substeps x iterations <= 1,000,000 sweeps a frame
  /// Contact-only sweeps at the end of every substep, >= 0, <= 10,000
  /// (default 0: none). After the substep's `iterations` sweeps (and, in
  /// the residual-driven mode, its checks), each runs the colliders' and
  /// tools' contacts with the particles and then the mesh contacts
  /// (MeshCollisionDesc), their multipliers carried on, and no other
  /// constraint; then the velocities are updated. Contacts solved last in
  /// a sweep share particles across colours and with each other (a folded
  /// or pressed surface, a heavy tool's faces), so one sweep leaves them
  /// unconverged: these end the substep with the contacts held, the
  /// elastic constraints answering in the next substep. Costs one contact
  /// pass each (the bodies' constraints are not swept). Measured
  /// (docs/collision.md, "Contacts that hold"). With method vbd: an error.
  int contact_sweeps = 0;
  /// Measure the frame's errors (FrameStats): costs one store per
  /// constraint in the last sweep and a read-back of the residuals,
  /// velocities and positions after each frame.
  bool measure_errors = true;
  /// Store the particles on the device in a memory-friendly order (reverse
  /// Cuthill-McKee within each body; each colour's constraints sorted by
  /// their first particle). Invisible to the API: read_positions and vertex
  /// references stay in the scene's numbering, and the positions are
  /// bitwise the same either way (only the last bits of the summed
  /// FrameStats may differ). Off: the device holds them in the scene's
  /// order, the mesher's, which is slower on large meshes.
  bool reorder_particles = true;

  // ---- Residual-driven mode (off by default: exactly `iterations` sweeps).
  /// Residual-driven mode, on when > 0 (unitless, finite, >= 0): each
  /// substep runs `iterations` sweeps, then `check_interval` more at a time
  /// until the RMS over all constraints of the normalised residual
  /// |C + alpha~ lambda| / (rest value) — the measure of
  /// FrameStats::residual_rms — is <= this, or max_iterations or
  /// time_budget_ms is spent; FrameStats::stop says which. Each check
  /// measures the residuals and reduces them on the device, and the host
  /// reads back 3 words per constraint block. For statics within ~5% the
  /// tolerance must be ~1/20 of the body's strain under its load (about
  /// rho g L / E): see docs/tissue.md's stiffness table. 0: fixed mode.
  double residual_tolerance = 0.0;
  /// Residual mode: the most sweeps per substep, >= iterations, <= 100,000
  /// (and substeps x max_iterations <= 1,000,000); rounded up to
  /// iterations plus a whole number of check_interval.
  int max_iterations = 200;
  /// Residual mode: sweeps between two residual checks, >= 1. Each check
  /// costs about one sweep's reads plus a round trip to the device.
  int check_interval = 4;
  /// Residual mode: the wall time [ms] a frame may spend (finite, >= 0;
  /// 0: no budget). Substep s of n stops sweeping when its next group of
  /// sweeps would end after (s + 1) / n of the budget from the frame's
  /// start (the group's time is estimated from the last one run).
  double time_budget_ms = 0.0;

  // ---- Lambda warm start (off by default).
  /// Start each substep's sweeps from the last substep's lambdas instead of
  /// 0, with the positions moved by the correction those lambdas make
  /// (x += w lambda grad C, the gradient at the substep's start), so x and
  /// lambda stay consistent. A body at rest then starts at its equilibrium
  /// and its static state does not depend on how many sweeps run; without
  /// it each substep rebuilds its lambdas from 0 and unconverged sweeps
  /// leave stiff bodies far softer than their material. Costs about one
  /// sweep per substep. Only in the residual-driven mode (an error
  /// otherwise): with a fixed number of unconverged sweeps the carried
  /// lambdas act a substep late, like an explicit force, and stiff bodies
  /// oscillate and diverge (measured: a 12^3-cell E = 30 MPa block at 5-40
  /// sweeps per frame); sweeping to a tolerance keeps each substep implicit.
  /// For the same reason a substep that stops at the time budget passes
  /// nothing on: the next substep starts from lambda = 0 (cold). One that
  /// stops at max_iterations passes its lambdas on only if its sweeps
  /// lowered the residual and it ended within 10x residual_tolerance; else
  /// it starts its successor cold too, so a cap far below what converges
  /// stays finite at the fixed mode's softness (FrameStats::
  /// dropped_warm_starts counts those substeps). Only for
  /// scenes of distance and volume constraints (tet bodies without an FEM
  /// material, line bodies without bending; no colliders, no mesh
  /// collision): others are an error naming this setting.
  bool warm_start = false;

  // ---- Chebyshev semi-iterative accelerator (off by default).
  /// Estimated spectral radius rho of one sweep, in [0, 1); 0: off (the
  /// sweeps run bitwise as without it). On: after every sweep past the
  /// first chebyshev_delay of a substep, positions AND lambdas are
  /// extrapolated (Wang, SIGGRAPH Asia 2015, eq. 12) with omega_k from rho.
  /// Too large a rho oscillates or diverges, too small gains little (see
  /// docs/tissue.md's stiffness section for measured values). Works in fixed
  /// and residual mode; costs one pass over positions and lambdas per sweep.
  /// Not with warm_start (an error): together they diverged on the tests'
  /// stiff cantilever.
  double chebyshev_rho = 0.0;
  /// Under-relaxation gamma of the accelerated sweeps, in (0, 1].
  double chebyshev_gamma = 1.0;
  /// S: plain sweeps of each substep before the acceleration starts, >= 2
  /// (the first extrapolation, after sweep S + 1, needs the states after
  /// sweeps S - 1 and S).
  int chebyshev_delay = 10;
};

/// Contacts between the bodies' meshes, and of a body with itself (issue
/// 12): every tet body's boundary surface and every tri body's triangles
/// collide (vertex-triangle and edge-edge contacts), and every line body's
/// segments with each other and with those triangles (edge-edge, and a
/// segment end against a triangle). Both sides move: corrections are
/// weighted by inverse masses through the closest points' barycentric
/// weights (kernels/shared/mesh_contact_params.h).
///
/// Contacts are found once per frame, at its start, and stay valid for the
/// whole frame: every pair of primitives closer than thickness + margin is
/// a contact, the margin covering how far the surfaces can move within the
/// frame (docs/collision.md, "Mesh collision"). Each contact keeps the first
/// primitive on its side of the separating plane through the second's
/// closest point, `thickness` away from it, so surfaces that start a frame
/// apart cannot pass through each other as long as no particle moves more
/// than half the margin within it. Redundant contacts are pruned: a
/// vertex keeps its nearest against another body, a triangle its 3
/// nearest immovable vertices, an edge its 4 nearest edges (docs/collision.md, "Mesh
/// collision"). Contacts are solved after the bodies'
/// constraints in every sweep, scheduled by `schedule`.
///
/// Not yet: with the Chebyshev accelerator (an error names the setting),
/// and on the device (the host finds the contacts; GPU backends read the
/// positions back once per frame).
/// How the contacts between meshes are scheduled within a sweep (docs/collision.md,
/// "Mesh collision", compares them):
///  - colored: coloured on the host every frame so that no two contacts of
///    a colour share a movable particle, one dispatch per colour
///    (Gauss-Seidel, like the bodies' constraints);
///  - jacobi: every contact solved from the same positions, then each
///    particle moved by the mean of its contacts' corrections (Macklin et
///    al., "Unified Particle Physics", 2014, section 4.2): two dispatches
///    per sweep however many colours the contacts would need;
///  - device_colored: coloured on the device at the frame's start
///    (Jones and Plassmann's parallel colouring, docs/collision.md), at
///    most MeshCollisionDesc::device_colors colours, one indirect dispatch
///    per colour (its count never comes to the host), and the contacts
///    left over (an overflow set: no colour below the cap free, or still
///    undecided after MeshCollisionDesc::device_rounds rounds) solved one
///    after another after the colours. Meant for GPUs: on CPU devices it
///    is slower than host colouring. Not with `continuous` (its contacts
///    are coloured on the host; an error names both).
enum class ContactSchedule { colored, jacobi, device_colored };

/// Contacts between the bodies' meshes and within them (SceneDesc::mesh_collision; docs/collision.md).
struct MeshCollisionDesc {
  bool enabled = false;                                 ///< off: no mesh contacts at all
  ContactSchedule schedule = ContactSchedule::colored;  ///< how the contacts are solved within a sweep
  /// The distance the surfaces keep from each other [m], > 0. Also the
  /// tissue's collision thickness in self-contact.
  double thickness = 1e-3;
  /// Extra distance [m], >= 0, under which contacts are made at the
  /// frame's start, on top of the motion margin the simulation measures
  /// every frame (2 |v|max dt + |g| dt^2 over the collidable particles).
  double margin = 0.0;
  /// A body's contacts with itself (its surface folding onto itself),
  /// skipping primitives that share a vertex and pairs of triangles already
  /// closer than the thickness in the shape the scene starts from (a
  /// mesh's fissures and creases: pushed apart to the thickness they would
  /// jump at the first frame; SceneInfo::rest_close_triangle_pairs counts
  /// them). Off: bodies collide only with other bodies.
  bool self_collision = true;
  /// Self-collision skips the patches of a surface too flat to touch
  /// themselves: connected through shared vertices, without open edges,
  /// every triangle normal at the frame's start within 30 degrees of one
  /// axis (normal cones, Volino and Magnenat-Thalmann 1994). It assumes no
  /// patch winds over itself like a helical ramp; turn it off for scenes
  /// that may form one (docs/collision.md, mesh collision).
  bool self_culling = true;
  /// The meshes' triangles and thread segments meet the rigid tools
  /// (ToolDesc) too, as they meet the colliders, and their reaction joins
  /// the vertices' on the tool: a thin tool pressed between a coarse
  /// mesh's vertices is held. Off: only vertices meet tools, as without
  /// mesh collision. Measured (docs/collision.md, "Mesh collision"): a 20 g tool on a
  /// virtual coupling in a 2 cm membrane cell is held with faces and passes
  /// through without; a heavy tool (10^4 times a particle) dropped onto a
  /// soft 5 mm block at 20 substeps rests without faces but bounces and
  /// falls through with them (the tool's coupling is explicit, rigid_tool.h).
  bool tool_faces = true;
  /// A capsule (a tool's or a collider's) lying along a triangle meets it
  /// at up to 3 points instead of 1 (a contact manifold): the triangle's
  /// deepest point in it, and the two ends of the part of its axis over
  /// the triangle (the axis projected onto the triangle's plane, clipped
  /// to it), each against the capsule's surface nearest to that point,
  /// where within reach, facing as the deepest point's contact does and a
  /// tenth of the triangle's longest edge apart. With one point a face
  /// pivots about it under a long tool (docs/collision.md, "Contacts that
  /// hold"). Off (the default): the deepest point only. (On, a probe
  /// pushed up under a free membrane with continuous collision needed more
  /// than 12 repair rounds: tests/continuous_collision_test.cpp.)
  bool face_manifold = false;
  double compliance = 0.0;        ///< of each contact [m/N], >= 0
  double static_friction = 0.3;   ///< >= 0
  double dynamic_friction = 0.2;  ///< >= 0, <= static_friction

  /// Continuous collision detection (docs/collision.md): after every
  /// substep's sweeps the host tests the motion the primitives made in it,
  /// from the substep's start to its end, linearly, with the CCD queries of
  /// sinew/ccd.h (no false negatives):
  ///  - each line body's segments against every other segment (skipping
  ///    neighbours, which share a vertex) and every triangle of the tet
  ///    bodies' surfaces and the tri bodies;
  ///  - the axis of every rigid tool and capsule collider (a tool's tip,
  ///    a needle) against those segments and triangles.
  /// Each touch becomes a contact for the rest of the frame (along the
  /// normal the primitives meet along, kept at `thickness`; against a
  /// capsule, its surface), the substep's sweeps run again (`iterations`
  /// more) and the motion is tested again. After `continuous_repairs` such
  /// rounds the fail-safe acts on the pairs that still touch until none
  /// does: tissue against tissue, the moving particles stop where the
  /// substep started (their velocity becomes 0); tissue against a capsule,
  /// they move with it. So a thread never passes through itself, another
  /// thread or a surface, and a tool's axis never through a membrane or a
  /// thread, however fast they move, provided the scene starts with none
  /// through another; the one exception, counted in FrameStats::ccd_forced,
  /// is a tool forcing tissue it carries or pinned tissue through other
  /// tissue (docs/collision.md, "Continuous collision detection"). Costs a read-back
  /// of the positions per substep. Needs ContactSchedule::colored, and
  /// a line body, or a tool or capsule collider and a surface. Surfaces
  /// against surfaces are not tested continuously (the frame's contacts
  /// hold them).
  bool continuous = false;
  /// Repair rounds per substep before the fail-safe stops the touching
  /// particles, >= 0 (0: stop them at once, no repair sweeps).
  int continuous_repairs = 4;
  /// ContactSchedule::device_colored: the most colours, in [1, 128]. Every
  /// colour is a dependent dispatch in every sweep; the contacts that find
  /// all of them taken by neighbours go to the overflow set, solved one by
  /// one (FrameStats::mesh_contact_overflow counts them). The pruned
  /// self-contacts of the bent kidney_57k surface need 39 colours; at 32,
  /// 36 of their 9,031 overflow (benchmarks/contact_coloring_benchmark.cpp).
  std::uint32_t device_colors = 32;
  /// ContactSchedule::device_colored: the colouring's rounds per frame, in
  /// [1, 254] (two dispatches each). A contact is decided in the round
  /// after its last neighbour of higher priority, so a set needs at least
  /// as many rounds as the most contacts on one movable particle; those
  /// still undecided join the overflow set.
  std::uint32_t device_rounds = 128;
};

/// A grasper: jaws that hold whatever vertices they close on
/// (Simulation::close_grasper, move_grasper, open_grasper). Each vertex it
/// holds is attached by a zero-length constraint to its own target, a point
/// fixed in the grasper's frame where the vertex was when the jaws closed;
/// the targets move with the grasper. Each grasper is one colour of
/// `capacity` slots (a vertex held by two graspers is solved twice). Like
/// every attachment, graspers cannot run with solver.warm_start.
struct GrasperDesc {
  std::uint32_t capacity = 64;  ///< the most vertices it holds at once, in [1, 2^20]
  /// The most surface points it holds at once, in [0, 2^20] (0: vertices
  /// only). A surface triangle that crosses the jaws with none of its
  /// vertices inside them (a coarse mesh, jaws closing between vertices)
  /// is held at its point nearest the jaws' centre, through barycentric
  /// weights (Simulation::close_grasper).
  std::uint32_t point_capacity = 16;
  double compliance = 0.0;      ///< of each hold [m/N], >= 0 (0: rigid)
};

/// A tissue surface that holds the scene's fluid and is pushed by it
/// (SceneDesc::fluid): sampled at the fluid's spacing with boundary
/// particles that follow the surface's vertices (Akinci et al., TOG 31(4),
/// 2012; sample_surface), whose push from the fluid goes back to those
/// vertices as forces.
struct FluidSurfaceDesc {
  BodyKind body_kind = BodyKind::tet;  ///< tet or tri
  std::size_t body = 0;                ///< index among the scene's bodies of that kind
  /// Triangles over the body's mesh vertices (e.g. the part of its boundary
  /// that faces the fluid); empty: a tet body's whole boundary surface
  /// (extract_boundary_surface), a tri body's triangles. Sampled once, at
  /// Simulation::create, on the rest mesh: cuts do not resample them.
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// A fluid that runs with the scene, on the Simulation's device, as one
/// stage of its frame (Simulation::fluid()). Each frame, on the device and
/// without the host: the surfaces' boundary particles move to the tissue's
/// positions and velocities at the frame's start, the fluid takes the
/// frame's steps (SolverSettings::time_step / FluidSettings::time_step of
/// them, a whole number), and the impulse J the fluid gave each boundary
/// particle over them becomes a constant force J / frame on its triangle's
/// vertices (by its barycentric weights) for the tissue's frame. So the
/// tissue gains in its frame the momentum the fluid lost to it (up to float
/// rounding; what lands on pinned or kinematic vertices goes to the fixed
/// world). The coupling is explicit, one frame apart: stable while the
/// fluid's push moves the surface by much less than a spacing per frame.
/// Host reads per frame: the fluid's counts and fastest speed (28 bytes).
struct SceneFluidDesc {
  /// The fluid (FluidDesc): its particles, fixed boundary, emitters and
  /// sinks. Its `device` is not used (the scene's runs it); its
  /// moving_boundary and boundary_forces are set when there are surfaces.
  FluidDesc fluid;
  std::vector<FluidSurfaceDesc> surfaces;  ///< may be empty: a fluid held by its fixed boundary only
};

/// A whole scene: its bodies, colliders, tools, interactions and solver
/// settings, in SI units. Simulation::create checks it (errors name the
/// field, e.g. "tet_bodies[0].density") and compiles it onto a device.
struct SceneDesc {
  std::array<double, 3> gravity{0.0, -9.81, 0.0};  ///< [m/s^2]
  SolverSettings solver;                   ///< time step, substeps, iterations, residual mode
  std::vector<TetBodyDesc> tet_bodies;     ///< volumetric tissue (tet meshes)
  std::vector<TriBodyDesc> tri_bodies;     ///< thin tissue: membranes, vessel walls (triangle meshes)
  std::vector<LineBodyDesc> line_bodies;   ///< threads (polylines)
  std::vector<ColliderDesc> colliders;     ///< kinematic shapes (Tools::collider reaches them by index)
  std::vector<std::array<double, 3>> targets;       ///< initial kinematic target positions [m]
  std::vector<AttachmentDesc> attachments; ///< vertices held to targets
  std::vector<BodyAttachmentDesc> body_attachments;  ///< points of two bodies attached to each other
  std::vector<ToolDesc> tools;             ///< rigid tools driven by force
  std::vector<NeedleDesc> needles;         ///< suture needles and their threads
  std::vector<GrasperDesc> graspers;       ///< graspers (Graspers closes them)
  MeshCollisionDesc mesh_collision;  ///< contacts between the bodies' meshes (off by default)
  /// Forces on single particles, set by the host before each frame
  /// (Simulation::set_particle_forces; e.g. a fluid's pressure on tissue,
  /// two-way coupling). A scene pays only for the stages it uses: without
  /// this, the frame program has no force kernel and the device no force
  /// buffer; with it, one dispatch per substep and 16 bytes per particle.
  bool external_forces = false;
  /// Tets, triangles and thread segments removed while the scene runs
  /// (Simulation::remove_tets, remove_triangles, remove_segments, cut_body,
  /// cauterize, the bodies' tear_strain; runtime/topology_editor.h). A
  /// scene pays only for what it uses: with this the Simulation keeps a
  /// host copy of every constraint block (what a removal patches) and the
  /// tet and tri bodies' adjacency; without it those calls are errors.
  bool topology_changes = false;
  /// A fluid coupled with the tissue (SceneFluidDesc); none by default. A
  /// fluid with surfaces gives the scene its force buffer (as
  /// external_forces = true does).
  std::optional<SceneFluidDesc> fluid;
};

/// Checks every parameter of a scene; the first problem found is returned,
/// naming the body and parameter (e.g. "tet_bodies[0].density must be > 0 (got -1)").
Status check_scene(const SceneDesc& scene);

}  // namespace sinew
