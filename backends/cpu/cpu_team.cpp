// cpu_team.cpp — the team's workers, its sense-reversing barrier and its
// waiting policy (see cpu_team.h for why).
#include "backends/cpu/cpu_team.h"

#include <algorithm>
#include <chrono>
#include <climits>
#include <system_error>

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

// The waiting policy's numbers, for 2-vCPU VMs of the project's kind:
// - The old policy (256 pauses, ~10 us, then 16 yields, then sleep) slept
//   inside the frame ~13,000 times a second on one such machine and ran
//   distance + volume on 2 threads slower than on one: a sleeping vCPU
//   takes tens of microseconds to wake, more than a colour's work.
// - A barrier's wait is the imbalance of the step before it (a fraction of
//   that step's time) or a short preemption of the partner (an interrupt, a
//   1 kHz haptic tick of a few microseconds). So a waiter spins for the
//   floor plus twice as long as its own share of the step took; a partner
//   later than that is not running, and yielding (it may be queued behind
//   us on this core) then sleeping (an idle core lets the scheduler pull it
//   over) is what gets it to run again.
// The floor also covers a stretch of steps too small to share, which member
// 0 does alone while the others wait (reductions, a small body's colours):
// with a 50 us floor a worker slept once a frame on a cube of 8^3 cells.
constexpr std::int64_t kSpinFloorNs = 200'000;
constexpr std::int64_t kSpinPerShareNs = 2;
constexpr std::int64_t kSpinCapNs = 2'000'000;
constexpr std::int64_t kYieldNs = 100'000;  // after the spin
// Between runs: the programs of one frame follow each other after host work
// of tens of microseconds to a millisecond or two (statistics, collision,
// a residual check). A worker spins through the short gaps, yields its core
// to anyone who wants it through the longer ones, and sleeps past them
// (between paced frames).
constexpr std::int64_t kIdleSpinNs = 300'000;
constexpr std::int64_t kIdleYieldNs = 2'000'000;

enum Count { waited, yielded, slept, idle_slept };

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Sleeping and waking on a 32-bit word. Why not std::atomic::wait/notify:
// GCC 12's libstdc++ lost a wakeup here: a 2-thread team hung with both
// members asleep in the barrier, one waiting for phase_ to leave a value it
// had already left (seen 2026-11-25 in bench_stiffness after minutes of
// residual-mode frames; libstdc++'s waiter-count shortcut in notify has
// lost wakeups before: GCC bug 98033, for its semaphores). The kernel's
// futex compares the word and sleeps atomically, so with the sleeper count
// ordered as below nothing is lost.
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

// Waits until `word` no longer holds `old`: spins with pause until spin_ns,
// yields until yield_ns, then sleeps on a futex with `sleepers` raised (see
// CpuTeam::wake). Returns how it ended: spun, yielded or slept.
Count await_change(const std::atomic<std::uint32_t>& word, std::uint32_t old, std::atomic<std::uint32_t>& sleepers,
                   std::int64_t start, std::int64_t spin_ns, std::int64_t yield_ns) {
  // The clock is read once every 16 pauses (~0.2-2 us, by the CPU's pause).
  for (;;) {
    for (int i = 0; i < 16; ++i) {
      if (word.load(std::memory_order_acquire) != old) return waited;
      SINEW_CPU_RELAX();
    }
    if (now_ns() - start >= spin_ns) break;
  }
  for (;;) {
    std::this_thread::yield();
    if (word.load(std::memory_order_acquire) != old) return yielded;
    if (now_ns() - start >= yield_ns) break;
  }
  sleepers.fetch_add(1, std::memory_order_seq_cst);
  while (word.load(std::memory_order_seq_cst) == old) sleep_while_equal(word, old);
  sleepers.fetch_sub(1, std::memory_order_seq_cst);
  return slept;
}

}  // namespace

