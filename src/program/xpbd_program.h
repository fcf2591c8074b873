// xpbd_program.h — the frame program of the xPBD solver: per substep,
// (external forces,) predict, `iterations` colour-by-colour sweeps, update
// velocities. Only the stages a scene has constraints for are emitted.
#pragma once

#include "compiler/scene_compiler.h"
#include "backends/backend.h"
#include "coloring/device_contact_coloring.h"
#include "mesh_contact_params.h"
#include "xpbd_params.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace sinew {

/// The device buffers of one constraint block.
struct BlockBuffers {
  BufferHandle particles, data, lambda, residual;
};

/// The device buffers a compiled scene lives in.
struct XpbdBuffers {
  BufferHandle position, previous, velocity;
  BufferHandle colliders, targets, contact_impulses;  ///< SceneBuffer (small placeholders when unused)
  BufferHandle level_set_grids;                      ///< SceneBuffer::level_set_grids (a placeholder when none)
  /// Force [N] per particle, float4 (xyz, w unused) in device order, that
  /// xpbd_external_force applies every substep; only with
  /// CompiledScene::external_forces (else no buffer: an invalid handle).
  BufferHandle external_force;
  std::vector<BlockBuffers> blocks;  ///< one per CompiledScene::blocks entry
};

/// The buffers of the contacts between meshes (mesh_contact_params.h),
/// rewritten by the host every frame (runtime/mesh_collision.h): room for
/// `capacity` contacts and `colors` colours.
struct MeshContactBuffers {
  BufferHandle table, particles, coefficients, normals, lambda;
  BufferHandle lambda_sum;  ///< the earlier substeps' lambdas, summed per contact (mesh_contact_params.h)
  BufferHandle motion;      ///< per contact, how far its shape's plane moves over the frame [m]
  std::uint32_t capacity = 0;
  std::uint32_t colors = 0;
  /// The Jacobi schedule (ContactSchedule::jacobi): table word 0 counts the
  /// contacts, word 1 the particles they touch; 4 corrections per contact,
  /// and per touched particle its slots among them (CSR: touched, offsets,
  /// slots; mesh_contact_params.h).
  bool jacobi = false;
  BufferHandle delta, touched, offsets, slots;
  std::uint32_t touched_capacity = 0;
  /// ContactSchedule::device_colored: the contacts lie uncoloured in their
  /// slots and `coloring` colours them on the device at the frame's start
  /// (its table's count word written by the host); `table` and `colors`
  /// are then unused by the solve.
  bool device_colored = false;
  DeviceContactColoring coloring;
  kernels::MeshContactParams params{};  ///< thickness, compliance, friction (the rest set per dispatch)
};

/// The buffers of the needles' and sutures' rows (suture_params.h),
/// rewritten by the host every frame (runtime/sutures.h).
struct SutureBuffers {
  BufferHandle table, needles, curve, slots, rows, weights, lambda;
};

/// The stages that end every sweep, after the bodies' constraints: the
/// mesh contacts (colour by colour), then the sutures. Each may be absent.
struct SweepExtras {
  const MeshContactBuffers* mesh_contacts = nullptr;
  const SutureBuffers* sutures = nullptr;
};

/// Appends one dispatch of xpbd_solve_mesh_contacts per colour k <
/// counters.size() (indirect over counter k, a barrier after each), with
/// `m` (colour set per dispatch). [in] table: the counts and firsts the
/// kernel reads (mesh_contact_params.h); order: its binding 9 (read when
/// m.ordered; any buffer otherwise).
void append_contact_colors(FrameProgram& program, const XpbdBuffers& buffers, const MeshContactBuffers& contacts,
                           BufferHandle table, BufferHandle order, std::span<const std::uint32_t> counters,
                           kernels::MeshContactParams m);

/// Appends one work item of xpbd_solve_mesh_contacts that solves colour
/// `color`'s contacts one after another (m.serial; the device colouring's
/// overflow set), then a barrier. [in] table, order, m: as above.
void append_serial_contact_color(FrameProgram& program, const XpbdBuffers& buffers, const MeshContactBuffers& contacts,
                                 BufferHandle table, BufferHandle order, std::uint32_t color,
                                 kernels::MeshContactParams m);

/// Contacts coloured on the device (coloring/device_contact_coloring.h):
/// its table and order, its cap and capacity.
struct DeviceColorTable {
  BufferHandle table, order;
  std::uint32_t colors = 0;    ///< the cap; the table holds colors + 1 (the overflow set last)
  std::uint32_t capacity = 0;  ///< contacts
};

/// Declares the counters of the device's colours below the cap (table
/// words 0 .. colors - 1, capacity: all contacts); returns their indices.
std::vector<std::uint32_t> declare_device_color_counters(FrameProgram& program, const DeviceColorTable& colored);

