// solve_stepper.cpp — the host side of the residual-driven mode and the
// Chebyshev accelerator (solve_stepper.h, program/solve_programs.h).
//
// A frame in residual mode: per substep, one program predicts and runs
// `iterations` sweeps, then checks (measures the residuals, reduces them on
// the device, 3 words per block come back); while the RMS residual is above
// the tolerance, the cap is not reached and the next group of sweeps fits
// in the substep's share of the time budget, a program of check_interval
// sweeps and a check runs. The velocity update of a substep rides at the
// front of the next substep's first program, so a substep that converges
// at its first check costs one round trip.
#include "runtime/solve_stepper.h"

#include <algorithm>
#include <chrono>
#include <string>

namespace sinew {

// A substep stopped at max_iterations passes its lambdas on only if it
// ended within this many times the residual tolerance (run_frame).
constexpr double kCarryAtCap = 10.0;
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

int rank(SolveStop stop) {
  switch (stop) {
    case SolveStop::time_budget: return 3;
    case SolveStop::iteration_cap: return 2;
    case SolveStop::converged: return 1;
    case SolveStop::fixed: return 0;
  }
  return 0;
}

// Distinct programs of check_interval sweeps per substep: the accelerator's
// omega changes from sweep to sweep (converging geometrically to its
// limit), so each group of sweeps until the cap would be its own program;
// past this many per substep the last one is run again (its omegas are
// then within float rounding of the limit for rho <= ~0.999).
constexpr int kMostChunkPrograms = 512;

}  // namespace

Result<std::unique_ptr<SolveStepper>> SolveStepper::create(Device& device, const CompiledScene& scene,
                                                           const XpbdBuffers& buffers, const SolverSettings& solver,
                                                           const std::array<double, 3>& gravity,
                                                           const StatsPlan& stats,
                                                           SweepExtras extras, bool per_substep) {
  // The frame's mesh contacts change every frame (and their slots with
  // them): no lambda of theirs may be carried into a substep.
  if (solver.warm_start && (extras.mesh_contacts || extras.sutures))
    return Error(ErrorCode::bad_parameter, "solver.warm_start supports distance and volume constraints only; "
                                           "the scene has mesh contacts (mesh_collision) or needles");
  if (solver.warm_start)
    for (const ConstraintBlock& block : scene.blocks)
      if (block.kernel != Kernel::xpbd_solve_distance && block.kernel != Kernel::xpbd_solve_volume)
        return Error(ErrorCode::bad_parameter, "solver.warm_start supports distance and volume constraints only; "
                                               "the scene has " + std::string(kernel_name(block.kernel)) +
                                               " constraints");
  auto st = std::unique_ptr<SolveStepper>(new SolveStepper());
  st->solver_ = solver;
  st->residual_mode_ = solver.residual_tolerance > 0.0;
  st->per_substep_ = per_substep;
  if (solver.chebyshev_rho > 0.0) {
    auto made = make_chebyshev_buffers(device, scene);
    if (!made) return made.error();
    st->chebyshev_ = std::move(*made);
  }
  if (st->residual_mode_) {
    auto check = make_residual_check(device, scene);
    if (!check) return check.error();
    st->check_ = std::move(*check);
  }
  if (Status s = st->build(device, scene, buffers, gravity, stats, extras); !s) return s.error();
  return st;
}

Status SolveStepper::rebuild(Device& device, const CompiledScene& scene, const XpbdBuffers& buffers,
                             const std::array<double, 3>& gravity, const StatsPlan& stats,
                             SweepExtras extras) {
  check_.in_use.clear();  // the counts in use changed (topology changes, graspers)
  for (const ConstraintBlock& block : scene.blocks) check_.in_use.push_back(block.in_use());
  std::vector<ProgramHandle> all{whole_, end_};
  all.insert(all.end(), begin_.begin(), begin_.end());
  all.insert(all.end(), repair_.begin(), repair_.end());
  all.insert(all.end(), begin_cold_.begin(), begin_cold_.end());
  for (const auto& chunks : chunks_) all.insert(all.end(), chunks.begin(), chunks.end());
  for (const ProgramHandle p : all)
    if (p.id != UINT32_MAX)
      if (Status s = device.destroy_program(p); !s) return s;
  whole_ = end_ = ProgramHandle{};
  begin_.clear();
  repair_.clear();
  begin_cold_.clear();
  chunks_.clear();
  shortest_frame_ = FrameProgram{};
  return build(device, scene, buffers, gravity, stats, extras);
}

