// parallel_pairs.h — the self-collision pair query of collision/bvh.h on
// several threads: the fast CPU path of the broad phase (issue 12), checked
// against the single-threaded reference and the brute force
// (tests/bvh_test.cpp).
//
// The node pairs of the first few levels of the self traversal are
// independent tasks (a node with itself, two sibling subtrees against each
// other); each task walks its part of the traversal and keeps its pairs in
// its own list, and the lists are joined in task order, so the result is
// the same on any number of threads. Not sorted (sorting the liver
// surface's 105,000 pairs took ~7 ms of a ~40 ms query).
#pragma once

#include <vector>

#include "collision/bvh.h"
#include "collision/normal_cones.h"

namespace sinew::collision {

/// The pairs of self_overlapping_pairs, in a fixed order that does not
/// depend on the thread count (not sorted). With `cones` (for the same
/// tree) culled like self_overlapping_pairs with that policy, though the
/// task split offers it other node pairs, so the two may keep different
/// (equally safe) subsets. `skip` is called from several threads at once.
template <class Skip>
void self_overlapping_pairs_parallel(const Bvh& tree, Skip skip, std::vector<Pair>& pairs,
                                     const NormalCones* cones = nullptr);

namespace detail {
// The tasks: node pairs (self pairs are (n, n)) whose traversals together
// are the whole self traversal (without what `cones` culls, when given);
// at most ~`wanted` of them.
std::vector<std::pair<std::uint32_t, std::uint32_t>> self_tasks(const Bvh& tree, std::size_t wanted,
                                                                const NormalCones* cones);
// Runs work(k) for k in [0, count) on TBB's threads.
void run_tasks(std::size_t count, void (*work)(void*, std::size_t), void* context);

}  // namespace detail

template <class Skip>
void self_overlapping_pairs_parallel(const Bvh& tree, Skip skip, std::vector<Pair>& pairs,
                                     const NormalCones* cones) {
  pairs.clear();
  if (tree.empty()) return;
  const auto tasks = detail::self_tasks(tree, 64, cones);
  std::vector<std::vector<Pair>> found(tasks.size());
  struct Context {
    const Bvh* tree;
    const Skip* skip;
    const std::vector<std::pair<std::uint32_t, std::uint32_t>>* tasks;
    std::vector<std::vector<Pair>>* found;
    const NormalCones* cones;
  } context{&tree, &skip, &tasks, &found, cones};
  detail::run_tasks(tasks.size(), [](void* c, std::size_t k) {
    auto& ctx = *static_cast<Context*>(c);
    const auto& order = ctx.tree->order();
    const auto& leaf = ctx.tree->leaf_boxes();
    std::vector<Pair>& out = (*ctx.found)[k];
    const auto [i, j] = (*ctx.tasks)[k];
    const auto visit = [&](const Bvh::Node& x, const Bvh::Node& y) {
      const bool same = &x == &y;
      for (std::uint32_t s = 0; s < x.count; ++s)
        for (std::uint32_t t = same ? s + 1 : 0; t < y.count; ++t) {
          if (!overlap(leaf[x.first + s], leaf[y.first + t])) continue;
          std::uint32_t a = order[x.first + s], b = order[y.first + t];
          if (a > b) std::swap(a, b);
          if (!(*ctx.skip)(a, b)) out.push_back({a, b});
        }
    };
    if (ctx.cones) detail::traverse_from(*ctx.tree, *ctx.tree, true, i, j, visit, *ctx.cones);
    else detail::traverse_from(*ctx.tree, *ctx.tree, true, i, j, visit);
  }, &context);
  std::size_t total = 0;
  for (const auto& f : found) total += f.size();
  pairs.reserve(total);
  for (const auto& f : found) pairs.insert(pairs.end(), f.begin(), f.end());
}

}  // namespace sinew::collision
