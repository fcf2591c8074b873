// frame_stage_test.cpp — the frame as stages (src/runtime/frame_stage.h):
// a stage added to a scene runs in every phase in the order registered,
// after the scene's own, and is profiled; its error stops the frame; the
// device counts what each stage reads back and how often the host waits,
// alike on every backend; a scene lists only the stages it uses.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "mesh_contact_support.h"
#include "suture_scenes.h"
#include "runtime/simulation_internals.h"
#include "test_support.h"

namespace sinew {
namespace {

// A stage that writes "<name>.<phase>" to a shared log; it checks what the
// scene's own stages did before it in the same phase.
class LogStage final : public FrameStage {
 public:
  LogStage(std::string name, std::vector<std::string>& log) : name_(std::move(name)), log_(log) {}
  std::string_view name() const override { return name_; }
  Status before_frame(FrameContext&) override { return note("before_frame"); }
  Status solve(FrameContext& frame) override {
    solved_sweeps = frame.stats.sweeps;  // the solve stage ran before this one
    return note("solve");
  }
  Status after_solve(FrameContext&) override { return note("after_solve"); }
  Status after_frame(FrameContext& frame) override {
    if (sleep_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(sleep_ms));
    if (fail) return Error(ErrorCode::bad_parameter, name_ + " refused the frame");
    if (bytes > 0) {  // reads `bytes` back from a buffer of its own
      if (!buffer_.valid()) {
        auto made = frame.device.create_buffer(bytes, name_);
        if (!made) return made.error();
        buffer_ = *made;
      }
      std::vector<std::uint8_t> host(bytes);
      if (Status s = frame.device.read_buffer(buffer_, 0, host.data(), bytes); !s) return s;
    }
    return note("after_frame");
  }

  int sleep_ms = 0;
  bool fail = false;
  std::uint64_t bytes = 0;
  std::uint64_t solved_sweeps = 0;

