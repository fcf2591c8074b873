// scene_compiler.h — turns a SceneDesc into flat arrays ready for a device:
// float4 particles (xyz + inverse mass), and per constraint type a
// structure-of-arrays sorted by colour, with each colour's range.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "backends/kernel.h"
#include "compiler/device_ranges.h"
#include "compiler/particle_order.h"
#include "math/vec4.h"
#include "sinew/scene.h"

namespace sinew {

/// Constraints solved by one kernel (arity particles each), sorted by
/// colour: colour k holds constraints [color_offsets[k], color_offsets[k+1]).
/// The solve kernels' bindings are described in kernels/shared/xpbd_params.h.
/// Scene-wide buffers a solve kernel may bind after its five standard ones.
enum class SceneBuffer {
  previous_position,  ///< float4 per particle: positions at the start of the substep
  colliders,          ///< CompiledScene::colliders (kernels/shared/contact_params.h)
  targets,            ///< CompiledScene::targets (kernels/shared/contact_params.h)
  contact_impulses,   ///< SINEW_CONTACT_IMPULSE_FLOAT4S float4 per particle and tool (see contact_params.h)
  level_set_grids,    ///< CompiledScene::level_set_grids (contact_params.h, binding 8 of the contacts)
};

struct ConstraintBlock {
  Kernel kernel = Kernel::count_;
  std::uint32_t arity = 0;
  std::uint32_t data_stride = 2;          ///< floats of data per constraint
  std::uint32_t lambda_stride = 1;        ///< lambdas per constraint
  std::vector<SceneBuffer> extra_bindings;
  std::vector<std::uint32_t> particles;   ///< arity per constraint
  std::vector<float> data;                ///< data_stride per constraint, e.g. (rest value, compliance alpha)
  std::vector<std::uint32_t> color_offsets{0};
  /// Constraints in use at the start of each colour (colour k solves
  /// [color_offsets[k], color_offsets[k] + color_counts[k])); empty: every
  /// slot. Topology changes (runtime/topology_editor.h) remove a constraint
  /// by moving its colour's last one into its slot, so a colour keeps its
  /// capacity and its constraints stay independent.
  std::vector<std::uint32_t> color_counts;
  /// Constraint damping time tau [s] of its bodies (SolveParams::damping =
  /// tau / h): bodies with different taus get different blocks.
  double damping_time = 0.0;
  [[nodiscard]] std::uint32_t size() const { return arity ? static_cast<std::uint32_t>(particles.size() / arity) : 0; }
  [[nodiscard]] std::uint32_t colors() const { return static_cast<std::uint32_t>(color_offsets.size() - 1); }
  /// Constraints in use (the sum of color_count): what the residuals'
  /// RMS divides by, after topology changes or in a grasper's block.
  [[nodiscard]] std::uint32_t in_use() const {
    std::uint32_t n = 0;
    for (std::size_t k = 0; k < colors(); ++k) n += color_count(k);
    return n;
  }
  /// Constraints colour k solves (see color_counts).
  [[nodiscard]] std::uint32_t color_count(std::size_t k) const {
    return color_counts.empty() ? color_offsets[k + 1] - color_offsets[k] : color_counts[k];
  }
};

/// The constraints of one kernel before colouring.
struct RawConstraints {
  Kernel kernel;
  std::uint32_t arity;
  std::uint32_t data_stride = 2;
  std::uint32_t lambda_stride = 1;
  std::vector<SceneBuffer> extra_bindings = {};
  std::vector<std::uint32_t> particles = {};
  std::vector<float> data = {};
  double damping_time = 0.0;  ///< see ConstraintBlock::damping_time
};

struct CompiledScene {
  std::vector<kernels::float4> positions;  ///< xyz [m], w = inverse mass [1/kg]
  /// Solved in this order (kSolveOrder, solve_order.h) in every
  /// iteration; there are no empty blocks.
  std::vector<ConstraintBlock> blocks;
  /// Scene-wide buffers that blocks bind (SceneBuffer), as uploaded; the
  /// Simulation rewrites colliders and targets between frames.
  std::vector<float> colliders;
  std::vector<float> targets;
  /// Every level-set collider's and level-set tool's NanoVDB grid, each at
  /// a 32-byte aligned offset (level_set_offsets [bytes], in
  /// SceneDesc::colliders order, then SceneDesc::tools; 0 for the other
  /// shapes), as 32-bit words.
  std::vector<std::uint32_t> level_set_grids;
  std::vector<std::uint64_t> level_set_offsets;
  std::uint32_t contact_impulse_slots = 0;  ///< float4s in the contact_impulses buffer
  /// Per particle (device order), the factor its velocity is multiplied by
  /// each substep, exp(-k h) for its body's velocity_damping k (1: none);
  /// uploaded as the velocity buffer's w (xpbd_params.h, xpbd_predict).
  std::vector<float> velocity_damping;
  /// SceneDesc::external_forces: the program applies a force buffer
  /// (xpbd_external_force) before every substep's predict.
  bool external_forces = false;
  /// Per SceneDesc::graspers entry: its block (one colour, no constraint in
  /// use until it closes) and its first target (its capacity follow, after
  /// SceneDesc::targets); and the same for its surface points
  /// (xpbd_solve_point_attachment; UINT32_MAX for a point_capacity of 0).
  std::vector<std::uint32_t> grasper_block, grasper_first_target;
  std::vector<std::uint32_t> grasper_point_block, grasper_point_first_target;
  std::vector<std::uint32_t> tet_body_first_particle;
  std::vector<std::uint32_t> tri_body_first_particle;
  std::vector<std::uint32_t> line_body_first_particle;
  /// Where each particle lives on the device (particle_order.h): every
  /// buffer above is in device order, the *_first_particle ranges and the
  /// public API in the user's.
  ParticleOrder order;
};

/// What each feature's compile step adds to: particles, their masses and
/// raw constraints. scene_compiler.cpp drives the steps, then colours every
/// block and sets the inverse masses.
struct SceneBuilder {
  std::vector<kernels::float4> positions;  ///< w is set at the end, from mass
  std::vector<double> mass;                ///< [kg]; 0 = immovable (pinned, kinematic)
  std::deque<RawConstraints> raw;          ///< one per kernel and damping time (a deque: references stay valid)
  /// Bodies that start away from their rest shape: (first particle, start
  /// positions), applied after every rest value has been computed.
  std::vector<std::pair<std::uint32_t, const std::vector<Vec3d>*>> initial;

