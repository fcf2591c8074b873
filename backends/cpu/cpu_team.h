// cpu_team.h — a fixed team of threads that run a frame program in lockstep:
// every member walks the same list of steps, does its share of each, and
// meets the others at a barrier where the next step reads what this one
// wrote.
//
// Why not a parallel_for per dispatch: a frame of a 57,000-tet kidney at 10
// substeps has ~900 dependent dispatches of ~1,500 constraints each (~10 us
// of work on one core). Waking TBB's workers and joining them costs a few
// microseconds per dispatch, so two threads ran that frame slower than one.
// Threads that stay awake across the whole program and meet at a spinning
// barrier pay a fraction of a microsecond per dispatch instead. This is the
// classic persistent-threads/spin-barrier scheme (Mellor-Crummey, Scott,
// "Algorithms for scalable synchronization on shared-memory
// multiprocessors", TOCS 1991: the sense-reversing centralised barrier).
//
// Why fixed shares and not chunks claimed by whoever is free: a member that
// does the same part of every colour keeps that part's particles in its own
// cache. Chunks handed out first come, first served (tried: a ticket
// scheme, claimed per chunk) moved them between the cores' caches at every
// colour and cost 50% more work in all on the cube. The shares are weighted
// by each member's measured speed instead (cpu_device.cpp), which balances
// vCPUs of unequal speed.
//
// How a member waits (cpu_team.cpp has the measurements):
// - Inside a run, at a barrier, it spins with `pause` for as long as a
//   partner that has a core can take to arrive: a floor that covers short
//   preemptions (an interrupt, a haptic tick) plus twice the time its own
//   share of the step took. Only past that does it yield its core and then
//   sleep: the partner it waits for is then not running, and an idle core
//   is what lets the scheduler move that partner onto it.
// - Between runs a worker spins, then yields, for about two milliseconds
//   before it sleeps: the programs of one frame follow each other after
//   short host work (collision, a residual check), so the team stays awake
//   for the whole frame and sleeps only between frames or when idle.
// Which programs the team runs at all (one thread runs those too small to
// share, and all while the team measures slower, as when another process
// keeps a core busy) is the device's choice (cpu_device.cpp, WidthChoice).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <thread>
#include <vector>

namespace sinew {

class CpuTeam {
 public:
  /// Starts a worker's loop on a thread of its own at once, or returns
  /// false (an engine's TaskHooks::start_thread, sinew/hooks.h).
  using StartThread = std::function<bool(std::function<void()> loop)>;
  /// A team of `members` threads: the caller of run() and members - 1
  /// workers started here, on std::thread or, given [in] start_thread, on
  /// the threads it starts. members >= 1; workers that cannot be started
  /// (the system or start_thread refused a thread) leave a smaller team,
  /// never an exception: members() says how many there are.
  explicit CpuTeam(unsigned members, const StartThread& start_thread = {});
  ~CpuTeam();
  CpuTeam(const CpuTeam&) = delete;
  CpuTeam& operator=(const CpuTeam&) = delete;

  [[nodiscard]] unsigned members() const { return members_; }

  /// Runs work(context, member) on every member at once (member 0 on the
  /// calling thread) and returns when all have returned. Not reentrant.
  void run(void (*work)(void* context, unsigned member), void* context);

  /// Called by every member inside run()'s work: returns once all members
  /// have called it; what a member wrote before is visible to all after.
  void barrier();

  /// How the waits ended, counted over the team's life (for benchmarks: on
  /// a quiet machine a frame should show no sleeps inside runs).
  struct Waits {
    std::uint64_t waits = 0;       ///< barrier waits that did not end at once
    std::uint64_t yielded = 0;     ///< of them, ended after yielding the core
    std::uint64_t slept = 0;       ///< of them, ended after sleeping
    std::uint64_t idle_slept = 0;  ///< workers that slept between runs
  };
  [[nodiscard]] Waits waits() const;

 private:
  void worker(unsigned member);
  void wake(const std::atomic<std::uint32_t>& word);
  void count(int what) { counts_[what].fetch_add(1, std::memory_order_relaxed); }

  unsigned members_ = 1;
  std::vector<std::thread> workers_;
  // Workers on an engine's threads (TaskHooks::start_thread) still running;
  // shared with their loops, so the last one can signal after the team is gone.
  std::shared_ptr<std::atomic<std::uint32_t>> hooked_running_;
  // The job: published by bumping job_; stop_ ends the workers.
  void (*work_)(void*, unsigned) = nullptr;
  void* context_ = nullptr;
  bool stop_ = false;
  alignas(64) std::atomic<std::uint32_t> job_{0};
  // The barrier: members arriving in this phase, and the phase.
  alignas(64) std::atomic<std::uint32_t> arrived_{0};
  alignas(64) std::atomic<std::uint32_t> phase_{0};
  // When the step in progress began [ns, steady clock]: the start of the
  // run or the opening of the last barrier (a waiter sizes its spin by
  // it). In phase_'s cache line: the opener writes both, the waiters read
  // both, so a barrier moves one line between cores, not two.
  std::atomic<std::int64_t> step_start_ns_{0};
  // Members asleep (or about to sleep) on job_ or phase_.
  alignas(64) std::atomic<std::uint32_t> sleepers_{0};
  alignas(64) std::atomic<std::uint64_t> counts_[4] = {};
};

}  // namespace sinew
