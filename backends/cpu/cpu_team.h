// cpu_team.h — a fixed team of threads that run a frame program in lockstep:
// every member walks the same list of steps, does its share of each, and
// meets the others at a barrier where the next step reads what this one
// wrote.
//
// Why not a parallel_for per dispatch: a frame of a 57,000-tet kidney at 10
// substeps has ~900 dependent dispatches of ~1,500 constraints each (~10 us
// of work on one core). Waking TBB's workers and joining them costs a few
// microseconds per dispatch, so two threads ran that frame slower than one
// (7.2 against ~6.2 ms). Threads that stay awake across the whole program
// and meet at a spinning barrier pay ~0.1 us per dispatch instead. This is
// the classic persistent-threads/spin-barrier scheme (Mellor-Crummey,
// Scott, "Algorithms for scalable synchronization on shared-memory
// multiprocessors", TOCS 1991: the sense-reversing centralised barrier).
//
// A member that waits spins a few microseconds, then yields its core a few
// times, then sleeps (a futex; see cpu_team.cpp): spinning only pays while the
// partner is running, and on a busy machine (ctest -j on two cores, other
// processes) a spinning member keeps the partner it waits for off the core.
#pragma once

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

namespace sinew {

class CpuTeam {
 public:
  /// A team of `members` threads: the caller of run() and members - 1
  /// workers started here. members >= 1.
  explicit CpuTeam(unsigned members);
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

 private:
  void worker(unsigned member);
  // Waits until `value` no longer holds `old`: spins, yields, then sleeps
  // on a futex (Linux); wake() after every change of job_ or phase_.
  void await_change(const std::atomic<std::uint32_t>& value, std::uint32_t old);
  void wake(const std::atomic<std::uint32_t>& value);

  unsigned members_;
  std::vector<std::thread> workers_;
  // The job: published by bumping job_; stop_ ends the workers.
  void (*work_)(void*, unsigned) = nullptr;
  void* context_ = nullptr;
  bool stop_ = false;
  alignas(64) std::atomic<std::uint32_t> job_{0};
  // The barrier: members arriving in this phase, and the phase.
  alignas(64) std::atomic<std::uint32_t> arrived_{0};
  alignas(64) std::atomic<std::uint32_t> phase_{0};
  // Members asleep (or about to sleep) in await_change.
  alignas(64) std::atomic<std::uint32_t> sleepers_{0};
};

}  // namespace sinew
