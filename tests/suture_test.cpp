// suture_test.cpp — needles and sutures (issue 13, part 4; NeedleDesc): a
// curved needle driven through two tissue pads either side of a cut
// punctures each pad going in and coming out, the punctures pass to its
// thread, the thread stays threaded through 1,000 frames of pulling, and
// pulling it closes the cut; triangles that cannot be punctured are
// refused without a NaN; the settings' errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "mesh_contact_support.h"
#include "suture_scenes.h"
#include "test_support.h"

namespace sinew::test {
namespace {

class SutureTest : public BackendTest {};

bool all_finite(const std::vector<float>& x) {
  for (float v : x)
    if (!std::isfinite(v)) return false;
  return true;
}

double distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

// Where the stitch is after the needle has been driven through (frame by
// frame: SuturePads::drive): each frame's punctures and the worst distance
// of a puncture on the thread from its own point on the thread.
struct StitchRun {
  std::vector<Simulation::Puncture> punctures;  // at the end
  int first_puncture = -1;                      // frame
  double push_at_puncture = 0.0;                // tip_force in the frame before it [N]
  double worst_off_thread = 0.0;                // [m]
  bool finite = true;
};

StitchRun stitch(Simulation& sim, const SceneDesc& scene, int frames) {
  StitchRun out;
  std::vector<float> x;
  double push = 0.0;
  for (int f = 0; f < frames; ++f) {
    EXPECT_TRUE(SuturePads::drive(sim, f).ok());
    const Status s = sim.step();
    EXPECT_TRUE(s.ok()) << s.error().message();
    if (!s.ok()) break;
    auto state = sim.needle_state(0);
    EXPECT_TRUE(state.ok());
    if (!state.ok()) break;
    out.punctures = state->punctures;
    if (out.first_puncture < 0 && !out.punctures.empty()) {
      out.first_puncture = f;
      out.push_at_puncture = std::max(push, state->tip_force);
    }
    push = state->tip_force;
    EXPECT_TRUE(sim.read_positions(x).ok());
    out.finite = out.finite && all_finite(x);
    for (const auto& p : out.punctures)
      if (p.on_thread)
        out.worst_off_thread = std::max(
            out.worst_off_thread,
            on_thread(puncture_point(scene, sim, p, x), p, sim, 0, SuturePads::thread_segments + 1, x).from_row);
  }
  return out;
}

// The needle driven through both pads: it punctures pad A's top (once its
// push passes puncture_force), leaves through A's cut face, enters B's cut
// face and leaves through B's top: four punctures in that order, each
// passed to the thread once the needle's tail has gone through, every
// point held within 0.3 mm of the thread. On every backend.
TEST_P(SutureTest, TheNeedlePassesThroughBothPadsAndTheThreadFollows) {
  const SceneDesc scene = SuturePads::scene();
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  const StitchRun run = stitch(*sim, scene, SuturePads::turn_frames + 10);
  std::printf("[%s] first puncture at frame %d after a push of %.4f N; %zu punctures; thread within %.3f mm\n",
              GetParam().c_str(), run.first_puncture, run.push_at_puncture, run.punctures.size(),
              run.worst_off_thread * 1e3);
  EXPECT_TRUE(run.finite);
  ASSERT_EQ(run.punctures.size(), 4u);
  const bool exits[4] = {false, true, false, true};
  const std::uint32_t bodies[4] = {0, 0, 1, 1};
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(run.punctures[k].body_kind, BodyKind::tet) << k;
    EXPECT_EQ(run.punctures[k].body, bodies[k]) << k;
    EXPECT_EQ(run.punctures[k].exit, exits[k]) << k;
    EXPECT_TRUE(run.punctures[k].on_thread) << "puncture " << k << " is still on the needle";
  }
  EXPECT_GE(run.push_at_puncture, scene.needles[0].puncture_force);
  EXPECT_LT(run.worst_off_thread, 3e-4);
  if (GetParam() == "cpu") return;
  // The same stitch on the CPU reference: the same punctures, the same positions.
  auto reference = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(reference);
  const StitchRun expected = stitch(*reference, scene, SuturePads::turn_frames + 10);
  ASSERT_EQ(expected.punctures.size(), run.punctures.size());
  for (std::size_t k = 0; k < run.punctures.size(); ++k) {
    EXPECT_EQ(run.punctures[k].triangle, expected.punctures[k].triangle) << k;
    EXPECT_EQ(run.punctures[k].thread_segment, expected.punctures[k].thread_segment) << k;
  }
  std::vector<float> x, y;
  SINEW_ASSERT_OK(sim->read_positions(x));
  SINEW_ASSERT_OK(reference->read_positions(y));
  double worst = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) worst = std::max(worst, std::abs(double(x[i]) - double(y[i])));
  std::printf("[%s] largest difference from the CPU reference after %d frames: %.3g m\n", GetParam().c_str(),
              SuturePads::turn_frames + 10, worst);
  EXPECT_LT(worst, 1e-6);
}

