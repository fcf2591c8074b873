// needle_forces_test.cpp — the force a needle feels over depth
// (docs/needles.md, "Needle forces"; scene: needle_forces_scene.h, a pad of
// 2 mm cells pinned at its bottom, a straight needle with a rounded tip of
// 4 mm radius pushed in at 10 mm/s, 64 substeps of 5 sweeps): it reaches a
// puncture force of 0.5 N with no tet inverted, the force drops at the
// puncture, then the shaft's friction grows with the inserted length and
// its parameters (Okamura, Simone and O'Leary, IEEE TBME 51(10), 2004); 10x
// E gives >= 5x the stiffness before puncture; bad settings are named.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "needle_forces_scene.h"
#include "sinew/scene_file.h"
#include "test_support.h"

namespace sinew::test {
namespace {

NeedlePushSettings settings(double young) {
  NeedlePushSettings s;
  s.young = young;
  s.tip_radius = 4e-3;
  s.substeps = 64;
  s.iterations = 5;
  return s;
}

std::vector<NeedlePushSample> push(const NeedlePushSettings& s, double depth) {
  std::vector<NeedlePushSample> trace;
  auto sim = Simulation::create(needle_push_scene(s), {.backend = "cpu"});
  EXPECT_TRUE(static_cast<bool>(sim));
  if (!sim) return trace;
  const Status st = push_needle(*sim, s, depth, trace);
  EXPECT_TRUE(st) << (st ? "" : st.error().message());
  return trace;
}

// The frame whose push punctured: at its end the needle holds a puncture
// (trace.size() if none).
std::size_t puncture_frame(const std::vector<NeedlePushSample>& trace) {
  for (std::size_t f = 0; f < trace.size(); ++f)
    if (trace[f].punctured) return f;
  return trace.size();
}

// Least-squares slope of force over depth for depths in [from, to] before the puncture [N/m].
double stiffness(const std::vector<NeedlePushSample>& trace, double from, double to) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (std::size_t f = 0; f < puncture_frame(trace); ++f)
    if (trace[f].depth >= from && trace[f].depth <= to)
      sx += trace[f].depth, sy += trace[f].force, sxx += trace[f].depth * trace[f].depth,
          sxy += trace[f].depth * trace[f].force, ++n;
  return n >= 2 ? (n * sxy - sx * sy) / (n * sxx - sx * sx) : 0.0;
}

// A needle pushed into kidney-class tissue (E 20 and 50 kPa) reaches 0.5 N
// before it punctures, with no tet turned inside out; the push rises with
// depth until then. With a point tip (tip_radius 0) the same push turns a
// tet inside out and passes through unpunctured.
TEST(NeedleForces, ABluntTipReachesHalfANewtonWithNoInvertedTet) {
  for (double young : {2e4, 5e4}) {
    const auto trace = push(settings(young), 0.0035);
    const std::size_t at = puncture_frame(trace);
    ASSERT_LT(at, trace.size()) << "E " << young << ": never punctured";
    ASSERT_GE(at, 2u);
    std::uint32_t inverted = 0;
    for (std::size_t f = 0; f <= at; ++f) {
      inverted = std::max(inverted, trace[f].inverted_tets);
      if (f > 0 && trace[f].depth > 2e-4) {
        EXPECT_GT(trace[f].force, trace[f - 1].force) << f;  // the rise
      }
    }
    std::printf("E %.0f Pa: punctured in frame %zu at %.2f mm after a push of %.4f N (reaction %.4f N), %u tets "
                "inverted until then\n",
                young, at + 1, trace[at].depth * 1e3, trace[at].tip_force, trace[at].force, inverted);
    EXPECT_GE(trace[at].tip_force, 0.5);
    EXPECT_LT(trace[at - 1].tip_force, 0.5);  // not before
    EXPECT_EQ(inverted, 0u);
    EXPECT_EQ(trace[at].refused_inverted, 0u);
  }
  NeedlePushSettings point = settings(5e4);
  point.tip_radius = 0.0;
  const auto trace = push(point, 0.004);
  std::uint32_t inverted = 0;
  for (std::size_t f = 0; f < puncture_frame(trace); ++f) inverted = std::max(inverted, trace[f].inverted_tets);
  std::printf("a point tip: %u tets inverted before any puncture (%s)\n", inverted,
              puncture_frame(trace) < trace.size() ? "punctured" : "never punctured");
  EXPECT_TRUE(inverted > 0 || puncture_frame(trace) == trace.size());
}

// 10x E gives >= 5x the stiffness before puncture (the slope of force over
// depth over the same depths, 0.2-1.2 mm).
TEST(NeedleForces, TenTimesTheModulusGivesAtLeastFiveTimesTheStiffness) {
  const double soft = stiffness(push(settings(5e3), 0.0013), 2e-4, 1.2e-3);
  const double stiff = stiffness(push(settings(5e4), 0.0013), 2e-4, 1.2e-3);
  std::printf("stiffness before puncture: %.1f N/m at 5 kPa, %.1f N/m at 50 kPa (x%.2f)\n", soft, stiff, stiff / soft);
  ASSERT_GT(soft, 0.0);
  EXPECT_GE(stiff / soft, 5.0);
}

// At the puncture the force drops; then, with the shaft's friction, it
// grows with the inserted length: the Coulomb level times the length plus
// the cutting force, and twice the friction gives about twice the growth.
// Without friction or cutting the shaft slides freely (0 N once through).
TEST(NeedleForces, TheForceDropsAtPunctureThenFrictionGrowsWithTheInsertedLength) {
  NeedlePushSettings s = settings(5e4);
  s.shaft_friction = 10.0;
  s.shaft_static_friction = 10.0;
  s.cutting_force = 0.05;
  const auto trace = push(s, 0.011);
  const std::size_t at = puncture_frame(trace);
  ASSERT_LT(at + 10, trace.size());
  const double before = trace[at].force, after = trace[at + 1].force;
  std::printf("the reaction %.4f N in the frame that punctured, %.4f N in the next, %.4f N at %.2f mm\n", before, after,
              trace.back().force, trace.back().depth * 1e3);
  EXPECT_LT(after, 0.5 * before);  // the drop
  // Friction: the force over the inserted length (the tip's depth less the
  // entry's, about the pad's top) after the cutting force, against the
  // Coulomb level (10 N/m; sticking at the same level).
  const auto& end = trace.back();
  const double per_length = (end.force - s.cutting_force) / end.depth;
  std::printf("friction %.2f N/m of inserted shaft (Coulomb level %.1f N/m)\n", per_length, s.shaft_friction);
  EXPECT_NEAR(per_length, s.shaft_friction, 0.25 * s.shaft_friction);
  // It grows with the inserted length, frame after frame.
  for (std::size_t f = at + 6; f < trace.size(); ++f) EXPECT_GT(trace[f].force, trace[f - 5].force) << f;
  // Twice the friction, about twice the growth.
  NeedlePushSettings twice = s;
  twice.shaft_friction = twice.shaft_static_friction = 20.0;
  const auto doubled = push(twice, 0.011);
  const double growth = trace.back().force - trace[at + 5].force;
  const double growth2 = doubled.back().force - doubled[puncture_frame(doubled) + 5].force;
  std::printf("growth after the puncture: %.4f N, with twice the friction %.4f N\n", growth, growth2);
  EXPECT_NEAR(growth2 / growth, 2.0, 0.3);
  // Without friction or cutting: nothing along the shaft.
  const auto free = push(settings(5e4), 0.004);
  EXPECT_NEAR(free.back().force, 0.0, 1e-6);
}

class NeedleForcesTest : public BackendTest {};

// The blunt tip's rows and the shaft's friction and cutting force on every
// backend: a lighter push (8 substeps of 10 sweeps, puncture_force 0.03 N)
// through the puncture and 3 mm on, its force trace and the pad's final
// positions as on the CPU (the GPU kernels do the same float operations;
// 1e-6 m and 1e-4 N allowed for GPUs that round otherwise).
TEST_P(NeedleForcesTest, BluntTipAndShaftFrictionAgreeWithTheCpu) {
  NeedlePushSettings s = settings(5e4);
  s.substeps = 8;
  s.iterations = 10;
  s.puncture_force = 0.03;  // (8 substeps converge the pad poorly: 24 N/m, inverting at 2.6 mm)
  s.shaft_friction = 10.0;
  s.shaft_static_friction = 15.0;
  s.shaft_viscous_friction = 100.0;
  s.cutting_force = 0.05;
  const auto run = [&](const std::string& backend, std::vector<NeedlePushSample>& trace, std::vector<float>& x) {
    auto sim = create_or_skip(needle_push_scene(s), backend);
    SINEW_ASSERT_OK(sim);
    SINEW_ASSERT_OK(push_needle(*sim, s, 0.004, trace));
    SINEW_ASSERT_OK(sim->read_positions(x));
  };
  std::vector<NeedlePushSample> cpu, here;
  std::vector<float> x_cpu, x_here;
  run("cpu", cpu, x_cpu);
  run(GetParam(), here, x_here);
  ASSERT_EQ(cpu.size(), here.size());
  ASSERT_LT(puncture_frame(cpu), cpu.size());  // it punctured, and then slid with friction
  EXPECT_GT(cpu.back().force, 0.05);  // the cutting force and the friction
  double worst_force = 0.0, worst_x = 0.0;
  for (std::size_t f = 0; f < cpu.size(); ++f) {
    EXPECT_EQ(cpu[f].punctured, here[f].punctured) << f;
    worst_force = std::max(worst_force, std::abs(cpu[f].force - here[f].force));
  }
  for (std::size_t i = 0; i < x_cpu.size(); ++i) worst_x = std::max(worst_x, double(std::abs(x_cpu[i] - x_here[i])));
  std::printf("[%s] against the CPU: forces %.3g N apart at most, positions %.3g m\n", GetParam().c_str(), worst_force,
              worst_x);
  EXPECT_LE(worst_force, 1e-4);
  EXPECT_LE(worst_x, 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Backends, NeedleForcesTest, ::testing::ValuesIn(backends()), backend_name);

// Bad settings are named errors.
TEST(NeedleForces, BadSettingsAreNamed) {
  const auto named = [](void (*change)(NeedleDesc&), const char* field) {
    SceneDesc scene = needle_push_scene(settings(5e4));
    change(scene.needles[0]);
    const Status s = check_scene(scene);
    ASSERT_FALSE(s) << field;
    EXPECT_NE(s.error().message().find(field), std::string::npos) << s.error().message();
  };
  named([](NeedleDesc& n) { n.tip_radius = -1e-3; }, "tip_radius");
  named([](NeedleDesc& n) { n.tip_radius = NAN; }, "tip_radius");
  named([](NeedleDesc& n) { n.shaft_friction = -1.0; }, "shaft_friction");
  named([](NeedleDesc& n) { n.shaft_friction = 2.0, n.shaft_static_friction = 1.0; }, "shaft_static_friction");
  named([](NeedleDesc& n) { n.shaft_viscous_friction = INFINITY; }, "shaft_viscous_friction");
  named([](NeedleDesc& n) { n.shaft_stick_velocity = 0.0; }, "shaft_stick_velocity");
  named([](NeedleDesc& n) { n.cutting_force = -0.1; }, "cutting_force");
}

// A scene file sets the fields (scenes/schema/scene.schema.json lists them);
// a bad value is named with its path in the file.
TEST(NeedleForces, SceneFilesSetTheFields) {
  auto file = parse_scene_json(R"({"tet_bodies": [{"mesh": {"grid": {"cells": [2, 2, 2], "cell_size": [0.002, 0.002, 0.002]}}}],
      "needles": [{"curve": [[0, 0.01, 0], [0, 0, 0]], "tip_radius": 0.004,
      "shaft_friction": 10, "shaft_static_friction": 15, "shaft_viscous_friction": 100,
      "shaft_stick_velocity": 0.002, "cutting_force": 0.05}]})",
                               ".");
  SINEW_ASSERT_OK(file);
  ASSERT_EQ(file->scene.needles.size(), 1u);
  const NeedleDesc& n = file->scene.needles[0];
  EXPECT_EQ(n.tip_radius, 0.004);
  EXPECT_EQ(n.shaft_friction, 10.0);
  EXPECT_EQ(n.shaft_static_friction, 15.0);
  EXPECT_EQ(n.shaft_viscous_friction, 100.0);
  EXPECT_EQ(n.shaft_stick_velocity, 0.002);
  EXPECT_EQ(n.cutting_force, 0.05);
  auto bad = parse_scene_json(R"({"tet_bodies": [{"mesh": {"grid": {"cells": [2, 2, 2], "cell_size": [0.002, 0.002, 0.002]}}}],
      "needles": [{"curve": [[0, 0.01, 0], [0, 0, 0]], "shaft_friction": 20,
      "shaft_static_friction": 15}]})",
                              ".");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message().find("/needles/0/shaft_friction"), std::string::npos) << bad.error().message();
}

}  // namespace
}  // namespace sinew::test