/// One sweep over contacts coloured on the device: each colour below the
/// cap dispatched indirectly (its count a device word, `counters` from
/// declare_device_color_counters), the slots read through the colouring's
/// order (the contacts stay where they were written), then the overflow set
/// by one work item, one contact after another. [in] m: thickness,
/// compliance, friction, inv_h2, reset_lambda and substep_end as for the
/// host's colours.
void append_device_colored_sweep(FrameProgram& program, const XpbdBuffers& buffers, const MeshContactBuffers& contacts,
                                 const DeviceColorTable& colored, std::span<const std::uint32_t> counters,
                                 kernels::MeshContactParams m);

/// The counters of the mesh contacts' indirect dispatches in a frame
/// program (begin_contacts), which every sweep over them names.
struct ContactCounters {
  std::vector<std::uint32_t> counters;  ///< colour k (host or device colours), or Jacobi's two
  DeviceColorTable device_colors;       ///< ContactSchedule::device_colored only
};

/// Opens a frame program's mesh contacts: with the device colouring, its
/// commands (once per frame, before anything moves) and counters
/// (DeviceColoringCounters); then the counters each sweep dispatches by.
/// Nothing without contacts (null). A program cut apart (solve_programs.h)
/// declares the same counters in the same order, so the indices match.
ContactCounters begin_contacts(FrameProgram& program, const XpbdBuffers& buffers,
                               const MeshContactBuffers* mesh_contacts);

/// The mesh contacts' parameters for a sweep of a substep ending at
/// `substep_end` (fraction of the frame), with `inv_h2` = 1 / h^2 [1/s^2];
/// reset_lambda 0 (the caller sets it for a substep's first sweep).
kernels::MeshContactParams mesh_contact_params(const MeshContactBuffers& contacts, float inv_h2, float substep_end);

/// One sweep over the mesh contacts in their schedule (host colours,
/// Jacobi, device colours), with parameters `m`.
void append_mesh_contact_sweep(FrameProgram& program, const XpbdBuffers& buffers, const MeshContactBuffers& contacts,
                               const ContactCounters& counters, kernels::MeshContactParams m);

/// One contact-only sweep at the end of substep `s` (SolverSettings::
/// contact_sweeps): the colliders' and tools' contacts with the particles
/// (the xpbd_solve_contacts block), then the mesh contacts (null: none),
/// their multipliers carried on from the substep's sweeps (no reset), no
/// other constraint. [in] counters: begin_contacts' of the same program.
void append_contact_sweep(FrameProgram& program, const CompiledScene& scene, const XpbdBuffers& buffers,
                          const SolverSettings& solver, int s, const MeshContactBuffers* mesh_contacts,
                          const ContactCounters& counters);

/// xpbd_predict's parameters for substeps of h [s] under `gravity`
/// [m/s^2] over `particles` particles (shared by the VBD program).
kernels::PredictParams predict_params(double h, const std::array<double, 3>& gravity, std::uint32_t particles);

/// xpbd_update_velocity's parameters, with the very float h predict_params
/// moves by.
kernels::UpdateVelocityParams update_params(double h, std::uint32_t particles);

/// Creates the buffers on `device` and uploads the compiled scene.
/// A device buffer holding `data`; an empty vector still gets a small
/// (16-byte) buffer so that every handle is valid.
template <class T>
Result<BufferHandle> make_buffer(Device& device, const std::vector<T>& data, std::string_view label) {
  auto buffer = device.create_buffer(std::max<std::size_t>(data.size() * sizeof(T), 16), label);
  if (!buffer) return buffer;
  if (!data.empty())
    if (Status s = device.write_buffer(*buffer, 0, data.data(), data.size() * sizeof(T)); !s) return s.error();
  return buffer;
}

Result<XpbdBuffers> upload_scene(Device& device, const CompiledScene& scene);

/// The dispatches of one frame of `solver`, with `gravity` [m/s^2].
/// With CompiledScene::external_forces, each substep starts with
/// xpbd_external_force (and a barrier) before its predict.
/// With mesh contacts, every sweep ends with one indirect dispatch per
/// contact colour (counts from its table, declared as counters); with
/// sutures, then one dispatch of one item for all their rows. With
/// MeshContactBuffers::device_colored the frame starts with the contacts'
/// colouring (append_device_contact_coloring) and every sweep ends with
/// append_device_colored_sweep; the program's first counters are then the
/// colouring's, in device_coloring_counter() order. With
/// SolverSettings::contact_sweeps, each substep ends (after the measuring
/// pass, before the velocity update) with that many append_contact_sweep.
FrameProgram build_xpbd_program(const CompiledScene& scene, const XpbdBuffers& buffers, const SolverSettings& solver,
                                const std::array<double, 3>& gravity, SweepExtras extras = {});

/// The device-coloured frame program's counters (build_xpbd_program; the
/// stepper's programs declare the whole frame's in the same order): the
/// contacts coloured, the overflow set and colour k < cap.
struct DeviceColoringCounters {
  static constexpr std::uint32_t contacts = 0;
  static constexpr std::uint32_t overflow = 3;
  static constexpr std::uint32_t first_color = 4;
};

}  // namespace sinew
