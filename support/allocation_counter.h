// allocation_counter.h — counts allocations made through the global operator
// new, for the executables that link allocation_counter.cpp (test_haptics,
// bench_haptic_loop; never the library): a haptic tick must allocate nothing.
#pragma once

#include <cstdint>

namespace sinew::support {

/// Allocations (any thread, any form of operator new) since the program started.
std::uint64_t allocation_count();

/// Marks the calling thread as tracked (e.g. from HapticLoopSettings::on_thread_start).
void track_this_thread();
/// Switches counting of tracked threads' allocations on or off (off at start).
void set_tracking(bool on);
/// Allocations on tracked threads while tracking was on.
std::uint64_t tracked_allocation_count();

}  // namespace sinew::support
