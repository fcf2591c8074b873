// stats_program.h — the per-frame statistics reduced on the device: the
// FrameStats errors (residuals, kinetic energy, volume change) and the sums
// the rigid tools need from the tissue (contact impulses and their moments,
// touching mass and inertia). The frame program ends with map kernels that
// write double-float terms and fixed-order reductions of them
// (kernels/shared/stats_params.h); the results are copied into one small
// buffer that the host reads after the frame: a few words instead of the
// position, velocity, residual and contact-impulse buffers it read before.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "compiler/scene_compiler.h"
#include "program/xpbd_program.h"

namespace sinew {

/// What the device reduced in the last frame, combined in double on the host.
struct DeviceStats {
  double residual_sum_squares = 0.0;  ///< over every constraint (normalised residuals)
  double residual_max = 0.0;
  std::uint64_t constraints = 0;
  double kinetic_energy = 0.0;  ///< [J]
  double volume = 0.0;          ///< total signed volume of the tet bodies [m^3]
  std::uint32_t inverted_tets = 0;  ///< tets whose signed volume is negative
  struct Tool {
    double sums[4][3] = {};  ///< frame impulse, its moment, last substep's impulse, its moment (contact_params.h)
    double mass = 0.0;       ///< mass of the particles touching it at the frame's end [kg]
    std::array<double, 9> inertia{};  ///< their inertia about the tool's centre [kg m^2], row-major
  };
  std::vector<Tool> tools;
};

/// The buffers and result layout of the statistics of one scene.
struct StatsPlan {
  bool errors = false;             ///< residuals, kinetic energy and volume are reduced
  std::uint32_t tools = 0;
  std::vector<std::uint32_t> block_sizes;
  /// Per block, the constraints in use (ConstraintBlock::in_use): the
  /// residuals' RMS divides by their sum (a block's unused slots hold
  /// residual 0). The Simulation refreshes it when the counts change.
  std::vector<std::uint32_t> in_use;
  std::uint32_t particles = 0, face_count = 0;
  /// Every tet of the tet bodies as (r, a, b, c) device particles, wound so
  /// that its rest volume is positive; a removed tet as (a, a, a, a), which
  /// never counts as inverted (clear_stats_tets). The host copy of `tets`.
  std::vector<std::array<std::uint32_t, 4>> tet_list;
  std::uint32_t removed_tets = 0;  ///< entries of tet_list marked removed
  /// Faces the buffers have room for (>= face_count): set_stats_faces
  /// changes the faces within it without making the plan again.
  std::uint32_t face_capacity = 0;
  BufferHandle constants, faces, tets, terms, scratch, results;
  std::uint32_t result_words = 0;
  // Word offsets in `results`:
  std::vector<std::uint32_t> residual_squares, residual_max;  ///< per block: a (hi, lo) pair, a float
  std::uint32_t kinetic_energy = 0, volume = 0;               ///< pairs
  std::uint32_t inverted = 0;                                 ///< a uint
  std::uint32_t tool_first = 0;                               ///< per tool 19 pairs: 12 sums, mass, 6 inertia
  std::vector<float> read_back;                               ///< the host copy, sized once
};

/// Creates the statistics' buffers. [in] faces: every tet body's boundary
/// triangles, wound outward, with a particle of the same body (the
/// reference point r of stats_surface_volume), as particle indices;
/// errors: SolverSettings::measure_errors; tools: rigid tools;
/// face_capacity: room for that many faces (at least faces.size());
/// tets: the tet bodies' tets, as StatsPlan::tet_list (the inverted count).
Result<StatsPlan> make_stats_plan(Device& device, const CompiledScene& scene,
                                  const std::vector<std::array<std::uint32_t, 4>>& faces, bool errors,
                                  std::uint32_t tools, std::uint32_t face_capacity,
                                  std::vector<std::array<std::uint32_t, 4>> tets);

/// Marks tets [in] removed (indices into tet_list) as removed: they no
/// longer count as inverted. One write per tet.
Status clear_stats_tets(Device& device, StatsPlan& plan, std::span<const std::uint32_t> removed);

/// Replaces the faces (as make_stats_plan's) when they fit in
/// face_capacity: one write of the faces and one of their count; the
/// frame program must be rebuilt (append_stats) to use the new count.
/// [out] fitted: false when they do not fit (nothing is written; make the
/// plan again).
Status set_stats_faces(Device& device, StatsPlan& plan, const std::vector<std::array<std::uint32_t, 4>>& faces,
                       bool& fitted);

/// Destroys the plan's buffers (before a plan for the scene's new topology
/// replaces it: its faces changed).
Status release_stats_plan(Device& device, StatsPlan& plan);

/// Appends the statistics to the end of a frame program (after its last
/// update of velocities), their results declared as the program's last end
/// read (FrameProgram::read_at_end): they reach the host with the wait that
/// ends the program. Nothing when the plan has neither errors nor tools.
void append_stats(FrameProgram& program, const StatsPlan& plan, const XpbdBuffers& buffers);

/// Takes the results the frame's last program brought back (its last end
/// read, Device::end_reads) into plan.read_back, with no transfer of its
/// own. [pre] the last program the device waited for was made with
/// append_stats. Errors (internal): that program brought back fewer words.
Status collect_stats(const Device& device, StatsPlan& plan);

/// Decodes the results collect_stats took into `out`.
Status read_stats(const StatsPlan& plan, DeviceStats& out);

}  // namespace sinew
