// solve_stepper.h — runs a frame as several programs that the host
// sequences: the residual-driven mode (sweep until the residual is below a
// tolerance, or a cap or time budget is spent) and the Chebyshev
// accelerator (SolverSettings). Without either, Simulation runs its one
// fixed frame program and this is not made.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "program/solve_programs.h"
#include "program/stats_program.h"
#include "sinew/simulation.h"

namespace sinew {

/// Work the host does between a substep's sweeps and its velocity update
/// (continuous collision detection, runtime/continuous_collision.h).
class SubstepHook {
 public:
  virtual ~SubstepHook() = default;
  /// Called after substep `substep`'s sweeps (round 0) and after each of
  /// its repair programs (round r > 0: r repairs run). [out] repair: run
  /// the substep's repair program (`iterations` more sweeps, the
  /// multipliers carried on), then call again.
  virtual Status after_sweeps(Device& device, int substep, int round, bool& repair) = 0;
};

class SolveStepper {
 public:
  /// Whether a solver needs this (residual mode or the accelerator on, or
  /// a SubstepHook: `per_substep`).
  static bool needed(const SolverSettings& solver, bool per_substep = false) {
    return per_substep || solver.residual_tolerance > 0.0 || solver.chebyshev_rho > 0.0 || solver.warm_start;
  }
  /// Builds and prepares the programs; the last one ends with the
  /// statistics of `stats` (append_stats). [in] scene, buffers must outlive
  /// the call only.
  /// extras: the mesh contacts' and sutures' buffers (each or none): they
  /// ride in every sweep; the residual checks measure the bodies'
  /// constraints only.
  static Result<std::unique_ptr<SolveStepper>> create(Device& device, const CompiledScene& scene,
                                                      const XpbdBuffers& buffers, const SolverSettings& solver,
                                                      const std::array<double, 3>& gravity, const StatsPlan& stats,
                                                      SweepExtras extras = {}, bool per_substep = false);
  /// Destroys the programs and builds them again (same buffers for the
  /// checks and the accelerator): after the mesh contacts outgrew their
  /// buffers or colours.
  Status rebuild(Device& device, const CompiledScene& scene, const XpbdBuffers& buffers,
                 const std::array<double, 3>& gravity, const StatsPlan& stats, SweepExtras extras);

  /// Runs one frame; fills stats.sweeps, stop, checked_residual,
  /// residual_checks and the device times (summed over the programs run).
  /// [in] hook: called after every substep's sweeps (only when made with
  /// per_substep; may be null then too).
  Status run_frame(Device& device, FrameStats& stats, SubstepHook* hook = nullptr);

  /// The frame's commands when every substep stops at its first check
  /// (fixed mode with the accelerator: the whole frame): what SceneInfo
  /// counts and what tests inspect.
  [[nodiscard]] const FrameProgram& frame_program() const { return shortest_frame_; }

  /// Whether the next frame warm-starts (false after a substep the time
  /// budget stopped); a saved state carries it (Simulation::save_state).
  [[nodiscard]] bool warm() const { return warm_; }
  void set_warm(bool warm) { warm_ = warm; }

 private:
  Status build(Device& device, const CompiledScene& scene, const XpbdBuffers& buffers,
               const std::array<double, 3>& gravity, const StatsPlan& stats, SweepExtras extras);
  Status run(Device& device, ProgramHandle program, DeviceTimes& times, bool first);
  Status run_hook(Device& device, SubstepHook* hook, int s, FrameStats& stats, std::uint64_t& sweeps);

  SolverSettings solver_;
  bool residual_mode_ = false;
  // A frame cut per substep for a SubstepHook: begin_[s], then repair_[s]
  // as often as the hook asks, then end_ (in the fixed mode too).
  bool per_substep_ = false;
  std::vector<ProgramHandle> repair_;
  ChebyshevBuffers chebyshev_;
  ResidualCheck check_;
  FrameProgram shortest_frame_;
  // Fixed mode: whole_ only. Residual mode: begin_[s] = (update of s - 1,)
  // predict and the first `iterations` sweeps of substep s, then a check;
  // chunks_[s][j]: check_interval more sweeps and a check (j past the end
  // reuses the last); end_: the last update and the statistics.
  ProgramHandle whole_;
  std::vector<ProgramHandle> begin_;
  // warm_start: begin_ warm-starts; begin_cold_[s] starts from lambda = 0,
  // run after a substep that the time budget stopped (warm_ false).
  std::vector<ProgramHandle> begin_cold_;
  bool warm_ = true;
  std::vector<std::vector<ProgramHandle>> chunks_;
  ProgramHandle end_;
  double chunk_ms_ = -1.0;  // wall time of the last chunk run (< 0: none yet)
};

}  // namespace sinew