// Then the thread is pulled 60 mm and tugged back and forth for the rest of
// 1,000 frames: its knot (last vertex) stops at the first puncture, every
// puncture stays on the thread, within 0.75 mm of it, every frame, each
// row holding the thread's closest point (not a segment off).
TEST(Suture, TheThreadStaysThreadedThroughAThousandFramesOfPulling) {
  const SceneDesc scene = SuturePads::scene();
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  const StitchRun passed = stitch(*sim, scene, SuturePads::turn_frames);
  ASSERT_EQ(passed.punctures.size(), 4u);
  std::vector<float> x;
  double worst = 0.0, stale = 0.0;
  int knotted = -1;
  for (int f = SuturePads::turn_frames; f < SuturePads::turn_frames + 1000; ++f) {
    SINEW_ASSERT_OK(SuturePads::drive(*sim, f));
    SINEW_ASSERT_OK(sim->step());
    auto state = sim->needle_state(0);
    SINEW_ASSERT_OK(state);
    ASSERT_EQ(state->punctures.size(), 4u) << "frame " << f;
    SINEW_ASSERT_OK(sim->read_positions(x));
    ASSERT_TRUE(all_finite(x)) << "frame " << f;
    for (const auto& p : state->punctures) {
      ASSERT_TRUE(p.on_thread) << "frame " << f;
      const OnThread d = on_thread(puncture_point(scene, *sim, p, x), p, *sim, 0, SuturePads::thread_segments + 1, x);
      worst = std::max(worst, d.from_closest);
      // The row's point may trail the closest one along the thread by the
      // friction's last step (it moves the two apart along the thread); a
      // wrong segment puts it a segment (1 mm) off.
      stale = std::max(stale, d.from_row - d.from_closest);
      ASSERT_LT(d.from_row - d.from_closest, 5e-4) << "frame " << f << ": the row holds the wrong point of the thread"
                                                   << " (segment " << p.thread_segment << ", s " << p.thread_s
                                                   << ", " << d.from_row << " m from it, " << d.from_closest
                                                   << " m from the closest)";
    }
    const auto& entry = state->punctures[0];
    if (knotted < 0 && entry.thread_segment + 1 == SuturePads::thread_segments && entry.thread_s == 1.0) knotted = f;
  }
  std::printf("knot at the first puncture from frame %d; punctures within %.3f mm of the thread, their rows' "
              "points at most %.3f mm farther, over 1,000 frames\n",
              knotted, worst * 1e3, stale * 1e3);
  EXPECT_GE(knotted, 0) << "the pull must bring the knot to the first puncture";
  // The pull asks more of the thread than it can give without stretching
  // the pads (a kinematic needle against a knot): the punctures lag the
  // thread by up to 0.62 mm under the tug (measured), under a third of a cell.
  EXPECT_LT(worst, 7.5e-4);
}

// Pulling the thread closes the cut: the distance between the wound's
// edges at the stitch (the tissue points where the thread leaves A's cut
// face and enters B's) shrinks from 4 mm by at least 0.5 mm (measured
// 0.78 mm), and the cut faces' mean distance at the stitch's plane too.
TEST(Suture, PullingTheThreadClosesTheCut) {
  const SceneDesc scene = SuturePads::scene();
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  std::vector<float> x;
  const auto faces = [&] {  // the mean gap between the cut faces' vertices in the z = 0 plane
    EXPECT_TRUE(sim->read_positions(x).ok());
    const std::uint32_t a = sim->info().tet_body_first_particle[0], b = sim->info().tet_body_first_particle[1];
    double gap = 0.0;
    for (std::uint32_t j = 0; j <= 5; ++j) gap += x[4 * (b + 0 + 7 * (j + 18))] - x[4 * (a + 6 + 7 * (j + 18))];
    return gap / 6.0;
  };
  const double faces_before = faces();
  const int frames = SuturePads::turn_frames + static_cast<int>(SuturePads::pulled_most / SuturePads::pull_speed) + 30;
  const StitchRun run = stitch(*sim, scene, frames);
  ASSERT_EQ(run.punctures.size(), 4u);
  SINEW_ASSERT_OK(sim->read_positions(x));
  const double edges = distance(puncture_point(scene, *sim, run.punctures[1], x),
                                puncture_point(scene, *sim, run.punctures[2], x));
  const double faces_after = faces();
  std::printf("cut faces %.3f -> %.3f mm apart; wound edges at the stitch 4.000 -> %.3f mm\n", faces_before * 1e3,
              faces_after * 1e3, edges * 1e3);
  EXPECT_LT(edges, 3.5e-3);
  EXPECT_LT(faces_after, faces_before - 2e-4);
}

