// view_parts_test.cpp — the parts of `sinew view` (apps/sinew/view/,
// docs/viewer.md) that need no window: the triple buffer between the
// physics and the viewer, the mouse's virtual haptic device, the orbit
// camera's drags, the shapes' meshes and the PPM screenshots.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "view/image_file.h"
#include "view/mouse_device.h"
#include "view/orbit_camera.h"
#include "view/shape_meshes.h"
#include "view/view_snapshot.h"

namespace sinew::view {
namespace {

// The reader only ever sees whole values, newest last: a writer fills
// vectors with one number each time and the reader checks every one it
// takes is uniform and never older than the one before.
TEST(ViewTripleBuffer, ReaderSeesWholeValuesInOrder) {
  TripleBuffer<std::vector<int>> buffer;
  constexpr int kValues = 20000;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (int v = 1; v <= kValues; ++v) {
      buffer.back().assign(64 + v % 7, v);
      buffer.publish();
    }
    done.store(true);
  });
  int last = 0, taken = 0;
  for (;;) {
    const bool finished = done.load();  // read before update(): then the last value is taken below
    if (!buffer.update()) {
      if (finished) break;
      continue;
    }
    const std::vector<int>& front = buffer.front();
    ASSERT_FALSE(front.empty());
    for (int x : front) ASSERT_EQ(x, front[0]) << "a torn value";
    ASSERT_GT(front[0], last) << "an older value after a newer one";
    last = front[0], ++taken;
  }
  writer.join();
  EXPECT_EQ(buffer.front().front(), kValues) << "the newest value is the last one taken";
  EXPECT_GT(taken, 0);
}

TEST(ViewTripleBuffer, NothingNewNothingTaken) {
  TripleBuffer<int> buffer;
  EXPECT_FALSE(buffer.update());
  buffer.back() = 7;
  buffer.publish();
  EXPECT_TRUE(buffer.update());
  EXPECT_EQ(buffer.front(), 7);
  EXPECT_FALSE(buffer.update());
  EXPECT_EQ(buffer.front(), 7);
}

constexpr std::int64_t kMs = 1'000'000;  // [ns]

TEST(ViewMouseDevice, NoSampleBeforeTheHandleIsPlaced) {
  MouseDevice device;
  haptics::DeviceSample s;
  EXPECT_FALSE(device.sample(0, s));
}

// place() puts the handle at once, at rest; move_to() is followed through
// the low-pass: towards the goal, never past it, with the filter's velocity.
TEST(ViewMouseDevice, HandleFollowsTheMouseSmoothly) {
  const double tau = 0.02;
  MouseDevice device(tau);
  device.place({0.1, 0.2, 0.3});
  haptics::DeviceSample s;
  ASSERT_TRUE(device.sample(0, s));
  EXPECT_EQ(s.position, (Vec3{0.1, 0.2, 0.3}));
  EXPECT_EQ(s.velocity, (Vec3{0, 0, 0}));

  device.move_to({0.2, 0.2, 0.3});
  double previous = 0.1;
  std::uint64_t sequence = s.sequence;
  for (int tick = 1; tick <= 200; ++tick) {
    ASSERT_TRUE(device.sample(tick * kMs, s));
    EXPECT_GT(s.sequence, sequence);
    sequence = s.sequence;
    EXPECT_GT(s.position[0], previous) << "tick " << tick;
    EXPECT_LE(s.position[0], 0.2) << "overshoot at tick " << tick;
    EXPECT_NEAR(s.velocity[0], (0.2 - s.position[0]) / tau, 1e-12);
    EXPECT_EQ(s.position[1], 0.2);
    previous = s.position[0];
  }
  // After 10 time constants the handle is there (e^-10 of the way left).
  EXPECT_NEAR(s.position[0], 0.2, 0.1 * std::exp(-10.0) * 1.01);
  // A first-order lag: after one time constant, 1 - 1/e of the way.
  MouseDevice again(tau);
  again.place({0, 0, 0});
  ASSERT_TRUE(again.sample(0, s));
  again.move_to({1, 0, 0});
  ASSERT_TRUE(again.sample(20 * kMs, s));
  EXPECT_NEAR(s.position[0], 1 - std::exp(-1.0), 1e-9);
}

