// sinew/haptics/clock.h — the time source of everything time-dependent in
// the haptics code, so tests run on a virtual clock and the real loop on
// CLOCK_MONOTONIC with absolute-time sleeps.
#pragma once

#include <atomic>
#include <cstdint>

namespace sinew::haptics {

inline constexpr std::int64_t kNsPerSecond = 1'000'000'000;
/// [in] seconds [s] -> [ns], rounded to nearest.
constexpr std::int64_t seconds_to_ns(double s) { return static_cast<std::int64_t>(s * 1e9 + (s >= 0 ? 0.5 : -0.5)); }
/// [in] ns [ns] -> [s].
constexpr double ns_to_seconds(std::int64_t ns) { return static_cast<double>(ns) * 1e-9; }

/// A monotonic time line in nanoseconds. Implementations are thread-safe:
/// the physics thread stamps snapshots with the clock the haptic loop reads.
class Clock {
 public:
  virtual ~Clock() = default;
  /// [out] the current time [ns]; never decreases.
  virtual std::int64_t now_ns() noexcept = 0;
  /// Returns once now_ns() >= t_ns (an absolute time [ns]); at once if already past.
  virtual void sleep_until(std::int64_t t_ns) noexcept = 0;
};

/// CLOCK_MONOTONIC (clock_gettime), sleeping with
/// clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, ...): absolute deadlines
/// do not drift by the time spent computing, and a signal (EINTR) resumes
/// the same sleep.
class MonotonicClock final : public Clock {
 public:
  std::int64_t now_ns() noexcept override;
  void sleep_until(std::int64_t t_ns) noexcept override;
};

/// A clock that moves only when told (tests): set() / advance() move it,
/// sleep_until() jumps straight to the deadline. Thread-safe.
class VirtualClock final : public Clock {
 public:
  explicit VirtualClock(std::int64_t start_ns = 0) : t_(start_ns) {}
  std::int64_t now_ns() noexcept override { return t_.load(std::memory_order_acquire); }
  void sleep_until(std::int64_t t_ns) noexcept override {
    std::int64_t now = t_.load(std::memory_order_acquire);
    while (now < t_ns && !t_.compare_exchange_weak(now, t_ns, std::memory_order_acq_rel)) {
    }
  }
  /// [in] t_ns: the new time [ns]; ignored if earlier than now (time never goes back).
  void set(std::int64_t t_ns) noexcept { sleep_until(t_ns); }
  /// [in] dt_ns: how far to move forward [ns], >= 0.
  void advance(std::int64_t dt_ns) noexcept { t_.fetch_add(dt_ns > 0 ? dt_ns : 0, std::memory_order_acq_rel); }

 private:
  std::atomic<std::int64_t> t_;
};

}  // namespace sinew::haptics
