// hooks_test.cpp — sinew/hooks.h: an engine's allocator gets every CPU
// buffer and gets each one back; an engine's threads run the CPU team; an
// engine's parallel_for runs the host's collision loops; results are
// bitwise those of the defaults, and a hook that refuses is handled.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <new>
#include <thread>
#include <vector>

#include "mesh_contact_support.h"
#include "robustness_scenes.h"
#include "sinew/hooks.h"

namespace sinew::test {
namespace {

class Hooks : public ::testing::Test {
 protected:
  void TearDown() override {
    set_allocation_hooks({});
    set_task_hooks({});
  }
};

// An allocator that counts what it gives and what comes back.
struct CountingAllocator {
  std::atomic<std::int64_t> live_blocks{0}, live_bytes{0}, calls{0};
  std::atomic<bool> misaligned{false}, wrong_size_back{false};
  std::mutex m;
  std::vector<std::pair<void*, std::size_t>> given;
  AllocationHooks hooks() {
    return {.allocate =
                [this](std::size_t bytes, std::size_t alignment) -> void* {
                  void* p = ::operator new(bytes, std::align_val_t{alignment}, std::nothrow);
                  if (reinterpret_cast<std::uintptr_t>(p) % alignment != 0 || bytes % alignment != 0)
                    misaligned = true;
                  ++calls, ++live_blocks, live_bytes += std::int64_t(bytes);
                  const std::lock_guard lock(m);
                  given.emplace_back(p, bytes);
                  return p;
                },
            .deallocate =
                [this](void* p, std::size_t bytes, std::size_t alignment) {
                  {
                    const std::lock_guard lock(m);
                    bool found = false;
                    for (auto& g : given)
                      if (g.first == p) {
                        found = g.second == bytes;
                        g.first = nullptr;
                      }
                    if (!found) wrong_size_back = true;
                  }
                  --live_blocks, live_bytes -= std::int64_t(bytes);
                  ::operator delete(p, std::align_val_t{alignment});
                }};
  }
};

Snapshot run_block(int frames, int threads = 2) {
  auto sim = Simulation::create(robustness_block(), {.backend = "cpu", .threads = threads, .quiet = true});
  EXPECT_TRUE(sim.ok()) << sim.error().message();
  if (!sim) return {};
  run(*sim, 1, frames);
  return snapshot(*sim);
}

TEST_F(Hooks, TheAllocatorGetsEveryCpuBufferAndEveryOneBack) {
  const Snapshot plain = run_block(5);
  CountingAllocator counting;
  ASSERT_TRUE(set_allocation_hooks(counting.hooks()));
  {
    auto sim = Simulation::create(robustness_block(), {.backend = "cpu", .threads = 2, .quiet = true});
    SINEW_ASSERT_OK(sim);
    EXPECT_GT(counting.live_blocks.load(), 10) << "the scene's buffers come from the hook";
    EXPECT_GT(counting.live_bytes.load(), std::int64_t(16) * sim->info().particles);
    run(*sim, 1, 5);
    EXPECT_TRUE(same_bits(snapshot(*sim), plain)) << "the hook's memory changes no result";
    // Hooks replaced while the Simulation lives: its buffers still go back to the first.
    set_allocation_hooks({});
  }
  EXPECT_EQ(counting.live_blocks.load(), 0) << "every buffer given back";
  EXPECT_EQ(counting.live_bytes.load(), 0);
  EXPECT_FALSE(counting.misaligned.load()) << "sizes and addresses are multiples of the alignment";
  EXPECT_FALSE(counting.wrong_size_back.load()) << "each block comes back with the size it was asked with";
}

TEST_F(Hooks, AnAllocatorWithNoMemoryIsANamedOutOfMemory) {
  CountingAllocator counting;
  AllocationHooks stingy = counting.hooks();
  // Room for the first three buffers, then none.
  stingy.allocate = [inner = stingy.allocate, n = std::make_shared<int>(0)](std::size_t b, std::size_t a) -> void* {
    return ++*n <= 3 ? inner(b, a) : nullptr;
  };
  ASSERT_TRUE(set_allocation_hooks(stingy));
  {
    auto sim = Simulation::create(robustness_block(), {.backend = "cpu", .quiet = true});
    ASSERT_FALSE(sim.ok());
    EXPECT_EQ(sim.error().code(), ErrorCode::out_of_memory) << sim.error().message();
    EXPECT_NE(sim.error().message().find("allocation hook"), std::string::npos) << sim.error().message();
    EXPECT_NE(sim.error().message().find("cpu buffer '"), std::string::npos) << "names the buffer: "
                                                                               << sim.error().message();
  }
  EXPECT_EQ(counting.live_blocks.load(), 0) << "the buffers made before the failure were given back";
}

TEST_F(Hooks, HalfAnAllocatorIsRefused) {
  AllocationHooks only_allocate, only_deallocate;
  only_allocate.allocate = [](std::size_t, std::size_t) -> void* { return nullptr; };
  only_deallocate.deallocate = [](void*, std::size_t, std::size_t) {};
  EXPECT_FALSE(set_allocation_hooks(only_allocate));
  EXPECT_FALSE(set_allocation_hooks(only_deallocate));
  // Nothing changed: the heap still serves.
  auto sim = Simulation::create(robustness_block(), {.backend = "cpu", .quiet = true});
  EXPECT_TRUE(sim.ok()) << sim.error().message();
}

// Engine threads: started by the hook, joined by the engine when their loop returns.
struct EngineThreads {
  std::mutex m;
  std::vector<std::thread> threads;
  std::atomic<int> started{0}, finished{0};
  bool refuse = false;
  TaskHooks hooks() {
    TaskHooks h;
    h.start_thread = [this](std::function<void()> loop) {
      if (refuse) return false;
      const std::lock_guard lock(m);
      threads.emplace_back([this, loop = std::move(loop)] {
        ++started;
        loop();
        ++finished;
      });
      return true;
    };
    return h;
  }
  ~EngineThreads() {
    for (std::thread& t : threads) t.join();
  }
};

TEST_F(Hooks, TheCpuTeamRunsOnTheEnginesThreads) {
  const Snapshot plain = run_block(5, 3);
  EngineThreads engine;
  set_task_hooks(engine.hooks());
  {
    auto sim = Simulation::create(robustness_block(), {.backend = "cpu", .threads = 3, .quiet = true});
    SINEW_ASSERT_OK(sim);
    EXPECT_NE(sim->device_name().find("3 threads"), std::string::npos) << sim->device_name();
    {
      const std::lock_guard lock(engine.m);
      EXPECT_EQ(engine.threads.size(), 2u) << "threads - 1 loops: the caller of step() is the third member";
    }
    run(*sim, 1, 5);
    EXPECT_TRUE(same_bits(snapshot(*sim), plain));
    EXPECT_EQ(engine.finished.load(), 0) << "the loops run for the Simulation's life";
  }
  EXPECT_EQ(engine.finished.load(), 2) << "destroying the Simulation ended (and waited for) both loops";
}

TEST_F(Hooks, AnEngineWithNoThreadsToGiveLeavesATeamOfOne) {
  const Snapshot plain = run_block(5, 3);
  EngineThreads engine;
  engine.refuse = true;
  set_task_hooks(engine.hooks());
  auto sim = Simulation::create(robustness_block(), {.backend = "cpu", .threads = 3, .quiet = true});
  SINEW_ASSERT_OK(sim);
  EXPECT_NE(sim->device_name().find("1 thread"), std::string::npos) << sim->device_name();
  run(*sim, 1, 5);
  EXPECT_TRUE(same_bits(snapshot(*sim), plain)) << "any team size computes the same bits";
}

TEST_F(Hooks, TheHostsCollisionLoopsRunOnTheEnginesParallelFor) {
  const SceneDesc scene = dropped_blocks_scene(ContactSchedule::colored);
  std::vector<float> plain, hooked;
  {
    auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
    SINEW_ASSERT_OK(sim);
    for (int f = 0; f < 30; ++f) SINEW_ASSERT_OK(sim->step());
    ASSERT_GT(sim->last_frame().mesh_contacts, 0u) << "the blocks touch: the loops had work";
    SINEW_ASSERT_OK(sim->read_positions(plain));
  }
  // The engine's loop: ranges of `grain` run on two threads of its own, backwards.
  std::atomic<std::uint64_t> loops{0}, items{0};
  TaskHooks engine;
  engine.parallel_for = [&](std::size_t count, std::size_t grain, const RangeBody& body) {
    ++loops;
    items += count;
    std::vector<std::pair<std::size_t, std::size_t>> ranges;
    for (std::size_t b = 0; b < count; b += grain) ranges.emplace_back(b, std::min(count, b + grain));
    std::atomic<std::size_t> next{0};
    const auto worker = [&] {
      for (std::size_t k; (k = next++) < ranges.size();) {
        const auto& [begin, end] = ranges[ranges.size() - 1 - k];
        body(begin, end);
      }
    };
    std::thread other(worker);
    worker();
    other.join();
  };
  set_task_hooks(engine);
  {
    auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
    SINEW_ASSERT_OK(sim);
    for (int f = 0; f < 30; ++f) SINEW_ASSERT_OK(sim->step());
    SINEW_ASSERT_OK(sim->read_positions(hooked));
  }
  EXPECT_GT(loops.load(), 30u) << "at least one loop per frame went through the hook";
  EXPECT_GT(items.load(), 0u);
  ASSERT_EQ(plain.size(), hooked.size());
  EXPECT_EQ(std::memcmp(plain.data(), hooked.data(), plain.size() * sizeof(float)), 0)
      << "the engine's split and order give the same contacts and positions";
}

}  // namespace
}  // namespace sinew::test
