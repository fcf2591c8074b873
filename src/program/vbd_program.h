// vbd_program.h — the frame program of Vertex Block Descent
// (SolverSettings::method = vbd; Chen, Liu, Yang, Yuksel, "Vertex Block
// Descent", ACM TOG 43(4), SIGGRAPH 2024): per substep, predict (the
// inertia target y), the initial guess, `iterations` sweeps over the
// vertex colours of every FEM block (optionally Chebyshev-accelerated),
// update velocities. The xPBD program (xpbd_program.h) is not touched.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "compiler/scene_compiler.h"
#include "program/xpbd_program.h"
#include "sinew/scene.h"

namespace sinew {

/// One FEM block's vertices, coloured (vertex_coloring.h), and their tets.
struct VbdBlock {
  std::size_t block = 0;  ///< its CompiledScene::blocks entry (particles, data and rotations bound from it)
  std::uint32_t model = 0;  ///< SINEW_VBD_COROTATIONAL or SINEW_VBD_NEO_HOOKEAN (vbd_params.h)
  BufferHandle vertices, offsets, incidences;  ///< vbd_solve_vertices bindings 2..4
  std::vector<std::uint32_t> color_offsets;    ///< colour k: entries [color_offsets[k], color_offsets[k + 1])
};

/// The host side of one FEM block's VBD data (the words of VbdBlock's
/// buffers): its movable vertices coloured by color_tet_vertices, listed
/// colour by colour (device order within a colour), and per entry its
/// incidences, tet slot * 4 + corner, in slot order.
struct VbdTopology {
  std::vector<std::uint32_t> vertices, offsets, incidences;
  std::vector<std::uint32_t> color_offsets;  ///< colours + 1 entries
};

/// [in] block: an FEM block (arity 4); positions: every particle (w = 0:
/// pinned, not listed).
VbdTopology make_vbd_topology(const ConstraintBlock& block, const std::vector<kernels::float4>& positions);

/// The buffers VBD adds to the scene's (upload_scene).
struct VbdBuffers {
  BufferHandle inertia;        ///< y per particle, float4
  BufferHandle newer, older;   ///< the accelerator's position history (chebyshev_rho > 0; else unused)
  std::vector<VbdBlock> blocks;
};

/// Checks that VBD can run `scene` (every block an FEM block of a
/// corotational or neo_hookean body) and uploads its vertex colouring and
/// incidences. Errors (bad_parameter) name what VBD does not support.
Result<VbdBuffers> upload_vbd(Device& device, const CompiledScene& scene);

/// The dispatches of one frame of VBD with `gravity` [m/s^2].
FrameProgram build_vbd_program(const CompiledScene& scene, const XpbdBuffers& buffers, const VbdBuffers& vbd,
                               const SolverSettings& solver, const std::array<double, 3>& gravity);

}  // namespace sinew
