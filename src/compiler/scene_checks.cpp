// scene_checks.cpp — parameter checks for SceneDesc. Every message names the
// parameter path and the offending value so a user can fix the scene.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "compiler/device_ranges.h"
#include "compiler/edge_network.h"
#include "contact_params.h"
#include "math/vec3.h"
#include "compiler/scene_compiler.h"
#include "sinew/scene.h"

namespace sinew {

std::string number_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::size_t vertex_count(const SceneDesc& scene, const VertexRef& ref) {
  switch (ref.body_kind) {
    case BodyKind::tet: return ref.body < scene.tet_bodies.size() ? scene.tet_bodies[ref.body].mesh.vertices.size() : 0;
    case BodyKind::tri: return ref.body < scene.tri_bodies.size() ? scene.tri_bodies[ref.body].mesh.vertices.size() : 0;
    case BodyKind::line: return ref.body < scene.line_bodies.size() ? scene.line_bodies[ref.body].vertices.size() : 0;
  }
  return 0;
}

namespace {

std::string str(double v) { return number_text(v); }

Status positive(const std::string& name, double v) {
  if (!std::isfinite(v) || v <= 0.0)
    return Error(ErrorCode::bad_parameter, name + " must be finite and > 0 (got " + str(v) + ")");
  return {};
}

Status non_negative(const std::string& name, double v) {
  if (!std::isfinite(v) || v < 0.0)
    return Error(ErrorCode::bad_parameter, name + " must be finite and >= 0 (got " + str(v) + ")");
  return {};
}

Status check_elastic(const std::string& prefix, double young, double poisson) {
  if (Status s = positive(prefix + "youngs_modulus", young); !s) return s;
  if (!std::isfinite(poisson) || poisson <= -1.0 || poisson >= 0.5)
    return Error(ErrorCode::bad_parameter, prefix + "poisson_ratio must be in (-1, 0.5) (got " + str(poisson) + ")");
  return {};
}

Status check_initial(const std::string& name, const std::vector<Vec3d>& initial, std::size_t vertex_count) {
  if (initial.empty()) return {};
  if (initial.size() != vertex_count)
    return Error(ErrorCode::bad_parameter,
                 name + ".initial_vertices has " + std::to_string(initial.size()) + " entries for " +
                 std::to_string(vertex_count) + " vertices");
  for (std::size_t i = 0; i < initial.size(); ++i)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(initial[i][k]))
        return Error(ErrorCode::bad_parameter, name + ".initial_vertices[" + std::to_string(i) + "] is not finite");
  return {};
}

Status check_pinned(const std::string& body, const std::vector<std::uint32_t>& pinned, std::size_t vertex_count) {
  for (std::size_t i = 0; i < pinned.size(); ++i)
    if (pinned[i] >= vertex_count)
      return Error(ErrorCode::bad_parameter,
                   body + ".pinned[" + std::to_string(i) + "] = " + std::to_string(pinned[i]) +
                   " is not a vertex (the body has " + std::to_string(vertex_count) + ")");
  return {};
}

// Both damping parameters: finite and >= 0 (no silent clamp of a negative
// damping, which would add energy).
Status check_damping(const std::string& name, double velocity_damping, double stiffness_damping) {
  if (Status s = non_negative(name + ".velocity_damping", velocity_damping); !s) return s;
  return non_negative(name + ".stiffness_damping", stiffness_damping);
}

Status check_tet_body(const TetBodyDesc& b, const std::string& name) {
  if (Status s = check_tet_mesh(b.mesh, name + ".mesh"); !s) return s;
  if (Status s = positive(name + ".density", b.density); !s) return s;
  if (Status s = non_negative(name + ".distance_compliance", b.distance_compliance); !s) return s;
  if (Status s = non_negative(name + ".volume_compliance", b.volume_compliance); !s) return s;
  if (Status s = check_damping(name, b.velocity_damping, b.stiffness_damping); !s) return s;
  if (b.material != TetMaterial::none || (b.calibrated_network && (b.distance_constraints || b.volume_constraints)))
    if (Status s = check_elastic(name + ".", b.youngs_modulus, b.poisson_ratio); !s) return s;
  if (Status s = check_initial(name, b.initial_vertices, b.mesh.vertices.size()); !s) return s;
  return check_pinned(name, b.pinned, b.mesh.vertices.size());
}

Status check_line_body(const LineBodyDesc& b, const std::string& name) {
  const std::size_t n = b.vertices.size();
  if (n == 0) return Error(ErrorCode::bad_parameter, name + ".vertices is empty");
  if (Status s = check_damping(name, b.velocity_damping, b.stiffness_damping); !s) return s;
  if (b.masses.size() != n)
    return Error(ErrorCode::bad_parameter,
                 name + ".masses has " + std::to_string(b.masses.size()) + " entries for " + std::to_string(n) +
                 " vertices");
  for (std::size_t i = 0; i < n; ++i) {
    for (double c : b.vertices[i])
      if (!std::isfinite(c))
        return Error(ErrorCode::bad_parameter, name + ".vertices[" + std::to_string(i) + "] is not finite");
    if (Status s = positive(name + ".masses[" + std::to_string(i) + "]", b.masses[i]); !s) return s;
  }
  for (std::size_t i = 0; i < b.segments.size(); ++i) {
    const auto [a, c] = b.segments[i];
    const std::string seg = name + ".segments[" + std::to_string(i) + "]";
    if (a >= n || c >= n)
      return Error(ErrorCode::bad_parameter,
                   seg + " = (" + std::to_string(a) + ", " + std::to_string(c) + ") refers past the " +
                   std::to_string(n) + " vertices");
    const Vec3d& p = b.vertices[a];
    const Vec3d& q = b.vertices[c];
    const double len = std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
    if (!(len > 0.0)) return Error(ErrorCode::bad_parameter, seg + " has zero rest length");
  }
  if (Status s = non_negative(name + ".compliance", b.compliance); !s) return s;
  if (std::isnan(b.bending_compliance)) return Error(ErrorCode::bad_parameter, name + ".bending_compliance is NaN");
  if (Status s = check_initial(name, b.initial_vertices, n); !s) return s;
  return check_pinned(name, b.pinned, n);
}

Status finite3(const std::string& name, const std::array<double, 3>& v) {
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(v[k]))
      return Error(ErrorCode::bad_parameter,
                   name + "[" + std::to_string(k) + "] must be finite (got " + str(v[k]) + ")");
  return {};
}