// The programs (the buffers exist): fixed mode one, residual mode the
// begin, chunk and end programs of every substep.
Status SolveStepper::build(Device& device, const CompiledScene& scene, const XpbdBuffers& buffers,
                           const std::array<double, 3>& gravity, const StatsPlan& stats,
                           SweepExtras extras) {
  const SolverSettings& solver = solver_;
  SolvePrograms parts(scene, buffers, solver, gravity, chebyshev_, extras);
  const int substeps = parts.substeps();
  const int iterations = solver.iterations;
  const auto prepare = [&](const FrameProgram& program) {
    FrameProgram counted = program;
    parts.declare_counters(counted);
    return device.create_program(counted);
  };
  // end_: (the last substep's measuring pass,) its velocity update and the statistics.
  const auto build_end = [&](bool measure) -> Status {
    FrameProgram end;
    if (measure) parts.append_measure(end, substeps - 1);
    parts.append_update(end, substeps - 1);
    append_stats(end, stats, buffers);
    append_commands(shortest_frame_, Commands(end.commands()));
    auto made = prepare(end);
    if (!made) return made.error();
    end_ = *made;
    return {};
  };

  // The hook's repair programs: `iterations` more sweeps of substep s,
  // the multipliers carried on (no reset).
  if (per_substep_)
    for (int s = 0; s < substeps; ++s) {
      FrameProgram repair;
      parts.append_sweeps(repair, s, iterations + 1, iterations, false);
      auto made = prepare(repair);
      if (!made) return made.error();
      repair_.push_back(*made);
    }
  if (!residual_mode_ && per_substep_) {
    // The fixed mode's frame cut at every substep's end (before its velocity update).
    begin_.resize(substeps);
    for (int s = 0; s < substeps; ++s) {
      FrameProgram begin;
      if (s > 0) parts.append_update(begin, s - 1);
      parts.append_predict(begin, s);
      parts.append_sweeps(begin, s, 1, iterations, false);
      append_commands(shortest_frame_, Commands(begin.commands()));
      auto made = prepare(begin);
      if (!made) return made.error();
      begin_[s] = *made;
    }
    return build_end(solver.measure_errors);
  }
  if (!residual_mode_) {
    FrameProgram& p = shortest_frame_;
    for (int s = 0; s < substeps; ++s) {
      parts.append_predict(p, s);
      parts.append_sweeps(p, s, 1, iterations, false);  // warm_start needs residual mode
      if (solver.measure_errors && s + 1 == substeps) parts.append_measure(p, s);
      parts.append_update(p, s);
    }
    append_stats(p, stats, buffers);
    auto made = prepare(p);
    if (!made) return made.error();
    whole_ = *made;
    return {};
  }

  const int c = solver.check_interval;
  const int chunks_to_cap = (std::max(0, solver.max_iterations - iterations) + c - 1) / c;
  int distinct = std::min(chunks_to_cap, 1);
  if (solver.chebyshev_rho > 0.0) {
    // Every group until the accelerator has started and settled, within a
    // bound on the programs held.
    const int until_started = (std::max(0, solver.chebyshev_delay + 1 - iterations) + c - 1) / c + 1;
    distinct = std::min(chunks_to_cap, std::max(until_started, kMostChunkPrograms / std::max(1, substeps)));
  }
  begin_.resize(substeps);
  chunks_.resize(substeps);
  if (solver.warm_start) begin_cold_.resize(substeps);
  for (int s = 0; s < substeps; ++s) {
    const auto begin_program = [&](bool warm) {
      FrameProgram begin;
      if (s > 0) parts.append_update(begin, s - 1);
      parts.append_predict(begin, s);
      parts.append_sweeps(begin, s, 1, iterations, warm);
      parts.append_check(begin, s, check_);
      return begin;
    };
    const FrameProgram begin = begin_program(solver.warm_start);
    append_commands(shortest_frame_, Commands(begin.commands()));
    auto made = prepare(begin);
    if (!made) return made.error();
    begin_[s] = *made;
    if (solver.warm_start) {
      made = prepare(begin_program(false));
      if (!made) return made.error();
      begin_cold_[s] = *made;
    }
    for (int j = 0; j < distinct; ++j) {
      FrameProgram chunk;
      parts.append_sweeps(chunk, s, iterations + j * c + 1, c, false);
      parts.append_check(chunk, s, check_);
      auto chunk_made = prepare(chunk);
      if (!chunk_made) return chunk_made.error();
      chunks_[s].push_back(*chunk_made);
    }
  }
  return build_end(false);
}

Status SolveStepper::run(Device& device, ProgramHandle program, DeviceTimes& times, bool first) {
  if (Status s = device.run_program(program); !s) return s;
  DeviceTimes t;
  if (Status s = device.last_run_times(t); !s) return s;
  if (first) {
    times = t;
    return {};
  }
  times.timed = times.timed && t.timed;
  times.span_ms += t.span_ms;
  for (std::size_t k = 0; k < DeviceTimes::max_kernels; ++k) {
    times.kernel_ms[k] += t.kernel_ms[k];
    times.dispatches[k] += t.dispatches[k];
  }
  return {};
}

// The hook after substep s's sweeps, and the repairs it asks for.
Status SolveStepper::run_hook(Device& device, SubstepHook* hook, int s, FrameStats& stats,
                              std::uint64_t& sweeps) {
  if (!hook) return {};
  for (int round = 0;; ++round) {
    bool repair = false;
    if (Status st = hook->after_sweeps(device, s, round, repair); !st) return st;
    if (!repair) return {};
    if (Status st = run(device, repair_[s], stats.device, false); !st) return st;
    sweeps += std::uint64_t(solver_.iterations);
  }
}

