// cpu_team.cpp — the team's workers and its sense-reversing barrier (see
// cpu_team.h for why).
#include "backends/cpu/cpu_team.h"

#include <climits>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define SINEW_CPU_RELAX() _mm_pause()
#else
#define SINEW_CPU_RELAX() std::this_thread::yield()
#endif

#ifdef __linux__
#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace sinew {
namespace {

// Sleeping and waking on a 32-bit word. Why not std::atomic::wait/notify:
// GCC 12's libstdc++ lost a wakeup here: a 2-thread team hung with both
// members asleep in the barrier, one waiting for phase_ to leave a value it
// had already left (seen 2026-11-25 in bench_stiffness after minutes of
// residual-mode frames; libstdc++'s waiter-count shortcut in notify has
// lost wakeups before: GCC bug 98033, for its semaphores). The kernel's
// futex compares the word and sleeps
// atomically, so with the sleeper count ordered as below nothing is lost.
#ifdef __linux__
void sleep_while_equal(const std::atomic<std::uint32_t>& word, std::uint32_t old) {
  syscall(SYS_futex, reinterpret_cast<const std::uint32_t*>(&word), FUTEX_WAIT_PRIVATE, old, nullptr, nullptr, 0);
}
void wake_all(const std::atomic<std::uint32_t>& word) {
  syscall(SYS_futex, reinterpret_cast<const std::uint32_t*>(&word), FUTEX_WAKE_PRIVATE, INT_MAX, nullptr, nullptr, 0);
}
#else
void sleep_while_equal(const std::atomic<std::uint32_t>&, std::uint32_t) { std::this_thread::yield(); }
void wake_all(const std::atomic<std::uint32_t>&) {}
#endif

}  // namespace

CpuTeam::CpuTeam(unsigned members) : members_(members < 1 ? 1 : members) {
  for (unsigned m = 1; m < members_; ++m) workers_.emplace_back([this, m] { worker(m); });
}

CpuTeam::~CpuTeam() {
  stop_ = true;
  job_.fetch_add(1, std::memory_order_seq_cst);
  wake(job_);
  for (std::thread& t : workers_) t.join();
}

// Wakes the sleepers on `value` after it changed. Dekker's pattern: the
// change (seq_cst) before reading sleepers_ here, sleepers_ raised (seq_cst)
// before re-reading the value in await_change; in the single order of those
// four operations either the waiter sees the change or this sees the
// waiter, and a wake that comes before the waiter's futex call is not lost
// because the kernel re-compares the word. Costs no system call while
// nobody sleeps.
void CpuTeam::wake(const std::atomic<std::uint32_t>& value) {
  if (sleepers_.load(std::memory_order_seq_cst) != 0) wake_all(value);
}

void CpuTeam::await_change(const std::atomic<std::uint32_t>& value, std::uint32_t old) {
  // A few microseconds of spinning cover the gap between two dispatches when
  // every member has a core. When one has none (a busy machine: ctest -j,
  // other processes), spinning longer only keeps it off the core it waits
  // for, so the waiter then yields its core a few times and finally sleeps.
  // Measured on the kidney (distance + volume, 910 barriers per frame) with
  // a parallel build running: 58.9 ms per frame spinning ~2,048 pauses
  // before sleeping, 14.6 ms with this policy (Neo-Hookean: 47.5 -> 17.2).
  for (int spin = 0; spin < 256; ++spin) {
    if (value.load(std::memory_order_acquire) != old) return;
    SINEW_CPU_RELAX();
  }
  for (int turn = 0; turn < 16; ++turn) {
    if (value.load(std::memory_order_acquire) != old) return;
    std::this_thread::yield();
  }
  sleepers_.fetch_add(1, std::memory_order_seq_cst);
  while (value.load(std::memory_order_seq_cst) == old) sleep_while_equal(value, old);
  sleepers_.fetch_sub(1, std::memory_order_seq_cst);
}

void CpuTeam::run(void (*work)(void*, unsigned), void* context) {
  if (members_ == 1) {
    work(context, 0);
    return;
  }
  work_ = work;
  context_ = context;
  job_.fetch_add(1, std::memory_order_seq_cst);  // publishes work_ and context_
  wake(job_);
  work(context, 0);
  barrier();  // every member is done with the job
}

void CpuTeam::barrier() {
  if (members_ == 1) return;
  const std::uint32_t phase = phase_.load(std::memory_order_acquire);
  if (arrived_.fetch_add(1, std::memory_order_acq_rel) + 1 == members_) {
    // The last to arrive opens the next phase for everyone.
    arrived_.store(0, std::memory_order_relaxed);
    phase_.store(phase + 1, std::memory_order_seq_cst);
    wake(phase_);
    return;
  }
  await_change(phase_, phase);
}

void CpuTeam::worker(unsigned member) {
  std::uint32_t seen = 0;
  for (;;) {
    await_change(job_, seen);
    seen = job_.load(std::memory_order_acquire);
    if (stop_) return;
    work_(context_, member);
    barrier();  // run() returns after this
  }
}

}  // namespace sinew
