// hooks.cpp — the process-wide allocation and task hooks (sinew/hooks.h).
// As with the log callback (log.cpp), each is held by a shared_ptr swapped
// under a mutex: a reader copies the pointer and uses the hooks without the
// lock, and a replacement never destroys hooks still in use (a CPU device
// frees its buffers through the hooks it allocated them with).
#include <mutex>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "hooks/hooks_internal.h"

namespace sinew {
namespace {

std::mutex& hooks_mutex() {
  static std::mutex m;
  return m;
}

std::shared_ptr<const AllocationHooks>& allocation_slot() {
  static std::shared_ptr<const AllocationHooks> hooks;
  return hooks;
}

std::shared_ptr<const TaskHooks>& task_slot() {
  static std::shared_ptr<const TaskHooks> hooks = std::make_shared<const TaskHooks>();
  return hooks;
}

}  // namespace

bool set_allocation_hooks(AllocationHooks hooks) {
  if (bool(hooks.allocate) != bool(hooks.deallocate)) return false;
  std::shared_ptr<const AllocationHooks> next;
  if (hooks.allocate) next = std::make_shared<const AllocationHooks>(std::move(hooks));
  const std::lock_guard lock(hooks_mutex());
  allocation_slot() = std::move(next);
  return true;
}

void set_task_hooks(TaskHooks hooks) {
  auto next = std::make_shared<const TaskHooks>(std::move(hooks));
  const std::lock_guard lock(hooks_mutex());
  task_slot() = std::move(next);
}

namespace hooks {

std::shared_ptr<const AllocationHooks> allocation() {
  const std::lock_guard lock(hooks_mutex());
  return allocation_slot();
}

std::shared_ptr<const TaskHooks> tasks() {
  const std::lock_guard lock(hooks_mutex());
  return task_slot();
}

void parallel_for(std::size_t count, std::size_t grain, const RangeBody& body) {
  if (count == 0) return;
  if (grain == 0) grain = 1;
  const std::shared_ptr<const TaskHooks> hooks = tasks();
  if (hooks->parallel_for) {
    hooks->parallel_for(count, grain, body);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, grain),
                    [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
}

void parallel_invoke(std::initializer_list<std::function<void()>> tasks) {
  const std::vector<std::function<void()>> list(tasks);
  parallel_for(list.size(), 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) list[k]();
  });
}

}  // namespace hooks
}  // namespace sinew
