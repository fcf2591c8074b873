// vbd_program.cpp — builds Vertex Block Descent's frame program
// (vbd_program.h).
//
// Anka He Chen, Ziheng Liu, Yin Yang, Cem Yuksel, "Vertex Block Descent",
// ACM TOG 43(4), SIGGRAPH 2024: per substep
//   y = x + h v + h^2 g                       (xpbd_predict, as xPBD's)
//   x = x + h v                               (vbd_initial_guess)
//   `iterations` times, colour by colour: every vertex of the colour takes
//     one Newton step on its own energy      (vbd_solve_vertices)
//     [Chebyshev: x = omega (x - x_older) + x_older past the delay]
//   v = (x - x_prev) / h                      (xpbd_update_velocity)
// The tets' data, particles and corotational rotations are the FEM
// blocks' own buffers (upload_scene), so a scene compiles once for either
// solver.
#include "program/vbd_program.h"

#include <algorithm>
#include <string>
#include <tuple>

#include "accelerator_params.h"
#include "coloring/vertex_coloring.h"
#include "program/solve_programs.h"
#include "vbd_params.h"
#include "xpbd_params.h"

namespace sinew {
VbdTopology make_vbd_topology(const ConstraintBlock& block, const std::vector<kernels::float4>& positions) {
  VbdTopology t;
  const auto particles = static_cast<std::uint32_t>(positions.size());
  // The movable particles of the block's tets, in device order.
  std::vector<std::uint8_t> listed(particles, 0);
  for (std::uint32_t q : block.particles)
    if (positions[q].w > 0.0f) listed[q] = 1;
  std::vector<std::uint32_t> vertices;
  for (std::uint32_t i = 0; i < particles; ++i)
    if (listed[i]) vertices.push_back(i);
  const Coloring coloring = color_tet_vertices(block.particles, vertices, particles);
  t.color_offsets.assign(coloring.color_count() + 1, 0);
  for (std::uint32_t c = 0; c < coloring.color_count(); ++c)
    t.color_offsets[c + 1] = t.color_offsets[c] + coloring.color_sizes[c];
  t.vertices.resize(vertices.size());
  std::vector<std::uint32_t> entry_of(particles, UINT32_MAX);
  {
    std::vector<std::uint32_t> fill(t.color_offsets.begin(), t.color_offsets.end() - 1);
    for (std::size_t e = 0; e < vertices.size(); ++e) {
      const std::uint32_t at = fill[coloring.color_of[e]]++;
      t.vertices[at] = vertices[e];
      entry_of[vertices[e]] = at;
    }
  }
  t.offsets.assign(t.vertices.size() + 1, 0);
  for (std::uint32_t q : block.particles)
    if (entry_of[q] != UINT32_MAX) ++t.offsets[entry_of[q] + 1];
  for (std::size_t e = 0; e < t.vertices.size(); ++e) t.offsets[e + 1] += t.offsets[e];
  t.incidences.resize(t.offsets.back());
  std::vector<std::uint32_t> fill(t.offsets.begin(), t.offsets.end() - 1);
  for (std::size_t slot = 0; slot < block.size(); ++slot)
    for (std::uint32_t corner = 0; corner < 4; ++corner) {
      const std::uint32_t e = entry_of[block.particles[slot * 4 + corner]];
      if (e != UINT32_MAX) t.incidences[fill[e]++] = static_cast<std::uint32_t>(slot) * 4 + corner;
    }
  return t;
}

Result<VbdBuffers> upload_vbd(Device& device, const CompiledScene& scene) {
  VbdBuffers out;
  for (std::size_t k = 0; k < scene.blocks.size(); ++k) {
    const ConstraintBlock& block = scene.blocks[k];
    VbdBlock b;
    b.block = k;
    if (block.kernel == Kernel::xpbd_solve_corotational) {
      b.model = SINEW_VBD_COROTATIONAL;
    } else if (block.kernel == Kernel::xpbd_solve_neo_hookean) {
      b.model = SINEW_VBD_NEO_HOOKEAN;
    } else {
      const std::string what = block.kernel == Kernel::xpbd_solve_stvk
                                   ? "the stvk material (its Hessian blocks are not positive semi-definite; "
                                     "use corotational or neo_hookean)"
                                   : std::string(kernel_name(block.kernel)) + " constraints";
      return Error(ErrorCode::bad_parameter,
                   "solver.method vbd supports tet bodies with a corotational or neo_hookean material only; "
                   "the scene has " + what);
    }
    VbdTopology topology = make_vbd_topology(block, scene.positions);
    b.color_offsets = std::move(topology.color_offsets);
    const std::string name = "vbd " + std::string(kernel_name(block.kernel));
    for (auto [handle, words, label] : {std::tuple{&b.vertices, &topology.vertices, " vertices"},
                                        std::tuple{&b.offsets, &topology.offsets, " offsets"},
                                        std::tuple{&b.incidences, &topology.incidences, " incidences"}}) {
      auto made = make_buffer(device, *words, name + label);
      if (!made) return made.error();
      *handle = *made;
    }
    out.blocks.push_back(std::move(b));
  }
  const std::size_t bytes = std::max<std::size_t>(scene.positions.size() * sizeof(kernels::float4), 16);
  for (auto [handle, label] : {std::pair{&out.inertia, "vbd inertia target"},
                               std::pair{&out.newer, "vbd chebyshev newer positions"},
                               std::pair{&out.older, "vbd chebyshev older positions"}}) {
    auto made = device.create_buffer(bytes, label);
    if (!made) return made.error();
    *handle = *made;
  }
  return out;
}

FrameProgram build_vbd_program(const CompiledScene& scene, const XpbdBuffers& buffers, const VbdBuffers& vbd,
                               const SolverSettings& solver, const std::array<double, 3>& gravity) {
  const double h = solver.time_step / solver.substeps;
  const auto particles = static_cast<std::uint32_t>(scene.positions.size());

  const kernels::PredictParams predict = predict_params(h, gravity, particles);
  kernels::VbdInitParams init{};
  init.h2g_x = static_cast<float>(h * h * gravity[0]);
  init.h2g_y = static_cast<float>(h * h * gravity[1]);
  init.h2g_z = static_cast<float>(h * h * gravity[2]);
  init.count = particles;
  const kernels::UpdateVelocityParams update = update_params(h, particles);
  kernels::VbdSolveParams solve{};
  solve.inv_h2 = static_cast<float>(1.0 / (h * h));

  // The accelerator (positions only: VBD carries no multipliers), with the
  // xPBD sweeps' recurrence and settings.
  const bool accelerate = solver.chebyshev_rho > 0.0;
  const std::vector<double> omega =
      accelerate ? chebyshev_omegas(solver.chebyshev_rho, solver.chebyshev_delay, std::size_t(solver.iterations) + 1)
                 : std::vector<double>{};
  kernels::ChebyshevParams cheb{};
  cheb.count = particles * 4;
  cheb.stride = 4;
  cheb.width = 3;
  cheb.gamma = static_cast<float>(solver.chebyshev_gamma);

  FrameProgram program;
  for (int s = 0; s < solver.substeps; ++s) {
    program.dispatch(Kernel::xpbd_predict, particles, {buffers.position, buffers.previous, buffers.velocity}, predict);
    program.barrier();
    program.dispatch(Kernel::vbd_initial_guess, particles, {buffers.position, vbd.inertia}, init);
    program.barrier();
    for (int n = 1; n <= solver.iterations; ++n) {
      for (const VbdBlock& b : vbd.blocks) {
        const BlockBuffers& tets = buffers.blocks[b.block];
        solve.model = b.model;
        solve.lambda_stride = scene.blocks[b.block].lambda_stride;
        for (std::size_t c = 0; c + 1 < b.color_offsets.size(); ++c) {
          solve.first = b.color_offsets[c];
          solve.count = b.color_offsets[c + 1] - b.color_offsets[c];
          if (solve.count == 0) continue;
          program.dispatch(Kernel::vbd_solve_vertices, solve.count,
                           {buffers.position, vbd.inertia, b.vertices, b.offsets, b.incidences, tets.particles,
                            tets.data, tets.lambda},
                           solve);
          program.barrier();
        }
      }
      if (accelerate && n >= solver.chebyshev_delay - 1) {
        cheb.mix = n > solver.chebyshev_delay ? 1u : 0u;  // record after sweeps S - 1 and S
        cheb.omega = static_cast<float>(omega[std::size_t(n)]);
        program.dispatch(Kernel::xpbd_chebyshev, cheb.count, {buffers.position, vbd.newer, vbd.older}, cheb);
        program.barrier();
      }
    }
    program.dispatch(Kernel::xpbd_update_velocity, particles, {buffers.position, buffers.previous, buffers.velocity},
                     update);
    program.barrier();
  }
  return program;
}

}  // namespace sinew