// A straight needle pushed down into a pad whose surface triangles under it
// have been made degenerate (a vertex moved onto its neighbour) or inverted
// (a vertex pushed below the layer under it, turning its tets inside out)
// in the starting shape: those are refused and counted (the tip may go on
// to puncture a sound triangle beyond), and nothing becomes a NaN.
TEST(Suture, TrianglesThatCannotBePuncturedAreRefused) {
  for (const bool inverted : {false, true}) {
    SceneDesc scene = SuturePads::scene();
    scene.tet_bodies.pop_back();
    scene.line_bodies.clear();
    TetBodyDesc& pad = scene.tet_bodies[0];
    pad.initial_vertices = pad.mesh.vertices;
    const std::uint32_t top = 3 + 7 * (5 + 6 * 3), beside = top + 1;  // (3, 5, 3) and (4, 5, 3)
    if (inverted) pad.initial_vertices[top][1] -= 1.5 * SuturePads::cell;
    else pad.initial_vertices[top] = pad.initial_vertices[beside];
    // Aim at a surface triangle of the moved vertex: one it shares with
    // its neighbour when degenerate, one whose tet has a negative volume
    // when inverted; at its centroid in the starting shape (a degenerate
    // one's is on the segment it has become).
    const auto& x0 = pad.initial_vertices;
    const auto inside_out = [&](const std::array<std::uint32_t, 3>& t) {
      for (const auto& tet : pad.mesh.tets) {
        if (std::count_if(tet.begin(), tet.end(), [&](std::uint32_t v) { return v == t[0] || v == t[1] || v == t[2]; }) < 3)
          continue;
        double e[3][3];
        for (int k = 0; k < 3; ++k)
          for (int a = 0; a < 3; ++a) e[k][a] = x0[tet[k + 1]][a] - x0[tet[0]][a];
        const double volume = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                              e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                              e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
        return volume < 0.0;
      }
      return false;
    };
    std::array<std::uint32_t, 3> aim{};
    bool found = false;
    for (const auto& t : extract_boundary_surface(pad.mesh).triangles) {
      const bool has_top = t[0] == top || t[1] == top || t[2] == top;
      const bool has_beside = t[0] == beside || t[1] == beside || t[2] == beside;
      if (has_top && (inverted ? inside_out(t) : has_beside)) {
        aim = t;
        found = true;
        break;
      }
    }
    ASSERT_TRUE(found) << "the test's own setup";
    Vec3d centroid{0.0, 0.0, 0.0};
    for (std::uint32_t v : aim)
      for (int a = 0; a < 3; ++a) centroid[a] += pad.initial_vertices[v][a] / 3.0;
    NeedleDesc needle;
    needle.curve = {{0.0, 0.01, 0.0}, {0.0, 0.0, 0.0}};  // tip down
    needle.position = {centroid[0], centroid[1] + 1e-4, centroid[2]};
    needle.puncture_force = 1e-4;
    scene.needles = {needle};
    auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
    SINEW_ASSERT_OK(sim);
    std::vector<float> x;
    std::uint32_t refused = 0;
    for (int f = 0; f < 5; ++f) {
      const auto& p = needle.position;
      SINEW_ASSERT_OK(sim->set_needle_pose(0, {p[0], p[1] - 0.002 * (f + 1), p[2]}, {1.0, 0.0, 0.0, 0.0}));
      SINEW_ASSERT_OK(sim->step());
      SINEW_ASSERT_OK(sim->read_positions(x));
      ASSERT_TRUE(all_finite(x)) << "frame " << f;
      auto state = sim->needle_state(0);
      SINEW_ASSERT_OK(state);
      refused = inverted ? state->refused_inverted : state->refused_degenerate;
    }
    std::printf("%s: %u refused\n", inverted ? "inverted" : "degenerate", refused);
    EXPECT_GT(refused, 0u) << (inverted ? "inverted" : "degenerate");
  }
}

