// sinew/hooks.h — an engine's own memory and threads for sinew.
//
// An engine that budgets its memory or owns its threads (named, pinned,
// prioritised, counted by its profiler) can give sinew both. The hooks are
// process-wide, like the log callback (sinew/log.h): set them before
// creating a Simulation; a Simulation keeps the hooks it was created with
// for its whole life (memory goes back through the hooks that gave it),
// so replacing them later affects only Simulations made afterwards.
//
//   sinew::set_allocation_hooks({
//       .allocate = [](std::size_t bytes, std::size_t align) { return my_arena.alloc(bytes, align); },
//       .deallocate = [](void* p, std::size_t bytes, std::size_t align) { my_arena.free(p, bytes, align); }});
//   sinew::set_task_hooks({
//       .start_thread = [](std::function<void()> loop) { return my_threads.start_dedicated(std::move(loop)); },
//       .parallel_for = [](std::size_t n, std::size_t grain, const sinew::RangeBody& body) {
//         my_jobs.parallel_for(n, grain, body); }});
//
// Unset hooks (the default) mean: memory from the C++ heap, threads from
// std::thread, host-side loops on TBB.
#pragma once

#include <cstddef>
#include <functional>

namespace sinew {

/// Where the large buffers' host memory comes from: every buffer of the CPU
/// backend (it is the CPU backend's device memory: particles, constraints,
/// contacts, fluid particles; its largest allocations). The GPU backends'
/// buffers live in the driver's device memory, which these hooks do not
/// provide. Give both functions or neither.
struct AllocationHooks {
  /// [in] bytes > 0, a multiple of [in] alignment (64, a power of two).
  /// Returns memory of that size and alignment, or nullptr when there is
  /// none (the call that needed it then fails with ErrorCode::out_of_memory
  /// naming the buffer). May be called from any thread that calls sinew.
  std::function<void*(std::size_t bytes, std::size_t alignment)> allocate;
  /// [in] memory from allocate, with the bytes and alignment it was asked for.
  std::function<void(void* memory, std::size_t bytes, std::size_t alignment)> deallocate;
};

/// Replaces the process-wide allocation hooks; empty hooks restore the
/// default (the C++ heap). Returns false, changing nothing, when exactly
/// one of the two functions is given.
bool set_allocation_hooks(AllocationHooks hooks);

/// A share of a parallel loop: [in] begin, end, the items [begin, end) to run.
using RangeBody = std::function<void(std::size_t begin, std::size_t end)>;

/// Whose threads run sinew's parallel work.
struct TaskHooks {
  /// The CPU backend's team (DeviceOptions::threads members; the thread
  /// that calls step() is one of them) runs a frame's dispatches in
  /// lockstep, meeting at spinning barriers, so its other members must be
  /// threads of their own that run at the same time as the caller. Each
  /// CPU Simulation calls start_thread (threads - 1) times when it is
  /// created, each time with a [in] loop that the hook must start at once on
  /// a thread of its own (not queued behind other work: the team's barriers
  /// wait for every member). The loop sleeps between frames and returns
  /// when the Simulation is destroyed (whose destructor waits for it).
  /// Returns false when no thread can be given: the team is then smaller
  /// (results are bitwise the same with any team size). Empty: std::thread.
  std::function<bool(std::function<void()> loop)> start_thread;
  /// The host's parallel loops (mesh collision's broad and narrow phases,
  /// normal cones, triangle boxes): run [in] body over [0, [in] count) in
  /// ranges of about [in] grain items or more, in parallel where the engine
  /// can, and return when every item has run. Each range's work is
  /// independent, so any split and order gives the same results. Empty: TBB.
  std::function<void(std::size_t count, std::size_t grain, const RangeBody& body)> parallel_for;
};

/// Replaces the process-wide task hooks; an empty function restores that
/// part's default.
void set_task_hooks(TaskHooks hooks);

}  // namespace sinew