Status unit_quaternion(const std::string& name, const std::array<double, 4>& q) {
  const double n = math::qnorm(q);
  if (!std::isfinite(n) || std::abs(n - 1.0) > 1e-6)
    return Error(ErrorCode::bad_parameter,
                 name + " must be a unit quaternion (w, x, y, z) (its norm is " + str(n) + ")");
  return {};
}

Status check_friction(const std::string& name, double mu_s, double mu_k) {
  if (Status s = non_negative(name + ".static_friction", mu_s); !s) return s;
  if (Status s = non_negative(name + ".dynamic_friction", mu_k); !s) return s;
  if (mu_k > mu_s)
    return Error(ErrorCode::bad_parameter,
                 name + ".dynamic_friction (" + str(mu_k) + ") must not exceed static_friction (" + str(mu_s) + ")");
  return {};
}

Status check_tri_body(const TriBodyDesc& b, const std::string& name) {
  const std::size_t n = b.mesh.vertices.size();
  if (b.mesh.triangles.empty()) return Error(ErrorCode::bad_parameter, name + ".mesh has no triangles");
  for (std::size_t i = 0; i < n; ++i)
    if (Status s = finite3(name + ".mesh.vertices[" + std::to_string(i) + "]", b.mesh.vertices[i]); !s) return s;
  for (std::size_t t = 0; t < b.mesh.triangles.size(); ++t) {
    const auto& tri = b.mesh.triangles[t];
    const std::string where = name + ".mesh.triangles[" + std::to_string(t) + "]";
    for (std::uint32_t v : tri)
      if (v >= n)
        return Error(ErrorCode::bad_parameter,
                     where + " refers to vertex " + std::to_string(v) + " of " + std::to_string(n));
    const Vec3d& p = b.mesh.vertices[tri[0]];
    const Vec3d& q = b.mesh.vertices[tri[1]];
    const Vec3d& r = b.mesh.vertices[tri[2]];
    const Vec3d u = math::sub(q, p), w = math::sub(r, p), normal = math::cross(u, w);
    const double area = 0.5 * std::hypot(normal[0], normal[1], normal[2]);
    const double scale = std::max({std::hypot(u[0], u[1], u[2]), std::hypot(w[0], w[1], w[2])});
    if (!(area > 1e-12 * scale * scale))
      return Error(ErrorCode::bad_parameter, where + " has zero area (degenerate triangle)");
  }
  if (Status s = positive(name + ".thickness", b.thickness); !s) return s;
  if (Status s = positive(name + ".density", b.density); !s) return s;
  if (Status s = non_negative(name + ".distance_compliance", b.distance_compliance); !s) return s;
  if (Status s = non_negative(name + ".area_compliance", b.area_compliance); !s) return s;
  if (Status s = check_damping(name, b.velocity_damping, b.stiffness_damping); !s) return s;
  if (std::isnan(b.bending_compliance)) return Error(ErrorCode::bad_parameter, name + ".bending_compliance is NaN");
  if (Status s = check_initial(name, b.initial_vertices, n); !s) return s;
  return check_pinned(name, b.pinned, n);
}