TEST(ViewMouseDevice, PlaceJumpsWithoutVelocity) {
  MouseDevice device;
  device.place({0, 0, 0});
  haptics::DeviceSample s;
  ASSERT_TRUE(device.sample(0, s));
  device.move_to({1, 0, 0});
  ASSERT_TRUE(device.sample(kMs, s));
  device.place({-1, 2, 0});
  ASSERT_TRUE(device.sample(2 * kMs, s));
  EXPECT_EQ(s.position, (Vec3{-1, 2, 0}));
  EXPECT_EQ(s.velocity, (Vec3{0, 0, 0}));
  EXPECT_EQ(device.goal(), (Vec3{-1, 2, 0}));
}

// The pixel position of a world point in a width x height viewport.
V3 to_pixels(const OrbitCamera& camera, V3 p, float width, float height) {
  const V3 ndc = transform_point(camera.projection(width / height) * camera.view(), p);
  return {(ndc.x * 0.5f + 0.5f) * width, (0.5f - ndc.y * 0.5f) * height, ndc.z};
}

// A handle dragged by (dx, dy) pixels in the view plane is drawn (dx, dy)
// pixels further, wherever it is and however the camera is turned.
TEST(ViewOrbitCamera, PlaneDragFollowsTheCursor) {
  OrbitCamera camera;
  camera.frame_box({0, 0, 0}, {0.1f, 0.025f, 0.05f});
  for (float yaw : {-2.0f, 0.3f, 1.2f}) {
    camera.yaw = yaw;
    camera.orbit(0, 40);
    const V3 at = camera.target + V3{0.01f, -0.02f, 0.005f};
    const V3 before = to_pixels(camera, at, 1280, 720);
    const V3 after = to_pixels(camera, at + camera.drag_in_plane(at, 30, -12, 720), 1280, 720);
    EXPECT_NEAR(after.x - before.x, 30, 0.5) << "yaw " << yaw;
    EXPECT_NEAR(after.y - before.y, -12, 0.5) << "yaw " << yaw;
  }
}

// A depth drag moves along the view direction: the handle stays under the
// cursor; dragging down brings it nearer the eye.
TEST(ViewOrbitCamera, DepthDragStaysUnderTheCursor) {
  OrbitCamera camera;
  const V3 at = camera.target;
  const V3 before = to_pixels(camera, at, 800, 600);
  const V3 moved = at + camera.drag_in_depth(at, 25, 600);
  const V3 after = to_pixels(camera, moved, 800, 600);
  EXPECT_NEAR(after.x, before.x, 0.5);
  EXPECT_NEAR(after.y, before.y, 0.5);
  EXPECT_LT(length(moved - camera.eye()), length(at - camera.eye()));
}

TEST(ViewShapeMeshes, CapsuleSurfaceIsAtItsRadius) {
  const double radius = 0.005, half_height = 0.015;
  const MeshData m = capsule(radius, half_height);
  ASSERT_GT(m.indices.size(), 0u);
  ASSERT_EQ(m.indices.size() % 3, 0u);
  for (std::size_t v = 0; v < m.vertices.size(); v += 9) {
    const V3 p{m.vertices[v], m.vertices[v + 1], m.vertices[v + 2]};
    const V3 n{m.vertices[v + 3], m.vertices[v + 4], m.vertices[v + 5]};
    const float y = std::fmax(-0.015f, std::fmin(0.015f, p.y));
    EXPECT_NEAR(length(p - V3{0, y, 0}), radius, 1e-6);
    EXPECT_NEAR(length(n), 1.0f, 1e-5);
    EXPECT_GT(dot(n, p - V3{0, y, 0}), 0.0f) << "normals point out";
  }
  for (std::uint32_t i : m.indices) EXPECT_LT(i, m.vertices.size() / 9);
}