Status SolveStepper::run_frame(Device& device, FrameStats& stats, SubstepHook* hook) {
  const int iterations = solver_.iterations;
  if (!residual_mode_ && per_substep_) {
    std::uint64_t sweeps = 0;
    for (int s = 0; s < static_cast<int>(begin_.size()); ++s) {
      if (Status st = run(device, begin_[s], stats.device, s == 0); !st) return st;
      sweeps += std::uint64_t(iterations);
      if (Status st = run_hook(device, hook, s, stats, sweeps); !st) return st;
    }
    if (Status st = run(device, end_, stats.device, false); !st) return st;
    stats.sweeps = sweeps;
    stats.stop = SolveStop::fixed;
    stats.dropped_warm_starts = 0;
    return {};
  }
  if (!residual_mode_) {
    if (Status s = run(device, whole_, stats.device, true); !s) return s;
    stats.sweeps = std::uint64_t(solver_.substeps) * std::uint64_t(iterations);
    stats.stop = SolveStop::fixed;
    stats.dropped_warm_starts = 0;
    return {};
  }
  const auto frame_start = Clock::now();
  const int substeps = static_cast<int>(begin_.size());
  const int c = solver_.check_interval;
  SolveStop worst = SolveStop::converged;
  std::uint64_t sweeps_total = 0;
  std::uint32_t checks = 0, cold = 0;
  CheckedResidual r;
  for (int s = 0; s < substeps; ++s) {
    const auto begin_start = Clock::now();
    // No warm start after a substep the time budget cut short: its
    // lambdas, a few sweeps from 0, act like a late explicit force and a
    // stiff body diverges (measured: NaN within seconds at a 4.5 ms budget
    // on the 10,368-tet block); its successor starts from 0. A substep at
    // the cap passes its lambdas on when they are near the answer: its
    // sweeps lowered the residual and it ended within kCarryAtCap times the
    // tolerance (thousands of sweeps leave them there, and a cold start can
    // never get back: plain sweeps from 0 stall at a residual of ~2e-5 on
    // that block). Other capped substeps drop them (carried on, a stiff
    // beam warm-started at one substep and capped every frame at 500 or
    // 2000 sweeps reached NaN by frame 33-41; dropped, it stays finite at
    // the softness of its sweeps, as in the fixed mode).
    const ProgramHandle first = begin_cold_.empty() || warm_ ? begin_[s] : begin_cold_[s];
    if (Status st = run(device, first, stats.device, s == 0); !st) return st;
    auto read = read_residual_check(device, check_);
    if (!read) return read.error();
    r = *read;
    const double first_rms = r.rms;
    ++checks;
    const double begin_ms = ms_since(begin_start);
    int sweeps = iterations;
    SolveStop stop = SolveStop::converged;
    for (std::size_t j = 0;; ++j) {
      if (r.rms <= solver_.residual_tolerance) break;
      if (sweeps >= solver_.max_iterations || chunks_[s].empty()) {
        stop = SolveStop::iteration_cap;
        break;
      }
      if (solver_.time_budget_ms > 0.0) {
        // The next group must end within this substep's share of the budget.
        const double deadline = solver_.time_budget_ms * double(s + 1) / double(substeps);
        // The last group's time, or this substep's first program's time per
        // sweep (a little more: it also predicts) if that is less, so that
        // one slow group cannot stop every later frame at its first check.
        const double from_begin = begin_ms * double(c) / double(iterations);
        const double estimate = chunk_ms_ >= 0.0 ? std::min(chunk_ms_, from_begin) : from_begin;
        if (ms_since(frame_start) + estimate > deadline) {
          stop = SolveStop::time_budget;
          break;
        }
      }
      const auto chunk_start = Clock::now();
      const ProgramHandle chunk = chunks_[s][std::min(j, chunks_[s].size() - 1)];
      if (Status st = run(device, chunk, stats.device, false); !st) return st;
      read = read_residual_check(device, check_);
      if (!read) return read.error();
      r = *read;
      ++checks;
      chunk_ms_ = ms_since(chunk_start);
      sweeps += c;
    }
    const bool diverging = stop == SolveStop::iteration_cap &&
                           !(r.rms < first_rms && r.rms <= kCarryAtCap * solver_.residual_tolerance);
    warm_ = stop != SolveStop::time_budget && !diverging;
    if (diverging) ++cold;
    if (rank(stop) > rank(worst)) worst = stop;
    sweeps_total += std::uint64_t(sweeps);
    if (per_substep_)
      if (Status st = run_hook(device, hook, s, stats, sweeps_total); !st) return st;
  }
  if (Status st = run(device, end_, stats.device, false); !st) return st;
  stats.sweeps = sweeps_total;
  stats.stop = worst;
  stats.dropped_warm_starts = cold;
  stats.checked_residual = r.rms;
  stats.residual_checks = checks;
  return {};
}

}  // namespace sinew
