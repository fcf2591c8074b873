// sph_solver.h — weakly compressible SPH on a device (issue 15, parts 2-4):
// fluid particles and boundary particles on the neighbour grid, one
// program per step:
//   sph_boundary_move      the boundary to the host's latest pose (moving_boundary)
//   sph_emit_flags, sph_emit, sph_emit_commit
//                          the emitters' layers appended where there is room (emitters)
//   sph_sink_flags, compaction, sph_pack, copies
//                          the particles inside sinks removed (sinks)
//   the grid               sorted by cell (neighbour_grid.h)
//   sph_density, sph_gather, sph_step [+ sph_fluid_cells, sph_boundary_force]
//   reduce                 the fastest particle, for the CFL check
// A scene without sinks, emitters or a moving boundary runs none of their
// kernels. The particle count n lives on the device (the grid's counts[0])
// and changes there; the host reads it back with the statistics.
//
// Particles carry an id in their velocity's w (sph_flow_params.h); their
// storage is re-sorted along the grid every step. Boundary particles
// (Akinci et al. 2012) get their volume on the device at create(): V_b = 1
// / sum_k W_bk over the boundary particles. The method and its papers:
// kernels/shared/sph_params.h.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "backends/backend.h"
#include "neighbours/neighbour_grid.h"
#include "sinew/fluid.h"
#include "sph_params.h"
#include "pbf_params.h"
#include "sph_tension_params.h"

namespace sinew {

using SphSettings = FluidSettings;
using SphParticle = FluidParticle;

class SphSolver {
 public:
  /// The fluid of `desc` (its device options unused) on `device`. Errors:
  /// as Fluid::create.
  static Result<std::unique_ptr<SphSolver>> create(Device& device, const FluidDesc& desc);
  /// Fluid at rest at `fluid` [m] and fixed boundary particles.
  static Result<std::unique_ptr<SphSolver>> create(Device& device, const SphSettings& settings,
                                                   std::span<const std::array<double, 3>> fluid,
                                                   std::span<const std::array<double, 3>> boundary);
  ~SphSolver();
  SphSolver(const SphSolver&) = delete;
  SphSolver& operator=(const SphSolver&) = delete;

  /// As Fluid::step.
  Status step(int steps);
  /// The fastest fluid particle after the last step() [m/s].
  [[nodiscard]] double last_max_speed() const { return stats_.max_speed; }
  /// last_max_speed() / c0: above about 0.1 the density varies more than
  /// about 1% (weak compressibility no longer holds).
  [[nodiscard]] double mach() const { return stats_.max_speed / speed_of_sound_; }
  /// [out] the fluid particles by increasing id, as the last step left
  /// them (density and pressure from its start).
  Status read(std::vector<SphParticle>& fluid);
  [[nodiscard]] const FluidStats& stats() const { return stats_; }

  Status set_emitter(std::size_t index, const FluidEmitter& emitter);
  Status set_sink(std::size_t index, const FluidSink& sink);
  Status set_boundary(std::span<const std::array<float, 3>> positions, std::span<const std::array<float, 3>> velocities);
  Status read_boundary_impulses(std::vector<std::array<float, 3>>& impulses);

  [[nodiscard]] std::uint32_t fluid_count() const { return stats_.particles; }
  [[nodiscard]] std::uint32_t boundary_count() const { return boundary_; }
  [[nodiscard]] std::uint32_t capacity() const { return capacity_; }
  [[nodiscard]] double particle_mass() const { return mass_; }
  [[nodiscard]] const kernels::SphParams& params() const { return params_; }
  /// The boundary's device arrays, float4 per boundary particle (invalid
  /// handles without moving_boundary, boundary_forces): what a stage
  /// coupling the fluid with tissue on the same device writes (positions,
  /// velocities) and reads (impulses) instead of set_boundary and
  /// read_boundary_impulses.
  [[nodiscard]] BufferHandle boundary_position_buffer() const { return boundary_position_; }
  [[nodiscard]] BufferHandle boundary_velocity_buffer() const { return boundary_velocity_; }
  [[nodiscard]] BufferHandle impulse_buffer() const { return impulse_; }
  /// A saved state's part of the fluid (Simulation::save_state): [out] out:
  /// every device buffer a step carries to the next (particles, the grid,
  /// the emitters' and sinks' records), with its size [bytes], appended.
  void state_buffers(std::vector<std::pair<BufferHandle, std::size_t>>& out) const;
  /// ... and the host's: the counts, the next particle id, the emitters' settings.
  struct HostState {
    FluidStats stats;
    std::uint32_t next_id = 0;
  };
  [[nodiscard]] HostState host_state() const { return {stats_, next_id_}; }
  void set_host_state(const HostState& state) {
    stats_ = state.stats;
    next_id_ = state.next_id;
  }
  [[nodiscard]] std::vector<FluidEmitter>& emitter_settings() { return emitters_desc_; }

 private:
  explicit SphSolver(Device& device) : device_(device) {}
  Status build_program(bool have_sinks, bool have_emitters, bool moving, bool forces);
  void append_wcsph(FrameProgram& step, bool forces) const;
  void append_pbf(FrameProgram& step) const;
  /// Emitter `index`'s record (sph_flow_params.h) and, at create, its lattice.
  Status write_emitter(std::size_t index, const FluidEmitter& emitter, std::vector<float>* pattern);
  Status check_emitter(std::size_t index, const FluidEmitter& emitter) const;
  Status read_counts();

  Device& device_;
  std::unique_ptr<NeighbourGrid> grid_;
  BufferHandle velocity_, sorted_velocity_, density_, pressure_, speed2_, scratch_;
  BufferHandle state_, emitters_, emit_flags_, pattern_, sinks_, flags_, kept_, compact_scratch_;
  BufferHandle boundary_position_, boundary_velocity_, impulse_;
  BufferHandle near_;  // uint per grid bucket: 1 where fluid lies in the 27 cells around (sph_fluid_cells)
  BufferHandle previous_, lambda_, moved_;  // pbf
  BufferHandle normals_;                    // surface tension
  kernels::TensionParams tension_params_{};
  bool tension_ = false;
  kernels::PbfParams pbf_params_{};
  bool pbf_ = false;
  int iterations_ = 0;
  std::uint32_t max_word_ = 0;  // the scratch word that holds the maximum |v|^2 after a step
  double speed_of_sound_ = 0.0, time_step_ = 0.0, h_ = 0.0, spacing_ = 0.0, mass_ = 0.0;
  ProgramHandle program_{};
  bool have_program_ = false;
  ProgramHandle rest_program_{};  // a step() call's later steps, without sph_boundary_move (moving boundaries)
  bool have_rest_program_ = false;
  kernels::SphParams params_{};
  std::uint32_t boundary_ = 0, capacity_ = 0, slots_ = 0;
  std::vector<FluidEmitter> emitters_desc_;
  std::vector<std::uint32_t> emitter_points_;  // lattice points per emitter
  std::vector<std::array<double, 3>> boundary_at_;  // the boundary's latest positions (the emitters' check)
  std::size_t sinks_count_ = 0;
  std::uint32_t lattice_points_ = 0, next_id_ = 0;  // the emitters' points; the next fluid id
  FluidStats stats_;
  std::vector<std::pair<BufferHandle, std::size_t>> sized_;  // the buffers create made, with their sizes
};

}  // namespace sinew
