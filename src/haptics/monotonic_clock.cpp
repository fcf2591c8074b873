// src/haptics/monotonic_clock.cpp — CLOCK_MONOTONIC and absolute-time sleeps.
#include <cerrno>
#include <ctime>

#include "sinew/haptics/clock.h"

namespace sinew::haptics {

std::int64_t MonotonicClock::now_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerSecond + ts.tv_nsec;
}

void MonotonicClock::sleep_until(std::int64_t t_ns) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t_ns / kNsPerSecond);
  ts.tv_nsec = static_cast<long>(t_ns % kNsPerSecond);
  // An absolute deadline: a signal (EINTR) resumes the same sleep, and the
  // time spent computing the tick does not add to the period.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace sinew::haptics