  double substep = 0.0;  ///< h [s], for the velocity damping factors
  DeviceStep step;       ///< h and 1/h^2 as the device's floats, for check_device_compliance
  /// Appends vertices as particles of mass 0 and velocity damping `k`
  /// [1/s] (factor exp(-k h) per substep); returns the first one's index.
  std::uint32_t add_vertices(const std::vector<Vec3d>& vertices, double velocity_damping);
  /// The raw constraints of `kernel` (and `damping_time`), made with this
  /// layout on first use.
  RawConstraints& constraints(Kernel kernel, std::uint32_t arity, std::uint32_t data_stride = 2,
                              std::uint32_t lambda_stride = 1, std::vector<SceneBuffer> extra_bindings = {},
                              double damping_time = 0.0);
  /// Distance and volume constraints of bodies with constraint damping time
  /// tau [s] (they bind the substep's start positions, see xpbd_params.h).
  RawConstraints& distance_constraints(double damping_time);
  RawConstraints& volume_constraints(double damping_time);
  /// Velocity damping factor per substep of each particle (1: none).
  std::vector<float> velocity_damping;
};

// The compile steps of each feature, each in its own file. `first` is the
// particle index of the body's vertex 0; `name` prefixes error messages
// (e.g. "tet_bodies[2]").

/// scene_compiler.cpp: distance and volume constraints, lumped masses.
Status add_tet_body(SceneBuilder& b, const TetBodyDesc& body, const std::string& name);
Status add_line_body(SceneBuilder& b, const LineBodyDesc& body, const std::string& name);
/// compile_fem.cpp: the two FEM constraints per tet (TetBodyDesc::material).
Status add_fem_constraints(SceneBuilder& b, const TetBodyDesc& body, std::uint32_t first, const std::string& name);
/// compile_thin.cpp: triangle bodies, and bending of line bodies.
Status add_tri_body(SceneBuilder& b, const TriBodyDesc& body, const std::string& name);
Status add_line_bending(SceneBuilder& b, const LineBodyDesc& body, std::uint32_t first, const std::string& name);
/// compile_contacts.cpp: colliders, tools, attachments (after all bodies).
Status add_contacts(SceneBuilder& b, const SceneDesc& scene, CompiledScene& out);

/// SceneDesc::fluid's parameters beyond FluidDesc's (the surfaces' bodies
/// and triangles, the frame a whole number of fluid steps); part of
/// check_scene (fluid_checks.cpp).
Status check_scene_fluid(const SceneDesc& scene);

/// The vertices of the body `ref` names (its vertex is not read), or 0 when
/// the scene has no such body (scene_checks.cpp).
std::size_t vertex_count(const SceneDesc& scene, const VertexRef& ref);

/// SceneDesc::body_attachments' parameters (BodyAttachmentDesc); part of
/// check_scene (body_attachment_checks.cpp).
Status check_body_attachments(const SceneDesc& scene);

/// What a scene may hold with SolverSettings::method = vbd; part of
/// check_scene (vbd_checks.cpp). Errors name the unsupported feature.
Status check_vbd_scene(const SceneDesc& scene);

/// Checks (check_scene) and compiles a scene. Errors name the parameter.
Result<CompiledScene> compile_scene(const SceneDesc& scene);

}  // namespace sinew