// A straight needle pushed 7 mm down into a pad punctures it, then is
// pulled back out: the puncture ends and its tissue point stays in the pad
// (the needle does not drag it out).
TEST(Suture, ANeedlePulledBackOutLeavesThePuncture) {
  SceneDesc scene = SuturePads::scene();
  scene.tet_bodies.pop_back();
  scene.line_bodies.clear();
  NeedleDesc needle;
  needle.curve = {{0.0, 0.012, 0.0}, {0.0, 0.0, 0.0}};  // tip down, 12 mm long
  needle.position = {-0.0071, 0.001, 0.0011};          // over pad A, off its grid lines
  needle.puncture_force = 0.005;
  scene.needles = {needle};
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  std::vector<float> x;
  std::size_t most = 0;
  double highest = -INFINITY;
  for (int f = 0; f < 40; ++f) {
    const double depth = f < 20 ? 4e-4 * (f + 1) : 4e-4 * (40 - f);  // the tip 7 mm into the 10 mm pad, back up
    SINEW_ASSERT_OK(sim->set_needle_pose(0, {-0.0071, 0.001 - depth, 0.0011}, {1.0, 0.0, 0.0, 0.0}));
    SINEW_ASSERT_OK(sim->step());
    auto state = sim->needle_state(0);
    SINEW_ASSERT_OK(state);
    most = std::max(most, state->punctures.size());
    SINEW_ASSERT_OK(sim->read_positions(x));
    ASSERT_TRUE(all_finite(x));
    for (const auto& p : state->punctures) highest = std::max(highest, puncture_point(scene, *sim, p, x)[1]);
  }
  auto state = sim->needle_state(0);
  SINEW_ASSERT_OK(state);
  std::printf("punctures at most %zu, at the end %zu; the highest puncture point %.2f mm\n", most,
              state->punctures.size(), highest * 1e3);
  EXPECT_EQ(most, 1u) << "the needle must puncture the pad going in";
  EXPECT_TRUE(state->punctures.empty()) << "pulled out, the needle must leave the puncture";
  EXPECT_LT(highest, 1e-3) << "the puncture's point was dragged out of the pad";
}

// A second stitch 1 mm beside the first (half a cell: it passes through
// triangles next to the first stitch's holes, now on the thread): it
// punctures like the first, 8 punctures in all.
TEST(Suture, ASecondStitchBesideTheFirstPuncturesToo) {
  const SceneDesc scene = SuturePads::scene();
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  const StitchRun first = stitch(*sim, scene, SuturePads::turn_frames);
  ASSERT_EQ(first.punctures.size(), 4u);
  const double a0 = SuturePads::last_angle;
  for (int f = 0; f < 20 + SuturePads::turn_frames; ++f) {
    // 20 frames over to z = 1 mm, then another turn.
    const double z = 0.001 * std::min(1.0, (f + 1) / 20.0);
    const double a = f < 20 ? a0 : a0 + SuturePads::last_angle * (f - 19) / SuturePads::turn_frames;
    SINEW_ASSERT_OK(sim->set_needle_pose(0, {0.0, SuturePads::centre_height, z}, SuturePads::needle_rotation(a)));
    SINEW_ASSERT_OK(sim->step());
  }
  auto state = sim->needle_state(0);
  SINEW_ASSERT_OK(state);
  std::printf("%zu punctures after two stitches 1 mm apart\n", state->punctures.size());
  EXPECT_EQ(state->punctures.size(), 8u);
}

