// hooks_internal.h — the library's side of sinew/hooks.h: the hooks in
// force, and the host's parallel loops that go through them.
#pragma once

#include <cstddef>
#include <functional>
#include <initializer_list>
#include <memory>

#include "sinew/hooks.h"

namespace sinew::hooks {

/// The allocation hooks in force; null when unset (the C++ heap). A holder
/// keeps the hooks its memory came from alive for as long as it needs them.
std::shared_ptr<const AllocationHooks> allocation();

/// The task hooks in force (never null; functions empty where unset).
std::shared_ptr<const TaskHooks> tasks();

/// Runs body over [0, count) in ranges of about `grain` items, on the
/// engine's parallel_for when one is set, else on TBB; returns when all have run.
void parallel_for(std::size_t count, std::size_t grain, const RangeBody& body);

/// Runs the tasks, in parallel where it can (through parallel_for); returns when all have run.
void parallel_invoke(std::initializer_list<std::function<void()>> tasks);

}  // namespace sinew::hooks
