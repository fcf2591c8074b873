// scene_compiler.cpp — from a scene description to flat, colour-sorted
// arrays. Rest lengths and volumes are computed from the float positions
// with the very functions the kernels use (kernels/math/xpbd_math.h), so a
// body at rest has C == 0 exactly and stays bitwise at rest.
#include "compiler/scene_compiler.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "coloring/greedy_coloring.h"
#include "compiler/device_ranges.h"
#include "compiler/edge_network.h"
#include "compiler/particle_order.h"
#include "compiler/solve_order.h"
#include "contact_params.h"
#include "math/xpbd_math.h"

namespace sinew {
namespace {

using kernels::float4;

}  // namespace

Status add_tet_body(SceneBuilder& b, const TetBodyDesc& body, const std::string& name) {
  const std::uint32_t first = b.add_vertices(body.mesh.vertices, body.velocity_damping);
  const auto& tets = body.mesh.tets;

  // Rest volumes in float, as the kernel computes them; lumped masses.
  std::vector<float> rest_volume(tets.size());
  for (std::size_t t = 0; t < tets.size(); ++t) {
    const auto& q = tets[t];
    const float v = kernels::tet_volume(b.positions[first + q[0]], b.positions[first + q[1]],
                                        b.positions[first + q[2]], b.positions[first + q[3]]);
    if (!(v > 0.0f))
      return Error(ErrorCode::bad_parameter,
                   name + ".mesh: tet " + std::to_string(t) +
                   " has no positive volume in single precision (too small for float32 positions)");
    rest_volume[t] = v;
    for (std::uint32_t k : q) b.mass[first + k] += body.density * v / 4.0;
  }

  // set_elastic: each tet's springs and volume term fitted to linear
  // elasticity (compiler/edge_network.h); else the compliances as given.
  std::vector<TetNetworkFit> fits;
  if (body.calibrated_network && (body.distance_constraints || body.volume_constraints))
    fits = fit_body_network(body.mesh, body.youngs_modulus, body.poisson_ratio).tets;

  if (body.volume_constraints) {
    RawConstraints& volume = b.volume_constraints(body.stiffness_damping);
    for (std::size_t t = 0; t < tets.size(); ++t) {
      for (std::uint32_t k : tets[t]) volume.particles.push_back(first + k);
      const double alpha = fits.empty() ? body.volume_compliance * rest_volume[t] : 1.0 / fits[t].volume;
      const char* field = fits.empty() ? ".volume_compliance" : ".youngs_modulus (its fitted volume alpha)";
      if (Status s = check_device_compliance(name, field, alpha, b.step); !s) return s;
      volume.data.push_back(rest_volume[t]);
      volume.data.push_back(static_cast<float>(alpha));
    }
  }

  if (body.distance_constraints) {
    // Unique edges, sorted (a < b) for memory locality; each tet gives V/6
    // of its volume to each of its six edges.
    using Edge = std::pair<std::uint32_t, std::uint32_t>;
    std::vector<Edge> edges;
    edges.reserve(tets.size() * 6);
    auto each_edge = [&](const auto& tet, auto&& fn) {
      for (const auto& pr : kTetEdgePairs) fn(Edge{std::min(tet[pr[0]], tet[pr[1]]), std::max(tet[pr[0]], tet[pr[1]])});
    };
    for (const auto& tet : tets) each_edge(tet, [&](Edge e) { edges.push_back(e); });
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    // Hand-set: the volume share V_e; calibrated: the spring k_e [N/m],
    // each summed over the edge's tets in tet order (as the topology
    // editor sums them again after a tet is removed).
    std::vector<double> share(edges.size(), 0.0);
    for (std::size_t t = 0; t < tets.size(); ++t) {
      int local = 0;
      each_edge(tets[t], [&](Edge e) {
        share[std::lower_bound(edges.begin(), edges.end(), e) - edges.begin()] +=
            fits.empty() ? rest_volume[t] / 6.0 : fits[t].edge[local];
        ++local;
      });
    }
    RawConstraints& distance = b.distance_constraints(body.stiffness_damping);
    for (std::size_t i = 0; i < edges.size(); ++i) {
      const float len = kernels::edge_length(b.positions[first + edges[i].first], b.positions[first + edges[i].second]);
      distance.particles.push_back(first + edges[i].first);
      distance.particles.push_back(first + edges[i].second);
      // Hand-set: c L^2 / V; calibrated: 1 / k.
      const double alpha =
          fits.empty() ? body.distance_compliance * static_cast<double>(len) * len / share[i] : 1.0 / share[i];
      const char* field = fits.empty() ? ".distance_compliance" : ".youngs_modulus (its fitted spring alpha)";
      if (Status s = check_device_compliance(name, field, alpha, b.step); !s) return s;
      distance.data.push_back(len);
      distance.data.push_back(static_cast<float>(alpha));
    }
  }
  if (body.material != TetMaterial::none)
    if (Status s = add_fem_constraints(b, body, first, name); !s) return s;
  if (!body.initial_vertices.empty()) b.initial.emplace_back(first, &body.initial_vertices);
  // Vertices used by no tet get no mass and so stay where they are (w = 0).
  for (std::uint32_t p : body.pinned) b.mass[first + p] = 0.0;
  return {};
}

Status add_line_body(SceneBuilder& b, const LineBodyDesc& body, const std::string& name) {
  const std::uint32_t first = b.add_vertices(body.vertices, body.velocity_damping);
  for (std::size_t i = 0; i < body.masses.size(); ++i) b.mass[first + i] = body.masses[i];
  RawConstraints& distance = b.distance_constraints(body.stiffness_damping);
  for (std::size_t s = 0; s < body.segments.size(); ++s) {
    const auto [p, q] = body.segments[s];
    const float len = kernels::edge_length(b.positions[first + p], b.positions[first + q]);
    if (!(len > 0.0f))
      return Error(ErrorCode::bad_parameter,
                   name + ".segments[" + std::to_string(s) + "] has zero length in single precision");
    distance.particles.push_back(first + p);
    distance.particles.push_back(first + q);
    distance.data.push_back(len);
    distance.data.push_back(static_cast<float>(body.compliance));
  }
  if (body.bending_compliance >= 0.0)
    if (Status s = add_line_bending(b, body, first, name); !s) return s;
  if (!body.initial_vertices.empty()) b.initial.emplace_back(first, &body.initial_vertices);
  for (std::uint32_t p : body.pinned) b.mass[first + p] = 0.0;
  return {};
}

std::uint32_t SceneBuilder::add_vertices(const std::vector<Vec3d>& vertices, double damping) {
  const auto first = static_cast<std::uint32_t>(positions.size());
  for (const Vec3d& v : vertices)
    positions.push_back({static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]), 0.0f});
  mass.resize(positions.size(), 0.0);
  // exp(-k h) on the host, once: every backend multiplies by the same float
  // (exp itself is not correctly rounded alike on every device).
  velocity_damping.resize(positions.size(), static_cast<float>(std::exp(-damping * substep)));
  return first;
}