 private:
  Status note(const char* phase) {
    log_.push_back(name_ + "." + phase);
    return {};
  }
  std::string name_;
  std::vector<std::string>& log_;
  BufferHandle buffer_;
};

SceneDesc hanging_block() {
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 2, .iterations = 3};
  TetBodyDesc body;
  body.mesh = *make_tet_grid({.nx = 3, .ny = 2, .nz = 2, .origin = {0, 0, 0}, .cell_size = {0.01, 0.01, 0.01}});
  EXPECT_TRUE(body.set_elastic(2e4, 0.3).ok());
  body.pinned = {0};
  scene.tet_bodies.push_back(body);
  return scene;
}

std::vector<std::string> names(const FrameStats& stats) {
  std::vector<std::string> out;
  for (const StageProfile& p : stats.stages) out.push_back(p.name);
  return out;
}

TEST(FrameStage, AnAddedStageRunsEveryPhaseInOrderAndIsProfiled) {
  auto sim = Simulation::create(hanging_block(), {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  std::vector<std::string> log;
  auto a = std::make_unique<LogStage>("a", log);
  auto b = std::make_unique<LogStage>("b", log);
  LogStage* first = a.get();
  b->sleep_ms = 3;
  b->bytes = 1000;
  SimulationInternals::add_stage(*sim, std::move(a));
  SimulationInternals::add_stage(*sim, std::move(b));
  ASSERT_TRUE(sim->step().ok());
  EXPECT_EQ(log, (std::vector<std::string>{"a.before_frame", "b.before_frame", "a.solve", "b.solve", "a.after_solve",
                                           "b.after_solve", "a.after_frame", "b.after_frame"}));
  EXPECT_EQ(first->solved_sweeps, 2u * 3u) << "the scene's solve runs before a stage added after it";
  const FrameStats& stats = sim->last_frame();
  EXPECT_EQ(names(stats), (std::vector<std::string>{"colliders and tools", "solve", "statistics", "a", "b"}));
  // Each stage's time is measured inside the frame's: at least b's sleep,
  // and all of them within wall_ms.
  const auto timed_within_the_frame = [](const FrameStats& s) {
    double sum = 0.0;
    for (const StageProfile& p : s.stages) sum += p.ms;
    return s.stages[4].ms >= 3.0 && sum <= s.wall_ms;
  };
  EXPECT_TRUE(timed_within_the_frame(stats));
  EXPECT_GT(stats.stages[1].ms, 0.0) << "the solve is timed";
  // The device counts the stage's read-back, and gives it to the stage.
  EXPECT_EQ(stats.counter("b", "read_bytes"), 1000.0);
  EXPECT_EQ(stats.counter("b", "host_waits"), 1.0) << "a read-back is a round trip";
  EXPECT_EQ(stats.counter("a", "read_bytes"), 0.0);
  EXPECT_GE(stats.read_back_bytes, 1000u + std::uint64_t(stats.counter("statistics", "read_bytes")));
  // The profile is of the last frame: a sum over two frames would pass the
  // second frame's wall time.
  log.clear();
  ASSERT_TRUE(sim->step().ok());
  EXPECT_EQ(log.size(), 8u);
  EXPECT_TRUE(timed_within_the_frame(sim->last_frame()));
}

TEST(FrameStage, AStagesErrorStopsTheFrameWithItsMessage) {
  auto sim = Simulation::create(hanging_block(), {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  std::vector<std::string> log;
  auto stage = std::make_unique<LogStage>("gate", log);
  stage->fail = true;
  SimulationInternals::add_stage(*sim, std::move(stage));
  const Status s = sim->step();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message().find("gate refused the frame"), std::string::npos) << s.error().message();
  EXPECT_EQ(sim->last_frame().frame, 0u) << "a failed frame is not counted";
}

TEST(FrameStage, AScenesStagesAreOnlyThoseItUses) {
  auto plain = Simulation::create(hanging_block(), {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(plain.ok()) << plain.error().message();
  EXPECT_EQ(names(plain->last_frame()), (std::vector<std::string>{"colliders and tools", "solve", "statistics"}));

  auto contact = Simulation::create(test::dropped_blocks_scene(ContactSchedule::colored), {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(contact.ok()) << contact.error().message();
  ASSERT_TRUE(contact->step().ok());
  EXPECT_EQ(names(contact->last_frame()),
            (std::vector<std::string>{"colliders and tools", "mesh collision", "solve", "statistics"}));
  EXPECT_GT(contact->last_frame().stages[1].ms, 0.0);

  SceneDesc forced = hanging_block();
  forced.external_forces = true;
  auto with_forces = Simulation::create(forced, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(with_forces.ok()) << with_forces.error().message();
  EXPECT_EQ(names(with_forces->last_frame()).front(), "forces");
}

// Mesh collision and needles both need the positions on the host, after the
// solve and (the needles) before the next frame: the stages share one
// read-back a frame.
TEST(FrameStage, ThePositionsAreReadBackOnceAFrame) {
  SceneDesc scene = test::SuturePads::scene();
  scene.mesh_collision.enabled = true;
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  const std::uint64_t position_bytes = std::uint64_t{sim->info().particles} * 16;
  for (int f = 0; f < 12; ++f) {
    ASSERT_TRUE(test::SuturePads::drive(*sim, f).ok());
    ASSERT_TRUE(sim->step().ok());
    const FrameStats& stats = sim->last_frame();
    // The first frame also reads the starting positions (nothing has read them before).
    EXPECT_EQ(stats.position_reads, f == 0 ? 2u : 1u) << "frame " << f;
    EXPECT_GE(stats.read_back_bytes, position_bytes) << "frame " << f;
    // Each stage reading its own would be three times the positions (mesh
    // collision after the solve, the needles before and after it); the
    // first frame also reads the starting velocities.
    EXPECT_LT(stats.read_back_bytes, (f == 0 ? 3 : 1) * position_bytes + position_bytes / 2) << "frame " << f;
    // Each stage's figures are its profile's counters.
    EXPECT_EQ(stats.counter("mesh collision", "contacts"), double(stats.mesh_contacts)) << "frame " << f;
    EXPECT_EQ(stats.counter("mesh collision", "violation_m"), stats.contact_violation) << "frame " << f;
    EXPECT_EQ(stats.counter("sutures", "host_ms"), stats.suture_ms) << "frame " << f;
    EXPECT_EQ(stats.counter("mesh collision", "no such counter"), 0.0);
  }
  EXPECT_EQ(names(sim->last_frame()),
            (std::vector<std::string>{"colliders and tools", "mesh collision", "sutures", "solve", "statistics"}));
}

// What the host reads and waits for is counted by the device, the same way
// on every backend: the frame's totals are the sum of the stages' shares,
// the positions are read once a frame by the whole runtime, and every
// backend reads the same bytes in the same number of round trips.
struct Transfers {
  std::uint64_t bytes = 0;
  std::uint32_t reads = 0, waits = 0, position_reads = 0;
  bool operator==(const Transfers&) const = default;
};

std::vector<Transfers> suture_frames(const std::string& backend, int frames) {
  SceneDesc scene = test::SuturePads::scene();
  scene.mesh_collision.enabled = true;
  auto sim = Simulation::create(scene, {.backend = backend, .quiet = true});
  EXPECT_TRUE(sim.ok()) << sim.error().message();
  std::vector<Transfers> out;
  if (!sim.ok()) return out;
  for (int f = 0; f < frames; ++f) {
    EXPECT_TRUE(test::SuturePads::drive(*sim, f).ok());
    EXPECT_TRUE(sim->step().ok());
    const FrameStats& stats = sim->last_frame();
    double stage_bytes = 0.0, stage_waits = 0.0;
    for (const StageProfile& p : stats.stages) {
      stage_bytes += stats.counter(p.name, "read_bytes");
      stage_waits += stats.counter(p.name, "host_waits");
    }
    EXPECT_EQ(stage_bytes, double(stats.read_back_bytes)) << backend << " frame " << f;
    EXPECT_EQ(stage_waits, double(stats.host_waits)) << backend << " frame " << f;
    EXPECT_GE(stats.host_waits, stats.host_reads) << "every read-back waits";
    EXPECT_LE(stats.position_reads, f == 0 ? 2u : 1u) << backend << " frame " << f;
    out.push_back({stats.read_back_bytes, stats.host_reads, stats.host_waits, stats.position_reads});
  }
  return out;
}

TEST(FrameStage, HostTransfersAreCountedAlikeOnEveryBackend) {
  constexpr int kFrames = 6;
  const std::vector<Transfers> cpu = suture_frames("cpu", kFrames);
  ASSERT_EQ(cpu.size(), std::size_t{kFrames});
  int ran = 0;
  for (const std::string& backend : test::backends()) {
    if (backend == "cpu" || !test::missing_device(backend).empty()) continue;
    ++ran;
    const std::vector<Transfers> got = suture_frames(backend, kFrames);
    ASSERT_EQ(got.size(), cpu.size()) << backend;
    for (int f = 0; f < kFrames; ++f) {
      EXPECT_EQ(got[f].bytes, cpu[f].bytes) << backend << " frame " << f;
      EXPECT_EQ(got[f].reads, cpu[f].reads) << backend << " frame " << f;
      EXPECT_EQ(got[f].waits, cpu[f].waits) << backend << " frame " << f;
    }
    std::printf("[ measured ] %s: frame %d read %llu bytes in %u reads, %u waits\n", backend.c_str(), kFrames - 1,
                static_cast<unsigned long long>(got.back().bytes), got.back().reads, got.back().waits);
  }
  if (ran == 0) GTEST_SKIP() << "no GPU backend with a device here (the CPU's counts were checked)";
}

// A scene with no host-side stage waits once a frame: the statistics'
// words come back with the program's end (its end read), not in a round
// trip of their own — within the whole-frame-on-the-device budget of one
// wait and 4 KB.
TEST(FrameStage, APlainFrameWaitsOnceForItsProgramAndItsStatistics) {
  for (const std::string& backend : test::backends()) {
    if (!test::missing_device(backend).empty()) continue;
    auto sim = Simulation::create(hanging_block(), {.backend = backend, .quiet = true});
    ASSERT_TRUE(sim.ok()) << sim.error().message();
    for (int f = 0; f < 2; ++f) {
      SINEW_ASSERT_OK(sim->step());
      const FrameStats& stats = sim->last_frame();
      EXPECT_EQ(stats.host_reads, 0u) << backend << ": no read of its own";
      EXPECT_EQ(stats.host_waits, 1u) << backend << ": the program's end";
      EXPECT_EQ(stats.position_reads, 0u) << backend;
      EXPECT_GT(stats.read_back_bytes, 0u) << backend << ": the statistics came back";
      EXPECT_EQ(double(stats.read_back_bytes), stats.counter("solve", "read_bytes")) << backend;
      EXPECT_LE(stats.read_back_bytes, 4096u) << backend << ": a few words, not the state";
      EXPECT_GT(stats.kinetic_energy, 0.0) << backend << ": the statistics are this frame's";
    }
  }
}

// Residual mode runs a program per check: each check's residuals come back
// with its program's end, so the frame waits once per program and reads
// nothing on its own.
TEST(FrameStage, ResidualChecksComeBackWithTheirPrograms) {
  for (const std::string& backend : test::backends()) {
    if (!test::missing_device(backend).empty()) continue;
    SceneDesc scene = hanging_block();
    scene.solver.residual_tolerance = 1e-5;
    scene.solver.max_iterations = 64;
    scene.solver.check_interval = 8;
    auto sim = Simulation::create(scene, {.backend = backend, .quiet = true});
    ASSERT_TRUE(sim.ok()) << sim.error().message();
    SINEW_ASSERT_OK(sim->step());
    const FrameStats& stats = sim->last_frame();
    ASSERT_GE(stats.residual_checks, 1u) << backend;
    EXPECT_GT(stats.checked_residual, 0.0) << backend;
    EXPECT_EQ(stats.host_reads, 0u) << backend;
    EXPECT_EQ(stats.host_waits, stats.residual_checks + 1u) << backend << ": each check's program, then the frame's end";
  }
}

}  // namespace
}  // namespace sinew