// The dimensions a shape needs, for colliders and implicit nodes alike.
enum class Dims { none, sphere, capsule, cylinder, box, torus };
Status check_dims(const std::string& name, Dims kind, double radius, double half_height,
                  const std::array<double, 3>& half_extents, double minor_radius) {
  if (kind == Dims::none) return {};
  if (kind == Dims::box) {
    for (int a = 0; a < 3; ++a)
      if (Status s = positive(name + ".half_extents[" + std::to_string(a) + "]", half_extents[a]); !s) return s;
    return {};
  }
  if (Status s = positive(name + ".radius", radius); !s) return s;
  if (kind == Dims::capsule) return non_negative(name + ".half_height", half_height);
  if (kind == Dims::cylinder) return positive(name + ".half_height", half_height);
  if (kind == Dims::torus) return positive(name + ".minor_radius", minor_radius);
  return {};
}

// An implicit shape: every node's values, and a postfix expression that
// never pops an empty stack, never holds more than the kernels' stack, and
// leaves exactly one value.
Status check_implicit(const std::vector<ImplicitNode>& nodes, const std::string& name) {
  if (nodes.empty()) return Error(ErrorCode::bad_parameter, name + " is empty (an implicit collider needs nodes)");
  if (nodes.size() > SINEW_IMPLICIT_MAX_NODES)
    return Error(ErrorCode::bad_parameter, name + " has " + std::to_string(nodes.size()) + " nodes, more than the " +
                                               std::to_string(SINEW_IMPLICIT_MAX_NODES) + " the kernels evaluate");
  int depth = 0;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const ImplicitNode& n = nodes[k];
    const std::string at = name + "[" + std::to_string(k) + "]";
    const bool operation = n.op == ImplicitOp::unite || n.op == ImplicitOp::intersect || n.op == ImplicitOp::subtract;
    if (operation) {
      if (depth < 2)
        return Error(ErrorCode::bad_parameter,
                     at + " is an operation with " + std::to_string(depth) + " value(s) before it (it needs two; postfix order)");
      --depth;
      continue;
    }
    if (++depth > SINEW_IMPLICIT_STACK)
      return Error(ErrorCode::bad_parameter, at + " makes " + std::to_string(depth) + " values pending at once, more than the " +
                                                 std::to_string(SINEW_IMPLICIT_STACK) + " the kernels hold (combine earlier)");
    if (Status s = finite3(at + ".position", n.position); !s) return s;
    if (Status s = unit_quaternion(at + ".rotation", n.rotation); !s) return s;
    if (Status s = non_negative(at + ".rounding", n.rounding); !s) return s;
    const Dims dims = n.op == ImplicitOp::sphere     ? Dims::sphere
                      : n.op == ImplicitOp::capsule  ? Dims::capsule
                      : n.op == ImplicitOp::cylinder ? Dims::cylinder
                      : n.op == ImplicitOp::box      ? Dims::box
                      : n.op == ImplicitOp::torus    ? Dims::torus
                                                     : Dims::none;  // half_space: the pose only
    if (Status s = check_dims(at, dims, n.radius, n.half_height, n.half_extents, n.minor_radius); !s) return s;
  }
  if (depth != 1)
    return Error(ErrorCode::bad_parameter, name + " leaves " + std::to_string(depth) +
                                               " values (a postfix expression leaves one: combine them with unite, "
                                               "intersect or subtract)");
  return {};
}

