// solve_programs.cpp — the frame's pieces for the residual-driven mode and
// the Chebyshev accelerator (see solve_programs.h).
//
// Accelerator: Huamin Wang, "A Chebyshev Semi-Iterative Approach for
// Accelerating Projective and Position-Based Dynamics", ACM TOG 34(6),
// SIGGRAPH Asia 2015, eqs. 11-12: with the estimated spectral radius rho of
// one sweep, omega_{k+1} = 1 for k < S, 2 / (2 - rho^2) for k = S and
// 4 / (4 - rho^2 omega_k) after, and
//   q^{k+1} = omega_{k+1} (gamma (q^ - q^k) + q^k - q^{k-1}) + q^{k-1}.
// Wang accelerates PBD positions. xPBD also carries lambda, with
// x - x~ = M^-1 grad C^T lambda (each sweep moves x by W grad C dlambda and
// lambda by dlambda); the residual C + alpha~ lambda and the force balance
// both read it. So the state q here is (x, lambda): the weights of eq. 12
// sum to 1, an affine combination keeps that linear relation (up to the
// change of grad C between the sweeps combined), and the sweeps converge
// to the same xPBD solution as without acceleration. Extrapolating x alone
// would leave lambda describing a different correction than the one
// applied, and the stiffness seen would depend on the extrapolation.
#include "program/solve_programs.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <variant>

#include "accelerator_params.h"
#include "fem_params.h"
#include "program/primitives.h"
#include "xpbd_params.h"