// A straight needle with a thread pushed down through a pinned membrane (a
// tri body: one puncture, no inside to leave) and on down until its tail
// has passed: the puncture holds the thread.
TEST(Suture, ANeedleThreadsAMembrane) {
  SceneDesc scene = SuturePads::scene();
  scene.tet_bodies.clear();
  TriBodyDesc sheet;
  sheet.mesh = membrane(8, 8, 0.002, 0.0);  // 16 x 16 mm at y = 0
  for (std::uint32_t i = 0; i <= 8; ++i)
    for (std::uint32_t k = 0; k <= 8; ++k)
      if (i == 0 || i == 8 || k == 0 || k == 8) sheet.pinned.push_back(i * 9 + k);
  scene.tri_bodies.push_back(sheet);
  NeedleDesc& needle = scene.needles[0];
  needle.curve = {{0.0, 0.008, 0.0}, {0.0, 0.0, 0.0}};  // tail up, tip down, 8 mm
  const std::array<double, 3> over{0.0071, 0.001, 0.0093};  // off the grid's lines
  needle.position = over;
  LineBodyDesc& thread = scene.line_bodies[0];
  for (std::size_t i = 0; i < thread.vertices.size(); ++i) thread.vertices[i] = {over[0], 0.009 + 0.001 * i, over[2]};
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  std::vector<float> x;
  for (int f = 0; f < 40; ++f) {  // 12 mm down at 0.3 mm per frame
    SINEW_ASSERT_OK(sim->set_needle_pose(0, {over[0], over[1] - 3e-4 * (f + 1), over[2]}, {1.0, 0.0, 0.0, 0.0}));
    SINEW_ASSERT_OK(sim->step());
  }
  SINEW_ASSERT_OK(sim->read_positions(x));
  ASSERT_TRUE(all_finite(x));
  auto state = sim->needle_state(0);
  SINEW_ASSERT_OK(state);
  ASSERT_EQ(state->punctures.size(), 1u);
  const auto& p = state->punctures[0];
  EXPECT_EQ(p.body_kind, BodyKind::tri);
  EXPECT_FALSE(p.exit);
  EXPECT_TRUE(p.on_thread);
  const OnThread d = on_thread(puncture_point(scene, *sim, p, x), p, *sim, 0, SuturePads::thread_segments + 1, x);
  std::printf("the membrane's puncture is %.3f mm from the thread\n", d.from_closest * 1e3);
  EXPECT_LT(d.from_closest, 3e-4);
}

// A straight needle driven along its axis onto a pad at 75 degrees from
// the surface's normal (max_puncture_angle is 1 rad, 57 degrees): it may
// not puncture there; its contact pushes along the surface's normal and
// its catch is bounded, so the tip slides over the surface instead of
// dragging it along (10 mm before either, 5 mm with the bound alone).
TEST(Suture, AGrazingTipSlidesInsteadOfDraggingTheSurface) {
  SceneDesc scene = SuturePads::scene();
  scene.tet_bodies.pop_back();
  scene.line_bodies.clear();
  NeedleDesc needle;
  const double slant = 75.0 * M_PI / 180.0;
  const std::array<double, 3> along{std::sin(slant), -std::cos(slant), 0.0};  // towards +x and down
  needle.curve = {{-0.01 * along[0], -0.01 * along[1], 0.0}, {0.0, 0.0, 0.0}};
  const std::array<double, 3> start{-0.0135, 0.0005, 0.0011};  // over pad A's far end
  needle.position = start;
  needle.puncture_force = 0.01;
  scene.needles = {needle};
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  std::vector<float> x;
  double dragged = 0.0;
  std::uint32_t refused = 0;
  const std::uint32_t first = sim->info().tet_body_first_particle[0];
  for (int f = 0; f < 20; ++f) {  // 10 mm along its axis
    const double d = 5e-4 * (f + 1);
    SINEW_ASSERT_OK(sim->set_needle_pose(0, {start[0] + d * along[0], start[1] + d * along[1], start[2]},
                                         {1.0, 0.0, 0.0, 0.0}));
    SINEW_ASSERT_OK(sim->step());
    SINEW_ASSERT_OK(sim->read_positions(x));
    for (std::size_t v = 0; v < scene.tet_bodies[0].mesh.vertices.size(); ++v)
      dragged = std::max(dragged, std::abs(double(x[4 * (first + v)]) - scene.tet_bodies[0].mesh.vertices[v][0]));
    auto state = sim->needle_state(0);
    SINEW_ASSERT_OK(state);
    refused = state->refused_angle;
  }
  std::printf("a grazing tip moved the pad by %.2f mm along it; %u refusals of its angle\n", dragged * 1e3, refused);
  EXPECT_LT(dragged, 3e-3);  // measured 1.7 mm; 5 mm when the tip pushed along its own axis
}