Status check_collider(const ColliderDesc& c, const std::string& name) {
  if (Status s = finite3(name + ".position", c.position); !s) return s;
  if (Status s = unit_quaternion(name + ".rotation", c.rotation); !s) return s;
  const Dims dims = c.shape == ColliderShape::sphere     ? Dims::sphere
                    : c.shape == ColliderShape::capsule  ? Dims::capsule
                    : c.shape == ColliderShape::cylinder ? Dims::cylinder
                    : c.shape == ColliderShape::box      ? Dims::box
                                                         : Dims::none;
  if (Status s = check_dims(name, dims, c.radius, c.half_height, c.half_extents, 0.0); !s) return s;
  if (c.shape == ColliderShape::implicit) {
    if (Status s = check_implicit(c.implicit, name + ".implicit"); !s) return s;
  } else if (!c.implicit.empty())
    return Error(ErrorCode::bad_parameter, name + ".implicit has nodes but the shape is not ColliderShape::implicit");
  if (c.shape == ColliderShape::level_set) {
    if (!c.level_set)
      return Error(ErrorCode::bad_parameter, name + ".level_set is missing (ColliderShape::level_set needs one)");
    if (c.level_set->nanovdb_bytes().empty())
      return Error(ErrorCode::backend_unavailable, name + ".level_set has no grid (sinew was built without OpenVDB)");
  } else if (c.level_set) {
    return Error(ErrorCode::bad_parameter, name + ".level_set is set but the shape is not ColliderShape::level_set");
  }
  if (Status s = check_friction(name, c.static_friction, c.dynamic_friction); !s) return s;
  return non_negative(name + ".compliance", c.compliance);
}

// A trocar: a finite pivot, a finite non-zero axis, and the tool's initial
// shaft line through the pivot within kTrocarPoseTolerance (scene.h).
Status check_trocar(const TrocarDesc& t, const Vec3d& position, const std::array<double, 4>& rotation,
                    const std::string& name) {
  if (Status s = finite3(name + ".pivot", t.pivot); !s) return s;
  if (Status s = finite3(name + ".axis", t.axis); !s) return s;
  const double length = std::sqrt(math::dot(t.axis, t.axis));
  if (!(length > 0.0) || !std::isfinite(length))
    return Error(ErrorCode::bad_parameter, name + ".axis must be non-zero (the shaft's direction in the tool frame)");
  const Vec3d u = math::rotate(rotation, math::mul(t.axis, 1.0 / length));
  const Vec3d to_pivot = math::sub(t.pivot, position);
  const Vec3d across = math::sub(to_pivot, math::mul(u, math::dot(u, to_pivot)));
  const double miss = std::sqrt(math::dot(across, across));
  if (!(miss <= kTrocarPoseTolerance))
    return Error(ErrorCode::bad_parameter,
                 name + ": the tool's initial shaft line (position + rotation * axis * s) passes " + str(miss) +
                     " m from the pivot; it must pass within " + str(kTrocarPoseTolerance) +
                     " m (place the tool on the line through the pivot)");
  return {};
}

Status check_tool(const ToolDesc& t, const std::string& name) {
  if (t.shape == ToolShape::capsule) {
    if (Status s = positive(name + ".radius", t.radius); !s) return s;
    if (Status s = non_negative(name + ".half_height", t.half_height); !s) return s;
    if (t.level_set)
      return Error(ErrorCode::bad_parameter, name + ".level_set is set but the shape is not ToolShape::level_set");
  } else {
    if (!t.level_set)
      return Error(ErrorCode::bad_parameter, name + ".level_set is missing (ToolShape::level_set needs one)");
    if (t.level_set->nanovdb_bytes().empty())
      return Error(ErrorCode::backend_unavailable, name + ".level_set has no grid (sinew was built without OpenVDB)");
    if (Status s = positive(name + ".penalty_stiffness", t.penalty_stiffness); !s) return s;
    if (Status s = non_negative(name + ".penalty_damping", t.penalty_damping); !s) return s;
  }
  if (Status s = positive(name + ".mass", t.mass); !s) return s;
  for (int k = 0; k < 3; ++k)
    if (Status s = positive(name + ".inertia[" + std::to_string(k) + "]", t.inertia[k]); !s) return s;
  if (Status s = finite3(name + ".position", t.position); !s) return s;
  if (Status s = unit_quaternion(name + ".rotation", t.rotation); !s) return s;
  if (Status s = check_friction(name, t.static_friction, t.dynamic_friction); !s) return s;
  if (Status s = non_negative(name + ".compliance", t.compliance); !s) return s;
  if (!t.trocar) return {};
  return check_trocar(*t.trocar, t.position, t.rotation, name + ".trocar");
}

