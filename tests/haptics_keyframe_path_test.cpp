// haptics_keyframe_path_test.cpp — a scripted hand's keyframed path
// (sinew/haptics/keyframe_path.h): poses at and between keys, the smooth
// ramp's rest at every key, rotations along the shorter arc, named errors.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "sinew/haptics/keyframe_path.h"

namespace sinew::haptics {
namespace {

KeyframePath two_keys(PathInterpolation interpolation) {
  auto p = KeyframePath::create({{.time = 1.0, .position = {0.0, 0.0, 0.0}}, {.time = 3.0, .position = {2.0, -4.0, 6.0}}},
                                interpolation);
  EXPECT_TRUE(p.ok());
  return *p;
}

TEST(KeyframePath, HoldsItsEndsOutsideTheKeys) {
  const KeyframePath p = two_keys(PathInterpolation::linear);
  EXPECT_EQ(p.at(0.0).position, (Vec3{0.0, 0.0, 0.0}));
  EXPECT_EQ(p.at(-5.0).position, (Vec3{0.0, 0.0, 0.0}));
  EXPECT_EQ(p.at(std::numeric_limits<double>::quiet_NaN()).position, (Vec3{0.0, 0.0, 0.0}));
  EXPECT_EQ(p.at(3.0).position, (Vec3{2.0, -4.0, 6.0}));
  EXPECT_EQ(p.at(100.0).position, (Vec3{2.0, -4.0, 6.0}));
  EXPECT_EQ(p.duration(), 3.0);
}

TEST(KeyframePath, LinearMovesAtConstantSpeed) {
  const KeyframePath p = two_keys(PathInterpolation::linear);
  EXPECT_NEAR(p.at(1.5).position[0], 0.5, 1e-15);
  EXPECT_NEAR(p.at(2.0).position[1], -2.0, 1e-15);
  EXPECT_NEAR(p.at(2.5).position[2], 4.5, 1e-15);
}

TEST(KeyframePath, SmoothStartsAndStopsAtRestAtEveryKey) {
  const KeyframePath p = two_keys(PathInterpolation::smooth);
  // Half way it is half way, faster than linear there: pi/2 x the mean speed.
  EXPECT_NEAR(p.at(2.0).position[0], 1.0, 1e-15);
  const double h = 1e-6;
  const double mid_speed = (p.at(2.0 + h).position[0] - p.at(2.0 - h).position[0]) / (2 * h);
  EXPECT_NEAR(mid_speed, M_PI / 2.0 * 1.0, 1e-6);
  // At the keys the speed is zero (a cosine ramp), on both sides.
  EXPECT_NEAR((p.at(1.0 + h).position[0] - p.at(1.0).position[0]) / h, 0.0, 1e-5);
  EXPECT_NEAR((p.at(3.0).position[0] - p.at(3.0 - h).position[0]) / h, 0.0, 1e-5);
  // The cosine ramp itself: a + (b - a) (1 - cos(pi s)) / 2.
  EXPECT_NEAR(p.at(1.5).position[0], 2.0 * (0.5 - 0.5 * std::cos(M_PI * 0.25)), 1e-15);
}

TEST(KeyframePath, RotatesAlongTheShorterArc) {
  // 0 and 90 degrees about z; the second key given as -q (the same rotation).
  const double c = std::cos(M_PI / 4), s = std::sin(M_PI / 4);
  auto p = KeyframePath::create({{.time = 0.0, .rotation = {1.0, 0.0, 0.0, 0.0}},
                                 {.time = 1.0, .rotation = {-c, 0.0, 0.0, -s}}},
                                PathInterpolation::linear);
  ASSERT_TRUE(p.ok());
  const Quat q = p->at(0.5).rotation;
  // Half way: 45 degrees about +z (w > 0), not 135 about -z.
  const double angle = 2.0 * std::atan2(std::hypot(q[1], q[2], q[3]), q[0]);
  EXPECT_NEAR(std::abs(angle), M_PI / 4, 1e-12);
  EXPECT_NEAR(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3], 1.0, 1e-15);
  // A key's rotation is normalised when the path is made.
  auto n = KeyframePath::create({{.time = 0.0, .rotation = {2.0, 0.0, 0.0, 0.0}}}, PathInterpolation::smooth);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(n->at(0.0).rotation, (Quat{1.0, 0.0, 0.0, 0.0}));
}

TEST(KeyframePath, BadKeysAreNamed) {
  const auto message = [](std::vector<PathKey> keys) {
    auto p = KeyframePath::create(std::move(keys), PathInterpolation::smooth);
    EXPECT_FALSE(p.ok());
    return p.ok() ? std::string() : p.error().message();
  };
  EXPECT_NE(message({}).find("at least one key"), std::string::npos);
  EXPECT_NE(message({{.time = 0.5}, {.time = 0.5}}).find("keys[1].time: must be greater"), std::string::npos);
  EXPECT_NE(message({{.time = -1.0}}).find("keys[0].time"), std::string::npos);
  EXPECT_NE(message({{.time = std::numeric_limits<double>::infinity()}}).find("keys[0].time"), std::string::npos);
  EXPECT_NE(message({{.time = 0.0}, {.time = 1.0, .position = {std::nan(""), 0.0, 0.0}}}).find("keys[1].position"),
            std::string::npos);
  EXPECT_NE(message({{.time = 0.0, .rotation = {0.0, 0.0, 0.0, 0.0}}}).find("keys[0].rotation"), std::string::npos);
}

TEST(KeyframePath, DrivesAScriptedDevice) {
  const KeyframePath p = two_keys(PathInterpolation::linear);
  ScriptedDevice device(p.script(), 0, 1000.0);
  ASSERT_TRUE(device.start(0).ok());
  DeviceSample sample;
  ASSERT_TRUE(device.sample(2'000'000'000, sample));  // t = 2 s
  EXPECT_NEAR(sample.position[0], 1.0, 1e-12);
  EXPECT_NEAR(sample.velocity[0], 1.0, 1e-6);  // 2 m over 2 s
}

}  // namespace
}  // namespace sinew::haptics