CpuTeam::CpuTeam(unsigned members, const StartThread& start_thread) {
  const unsigned asked = members < 1 ? 1 : members;
  hooked_running_ = std::make_shared<std::atomic<std::uint32_t>>(0);
  // A thread the system (or the engine's hook) refuses ends the team where
  // it is: a smaller team computes the same results (a dispatch's split
  // does not change them).
  for (unsigned m = 1; m < asked; ++m) {
    if (start_thread) {
      hooked_running_->fetch_add(1);
      bool started = false;
      try {
        started = start_thread([this, m, running = hooked_running_] {
          worker(m);
          // The team may be destroyed from here on: only `running` is touched.
          running->fetch_sub(1);
          running->notify_all();
        });
      } catch (...) {  // an engine's hook that throws refuses the thread too
      }
      if (!started) {
        hooked_running_->fetch_sub(1);
        break;
      }
    } else {
      try {
        workers_.emplace_back([this, m] { worker(m); });
      } catch (const std::system_error&) {
        break;
      }
    }
    members_ = m + 1;
  }
}

CpuTeam::~CpuTeam() {
  stop_ = true;
  job_.fetch_add(1, std::memory_order_seq_cst);
  wake(job_);
  for (std::thread& t : workers_) t.join();
  for (std::uint32_t left = hooked_running_->load(); left != 0; left = hooked_running_->load())
    hooked_running_->wait(left);
}

// Wakes the sleepers on `word` after it changed. Dekker's pattern: the
// change (seq_cst) before reading sleepers_ here, sleepers_ raised (seq_cst)
// before re-reading the word in await_change; in the single order of those
// four operations either the waiter sees the change or this sees the
// waiter, and a wake that comes before the waiter's futex call is not lost
// because the kernel re-compares the word. Costs no system call while
// nobody sleeps.
void CpuTeam::wake(const std::atomic<std::uint32_t>& word) {
  if (sleepers_.load(std::memory_order_seq_cst) != 0) wake_all(word);
}

CpuTeam::Waits CpuTeam::waits() const {
  auto c = [this](Count k) { return counts_[k].load(std::memory_order_relaxed); };
  return {c(waited), c(yielded), c(slept), c(idle_slept)};
}

void CpuTeam::run(void (*work)(void*, unsigned), void* context) {
  if (members_ == 1) {
    work(context, 0);
    return;
  }
  work_ = work;
  context_ = context;
  step_start_ns_.store(now_ns(), std::memory_order_relaxed);
  job_.fetch_add(1, std::memory_order_seq_cst);  // publishes work_, context_ and the clock
  wake(job_);
  work(context, 0);
  barrier();  // every member is done with the job
}

void CpuTeam::barrier() {
  if (members_ == 1) return;
  const std::uint32_t phase = phase_.load(std::memory_order_acquire);
  if (arrived_.fetch_add(1, std::memory_order_acq_rel) + 1 == members_) {
    // The last to arrive opens the next phase for everyone and starts the
    // clock of the step that follows.
    arrived_.store(0, std::memory_order_relaxed);
    step_start_ns_.store(now_ns(), std::memory_order_relaxed);
    phase_.store(phase + 1, std::memory_order_seq_cst);
    wake(phase_);
    return;
  }
  if (phase_.load(std::memory_order_acquire) != phase) return;
  // This member's share of the step took (now - the step's start); a
  // partner with a core finishes a share of about the same size soon
  // after. (If the phase has opened meanwhile, the start read may be the
  // next step's: the spin is then the floor, and the wait ends at once.)
  const std::int64_t now = now_ns();
  const std::int64_t share = std::max<std::int64_t>(0, now - step_start_ns_.load(std::memory_order_relaxed));
  const std::int64_t spin = std::min(kSpinCapNs, kSpinFloorNs + kSpinPerShareNs * share);
  const Count how = await_change(phase_, phase, sleepers_, now, spin, spin + kYieldNs);
  count(waited);
  if (how != waited) count(how);
}

void CpuTeam::worker(unsigned member) {
  std::uint32_t seen = 0;
  for (;;) {
    if (job_.load(std::memory_order_acquire) == seen &&
        await_change(job_, seen, sleepers_, now_ns(), kIdleSpinNs, kIdleYieldNs) == slept)
      count(idle_slept);
    seen = job_.load(std::memory_order_acquire);
    if (stop_) return;
    work_(context_, member);
    barrier();  // run() returns after this
  }
}

}  // namespace sinew