// A cutting tool's collider is a level set, and its cutter has a size.
Status check_tool_cut(const SceneDesc& scene, const ToolCutDesc& cut, const std::string& name) {
  if (cut.collider >= scene.colliders.size())
    return Error(ErrorCode::bad_parameter, name + ".collider: collider " + std::to_string(cut.collider) +
                                               " does not exist (the scene has " +
                                               std::to_string(scene.colliders.size()) + ")");
  if (scene.colliders[cut.collider].shape != ColliderShape::level_set)
    return Error(ErrorCode::bad_parameter, name + ".collider: collider " + std::to_string(cut.collider) +
                                               " is not a level set (only a level set can be cut)");
  const CutterShape& c = cut.cutter;
  if (c.kind == CutterShape::Kind::box) {
    for (int k = 0; k < 3; ++k)
      if (Status s = positive(name + ".cutter.half_extents[" + std::to_string(k) + "]", c.half_extents[k]); !s)
        return s;
    return {};
  }
  if (Status s = positive(name + ".cutter.radius", c.radius); !s) return s;
  if (c.kind == CutterShape::Kind::capsule) return non_negative(name + ".cutter.half_height", c.half_height);
  return {};
}

// The blunt tip, the shaft's Karnopp friction and the cutting force (docs/needles.md).
Status check_needle_forces(const NeedleDesc& n, const std::string& name) {
  if (Status s = non_negative(name + ".tip_radius", n.tip_radius); !s) return s;
  if (Status s = non_negative(name + ".shaft_friction", n.shaft_friction); !s) return s;
  if (Status s = non_negative(name + ".shaft_static_friction", n.shaft_static_friction); !s) return s;
  if (n.shaft_friction > n.shaft_static_friction)
    return Error(ErrorCode::bad_parameter, name + ".shaft_friction (" + str(n.shaft_friction) +
                                               " N/m) must not exceed shaft_static_friction (" +
                                               str(n.shaft_static_friction) + " N/m)");
  if (Status s = non_negative(name + ".shaft_viscous_friction", n.shaft_viscous_friction); !s) return s;
  if (Status s = positive(name + ".shaft_stick_velocity", n.shaft_stick_velocity); !s) return s;
  return non_negative(name + ".cutting_force", n.cutting_force);
}

Status check_needle(const SceneDesc& scene, const NeedleDesc& n, const std::string& name) {
  if (n.curve.size() < 2)
    return Error(ErrorCode::bad_parameter,
                 name + ".curve must have at least 2 points (tail to tip), got " + std::to_string(n.curve.size()));
  for (std::size_t k = 0; k < n.curve.size(); ++k) {
    if (Status s = finite3(name + ".curve[" + std::to_string(k) + "]", n.curve[k]); !s) return s;
    if (k > 0 && n.curve[k] == n.curve[k - 1])
      return Error(ErrorCode::bad_parameter, name + ".curve[" + std::to_string(k) + "] repeats the point before it "
                                                    "(a segment of zero length has no direction)");
  }
  if (Status s = finite3(name + ".position", n.position); !s) return s;
  if (Status s = unit_quaternion(name + ".rotation", n.rotation); !s) return s;
  if (Status s = positive(name + ".puncture_force", n.puncture_force); !s) return s;
  if (!(n.max_puncture_angle > 0.0 && n.max_puncture_angle <= M_PI / 2))
    return Error(ErrorCode::bad_parameter,
                 name + ".max_puncture_angle must be in (0, pi/2] radians (got " + str(n.max_puncture_angle) + ")");
  if (Status s = non_negative(name + ".compliance", n.compliance); !s) return s;
  if (Status s = check_friction(name + ".thread", n.thread_static_friction, n.thread_dynamic_friction); !s) return s;
  if (Status s = check_needle_forces(n, name); !s) return s;
  if (n.thread < -1 || n.thread >= static_cast<int>(scene.line_bodies.size()))
    return Error(ErrorCode::bad_parameter, name + ".thread = " + std::to_string(n.thread) +
                                               " is not a line body (the scene has " +
                                               std::to_string(scene.line_bodies.size()) + "; -1 for none)");
  if (n.drive != NeedleDrive::kinematic && n.drive != NeedleDrive::force)
    return Error(ErrorCode::bad_parameter, name + ".drive is neither kinematic nor force");
  if (n.drive == NeedleDrive::force) {
    if (Status s = positive(name + ".mass", n.mass); !s) return s;
    for (int k = 0; k < 3; ++k)
      if (Status s = positive(name + ".inertia[" + std::to_string(k) + "]", n.inertia[k]); !s) return s;
  }
  for (std::size_t other = 0; n.thread >= 0 && &scene.needles[other] != &n; ++other)
    if (scene.needles[other].thread == n.thread)
      return Error(ErrorCode::bad_parameter, name + ".thread = " + std::to_string(n.thread) +
                                                 " is already needles[" + std::to_string(other) + "]'s thread");
  return {};
}

