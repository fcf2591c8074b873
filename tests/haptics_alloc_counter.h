// haptics_alloc_counter.h — counts every allocation made through the global
// operator new in the test_haptics executable (replaced in
// haptics_alloc_counter.cpp; this executable only, never the library).
#pragma once

#include <cstdint>

namespace sinew::test {
/// Allocations (any thread, any form of operator new) since the program started.
std::uint64_t allocation_count();
}  // namespace sinew::test