RawConstraints& SceneBuilder::constraints(Kernel kernel, std::uint32_t arity, std::uint32_t data_stride,
                                          std::uint32_t lambda_stride, std::vector<SceneBuffer> extra_bindings,
                                          double damping_time) {
  for (RawConstraints& r : raw)
    if (r.kernel == kernel && r.damping_time == damping_time) return r;
  raw.push_back({kernel, arity, data_stride, lambda_stride, std::move(extra_bindings), {}, {}, damping_time});
  return raw.back();
}

RawConstraints& SceneBuilder::distance_constraints(double damping_time) {
  return constraints(Kernel::xpbd_solve_distance, 2, 2, 1, {SceneBuffer::previous_position}, damping_time);
}

RawConstraints& SceneBuilder::volume_constraints(double damping_time) {
  return constraints(Kernel::xpbd_solve_volume, 4, 2, 1, {SceneBuffer::previous_position}, damping_time);
}

namespace {

// Colours a block's constraints and reorders them colour by colour. The
// colouring runs in the scene's constraint order, so it, and with it every
// result, is the same whatever order the particles live in; inside a colour
// the constraints are independent (no shared movable particle), so their
// order there changes no bit either: with `by_first_particle` they are
// sorted by their smallest particle, for a sweep that walks memory forward
// (particle_order.h), otherwise kept in the scene's order.
ConstraintBlock color_and_sort(const RawConstraints& raw, std::span<const std::uint8_t> movable,
                               bool by_first_particle) {
  ConstraintBlock out;
  out.kernel = raw.kernel;
  out.arity = raw.arity;
  out.data_stride = raw.data_stride;
  out.lambda_stride = raw.lambda_stride;
  out.extra_bindings = raw.extra_bindings;
  out.damping_time = raw.damping_time;
  const auto n = static_cast<std::uint32_t>(raw.particles.size() / raw.arity);
  if (n == 0) return out;
  const Coloring coloring = color_constraints(raw.particles, raw.arity, movable);
  out.color_offsets.assign(coloring.color_count() + 1, 0);
  for (std::uint32_t k = 0; k < coloring.color_count(); ++k)
    out.color_offsets[k + 1] = out.color_offsets[k] + coloring.color_sizes[k];
  const std::vector<std::uint32_t> order =
      constraint_order(raw.particles, raw.arity, coloring.color_of, by_first_particle);
  out.particles.resize(raw.particles.size());
  out.data.resize(raw.data.size());
  for (std::uint32_t to = 0; to < n; ++to) {
    const std::uint32_t c = order[to];
    std::copy_n(&raw.particles[c * raw.arity], raw.arity, &out.particles[to * raw.arity]);
    std::copy_n(&raw.data[c * raw.data_stride], raw.data_stride, &out.data[to * raw.data_stride]);
  }
  return out;
}

}  // namespace