Status check_attachment(const SceneDesc& scene, const AttachmentDesc& a, const std::string& name) {
  const std::size_t n = vertex_count(scene, a.vertex);
  if (n == 0)
    return Error(ErrorCode::bad_parameter,
                 name + ".vertex refers to body " + std::to_string(a.vertex.body) + ", which does not exist");
  if (a.vertex.vertex >= n)
    return Error(ErrorCode::bad_parameter,
                 name + ".vertex.vertex = " + std::to_string(a.vertex.vertex) + " is not a vertex (the body has " +
                 std::to_string(n) + ")");
  if (a.target >= scene.targets.size())
    return Error(ErrorCode::bad_parameter,
                 name + ".target = " + std::to_string(a.target) + " is not a target (the scene has " +
                 std::to_string(scene.targets.size()) + ")");
  return non_negative(name + ".compliance", a.compliance);
}

Status check_mesh_collision(const SceneDesc& scene) {
  const MeshCollisionDesc& c = scene.mesh_collision;
  if (!c.enabled) return {};
  if (Status s = positive("mesh_collision.thickness", c.thickness); !s) return s;
  if (Status s = non_negative("mesh_collision.margin", c.margin); !s) return s;
  if (Status s = non_negative("mesh_collision.compliance", c.compliance); !s) return s;
  if (Status s = check_friction("mesh_collision", c.static_friction, c.dynamic_friction); !s) return s;
  // The accelerator extrapolates positions and the blocks' multipliers;
  // the contacts' multipliers are not part of its state, and an
  // extrapolation could push a contact through.
  if (scene.solver.chebyshev_rho > 0.0)
    return Error(ErrorCode::bad_parameter,
                 "mesh_collision.enabled is not supported with solver.chebyshev_rho > 0 (got " +
                     str(scene.solver.chebyshev_rho) + ")");
  if (c.device_colors < 1 || c.device_colors > 128)
    return Error(ErrorCode::bad_parameter,
                 "mesh_collision.device_colors must be in [1, 128] (got " + std::to_string(c.device_colors) + ")");
  if (c.device_rounds < 1 || c.device_rounds > 254)
    return Error(ErrorCode::bad_parameter,
                 "mesh_collision.device_rounds must be in [1, 254] (got " + std::to_string(c.device_rounds) + ")");
  if (!c.continuous) return {};
  if (c.continuous_repairs < 0)
    return Error(ErrorCode::bad_parameter,
                 "mesh_collision.continuous_repairs must be >= 0 (got " + std::to_string(c.continuous_repairs) + ")");
  // CCD contacts join the frame's in colours of their own, appended mid-frame.
  if (c.schedule == ContactSchedule::device_colored)
    return Error(ErrorCode::bad_parameter,
                 "mesh_collision.continuous is not supported with mesh_collision.schedule = "
                 "ContactSchedule::device_colored (continuous collision's contacts are coloured on the host); "
                 "use ContactSchedule::colored");
  if (c.schedule != ContactSchedule::colored)
    return Error(ErrorCode::bad_parameter,
                 "mesh_collision.continuous needs mesh_collision.schedule = ContactSchedule::colored");
  // What is tested: threads against anything, tools' and capsule colliders' axes against surfaces.
  bool capsules = false;
  for (const ToolDesc& tool : scene.tools) capsules |= tool.shape == ToolShape::capsule;
  for (const ColliderDesc& collider : scene.colliders) capsules |= collider.shape == ColliderShape::capsule;
  const bool surfaces = !scene.tet_bodies.empty() || !scene.tri_bodies.empty();
  if (scene.line_bodies.empty() && !(capsules && surfaces))
    return Error(ErrorCode::bad_parameter,
                 "mesh_collision.continuous tests thread segments (line bodies), and tools and capsule colliders "
                 "against surfaces; the scene has neither");
  return {};
}

}  // namespace

Status TetBodyDesc::set_elastic(double young, double poisson) {
  if (Status s = check_elastic("", young, poisson); !s) return s;
  if (poisson < kNetworkMinPoisson)
    return Error(ErrorCode::bad_parameter,
                 "poisson_ratio below " + str(kNetworkMinPoisson) + " (got " + str(poisson) +
                     ") cannot be reached by a distance + volume network (its springs are central forces); "
                     "use set_material for a lower Poisson's ratio");
  youngs_modulus = young;
  poisson_ratio = poisson;
  calibrated_network = true;
  return {};
}