// A needle's tube: every vertex at the radius from its own segment, normals out.
TEST(ViewShapeMeshes, TubeAroundAPolyline) {
  const std::vector<Vec3d> curve = {{0, 0, 0}, {0.01, 0, 0}, {0.01, 0.01, 0.005}};
  const double radius = 2e-4;
  const int slices = 8;
  const MeshData m = tube(curve, radius, slices);
  const std::size_t per_segment = 2 * (slices + 1);  // a ring at each end
  ASSERT_EQ(m.vertices.size(), 9 * per_segment * (curve.size() - 1));
  ASSERT_EQ(m.indices.size(), 6u * slices * (curve.size() - 1));
  for (std::size_t v = 0; v < m.vertices.size() / 9; ++v) {
    const V3 p{m.vertices[9 * v], m.vertices[9 * v + 1], m.vertices[9 * v + 2]};
    const V3 n{m.vertices[9 * v + 3], m.vertices[9 * v + 4], m.vertices[9 * v + 5]};
    const std::size_t k = v / per_segment + 1;
    const V3 a(curve[k - 1]), b(curve[k]);
    const float t = dot(p - a, b - a) / dot(b - a, b - a);
    EXPECT_TRUE(std::fabs(t) < 1e-4f || std::fabs(t - 1) < 1e-4f) << "vertex " << v << " not at an end";
    EXPECT_NEAR(length(p - (a + (b - a) * t)), radius, 1e-7);
    EXPECT_NEAR(length(n), 1.0f, 1e-5);
    EXPECT_NEAR(dot(n, b - a), 0.0f, 1e-7);
    EXPECT_GT(dot(n, p - (a + (b - a) * t)), 0.0f);
  }
}

// A body's vertex normals: the mean of its faces', outward for a closed box.
TEST(ViewShapeMeshes, BodyNormalsPointOut) {
  // The unit box's corners as one body (8 particles, 12 outward triangles).
  const std::vector<float> xyzw = {-1, -1, -1, 1, 1, -1, -1, 1, 1, 1, -1, 1, -1, 1, -1, 1,
                                   -1, -1, 1, 1,  1, -1, 1, 1,  1, 1, 1, 1,  -1, 1, 1, 1};
  const std::vector<std::array<std::uint32_t, 3>> triangles = {
      {0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
      {3, 7, 6}, {3, 6, 2}, {0, 4, 7}, {0, 7, 3}, {1, 2, 6}, {1, 6, 5}};
  MeshData m;
  body_vertices(xyzw, triangles, {}, m);
  ASSERT_EQ(m.vertices.size(), 8u * 9);
  for (std::size_t v = 0; v < 8; ++v) {
    const V3 p{m.vertices[9 * v], m.vertices[9 * v + 1], m.vertices[9 * v + 2]};
    const V3 n{m.vertices[9 * v + 3], m.vertices[9 * v + 4], m.vertices[9 * v + 5]};
    EXPECT_NEAR(length(n), 1.0f, 1e-5);
    EXPECT_GT(dot(n, p), 0.0f) << "vertex " << v;
  }
}

TEST(ViewImageFile, WritesBinaryPpm) {
  const std::filesystem::path dir = SINEW_TEST_TMP_DIR;
  std::filesystem::create_directories(dir);
  const std::filesystem::path path = dir / "view_parts.ppm";
  const std::vector<std::uint8_t> rgb = {255, 0, 0, 0, 255, 0, 0, 0, 255, 9, 9, 9, 1, 2, 3, 4, 5, 6};
  ASSERT_TRUE(write_ppm(path, 3, 2, rgb));
  std::ifstream in(path, std::ios::binary);
  const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string header = "P6\n3 2\n255\n";
  ASSERT_EQ(data.size(), header.size() + rgb.size());
  EXPECT_EQ(data.substr(0, header.size()), header);
  EXPECT_EQ(std::vector<std::uint8_t>(data.begin() + static_cast<long>(header.size()), data.end()), rgb);
}

TEST(ViewImageFile, WrongSizeAndUnwritablePathAreErrors) {
  const std::vector<std::uint8_t> rgb(10);
  const Status bad = write_ppm(std::filesystem::path(SINEW_TEST_TMP_DIR) / "x.ppm", 2, 2, rgb);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message().find("is not 2 x 2 RGB pixels"), std::string::npos) << bad.error().message();
  const std::vector<std::uint8_t> ok(12);
  const Status nowhere = write_ppm("/nonexistent-folder/x.ppm", 2, 2, ok);
  ASSERT_FALSE(nowhere);
  EXPECT_NE(nowhere.error().message().find("cannot be written"), std::string::npos);
}

}  // namespace
}  // namespace sinew::view