namespace sinew {
namespace {

// A block's sweep or measuring dispatch (SolveParams); the mesh contacts'
// dispatches (MeshContactParams) ride along with the sweep they follow.
bool is_solve(const Dispatch& d) {
  return kernel_name(d.kernel).starts_with("xpbd_solve_") && d.kernel != Kernel::xpbd_solve_mesh_contacts;
}

kernels::SolveParams solve_params(const Dispatch& d) {
  kernels::SolveParams p{};
  std::memcpy(&p, d.params, sizeof(p));
  return p;
}

// The sweeps of the measuring pass write only the residual, so they may run
// at any substep; their substep_end says where the colliders and targets are.
Commands with_substep_end(Commands commands, float substep_end) {
  for (auto& c : commands) {
    if (auto* d = std::get_if<Dispatch>(&c); d && is_solve(*d)) {
      kernels::SolveParams p = solve_params(*d);
      p.substep_end = substep_end;
      std::memcpy(d->params, &p, sizeof(p));
    }
  }
  return commands;
}

Result<BufferHandle> zero_buffer(Device& device, std::size_t bytes, std::string_view label) {
  return device.create_buffer(std::max<std::size_t>(bytes, 16), label);
}

// Leading floats of a block's lambda record that are multipliers: the
// corotational solve keeps its rotation quaternion after them.
std::uint32_t lambda_width(const ConstraintBlock& block) {
  if (block.kernel == Kernel::xpbd_solve_corotational) return std::min<std::uint32_t>(block.lambda_stride, SINEW_FEM_ROTATION);
  return block.lambda_stride;
}

}  // namespace

void append_commands(FrameProgram& program, const Commands& commands) {
  for (const auto& command : commands) {
    if (const auto* d = std::get_if<Dispatch>(&command)) {
      program.dispatch_raw(*d);
    } else if (std::holds_alternative<Barrier>(command)) {
      program.barrier();
    } else if (const auto* f = std::get_if<Fill>(&command)) {
      program.fill(f->buffer, f->word, f->words, f->value);
    } else if (const auto* c = std::get_if<Copy>(&command)) {
      program.copy(c->source, c->source_word, c->target, c->target_word, c->words);
    }
  }
}

SolvePrograms::SolvePrograms(const CompiledScene& scene, const XpbdBuffers& buffers, const SolverSettings& solver,
                             const std::array<double, 3>& gravity, ChebyshevBuffers chebyshev,
                             SweepExtras extras)
    : scene_(scene), buffers_(buffers), solver_(solver), chebyshev_(std::move(chebyshev)) {
  // Two iterations give one sweep of each kind; measuring on gives the
  // measuring pass (emitted once, in the last substep).
  SolverSettings cut = solver;
  cut.iterations = 2;
  cut.measure_errors = true;
  cut.contact_sweeps = 0;  // emitted by append_update (below): they would read as later sweeps here
  const FrameProgram whole = build_xpbd_program(scene, buffers, cut, gravity, extras);
  counters_ = whole.counters();
  enum class Phase { predict, first_sweep, sweep, measure, update } phase = Phase::predict;
  for (const auto& command : whole.commands()) {
    if (const auto* d = std::get_if<Dispatch>(&command)) {
      if (d->kernel == Kernel::xpbd_external_force || d->kernel == Kernel::xpbd_predict) {
        // A substep opens with its external forces (when the scene has
        // them) or else its predict: the predict that follows the forces
        // belongs to the same substep's part.
        if (parts_.empty() || phase != Phase::predict) parts_.emplace_back();
        phase = Phase::predict;
      } else if (d->kernel == Kernel::xpbd_update_velocity) {
        phase = Phase::update;
      } else if (is_solve(*d)) {
        const kernels::SolveParams p = solve_params(*d);
        phase = p.measure_only ? Phase::measure : p.reset_lambda ? Phase::first_sweep : Phase::sweep;
      }
    }
    if (parts_.empty()) parts_.emplace_back();
    Parts& part = parts_.back();
    switch (phase) {
      case Phase::predict: part.predict.push_back(command); break;
      case Phase::first_sweep: part.first_sweep.push_back(command); break;
      case Phase::sweep: part.sweep.push_back(command); break;
      case Phase::measure: part.measure.push_back(command); break;
      case Phase::update: part.update.push_back(command); break;
    }
  }
  // Every substep gets the last one's measuring pass, at its own point of
  // the frame (substep_end of its sweeps).
  const Commands measure = parts_.empty() ? Commands{} : parts_.back().measure;
  for (Parts& part : parts_) {
    float substep_end = 1.0f;
    for (const auto& c : part.first_sweep)
      if (const auto* d = std::get_if<Dispatch>(&c); d && is_solve(*d)) {
        substep_end = solve_params(*d).substep_end;
        break;
      }
    part.measure = with_substep_end(measure, substep_end);
  }
  // Each substep's contact-only sweep, its dispatches naming the counters
  // the whole frame declares (begin_contacts declares them first, in the
  // same order, on a scratch program).
  if (solver.contact_sweeps > 0) {
    for (int s = 0; s < static_cast<int>(parts_.size()); ++s) {
      FrameProgram scratch;
      const ContactCounters contact_counters = begin_contacts(scratch, buffers, extras.mesh_contacts);
      const std::size_t before = scratch.commands().size();
      append_contact_sweep(scratch, scene, buffers, solver, s, extras.mesh_contacts, contact_counters);
      parts_[s].contacts.assign(scratch.commands().begin() + std::ptrdiff_t(before), scratch.commands().end());
    }
  }
  // omega_n of the sweeps this solver may run (Wang's eq. 11, sweep n = k + 1).
  int most = solver.iterations;
  if (solver.residual_tolerance > 0.0) {
    const int more = std::max(0, solver.max_iterations - solver.iterations);
    most += (more + solver.check_interval - 1) / solver.check_interval * solver.check_interval;
  }
  omega_ = chebyshev_omegas(solver.chebyshev_rho, solver.chebyshev_delay, std::size_t(most) + 2);
}

std::vector<double> chebyshev_omegas(double rho, int delay, std::size_t count) {
  std::vector<double> omega(count, 1.0);
  const double rho2 = rho * rho;
  for (int n = delay + 1; n < int(omega.size()); ++n)
    omega[n] = n == delay + 1 ? 2.0 / (2.0 - rho2) : 4.0 / (4.0 - rho2 * omega[n - 1]);
  return omega;
}

SolvePrograms::ChebyshevStep SolvePrograms::chebyshev_step(int n) const {
  ChebyshevStep step;
  if (solver_.chebyshev_rho <= 0.0) return step;
  const int s = solver_.chebyshev_delay;
  if (n == s - 1 || n == s) {
    step.record = true;  // the two states the first extrapolation combines
  } else if (n > s) {
    step.mix = true;
    // Past the precomputed range (never in a valid frame) the recurrence's
    // limit is as good: omega_n converges geometrically.
    step.omega = static_cast<float>(omega_[std::min<std::size_t>(std::size_t(n), omega_.size() - 1)]);
  }
  return step;
}

void SolvePrograms::append_chebyshev(FrameProgram& program, const ChebyshevStep& step) const {
  if (!step.record && !step.mix) return;
  kernels::ChebyshevParams p{};
  p.mix = step.mix ? 1u : 0u;
  p.omega = step.omega;
  p.gamma = static_cast<float>(solver_.chebyshev_gamma);
  // Positions: xyz of each float4 (w, the inverse mass, is not state).
  p.count = static_cast<std::uint32_t>(scene_.positions.size() * 4);
  p.stride = 4;
  p.width = 3;
  program.dispatch(Kernel::xpbd_chebyshev, p.count, {buffers_.position, chebyshev_.newer, chebyshev_.older}, p);
  for (std::size_t k = 0; k < scene_.blocks.size(); ++k) {
    const ConstraintBlock& block = scene_.blocks[k];
    p.count = block.size() * block.lambda_stride;
    p.stride = block.lambda_stride;
    p.width = lambda_width(block);
    if (p.count == 0) continue;
    program.dispatch(Kernel::xpbd_chebyshev, p.count,
                     {buffers_.blocks[k].lambda, chebyshev_.block_newer[k], chebyshev_.block_older[k]}, p);
  }
  program.barrier();
}

void SolvePrograms::append_predict(FrameProgram& program, int s) const { append_commands(program, parts_[s].predict); }

void SolvePrograms::declare_counters(FrameProgram& program) const {
  for (const Counter& c : counters_) program.counter(c.label, c.buffer, c.word, c.capacity);
}

void SolvePrograms::append_warm_start(FrameProgram& program) const {
  for (std::size_t k = 0; k < scene_.blocks.size(); ++k) {
    const ConstraintBlock& block = scene_.blocks[k];
    kernels::WarmStartParams p{};
    p.arity = block.arity;
    for (std::size_t c = 0; c + 1 < block.color_offsets.size(); ++c) {
      p.first = block.color_offsets[c];
      p.count = block.color_count(c);
      if (p.count == 0) continue;  // emptied by topology changes
      program.dispatch(Kernel::xpbd_warm_start, p.count,
                       {buffers_.position, buffers_.previous, buffers_.blocks[k].particles, buffers_.blocks[k].lambda}, p);
      program.barrier();
    }
  }
}

void SolvePrograms::append_sweeps(FrameProgram& program, int s, int first, int count, bool warm) const {
  for (int n = first; n < first + count; ++n) {
    // Warm start: the first sweep keeps the lambdas the warm start applied.
    if (n == 1 && warm) append_warm_start(program);
    append_commands(program, n == 1 && !warm ? parts_[s].first_sweep : parts_[s].sweep);
    append_chebyshev(program, chebyshev_step(n));
  }
}

void SolvePrograms::append_measure(FrameProgram& program, int s) const { append_commands(program, parts_[s].measure); }

void SolvePrograms::append_update(FrameProgram& program, int s) const {
  for (int c = 0; c < solver_.contact_sweeps; ++c) append_commands(program, parts_[s].contacts);
  append_commands(program, parts_[s].update);
}

void SolvePrograms::append_check(FrameProgram& program, int s, const ResidualCheck& check) const {
  append_measure(program, s);
  program.barrier();
  std::uint32_t scratch = 0;
  for (std::size_t k = 0; k < check.block_sizes.size(); ++k) {
    const std::uint32_t n = check.block_sizes[k];
    const DeviceCount count{check.constants, static_cast<std::uint32_t>(k), n};
    const DeviceWords residual{buffers_.blocks[k].residual, 0};
    std::uint32_t from = append_reduce_dd(program, count, DdItems::squares, residual, 1, {check.scratch, scratch});
    program.copy(check.scratch, from, check.results, check.squares_word[k], 2);
    scratch += reduce_dd_scratch_words(n);
    from = append_reduce(program, count, ReduceOp::max_f32, residual, 1, {check.scratch, scratch});
    program.copy(check.scratch, from, check.results, check.max_word[k], 1);
    scratch += reduce_scratch_words(n);
  }
  program.barrier();
  // The results come back with the wait that ends the program.
  if (check.result_words > 0) program.read_at_end(check.results, 0, check.result_words);
}

Result<ChebyshevBuffers> make_chebyshev_buffers(Device& device, const CompiledScene& scene) {
  ChebyshevBuffers b;
  const std::size_t particle_bytes = scene.positions.size() * sizeof(kernels::float4);
  for (auto [handle, label] : {std::pair{&b.newer, "chebyshev newer positions"}, std::pair{&b.older, "chebyshev older positions"}}) {
    auto made = zero_buffer(device, particle_bytes, label);
    if (!made) return made.error();
    *handle = *made;
  }
  for (const ConstraintBlock& block : scene.blocks) {
    const std::size_t bytes = std::size_t{block.size()} * block.lambda_stride * sizeof(float);
    const std::string name(kernel_name(block.kernel));
    auto newer = zero_buffer(device, bytes, "chebyshev newer lambda " + name);
    if (!newer) return newer.error();
    auto older = zero_buffer(device, bytes, "chebyshev older lambda " + name);
    if (!older) return older.error();
    b.block_newer.push_back(*newer);
    b.block_older.push_back(*older);
  }
  return b;
}

Result<ResidualCheck> make_residual_check(Device& device, const CompiledScene& scene) {
  ResidualCheck check;
  std::uint32_t scratch_words = 0;
  for (const ConstraintBlock& block : scene.blocks) {
    check.block_sizes.push_back(block.size());
    check.in_use.push_back(block.in_use());
    check.squares_word.push_back(check.result_words);
    check.max_word.push_back(check.result_words + 2);
    check.result_words += 3;
    scratch_words += reduce_dd_scratch_words(block.size()) + reduce_scratch_words(block.size());
  }
  auto made = zero_buffer(device, check.block_sizes.size() * 4, "residual check counts");
  if (!made) return made.error();
  check.constants = *made;
  if (!check.block_sizes.empty())
    if (Status s = device.write_buffer(check.constants, 0, check.block_sizes.data(), check.block_sizes.size() * 4); !s)
      return s.error();
  made = zero_buffer(device, std::size_t{scratch_words} * 4, "residual check scratch");
  if (!made) return made.error();
  check.scratch = *made;
  made = zero_buffer(device, std::size_t{check.result_words} * 4, "residual check results");
  if (!made) return made.error();
  check.results = *made;
  check.read_back.resize(check.result_words);
  return check;
}

Result<CheckedResidual> read_residual_check(const Device& device, ResidualCheck& check) {
  CheckedResidual out;
  if (check.result_words == 0) return out;
  std::vector<float>& r = check.read_back;
  const std::span<const std::uint32_t> words = device.end_reads();
  if (words.size() < check.result_words)
    return Error(ErrorCode::internal, "residual check: the last program brought back " + std::to_string(words.size()) +
                                          " words, not its " + std::to_string(check.result_words) + " results");
  std::memcpy(r.data(), words.data() + (words.size() - check.result_words), std::size_t{check.result_words} * 4);
  double sum = 0.0;
  std::uint64_t constraints = 0;
  for (std::size_t k = 0; k < check.block_sizes.size(); ++k) {
    if (check.block_sizes[k] == 0) continue;
    sum += double(r[check.squares_word[k]]) + double(r[check.squares_word[k] + 1]);
    out.max = std::max(out.max, double(r[check.max_word[k]]));
    constraints += check.in_use[k];
  }
  out.rms = constraints ? std::sqrt(sum / double(constraints)) : 0.0;
  return out;
}

}  // namespace sinew