Status TetBodyDesc::set_material(TetMaterial model, double young, double poisson) {
  if (Status s = check_elastic("", young, poisson); !s) return s;
  material = model;
  youngs_modulus = young;
  poisson_ratio = poisson;
  distance_constraints = false;
  volume_constraints = false;
  return {};
}

// The residual-driven mode and the Chebyshev accelerator (scene.h).
static Status check_solve_modes(const SolverSettings& solver) {
  if (solver.method != SolverMethod::xpbd && solver.method != SolverMethod::vbd)
    return Error(ErrorCode::bad_parameter, "solver.method must be xpbd or vbd (got " +
                                               std::to_string(static_cast<int>(solver.method)) + ")");
  if (Status s = non_negative("solver.residual_tolerance", solver.residual_tolerance); !s) return s;
  if (solver.residual_tolerance > 0.0) {
    if (solver.max_iterations < solver.iterations)
      return Error(ErrorCode::bad_parameter, "solver.max_iterations must be >= solver.iterations (" +
                                                 std::to_string(solver.iterations) + ") in residual mode (got " +
                                                 std::to_string(solver.max_iterations) + ")");
    if (solver.check_interval < 1)
      return Error(ErrorCode::bad_parameter,
                   "solver.check_interval must be >= 1 (got " + std::to_string(solver.check_interval) + ")");
    if (Status s = non_negative("solver.time_budget_ms", solver.time_budget_ms); !s) return s;
  }
  if (solver.warm_start && solver.residual_tolerance <= 0.0)
    return Error(ErrorCode::bad_parameter,
                 "solver.warm_start needs the residual-driven mode (solver.residual_tolerance > 0): with a fixed "
                 "number of unconverged sweeps the carried lambdas can oscillate and diverge on stiff bodies");
  if (!std::isfinite(solver.chebyshev_rho) || solver.chebyshev_rho < 0.0 || solver.chebyshev_rho >= 1.0)
    return Error(ErrorCode::bad_parameter,
                 "solver.chebyshev_rho must be in [0, 1) (got " + str(solver.chebyshev_rho) + ")");
  if (solver.chebyshev_rho > 0.0) {
    if (solver.warm_start)
      return Error(ErrorCode::bad_parameter,
                   "solver.chebyshev_rho must be 0 with solver.warm_start (got " + str(solver.chebyshev_rho) +
                   "): extrapolating from the warm start diverged on a stiff cantilever (tests/stiffness_test.cpp)");
    if (!std::isfinite(solver.chebyshev_gamma) || solver.chebyshev_gamma <= 0.0 || solver.chebyshev_gamma > 1.0)
      return Error(ErrorCode::bad_parameter,
                   "solver.chebyshev_gamma must be in (0, 1] (got " + str(solver.chebyshev_gamma) + ")");
    if (solver.chebyshev_delay < 2)
      return Error(ErrorCode::bad_parameter,
                   "solver.chebyshev_delay must be >= 2 (got " + std::to_string(solver.chebyshev_delay) + ")");
  }
  return {};
}

