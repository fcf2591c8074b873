// parallel_pairs.cpp — the task split and the TBB loop of the parallel
// self-pair query (see parallel_pairs.h).
#include "collision/parallel_pairs.h"
#include "hooks/hooks_internal.h"


namespace sinew::collision::detail {

std::vector<std::pair<std::uint32_t, std::uint32_t>> self_tasks(const Bvh& tree, std::size_t wanted,
                                                                const NormalCones* cones) {
  // Expand the self traversal breadth-first until there are enough tasks:
  // (n, n) becomes its children with themselves and with each other; a
  // cross pair becomes its children against the other side (after the
  // same overlap test the traversal makes, so no task is empty for a reason
  // the traversal would not skip).
  const auto& nodes = tree.nodes();
  std::vector<std::pair<std::uint32_t, std::uint32_t>> tasks{{0, 0}}, next;
  while (tasks.size() < wanted) {
    next.clear();
    bool split = false;
    for (const auto& [a, b] : tasks) {
      const Bvh::Node& x = nodes[a];
      const Bvh::Node& y = nodes[b];
      if (cones && (a == b ? cones->self(a) : cones->pair(a, b))) continue;  // nothing of it is visited
      if (a == b && x.count == 0) {
        next.push_back({x.left, x.left});
        next.push_back({x.left + 1, x.left + 1});
        next.push_back({x.left, x.left + 1});
        split = true;
      } else if (a != b && x.count == 0 && y.count == 0) {
        if (!overlap(x.box, y.box)) continue;  // the traversal would stop here too
        next.push_back({x.left, b});
        next.push_back({x.left + 1, b});
        split = true;
      } else {
        next.push_back({a, b});
      }
    }
    tasks.swap(next);
    if (!split) break;
  }
  return tasks;
}

void run_tasks(std::size_t count, void (*work)(void*, std::size_t), void* context) {
  hooks::parallel_for(count, 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) work(context, k);
  });
}

}  // namespace sinew::collision::detail