Result<CompiledScene> compile_scene(const SceneDesc& scene) {
  if (Status s = check_scene(scene); !s) return s.error();

  std::size_t total = 0;
  for (const auto& body : scene.tet_bodies) total += body.mesh.vertices.size();
  for (const auto& body : scene.tri_bodies) total += body.mesh.vertices.size();
  for (const auto& body : scene.line_bodies) total += body.vertices.size();
  if (total >= std::numeric_limits<std::uint32_t>::max())
    return Error(ErrorCode::bad_parameter,
                 "the scene has " + std::to_string(total) + " particles, more than 32-bit indices can address");

  SceneBuilder b;
  b.substep = scene.solver.time_step / scene.solver.substeps;
  b.step = *device_step(scene.solver);  // checked by check_scene
  CompiledScene out;
  // A fluid on the tissue's surfaces pushes it through the force buffer.
  out.external_forces = scene.external_forces || (scene.fluid && !scene.fluid->surfaces.empty());
  for (std::size_t i = 0; i < scene.tet_bodies.size(); ++i) {
    out.tet_body_first_particle.push_back(static_cast<std::uint32_t>(b.positions.size()));
    if (Status s = add_tet_body(b, scene.tet_bodies[i], "tet_bodies[" + std::to_string(i) + "]"); !s) return s.error();
  }
  for (std::size_t i = 0; i < scene.tri_bodies.size(); ++i) {
    out.tri_body_first_particle.push_back(static_cast<std::uint32_t>(b.positions.size()));
    if (Status s = add_tri_body(b, scene.tri_bodies[i], "tri_bodies[" + std::to_string(i) + "]"); !s) return s.error();
  }
  for (std::size_t i = 0; i < scene.line_bodies.size(); ++i) {
    out.line_body_first_particle.push_back(static_cast<std::uint32_t>(b.positions.size()));
    if (Status s = add_line_body(b, scene.line_bodies[i], "line_bodies[" + std::to_string(i) + "]"); !s)
      return s.error();
  }
  out.positions = b.positions;  // add_contacts may need the bodies' layout
  if (Status s = add_contacts(b, scene, out); !s) return s.error();

  for (const auto& [first, start] : b.initial)
    for (std::size_t i = 0; i < start->size(); ++i) {
      const Vec3d& p = (*start)[i];
      b.positions[first + i] = {static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]), 0.0f};
    }
  std::vector<std::uint8_t> movable(b.positions.size());
  // The body a particle belongs to, for messages.
  const auto body_of = [&](std::size_t p) {
    std::string name;
    const auto find = [&](const std::vector<std::uint32_t>& firsts, const char* kind) {
      for (std::size_t i = 0; i < firsts.size(); ++i)
        if (firsts[i] <= p) name = std::string(kind) + "[" + std::to_string(i) + "]";
    };
    find(out.tet_body_first_particle, "tet_bodies");
    find(out.tri_body_first_particle, "tri_bodies");
    find(out.line_body_first_particle, "line_bodies");
    return name;
  };
  for (std::size_t p = 0; p < b.positions.size(); ++p) {
    const double w = b.mass[p] > 0.0 ? 1.0 / b.mass[p] : 0.0;
    if (!std::isfinite(static_cast<float>(w)))
      return Error(ErrorCode::bad_parameter,
                   body_of(p) + ": particle " + std::to_string(p) + " has a mass of " + std::to_string(b.mass[p]) +
                   " kg, too small for a float32 inverse mass");
    // An inverse mass that rounds to 0 in float would pin the particle
    // (w = 0 means immovable): a density or mass too large is an error.
    if (b.mass[p] > 0.0 && !(static_cast<float>(w) >= std::numeric_limits<float>::min()))
      return Error(ErrorCode::bad_parameter,
                   body_of(p) + ": particle " + std::to_string(p) + " has a mass of " + std::to_string(b.mass[p]) +
                   " kg, too large for a float32 inverse mass (it would round to 0, which pins it): check the "
                   "body's density or masses");
    b.positions[p].w = static_cast<float>(w);
  }
  // Device order (particle_order.h): each body's particles in reverse
  // Cuthill-McKee order, constraints renumbered (and sorted by first
  // particle within their colour, in color_and_sort).
  if (scene.solver.reorder_particles) {
    std::vector<std::uint32_t> body_first = out.tet_body_first_particle;
    body_first.insert(body_first.end(), out.tri_body_first_particle.begin(), out.tri_body_first_particle.end());
    body_first.insert(body_first.end(), out.line_body_first_particle.begin(), out.line_body_first_particle.end());
    std::vector<ConstraintList> lists;
    for (const RawConstraints& raw : b.raw) lists.push_back({raw.particles, raw.arity});
    out.order = bandwidth_order(static_cast<std::uint32_t>(b.positions.size()), lists, std::move(body_first));
  } else {
    out.order = identity_order(static_cast<std::uint32_t>(b.positions.size()));
  }
  std::vector<kernels::float4> device_positions(b.positions.size());
  for (std::size_t slot = 0; slot < b.positions.size(); ++slot) {
    device_positions[slot] = b.positions[out.order.user_of[slot]];
    movable[slot] = device_positions[slot].w > 0.0f;
  }
  b.positions = std::move(device_positions);
  out.velocity_damping.resize(b.velocity_damping.size());
  for (std::size_t slot = 0; slot < out.velocity_damping.size(); ++slot)
    out.velocity_damping[slot] = b.velocity_damping[out.order.user_of[slot]];
  for (RawConstraints& raw : b.raw)
    for (std::uint32_t& p : raw.particles) p = out.order.device_of[p];
  // Gauss-Seidel order: kSolveOrder (solve_order.h; contacts last, so they win).
  for (const RawConstraints& raw : b.raw)
    if (solve_rank(raw.kernel) == kNotSolved)
      return Error(ErrorCode::internal,
                   "internal: kernel " + std::string(kernel_name(raw.kernel)) +
                   " has no place in the solve order (src/compiler/solve_order.h)");
  std::stable_sort(b.raw.begin(), b.raw.end(), [](const RawConstraints& x, const RawConstraints& y) {
    return solve_rank(x.kernel) < solve_rank(y.kernel);
  });
  for (const RawConstraints& raw : b.raw)
    if (!raw.particles.empty()) out.blocks.push_back(color_and_sort(raw, movable, scene.solver.reorder_particles));
  // Graspers, last in every sweep: a block each, one colour of `capacity`
  // attachment slots, none in use (runtime/graspers.h fills them when the
  // jaws close), and a block of `point_capacity` surface points after it
  // (xpbd_solve_point_attachment, after the vertices' holds in the solve
  // order); each slot has its own target, after the scene's.
  const auto grasper_block = [&](Kernel kernel, std::uint32_t arity, std::uint32_t stride, std::uint32_t capacity,
                                 double compliance, std::vector<std::uint32_t>& block_of,
                                 std::vector<std::uint32_t>& first_target_of) {
    ConstraintBlock block;
    block.kernel = kernel;
    block.arity = arity;
    block.data_stride = stride;
    block.lambda_stride = 1;
    block.extra_bindings = {SceneBuffer::targets};
    block.particles.assign(std::size_t{capacity} * arity, 0);
    const auto first_target = static_cast<std::uint32_t>(out.targets.size() / (sizeof(kernels::TargetEntry) / 4));
    for (std::uint32_t i = 0; i < capacity; ++i) {
      std::vector<float> data(stride, 0.0f);
      if (kernel == Kernel::xpbd_solve_attachment) {
        data[0] = static_cast<float>(first_target + i), data[1] = static_cast<float>(compliance);
      } else {  // the weights are written when the jaws close
        data[3] = static_cast<float>(compliance), data[4] = static_cast<float>(first_target + i);
      }
      block.data.insert(block.data.end(), data.begin(), data.end());
      out.targets.insert(out.targets.end(), sizeof(kernels::TargetEntry) / 4, 0.0f);
    }
    block.color_offsets = {0, capacity};
    block.color_counts = {0};
    block_of.push_back(static_cast<std::uint32_t>(out.blocks.size()));
    first_target_of.push_back(first_target);
    out.blocks.push_back(std::move(block));
  };
  for (const GrasperDesc& g : scene.graspers)
    grasper_block(Kernel::xpbd_solve_attachment, 1, SINEW_ATTACHMENT_DATA_STRIDE, g.capacity, g.compliance,
                  out.grasper_block, out.grasper_first_target);
  for (const GrasperDesc& g : scene.graspers) {
    if (g.point_capacity > 0) {
      grasper_block(Kernel::xpbd_solve_point_attachment, 3, SINEW_POINT_ATTACHMENT_DATA_STRIDE, g.point_capacity,
                    g.compliance, out.grasper_point_block, out.grasper_point_first_target);
    } else {
      out.grasper_point_block.push_back(UINT32_MAX);
      out.grasper_point_first_target.push_back(UINT32_MAX);
    }
  }
  out.positions = std::move(b.positions);
  return out;
}

}  // namespace sinew
