// solve_programs.h — the frame cut into programs the host sequences, for
// the residual-driven mode and the Chebyshev accelerator (SolverSettings).
//
// The fixed mode runs one program per frame (build_xpbd_program). Here the
// same commands are cut apart — per substep: predict, the first sweep (it
// resets lambda), a later sweep, the measuring pass, the velocity update —
// so they can be re-assembled: sweeps interleaved with the accelerator's
// extrapolation (xpbd_chebyshev), and frames split at residual checks
// (measure, reduce on the device, copy 3 words per block for the host).
// Cutting build_xpbd_program's own output, not re-emitting its dispatches,
// keeps one definition of what a sweep is: with the accelerator off and
// the same sweep count the re-assembled frame is bitwise the fixed one.
// The contact-only sweeps (SolverSettings::contact_sweeps) are the one
// exception: cut out they would read as later sweeps, so both programs
// emit them with append_contact_sweep (xpbd_program.h).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "compiler/scene_compiler.h"
#include "program/xpbd_program.h"
#include "sinew/scene.h"

namespace sinew {

using Commands = std::vector<FrameProgram::Command>;

/// Appends commands (dispatches, barriers, fills, copies) to a program.
void append_commands(FrameProgram& program, const Commands& commands);

/// The accelerator's history: the states after the last two sweeps, for
/// the positions (float4 per particle) and each block's lambdas.
struct ChebyshevBuffers {
  BufferHandle newer, older;
  std::vector<BufferHandle> block_newer, block_older;  ///< one per CompiledScene::blocks entry
};

/// The residual check: each block's measured residuals reduced on the
/// device (sum of squares as a double-float, max) into 3 words per block.
struct ResidualCheck {
  BufferHandle constants, scratch, results;
  std::vector<std::uint32_t> block_sizes;
  std::vector<std::uint32_t> in_use;  ///< per block, constraints in use (as StatsPlan::in_use)
  std::vector<std::uint32_t> squares_word, max_word;  ///< per block, in `results`
  std::uint32_t result_words = 0;
  std::vector<float> read_back;
};

/// What a check found: normalised residuals (see FrameStats::residual_rms).
struct CheckedResidual {
  double rms = 0.0;
  double max = 0.0;
};

/// Builds the pieces of the frame from one scene's build_xpbd_program.
class SolvePrograms {
 public:
  /// [in] solver: the scene's settings; chebyshev: its buffers when
  /// solver.chebyshev_rho > 0 (else unused); extras: the mesh contacts'
  /// and the sutures' buffers (each or none), which ride in every sweep
  /// after the bodies' constraints, as in build_xpbd_program.
  SolvePrograms(const CompiledScene& scene, const XpbdBuffers& buffers, const SolverSettings& solver,
                const std::array<double, 3>& gravity, ChebyshevBuffers chebyshev,
                SweepExtras extras = {});

  /// Declares on `program` the counters of the whole frame's indirect
  /// dispatches (the mesh contacts' colours), so their capacity is checked
  /// after the program runs: the commands cut from the whole frame keep
  /// their counters' buffer and word, not the declarations.
  void declare_counters(FrameProgram& program) const;

  [[nodiscard]] int substeps() const { return static_cast<int>(parts_.size()); }
  /// Predict of substep s (and whatever precedes its first sweep: the
  /// external forces, xpbd_external_force, when the scene has them).
  void append_predict(FrameProgram& program, int s) const;
  /// Sweeps number first .. first + count - 1 (1-based within the
  /// substep) of substep s, each followed by its accelerator step. With
  /// `warm` (only with SolverSettings::warm_start) sweep 1 starts from the
  /// last substep's lambdas; without, from 0 (xPBD's reset).
  void append_sweeps(FrameProgram& program, int s, int first, int count, bool warm) const;
  /// The measuring pass at the end of substep s (read-only).
  void append_measure(FrameProgram& program, int s) const;
  /// The end of substep s: its SolverSettings::contact_sweeps (as
  /// build_xpbd_program emits them), then its velocity update.
  void append_update(FrameProgram& program, int s) const;
  /// Measure, then reduce the residuals into check.results, declared as
  /// the program's last end read (FrameProgram::read_at_end).
  void append_check(FrameProgram& program, int s, const ResidualCheck& check) const;
  /// The accelerator's step after sweep n (1-based): none, record or mix.
  struct ChebyshevStep {
    bool record = false, mix = false;
    float omega = 1.0f;
  };
  [[nodiscard]] ChebyshevStep chebyshev_step(int n) const;

 private:
  struct Parts {
    Commands predict, first_sweep, sweep, measure, update;
    Commands contacts;  ///< one contact-only sweep (append_contact_sweep)
  };
  void append_chebyshev(FrameProgram& program, const ChebyshevStep& step) const;
  void append_warm_start(FrameProgram& program) const;

  std::vector<Parts> parts_;
  std::vector<Counter> counters_;  ///< of the whole frame (declare_counters)
  const CompiledScene& scene_;
  const XpbdBuffers& buffers_;
  SolverSettings solver_;
  ChebyshevBuffers chebyshev_;
  std::vector<double> omega_;  ///< omega_n for n = 0 .. (grown on demand, see chebyshev_step)
};

/// omega_n of Wang's recurrence (eq. 11) for sweeps n = 0 .. count - 1
/// (1-based sweep numbers; omega_0 unused): 1 up to sweep `delay`, then
/// 2 / (2 - rho^2) and 4 / (4 - rho^2 omega_{n-1}). Shared by the xPBD
/// sweeps and Vertex Block Descent's (vbd_program.h).
std::vector<double> chebyshev_omegas(double rho, int delay, std::size_t count);

/// The accelerator's buffers (zero-filled).
Result<ChebyshevBuffers> make_chebyshev_buffers(Device& device, const CompiledScene& scene);

/// The residual check's buffers.
Result<ResidualCheck> make_residual_check(Device& device, const CompiledScene& scene);

/// Takes the last check's 3 words per block from what the program that ran
/// it brought back (its last end read, declared by append_check), with no
/// transfer of its own. [pre] the last program the device waited for ends
/// with append_check. Errors (internal): that program brought back fewer words.
Result<CheckedResidual> read_residual_check(const Device& device, ResidualCheck& check);

}  // namespace sinew
