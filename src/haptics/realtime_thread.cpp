// src/haptics/realtime_thread.cpp — asking for SCHED_FIFO (and a CPU) for
// the calling thread, and reporting what was obtained, never assuming it.
#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>

#include <string>
#include <system_error>

#include "sinew/haptics/haptic_loop.h"

namespace sinew::haptics {

namespace {
std::string policy_name(int policy) {
  switch (policy) {
    case SCHED_FIFO: return "SCHED_FIFO";
    case SCHED_RR: return "SCHED_RR";
    case SCHED_OTHER: return "SCHED_OTHER";
#ifdef SCHED_BATCH
    case SCHED_BATCH: return "SCHED_BATCH";
#endif
#ifdef SCHED_IDLE
    case SCHED_IDLE: return "SCHED_IDLE";
#endif
    default: return "policy " + std::to_string(policy);
  }
}
}  // namespace

SchedulingReport set_thread_scheduling(bool realtime, int priority, int cpu) {
  SchedulingReport r;
  const pthread_t self = pthread_self();
  if (cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    if (const int e = pthread_setaffinity_np(self, sizeof(set), &set); e != 0)
      r.error = "pthread_setaffinity_np(cpu " + std::to_string(cpu) + "): " + std::system_category().message(e);
    else
      r.cpu = cpu;
  }
  if (realtime) {
    r.requested = "SCHED_FIFO priority " + std::to_string(priority);
    sched_param p{};
    p.sched_priority = priority;
    if (const int e = pthread_setschedparam(self, SCHED_FIFO, &p); e != 0) {
      if (!r.error.empty()) r.error += "; ";
      r.error += "pthread_setschedparam(SCHED_FIFO, " + std::to_string(priority) + "): " +
                 std::system_category().message(e);
    }
  } else {
    r.requested = "SCHED_OTHER (real-time not requested)";
  }
  int policy = 0;
  sched_param got{};
  if (const int e = pthread_getschedparam(self, &policy, &got); e != 0) {
    r.policy = "unknown";
    if (!r.error.empty()) r.error += "; ";
    r.error += "pthread_getschedparam: " + std::system_category().message(e);
  } else {
    r.policy = policy_name(policy);
    r.priority = got.sched_priority;
  }
  return r;
}

std::string SchedulingReport::describe() const {
  std::string s = policy + " priority " + std::to_string(priority) + " (requested " + requested + ")";
  if (cpu >= 0) s += ", pinned to CPU " + std::to_string(cpu);
  if (!error.empty()) s += ": " + error;
  s += "; CPU wake-up latency (PM QoS): " + cpu_latency;
  return s;
}

int hold_cpu_latency(int microseconds, std::string& report) {
  const int fd = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
  if (fd < 0) {
    report = "cannot open /dev/cpu_dma_latency: " + std::system_category().message(errno);
    return -1;
  }
  const std::int32_t value = microseconds;
  if (::write(fd, &value, sizeof value) != static_cast<ssize_t>(sizeof value)) {
    report = "cannot write /dev/cpu_dma_latency: " + std::system_category().message(errno);
    ::close(fd);
    return -1;
  }
  report = std::to_string(microseconds) + " us held";
  return fd;
}

void release_cpu_latency(int fd) {
  if (fd >= 0) ::close(fd);
}

}  // namespace sinew::haptics
