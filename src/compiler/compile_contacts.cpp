// compile_contacts.cpp — colliders, tools and attachments: the collider
// buffer (implicit shapes' nodes after the entries) and the target buffer
// (kernels/shared/contact_params.h), one contact constraint per movable
// particle and one attachment constraint per attached vertex.
// Called after every body has been added, so the particle layout is final.
#include <cmath>
#include <cstring>
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "compiler/float_words.h"
#include "compiler/scene_compiler.h"
#include "contact_params.h"

namespace sinew {
namespace {

using kernels::ColliderEntry;
using kernels::ColliderHeader;
using kernels::ImplicitEntry;
using kernels::TargetEntry;

ColliderEntry entry(std::uint32_t shape, const std::array<double, 3>& position, const std::array<double, 4>& rotation) {
  ColliderEntry e{};
  e.shape = shape;
  e.start_px = e.end_px = static_cast<float>(position[0]);
  e.start_py = e.end_py = static_cast<float>(position[1]);
  e.start_pz = e.end_pz = static_cast<float>(position[2]);
  e.start_qw = e.end_qw = static_cast<float>(rotation[0]);
  e.start_qx = e.end_qx = static_cast<float>(rotation[1]);
  e.start_qy = e.end_qy = static_cast<float>(rotation[2]);
  e.start_qz = e.end_qz = static_cast<float>(rotation[3]);
  return e;
}

std::uint32_t shape_code(ColliderShape shape) {
  switch (shape) {
    case ColliderShape::plane: return SINEW_SHAPE_PLANE;
    case ColliderShape::sphere: return SINEW_SHAPE_SPHERE;
    case ColliderShape::capsule: return SINEW_SHAPE_CAPSULE;
    case ColliderShape::box: return SINEW_SHAPE_BOX;
    case ColliderShape::cylinder: return SINEW_SHAPE_CYLINDER;
    case ColliderShape::implicit: return SINEW_SHAPE_IMPLICIT;
    case ColliderShape::level_set: return SINEW_SHAPE_LEVEL_SET;
  }
  return SINEW_SHAPE_PLANE;
}

std::uint32_t op_code(ImplicitOp op) {
  switch (op) {
    case ImplicitOp::half_space: return SINEW_IMPLICIT_HALF_SPACE;
    case ImplicitOp::sphere: return SINEW_IMPLICIT_SPHERE;
    case ImplicitOp::capsule: return SINEW_IMPLICIT_CAPSULE;
    case ImplicitOp::box: return SINEW_IMPLICIT_BOX;
    case ImplicitOp::cylinder: return SINEW_IMPLICIT_CYLINDER;
    case ImplicitOp::torus: return SINEW_IMPLICIT_TORUS;
    case ImplicitOp::unite: return SINEW_IMPLICIT_UNITE;
    case ImplicitOp::intersect: return SINEW_IMPLICIT_INTERSECT;
    case ImplicitOp::subtract: return SINEW_IMPLICIT_SUBTRACT;
  }
  return SINEW_IMPLICIT_UNITE;
}

ImplicitEntry implicit_entry(const ImplicitNode& n) {
  ImplicitEntry e{};
  e.op = op_code(n.op);
  e.radius = static_cast<float>(n.radius);
  e.half_height = static_cast<float>(n.half_height);
  e.rounding = static_cast<float>(n.rounding);
  e.half_x = static_cast<float>(n.half_extents[0]);
  e.half_y = static_cast<float>(n.half_extents[1]);
  e.half_z = static_cast<float>(n.half_extents[2]);
  e.minor_radius = static_cast<float>(n.minor_radius);
  e.px = static_cast<float>(n.position[0]);
  e.py = static_cast<float>(n.position[1]);
  e.pz = static_cast<float>(n.position[2]);
  e.qw = static_cast<float>(n.rotation[0]);
  e.qx = static_cast<float>(n.rotation[1]);
  e.qy = static_cast<float>(n.rotation[2]);
  e.qz = static_cast<float>(n.rotation[3]);
  return e;
}

std::uint32_t first_particle(const CompiledScene& out, const VertexRef& v) {
  switch (v.body_kind) {
    case BodyKind::tet: return out.tet_body_first_particle[v.body];
    case BodyKind::tri: return out.tri_body_first_particle[v.body];
    case BodyKind::line: return out.line_body_first_particle[v.body];
  }
  return 0;
}

// Appends a level set's NanoVDB grid to the grids buffer at the next
// 32-byte boundary (NanoVDB's alignment), for collider entry `index`
// (scene colliders, then tools): the kernels address it by byte offset in
// 32 bits (implicit_first) and need 1/h and 1/2h (half_x, half_y).
Status add_level_set(const LevelSet& level_set, std::size_t index, ColliderEntry& e, CompiledScene& out) {
  const std::span<const std::byte> bytes = level_set.nanovdb_bytes();
  const std::uint64_t offset = (std::uint64_t{out.level_set_grids.size()} * 4 + 31) / 32 * 32;
  if (offset + bytes.size() > std::uint64_t{UINT32_MAX})
    return Error(ErrorCode::bad_parameter, "colliders and tools: the level-set grids take more than 4 GiB (" +
                                               std::to_string(offset + bytes.size()) + " bytes)");
  out.level_set_grids.resize(offset / 4 + bytes.size() / 4, 0u);
  std::memcpy(out.level_set_grids.data() + offset / 4, bytes.data(), bytes.size());
  out.level_set_offsets[index] = offset;
  e.implicit_first = static_cast<std::uint32_t>(offset);
  e.half_x = static_cast<float>(1.0 / level_set.voxel_size());
  e.half_y = static_cast<float>(0.5 / level_set.voxel_size());
  e.half_z = 0.0f;
  return {};
}

}  // namespace

Status add_contacts(SceneBuilder& b, const SceneDesc& scene, CompiledScene& out) {
  const auto colliders = static_cast<std::uint32_t>(scene.colliders.size());
  const auto tools = static_cast<std::uint32_t>(scene.tools.size());
  const auto particles = static_cast<std::uint32_t>(b.positions.size());

  // The collider buffer: header, scene colliders, then tools (capsules or level sets).
  ColliderHeader header{};
  header.colliders = colliders;
  header.tools = tools;
  header.substep_fraction = static_cast<float>(1.0 / scene.solver.substeps);
  out.colliders.clear();
  append_words(out.colliders, header);
  std::vector<ImplicitEntry> nodes;  // every implicit collider's nodes, after the entries
  out.level_set_grids.clear();
  out.level_set_offsets.assign(scene.colliders.size() + scene.tools.size(), 0);
  for (std::size_t k = 0; k < scene.colliders.size(); ++k) {
    const ColliderDesc& c = scene.colliders[k];
    ColliderEntry e = entry(shape_code(c.shape), c.position, c.rotation);
    if (c.shape == ColliderShape::implicit) {
      e.implicit_first = static_cast<std::uint32_t>(nodes.size());
      e.implicit_count = static_cast<std::uint32_t>(c.implicit.size());
      for (const ImplicitNode& n : c.implicit) nodes.push_back(implicit_entry(n));
    }
    e.radius = static_cast<float>(c.radius);
    e.half_height = static_cast<float>(c.half_height);
    e.half_x = static_cast<float>(c.half_extents[0]);
    e.half_y = static_cast<float>(c.half_extents[1]);
    e.half_z = static_cast<float>(c.half_extents[2]);
    if (c.shape == ColliderShape::level_set) {
      if (Status s = add_level_set(*c.level_set, k, e, out); !s) return s;
    }
    e.static_friction = static_cast<float>(c.static_friction);
    e.dynamic_friction = static_cast<float>(c.dynamic_friction);
    e.compliance = static_cast<float>(c.compliance);
    append_words(out.colliders, e);
  }
  for (std::size_t k = 0; k < scene.tools.size(); ++k) {
    const ToolDesc& t = scene.tools[k];
    ColliderEntry e = entry(SINEW_SHAPE_CAPSULE, t.position, t.rotation);
    e.radius = static_cast<float>(t.radius);
    e.half_height = static_cast<float>(t.half_height);
    if (t.shape == ToolShape::level_set) {
      e = entry(SINEW_SHAPE_LEVEL_SET, t.position, t.rotation);
      if (Status s = add_level_set(*t.level_set, scene.colliders.size() + k, e, out); !s) return s;
    }
    e.static_friction = static_cast<float>(t.static_friction);
    e.dynamic_friction = static_cast<float>(t.dynamic_friction);
    e.compliance = static_cast<float>(t.compliance);
    append_words(out.colliders, e);
  }
  for (const ImplicitEntry& n : nodes) append_words(out.colliders, n);

  out.targets.clear();
  for (const auto& t : scene.targets) {
    TargetEntry e{};
    e.start_x = e.end_x = static_cast<float>(t[0]);
    e.start_y = e.end_y = static_cast<float>(t[1]);
    e.start_z = e.end_z = static_cast<float>(t[2]);
    append_words(out.targets, e);
  }

  // Contacts: every movable particle against every collider and tool.
  out.contact_impulse_slots = 0;
  const std::uint32_t surfaces = colliders + tools;
  if (surfaces > 0 && particles > 0) {
    const std::uint64_t slots = std::uint64_t{SINEW_CONTACT_IMPULSE_FLOAT4S} * particles * tools;
    if (slots > std::numeric_limits<std::uint32_t>::max() / 4)
      return Error(ErrorCode::bad_parameter,
                   "tools: " + std::to_string(tools) + " tools and " + std::to_string(particles) +
                   " particles need more contact-impulse slots than 32-bit sizes address");
    RawConstraints& contacts =
        b.constraints(Kernel::xpbd_solve_contacts, 1, SINEW_CONTACT_DATA_STRIDE,
                      SINEW_CONTACT_LAMBDA_PER_COLLIDER * surfaces,
                      {SceneBuffer::previous_position, SceneBuffer::colliders, SceneBuffer::contact_impulses,
                       SceneBuffer::level_set_grids});
    for (std::uint32_t p = 0; p < particles; ++p) {
      if (!(b.mass[p] > 0.0)) continue;  // pinned: never moves, never collides
      contacts.particles.push_back(p);
      contacts.data.push_back(0.0f);  // margin [m]: mesh vertices touch the surface itself
    }
    if (tools > 0) out.contact_impulse_slots = static_cast<std::uint32_t>(slots);
  }

  // Attachments: a zero-length constraint from a vertex to its target. The
  // colouring puts several attachments of one particle in different colours.
  if (scene.targets.size() >= (std::size_t{1} << 24))
    return Error(ErrorCode::bad_parameter,
                 "targets: " + std::to_string(scene.targets.size()) +
                 " targets are more than the 2^24 an attachment can index");
  for (const AttachmentDesc& a : scene.attachments) {
    const std::uint32_t particle = first_particle(out, a.vertex) + a.vertex.vertex;
    if (!(b.mass[particle] > 0.0)) continue;  // a pinned vertex stays where it is
    RawConstraints& attachments = b.constraints(Kernel::xpbd_solve_attachment, 1, SINEW_ATTACHMENT_DATA_STRIDE, 1,
                                                {SceneBuffer::targets});
    attachments.particles.push_back(particle);
    attachments.data.push_back(static_cast<float>(a.target));
    attachments.data.push_back(static_cast<float>(a.compliance));
  }

  // Attachments between bodies (xpbd_solve_body_attachment): 4 particle
  // slots a side, an unused slot repeating the side's first particle with
  // weight 0 (the kernel never writes it). The colouring keeps two
  // attachments of one movable particle in different colours.
  for (const BodyAttachmentDesc& a : scene.body_attachments) {
    RawConstraints& links =
        b.constraints(Kernel::xpbd_solve_body_attachment, 8, SINEW_BODY_ATTACHMENT_DATA_STRIDE);
    std::array<float, 8> weights{};
    for (int side = 0; side < 2; ++side) {
      const BarycentricPoint& point = side == 0 ? a.a : a.b;
      const std::uint32_t first = first_particle(out, VertexRef{point.body_kind, point.body, 0});
      for (std::size_t k = 0; k < 4; ++k) {
        const bool used = k < point.vertices.size();
        links.particles.push_back(first + point.vertices[used ? k : 0]);
        weights[4 * side + k] = used ? static_cast<float>(point.weights[k]) : 0.0f;
      }
    }
    links.data.insert(links.data.end(), weights.begin(), weights.end());
    // A break force of infinity is stored as 0: "never" (no infinity on the device).
    const float break_force = std::isfinite(a.break_force) ? static_cast<float>(a.break_force) : 0.0f;
    links.data.insert(links.data.end(),
                      {static_cast<float>(a.compliance), break_force, 0.0f, static_cast<float>(a.rest_length)});
  }
  return {};
}

}  // namespace sinew
