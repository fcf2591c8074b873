// xpbd_program.cpp — builds the xPBD frame program.
//
// Macklin, Storey, Lu, Terdiman, Chentanez, Jeschke, Müller, "Small Steps in
// Physics Simulation", SCA 2019: a frame is split into substeps of
// h = dt / n; each substep predicts positions, solves the constraints with
// lambda reset to zero, and derives velocities from the position change.
// Within an iteration the constraints are swept colour by colour
// (Gauss-Seidel across colours, Jacobi-free within one since a colour's
// constraints share no movable particle); each colour ends with a barrier.
#include "program/xpbd_program.h"

#include <span>
#include <string>
#include <tuple>
#include <utility>

#include "suture_params.h"
#include "xpbd_params.h"

namespace sinew {
namespace {

// A range of one block's slots that one dispatch solves.
struct SlotRange {
  std::uint32_t first, count;
};

// The block's colours, each the constraints in use at its start
// (ConstraintBlock::color_counts); colours emptied by topology changes are
// left out.
std::vector<SlotRange> color_ranges(const ConstraintBlock& block) {
  std::vector<SlotRange> ranges;
  for (std::size_t c = 0; c < block.colors(); ++c)
    if (const std::uint32_t n = block.color_count(c); n > 0) ranges.push_back({block.color_offsets[c], n});
  return ranges;
}

// One Gauss-Seidel sweep over a block: a dispatch per range (the colours),
// each followed by a barrier since the next colour reads what this one
// wrote.
void sweep(FrameProgram& program, const ConstraintBlock& block, std::span<const SlotRange> ranges,
           const BlockBuffers& buffers, const XpbdBuffers& scene_buffers, kernels::SolveParams p) {
  std::vector<BufferHandle> bindings{scene_buffers.position, buffers.particles, buffers.data, buffers.lambda,
                                     buffers.residual};
  for (SceneBuffer extra : block.extra_bindings) {
    switch (extra) {
      case SceneBuffer::previous_position: bindings.push_back(scene_buffers.previous); break;
      case SceneBuffer::colliders: bindings.push_back(scene_buffers.colliders); break;
      case SceneBuffer::targets: bindings.push_back(scene_buffers.targets); break;
      case SceneBuffer::contact_impulses: bindings.push_back(scene_buffers.contact_impulses); break;
      case SceneBuffer::level_set_grids: bindings.push_back(scene_buffers.level_set_grids); break;
    }
  }
  for (const SlotRange& r : ranges) {
    p.first = r.first;
    p.count = r.count;
    program.dispatch(block.kernel, p.count, bindings, p);
    program.barrier();
  }
}

}  // namespace

Result<XpbdBuffers> upload_scene(Device& device, const CompiledScene& scene) {
  XpbdBuffers b;
  const std::vector<kernels::float4> zeros(scene.positions.size(), kernels::float4{0, 0, 0, 0});
  // Velocities start at 0, with each particle's damping factor in w (xpbd_predict).
  std::vector<kernels::float4> damped(scene.positions.size(), kernels::float4{0, 0, 0, 1});
  for (std::size_t p = 0; p < damped.size() && p < scene.velocity_damping.size(); ++p)
    damped[p].w = scene.velocity_damping[p];
  for (auto [handle, data, label] : {std::tuple{&b.position, &scene.positions, "position"},
                                     std::tuple{&b.previous, &zeros, "previous position"},
                                     std::tuple{&b.velocity, &std::as_const(damped), "velocity"}}) {
    auto made = make_buffer(device, *data, label);
    if (!made) return made.error();
    *handle = *made;
  }
  const std::vector<kernels::float4> impulses(scene.contact_impulse_slots, kernels::float4{0, 0, 0, 0});
  for (auto [handle, data, label] : {std::tuple{&b.colliders, &scene.colliders, "colliders"},
                                     std::tuple{&b.targets, &scene.targets, "targets"}}) {
    auto made = make_buffer(device, *data, label);
    if (!made) return made.error();
    *handle = *made;
  }
  auto contact_impulses = make_buffer(device, impulses, "contact impulses");
  if (!contact_impulses) return contact_impulses.error();
  b.contact_impulses = *contact_impulses;
  auto grids = make_buffer(device, scene.level_set_grids, "level-set grids");
  if (!grids) return grids.error();
  b.level_set_grids = *grids;
  if (scene.external_forces) {  // only then: a scene pays for the stages it uses
    auto forces = make_buffer(device, zeros, "external forces");
    if (!forces) return forces.error();
    b.external_force = *forces;
  }
  for (const ConstraintBlock& block : scene.blocks) {
    const std::string name(kernel_name(block.kernel));
    auto particles = make_buffer(device, block.particles, name + " particles");
    if (!particles) return particles.error();
    auto data = make_buffer(device, block.data, name + " data");
    if (!data) return data.error();
    auto lambda = make_buffer(device, std::vector<float>(std::size_t{block.size()} * block.lambda_stride, 0.0f),
                              name + " lambda");
    if (!lambda) return lambda.error();
    auto residual = make_buffer(device, std::vector<float>(block.size(), 0.0f), name + " residual");
    if (!residual) return residual.error();
    b.blocks.push_back({*particles, *data, *lambda, *residual});
  }
  return b;
}

void append_contact_colors(FrameProgram& program, const XpbdBuffers& buffers, const MeshContactBuffers& contacts,
                           BufferHandle table, BufferHandle order, std::span<const std::uint32_t> counters,
                           kernels::MeshContactParams m) {
  for (std::uint32_t k = 0; k < counters.size(); ++k) {
    m.color = k;
    program.dispatch_indirect(Kernel::xpbd_solve_mesh_contacts, counters[k],
                              {buffers.position, buffers.previous, table, contacts.particles, contacts.coefficients,
                               contacts.normals, contacts.lambda, contacts.lambda_sum, contacts.motion, order},
                              m);
    program.barrier();
  }
}

std::vector<std::uint32_t> declare_device_color_counters(FrameProgram& program, const DeviceColorTable& colored) {
  std::vector<std::uint32_t> counters;
  for (std::uint32_t k = 0; k < colored.colors; ++k)
    counters.push_back(program.counter("mesh contacts of device colour " + std::to_string(k), colored.table, k,
                                       colored.capacity));
  return counters;
}

void append_device_colored_sweep(FrameProgram& program, const XpbdBuffers& buffers, const MeshContactBuffers& contacts,
                                 const DeviceColorTable& colored, std::span<const std::uint32_t> counters,
                                 kernels::MeshContactParams m) {
  m.colors = colored.colors + 1;
  m.ordered = 1;
  append_contact_colors(program, buffers, contacts, colored.table, colored.order, counters, m);
  append_serial_contact_color(program, buffers, contacts, colored.table, colored.order, colored.colors, m);
}

void append_serial_contact_color(FrameProgram& program, const XpbdBuffers& buffers, const MeshContactBuffers& contacts,
                                 BufferHandle table, BufferHandle order, std::uint32_t color,
                                 kernels::MeshContactParams m) {
  m.color = color;
  m.serial = 1;
  program.dispatch(Kernel::xpbd_solve_mesh_contacts, 1,
                   {buffers.position, buffers.previous, table, contacts.particles, contacts.coefficients,
                    contacts.normals, contacts.lambda, contacts.lambda_sum, contacts.motion, order},
                   m);
  program.barrier();
}

ContactCounters begin_contacts(FrameProgram& program, const XpbdBuffers& buffers,
                               const MeshContactBuffers* mesh_contacts) {
  // Mesh contacts: colour k's count is word k of the table, which the host
  // writes before each frame (at most the capacity, checked after the run).
  ContactCounters out;
  if (mesh_contacts && mesh_contacts->device_colored) {
    // Once per frame, before anything moves the particles (the colouring
    // reads only their inverse masses): its counters come first
    // (DeviceColoringCounters), then the colours'.
    const DeviceContactColoring& c = mesh_contacts->coloring;
    append_device_contact_coloring(program, c, mesh_contacts->particles, buffers.position);
    out.device_colors = {c.table, c.order, c.colors, c.capacity};
    out.counters = declare_device_color_counters(program, out.device_colors);
  } else if (mesh_contacts && mesh_contacts->jacobi) {
    out.counters.push_back(program.counter("mesh contacts", mesh_contacts->table, 0, mesh_contacts->capacity));
    out.counters.push_back(program.counter("particles touched by mesh contacts", mesh_contacts->table, 1,
                                           mesh_contacts->touched_capacity));
  } else if (mesh_contacts) {
    for (std::uint32_t k = 0; k < mesh_contacts->colors; ++k)
      out.counters.push_back(program.counter("mesh contacts of colour " + std::to_string(k), mesh_contacts->table, k,
                                             mesh_contacts->capacity));
  }
  return out;
}

kernels::MeshContactParams mesh_contact_params(const MeshContactBuffers& contacts, float inv_h2, float substep_end) {
  kernels::MeshContactParams m = contacts.params;
  m.colors = contacts.colors;
  m.inv_h2 = inv_h2;
  m.reset_lambda = 0u;
  m.substep_end = substep_end;
  return m;
}

void append_mesh_contact_sweep(FrameProgram& program, const XpbdBuffers& buffers, const MeshContactBuffers& contacts,
                               const ContactCounters& counters, kernels::MeshContactParams m) {
  if (contacts.jacobi) {
    program.dispatch_indirect(Kernel::xpbd_mesh_contacts_jacobi, counters.counters[0],
                              {buffers.position, buffers.previous, contacts.table, contacts.particles,
                               contacts.coefficients, contacts.normals, contacts.lambda, contacts.delta,
                               contacts.lambda_sum, contacts.motion},
                              m);
    program.barrier();
    program.dispatch_indirect(Kernel::xpbd_mesh_contacts_gather, counters.counters[1],
                              {buffers.position, contacts.table, contacts.touched, contacts.offsets, contacts.slots,
                               contacts.delta},
                              m);
    program.barrier();
  } else if (contacts.device_colored) {
    append_device_colored_sweep(program, buffers, contacts, counters.device_colors, counters.counters, m);
  } else {
    append_contact_colors(program, buffers, contacts, contacts.table, contacts.table, counters.counters, m);
  }
}

void append_contact_sweep(FrameProgram& program, const CompiledScene& scene, const XpbdBuffers& buffers,
                          const SolverSettings& solver, int s, const MeshContactBuffers* mesh_contacts,
                          const ContactCounters& counters) {
  const double h = solver.time_step / solver.substeps;
  kernels::SolveParams p{};
  p.inv_h2 = static_cast<float>(1.0 / (h * h));
  p.reset_lambda = 0u;  // the multipliers carry on from the substep's sweeps
  p.h = static_cast<float>(h);
  p.substep_end = static_cast<float>(double(s + 1) / solver.substeps);
  for (std::size_t k = 0; k < scene.blocks.size(); ++k) {
    if (scene.blocks[k].kernel != Kernel::xpbd_solve_contacts) continue;
    p.damping = static_cast<float>(scene.blocks[k].damping_time / h);
    sweep(program, scene.blocks[k], color_ranges(scene.blocks[k]), buffers.blocks[k], buffers, p);
  }
  if (mesh_contacts)
    append_mesh_contact_sweep(program, buffers, *mesh_contacts, counters,
                              mesh_contact_params(*mesh_contacts, p.inv_h2, p.substep_end));
}

kernels::PredictParams predict_params(double h, const std::array<double, 3>& gravity, std::uint32_t particles) {
  kernels::PredictParams predict{};
  predict.h = static_cast<float>(h);
  predict.gravity_x = static_cast<float>(gravity[0]);
  predict.gravity_y = static_cast<float>(gravity[1]);
  predict.gravity_z = static_cast<float>(gravity[2]);
  predict.count = particles;
  return predict;
}

kernels::UpdateVelocityParams update_params(double h, std::uint32_t particles) {
  kernels::UpdateVelocityParams update{};
  update.inv_h = static_cast<float>(1.0 / h);
  update.h = static_cast<float>(h);  // the very float xpbd_predict moves by
  update.count = particles;
  return update;
}

FrameProgram build_xpbd_program(const CompiledScene& scene, const XpbdBuffers& buffers, const SolverSettings& solver,
                                const std::array<double, 3>& gravity, SweepExtras extras) {
  const MeshContactBuffers* mesh_contacts = extras.mesh_contacts;
  const bool measure_errors = solver.measure_errors;
  const double h = solver.time_step / solver.substeps;
  const auto particles = static_cast<std::uint32_t>(scene.positions.size());
  const auto inv_h2 = static_cast<float>(1.0 / (h * h));

  const kernels::PredictParams predict = predict_params(h, gravity, particles);
  kernels::ExternalForceParams force{};
  force.h = predict.h;  // the very float xpbd_predict moves by
  force.count = particles;
  const kernels::UpdateVelocityParams update = update_params(h, particles);

  FrameProgram program;
  const ContactCounters contact_counters = begin_contacts(program, buffers, mesh_contacts);
  for (int s = 0; s < solver.substeps; ++s) {
    if (scene.external_forces) {
      // Into the velocity before predict, so the force acts in every
      // substep as gravity does (its impulse then damped like any velocity).
      program.dispatch(Kernel::xpbd_external_force, particles,
                       {buffers.position, buffers.external_force, buffers.velocity}, force);
      program.barrier();
    }
    program.dispatch(Kernel::xpbd_predict, particles, {buffers.position, buffers.previous, buffers.velocity}, predict);
    program.barrier();
    for (int it = 0; it < solver.iterations; ++it) {
      kernels::SolveParams p{};
      p.inv_h2 = inv_h2;
      p.reset_lambda = it == 0 ? 1u : 0u;
      p.h = static_cast<float>(h);
      p.substep_end = static_cast<float>(double(s + 1) / solver.substeps);
      for (std::size_t k = 0; k < scene.blocks.size(); ++k) {
        p.damping = static_cast<float>(scene.blocks[k].damping_time / h);  // gamma of eq. 26
        sweep(program, scene.blocks[k], color_ranges(scene.blocks[k]), buffers.blocks[k], buffers, p);
      }
      if (mesh_contacts) {  // after the bodies' constraints, colour by colour
        kernels::MeshContactParams m = mesh_contact_params(*mesh_contacts, inv_h2, p.substep_end);
        m.reset_lambda = p.reset_lambda == 0u ? 0u : s == 0 ? 2u : 1u;  // 2: the frame's first sweep
        append_mesh_contact_sweep(program, buffers, *mesh_contacts, contact_counters, m);
      }
      if (const SutureBuffers* sutures = extras.sutures) {  // last: they hold the tissue on the needles
        kernels::SutureParams q{};
        q.inv_h2 = inv_h2;
        q.reset_lambda = p.reset_lambda == 0u ? 0u : s == 0 ? 2u : 1u;  // 2: the frame's first sweep
        q.substep_end = p.substep_end;
        q.substep_begin = static_cast<float>(double(s) / solver.substeps);
        q.h = p.h;
        program.dispatch(Kernel::xpbd_sutures, 1,
                         {buffers.position, buffers.previous, sutures->table, sutures->needles, sutures->curve,
                          sutures->slots, sutures->rows, sutures->weights, sutures->lambda},
                         q);
        program.barrier();
      }
    }
    if (measure_errors && s + 1 == solver.substeps) {
      // Residuals of the final state: read-only, one dispatch per block.
      kernels::SolveParams p{};
      p.inv_h2 = inv_h2;
      p.h = static_cast<float>(h);
      p.substep_end = 1.0f;
      p.measure_only = 1;
      // (A block with removed constraints measures its colours' ranges: the
      // slots past them hold stale copies.)
      for (std::size_t k = 0; k < scene.blocks.size(); ++k) {
        const ConstraintBlock& block = scene.blocks[k];
        const std::vector<SlotRange> whole{{0, block.size()}};
        sweep(program, block, block.color_counts.empty() ? whole : color_ranges(block), buffers.blocks[k], buffers, p);
      }
    }
    for (int c = 0; c < solver.contact_sweeps; ++c)
      append_contact_sweep(program, scene, buffers, solver, s, mesh_contacts, contact_counters);
    program.dispatch(Kernel::xpbd_update_velocity, particles, {buffers.position, buffers.previous, buffers.velocity},
                     update);
    program.barrier();
  }
  return program;
}

}  // namespace sinew