Status check_scene(const SceneDesc& scene) {
  if (Status s = finite3("gravity", scene.gravity); !s) return s;
  if (Status s = positive("solver.time_step", scene.solver.time_step); !s) return s;
  if (scene.solver.substeps < 1)
    return Error(ErrorCode::bad_parameter,
                 "solver.substeps must be >= 1 (got " + std::to_string(scene.solver.substeps) + ")");
  if (scene.solver.iterations < 1)
    return Error(ErrorCode::bad_parameter,
                 "solver.iterations must be >= 1 (got " + std::to_string(scene.solver.iterations) + ")");
  if (Status s = check_solve_modes(scene.solver); !s) return s;
  if (scene.solver.contact_sweeps < 0)
    return Error(ErrorCode::bad_parameter,
                 "solver.contact_sweeps must be >= 0 (got " + std::to_string(scene.solver.contact_sweeps) + ")");
  if (scene.solver.contact_sweeps > 0 && scene.solver.method == SolverMethod::vbd)
    return Error(ErrorCode::bad_parameter, "solver.contact_sweeps must be 0 with solver.method vbd (got " +
                                               std::to_string(scene.solver.contact_sweeps) +
                                               "): its sweeps have no separate contact pass");
  if (scene.tet_bodies.empty() && scene.tri_bodies.empty() && scene.line_bodies.empty() && scene.tools.empty())
    return Error(ErrorCode::bad_parameter, "the scene has no bodies");
  if (Status s = check_all(scene.tet_bodies, "tet_bodies", check_tet_body); !s) return s;
  if (Status s = check_all(scene.tri_bodies, "tri_bodies", check_tri_body); !s) return s;
  if (Status s = check_all(scene.line_bodies, "line_bodies", check_line_body); !s) return s;
  if (Status s = check_all(scene.colliders, "colliders", check_collider); !s) return s;
  if (Status s = check_all(scene.tools, "tools", check_tool); !s) return s;
  for (std::size_t t = 0; t < scene.tools.size(); ++t)
    if (scene.tools[t].cuts)
      if (Status s = check_tool_cut(scene, *scene.tools[t].cuts, "tools[" + std::to_string(t) + "].cuts"); !s) return s;
  if (Status s = check_mesh_collision(scene); !s) return s;
  if (Status s = check_scene_fluid(scene); !s) return s;
  for (std::size_t i = 0; i < scene.needles.size(); ++i)
    if (Status s = check_needle(scene, scene.needles[i], "needles[" + std::to_string(i) + "]"); !s) return s;
  if (!scene.needles.empty() && scene.solver.chebyshev_rho > 0.0)
    return Error(ErrorCode::bad_parameter, "needles are not supported with solver.chebyshev_rho > 0 (got " +
                                               str(scene.solver.chebyshev_rho) +
                                               "): the accelerator would extrapolate the punctured tissue");
  if (!scene.needles.empty() && scene.topology_changes)
    return Error(ErrorCode::bad_parameter,
                 "needles are not supported with topology_changes = true yet: their puncturable surfaces and "
                 "sutures are made once, from the meshes the scene starts with");
  // Tearing: a strain >= 0, and the topology changes it needs.
  const auto check_tear = [&](const std::string& name, double strain) -> Status {
    if (Status s = non_negative(name, strain); !s) return s;
    if (strain > 0.0 && !scene.topology_changes)
      return Error(ErrorCode::bad_parameter,
                   name + " = " + str(strain) + " needs topology_changes = true (tearing removes elements)");
    return {};
  };
  for (std::size_t i = 0; i < scene.tet_bodies.size(); ++i)
    if (Status s = check_tear("tet_bodies[" + std::to_string(i) + "].tear_strain", scene.tet_bodies[i].tear_strain); !s)
      return s;
  for (std::size_t i = 0; i < scene.tri_bodies.size(); ++i)
    if (Status s = check_tear("tri_bodies[" + std::to_string(i) + "].tear_strain", scene.tri_bodies[i].tear_strain); !s)
      return s;
  for (std::size_t i = 0; i < scene.line_bodies.size(); ++i)
    if (Status s = check_tear("line_bodies[" + std::to_string(i) + "].tear_strain", scene.line_bodies[i].tear_strain);
        !s)
      return s;
  std::size_t grasper_targets = 0;
  for (std::size_t i = 0; i < scene.graspers.size(); ++i) {
    const std::string name = "graspers[" + std::to_string(i) + "]";
    const GrasperDesc& g = scene.graspers[i];
    if (g.capacity < 1 || g.capacity > (1u << 20))
      return Error(ErrorCode::bad_parameter,
                   name + ".capacity must be in [1, 2^20] (got " + std::to_string(g.capacity) + ")");
    if (g.point_capacity > (1u << 20))
      return Error(ErrorCode::bad_parameter,
                   name + ".point_capacity must be in [0, 2^20] (got " + std::to_string(g.point_capacity) + ")");
    if (Status s = non_negative(name + ".compliance", g.compliance); !s) return s;
    grasper_targets += std::size_t{g.capacity} + g.point_capacity;
  }
  if (scene.targets.size() + grasper_targets >= (std::size_t{1} << 24))
    return Error(ErrorCode::bad_parameter, "targets and graspers: " + std::to_string(scene.targets.size()) + " + " +
                                               std::to_string(grasper_targets) +
                                               " targets are more than the 2^24 an attachment can index");
  for (std::size_t i = 0; i < scene.targets.size(); ++i)
    if (Status s = finite3("targets[" + std::to_string(i) + "]", scene.targets[i]); !s) return s;
  for (std::size_t i = 0; i < scene.attachments.size(); ++i)
    if (Status s = check_attachment(scene, scene.attachments[i], "attachments[" + std::to_string(i) + "]"); !s)
      return s;
  if (Status s = check_body_attachments(scene); !s) return s;
  if (Status s = check_vbd_scene(scene); !s) return s;
  // Last, on values known finite: what the device makes of them in float,
  // and the caps on a frame's work (device_ranges.h).
  return check_device_ranges(scene);
}

}  // namespace sinew