// The stitch with mesh collision and continuous collision detection on:
// the thread runs through the tissue at its punctures, so neither may push
// it out there (suture_exemption.h). Without that exemption the thread's
// CCD fought the punctures (thousands of touches a frame, the rows jumping
// along the thread) and the knot never reached the first puncture.
TEST(Suture, TheStitchHoldsWithMeshCollisionAndContinuousCollisionOn) {
  SceneDesc scene = SuturePads::scene();
  scene.mesh_collision.enabled = true;
  scene.mesh_collision.thickness = 5e-4;
  scene.mesh_collision.self_collision = false;
  scene.mesh_collision.continuous = true;
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  std::uint32_t forced = 0;
  for (int f = 0; f < 300; ++f) {
    SINEW_ASSERT_OK(SuturePads::drive(*sim, f));
    SINEW_ASSERT_OK(sim->step());
    forced += sim->last_frame().ccd_forced;
  }
  auto state = sim->needle_state(0);
  SINEW_ASSERT_OK(state);
  ASSERT_EQ(state->punctures.size(), 4u);
  for (const auto& p : state->punctures) EXPECT_TRUE(p.on_thread);
  EXPECT_EQ(state->punctures[0].thread_segment + 1, std::uint32_t{SuturePads::thread_segments})
      << "the knot must reach the first puncture";
  EXPECT_EQ(forced, 0u);
}

// Bad settings and calls are named.
TEST(Suture, BadSettingsAreNamed) {
  const auto error_of = [](const SceneDesc& scene) {
    auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
    return sim.ok() ? std::string() : sim.error().message();
  };
  SceneDesc scene = SuturePads::scene();
  scene.needles[0].curve.resize(1);
  EXPECT_NE(error_of(scene).find("needles[0].curve must have at least 2 points"), std::string::npos) << error_of(scene);
  scene = SuturePads::scene();
  scene.needles[0].curve[3] = scene.needles[0].curve[2];
  EXPECT_NE(error_of(scene).find("needles[0].curve[3] repeats"), std::string::npos) << error_of(scene);
  scene = SuturePads::scene();
  scene.needles[0].curve[5][1] = NAN;
  EXPECT_NE(error_of(scene).find("needles[0].curve[5]"), std::string::npos) << error_of(scene);
  scene = SuturePads::scene();
  scene.needles[0].puncture_force = 0.0;
  EXPECT_NE(error_of(scene).find("needles[0].puncture_force"), std::string::npos) << error_of(scene);
  scene = SuturePads::scene();
  scene.needles[0].max_puncture_angle = 2.0;
  EXPECT_NE(error_of(scene).find("needles[0].max_puncture_angle"), std::string::npos) << error_of(scene);
  scene = SuturePads::scene();
  scene.needles[0].thread = 3;
  EXPECT_NE(error_of(scene).find("needles[0].thread = 3 is not a line body"), std::string::npos) << error_of(scene);
  scene = SuturePads::scene();
  scene.needles.push_back(scene.needles[0]);
  EXPECT_NE(error_of(scene).find("needles[1].thread = 0 is already needles[0]'s thread"), std::string::npos)
      << error_of(scene);
  scene = SuturePads::scene();
  scene.needles[0].thread_dynamic_friction = 1.0;
  EXPECT_NE(error_of(scene).find("needles[0].thread.dynamic_friction"), std::string::npos) << error_of(scene);

  auto sim = Simulation::create(SuturePads::scene(), {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  const Status bad_rotation = sim->set_needle_pose(0, {0.0, 0.0, 0.0}, {2.0, 0.0, 0.0, 0.0});
  ASSERT_FALSE(bad_rotation.ok());
  EXPECT_NE(bad_rotation.error().message().find("unit quaternion"), std::string::npos);
  const Status nan_position = sim->set_needle_pose(0, {0.0, NAN, 0.0}, {1.0, 0.0, 0.0, 0.0});
  ASSERT_FALSE(nan_position.ok());
  EXPECT_NE(nan_position.error().message().find("set_needle_pose: position"), std::string::npos)
      << nan_position.error().message();
  const Status half_turn = sim->set_needle_pose(0, {0.0, 0.0, 0.0}, SuturePads::needle_rotation(M_PI));
  ASSERT_FALSE(half_turn.ok());
  EXPECT_NE(half_turn.error().message().find("at most pi/2"), std::string::npos) << half_turn.error().message();
  const Status bad_index = sim->set_needle_pose(1, {0.0, 0.0, 0.0}, {1.0, 0.0, 0.0, 0.0});
  ASSERT_FALSE(bad_index.ok());
  EXPECT_NE(bad_index.error().message().find("set_needle_pose: index 1 is not a needle"), std::string::npos)
      << bad_index.error().message();
  EXPECT_FALSE(sim->needle_state(1).ok());
}

INSTANTIATE_TEST_SUITE_P(Backends, SutureTest, ::testing::ValuesIn(backends()), backend_name);

}  // namespace
}  // namespace sinew::test
