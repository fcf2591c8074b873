// Interpolation and extrapolation of the two newest snapshots against
// hand-computed values, on a virtual time line (stamps in ns):
//   A at a = 100 ms: position (0, 0, 0), velocity (1, 0, 0), rotation identity
//   B at b = 110 ms: position (0.01, 0.02, 0), velocity (3, 0, 0), rotation 90 deg about z
// D = 10 ms; u = (now - b) / D; state = A + u (B - A); horizon 5 ms -> u <= 1.5.
#include <gtest/gtest.h>

#include <cmath>

#include "sinew/haptics/clock.h"
#include "sinew/haptics/snapshot_interpolator.h"

namespace {

using namespace sinew::haptics;

constexpr std::int64_t ms = 1'000'000;

HapticSnapshot snap(std::int64_t stamp, Vec3 x, Vec3 v, Quat q, std::uint64_t seq) {
  HapticSnapshot s;
  s.sequence = seq;
  s.stamp_ns = stamp;
  s.position = x;
  s.velocity = v;
  s.rotation = q;
  return s;
}

class HapticsInterpolation : public ::testing::Test {
 protected:
  void SetUp() override {
    const double h = std::sqrt(0.5);
    history.push(snap(100 * ms, {0, 0, 0}, {1, 0, 0}, {1, 0, 0, 0}, 1));
    history.push(snap(110 * ms, {0.01, 0.02, 0}, {3, 0, 0}, {h, 0, 0, h}, 2));
    params.extrapolation_horizon = 0.005;
  }
  SnapshotHistory history;
  InterpolationParams params;
};

TEST_F(HapticsInterpolation, NothingBeforeTheFirstSnapshot) {
  SnapshotHistory empty;
  const RenderedTool r = empty.render(5 * ms, params);
  EXPECT_FALSE(r.valid());
  EXPECT_TRUE(std::isinf(r.snapshot_age));
}

TEST_F(HapticsInterpolation, OneSnapshotIsHeld) {
  SnapshotHistory one;
  one.push(snap(100 * ms, {1, 2, 3}, {4, 5, 6}, {1, 0, 0, 0}, 1));
  const RenderedTool r = one.render(130 * ms, params);
  EXPECT_EQ(r.mode, RenderMode::single);
  EXPECT_EQ(r.position, (Vec3{1, 2, 3}));
  EXPECT_EQ(r.velocity, (Vec3{4, 5, 6}));
  EXPECT_DOUBLE_EQ(r.snapshot_age, 0.030);
}

TEST_F(HapticsInterpolation, AtArrivalTheOlderSnapshotIsRendered) {
  const RenderedTool r = history.render(110 * ms, params);  // u = 0
  EXPECT_EQ(r.mode, RenderMode::interpolated);
  EXPECT_DOUBLE_EQ(r.u, 0.0);
  EXPECT_EQ(r.position, (Vec3{0, 0, 0}));
  EXPECT_DOUBLE_EQ(r.render_age, 0.010) << "one interval behind";
  EXPECT_DOUBLE_EQ(r.snapshot_age, 0.0);
}

TEST_F(HapticsInterpolation, HalfwayByHand) {
  const RenderedTool r = history.render(115 * ms, params);  // u = 0.5
  EXPECT_EQ(r.mode, RenderMode::interpolated);
  EXPECT_DOUBLE_EQ(r.u, 0.5);
  EXPECT_DOUBLE_EQ(r.position[0], 0.005);
  EXPECT_DOUBLE_EQ(r.position[1], 0.010);
  EXPECT_DOUBLE_EQ(r.velocity[0], 2.0);
  // Normalised lerp halfway between identity and 90 deg about z is 45 deg about z.
  EXPECT_NEAR(r.rotation[0], std::cos(M_PI / 8), 1e-15);
  EXPECT_NEAR(r.rotation[3], std::sin(M_PI / 8), 1e-15);
  EXPECT_NEAR(r.rotation[1], 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(r.snapshot_age, 0.005);
  EXPECT_DOUBLE_EQ(r.render_age, 0.010);
  // At u = 1 (one interval after B arrived), B itself.
  const RenderedTool e = history.render(120 * ms, params);
  EXPECT_DOUBLE_EQ(e.position[0], 0.01);
  EXPECT_DOUBLE_EQ(e.position[1], 0.02);
}

TEST_F(HapticsInterpolation, ExtrapolatesWithinTheHorizon) {
  const RenderedTool r = history.render(123 * ms, params);  // u = 1.3: 3 ms past B, horizon 5 ms
  EXPECT_EQ(r.mode, RenderMode::extrapolated);
  EXPECT_NEAR(r.u, 1.3, 1e-12);
  EXPECT_NEAR(r.position[0], 0.013, 1e-15);
  EXPECT_NEAR(r.position[1], 0.026, 1e-15);
  EXPECT_NEAR(r.velocity[0], 3.6, 1e-12);
  EXPECT_NEAR(r.render_age, 0.010, 1e-12) << "still one interval: the line is extended at the same delay";
}

TEST_F(HapticsInterpolation, TheHorizonHolds) {
  // 5 ms past B is the last extrapolated instant (u = 1.5); later it holds there.
  const RenderedTool edge = history.render(125 * ms, params);
  EXPECT_EQ(edge.mode, RenderMode::extrapolated);
  EXPECT_NEAR(edge.position[0], 0.015, 1e-15);
  for (std::int64_t t : {126 * ms, 140 * ms, 10'000 * ms}) {
    const RenderedTool r = history.render(t, params);
    EXPECT_EQ(r.mode, RenderMode::held) << t;
    EXPECT_DOUBLE_EQ(r.u, 1.5);
    EXPECT_NEAR(r.position[0], 0.015, 1e-15);
    EXPECT_NEAR(r.position[1], 0.030, 1e-15);
    EXPECT_NEAR(r.velocity[0], 4.0, 1e-12);
    EXPECT_NEAR(r.render_age, ns_to_seconds(t) - 0.115, 1e-12) << "the held state ages";
  }
  // Horizon 0: never extrapolates.
  params.extrapolation_horizon = 0.0;
  const RenderedTool z = history.render(121 * ms, params);
  EXPECT_EQ(z.mode, RenderMode::held);
  EXPECT_DOUBLE_EQ(z.position[0], 0.01);
}

TEST_F(HapticsInterpolation, ASnapshotStampedAfterTheTickIsNotExtrapolatedBackwards) {
  const RenderedTool r = history.render(108 * ms, params);  // before b: u < 0 taken as 0
  EXPECT_DOUBLE_EQ(r.u, 0.0);
  EXPECT_EQ(r.position, (Vec3{0, 0, 0}));
}

TEST_F(HapticsInterpolation, AGapLongerThanMaxIntervalIsNotInterpolated) {
  // After a stall, the first fresh snapshot is held rather than slid towards
  // from a state the stall made old.
  params.max_interval = 0.05;
  history.push(snap(300 * ms, {1, 1, 1}, {0, 0, 0}, {1, 0, 0, 0}, 3));
  const RenderedTool r = history.render(305 * ms, params);
  EXPECT_EQ(r.mode, RenderMode::single);
  EXPECT_EQ(r.position, (Vec3{1, 1, 1}));
  history.push(snap(310 * ms, {2, 1, 1}, {0, 0, 0}, {1, 0, 0, 0}, 4));
  const RenderedTool s = history.render(315 * ms, params);
  EXPECT_EQ(s.mode, RenderMode::interpolated);
  EXPECT_DOUBLE_EQ(s.position[0], 1.5);
}

TEST(HapticsInterpolationMinInterval, PublicationsMicrosecondsApartAreNotExtrapolated) {
  // Two physics frames 4 mm apart published 10 us apart on the loop clock
  // (a frame finished late, the next one at once): their spacing is not the
  // tool's speed. Extrapolated, 5 ms later the tool would be 500 x 4 mm = 2 m
  // away (speed 400 m/s); the newest is held instead.
  SnapshotHistory history;
  const InterpolationParams params;  // min_interval 1 ms
  history.push(snap(100 * ms, {0, 0, 0}, {1, 0, 0}, {1, 0, 0, 0}, 1));
  history.push(snap(100 * ms + 10'000, {0.004, 0, 0}, {1, 0, 0}, {1, 0, 0, 0}, 2));
  for (std::int64_t t : {100 * ms + 10'000, 100 * ms + 20'000, 105 * ms, 200 * ms}) {
    const RenderedTool r = history.render(t, params);
    EXPECT_EQ(r.mode, RenderMode::single) << t;
    EXPECT_EQ(r.position, (Vec3{0.004, 0, 0})) << t;
    EXPECT_DOUBLE_EQ(r.render_age, r.snapshot_age);
  }
  // At exactly min_interval apart, interpolation resumes.
  SnapshotHistory edge;
  edge.push(snap(100 * ms, {0, 0, 0}, {0, 0, 0}, {1, 0, 0, 0}, 1));
  edge.push(snap(101 * ms, {0.004, 0, 0}, {0, 0, 0}, {1, 0, 0, 0}, 2));
  EXPECT_EQ(edge.render(101 * ms + 500'000, params).mode, RenderMode::interpolated);
  // The next publication a regular interval later interpolates again.
  history.push(snap(104 * ms + 10'000, {0.008, 0, 0}, {1, 0, 0}, {1, 0, 0, 0}, 3));
  const RenderedTool r = history.render(106 * ms + 10'000, params);
  EXPECT_EQ(r.mode, RenderMode::interpolated);
  EXPECT_NEAR(r.position[0], 0.006, 1e-15);
}

TEST(HapticsInterpolationParams, NamesTheParameter) {
  InterpolationParams p;
  p.extrapolation_horizon = -1;
  auto s = check(p);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message().find("extrapolation_horizon"), std::string::npos);
  p = {};
  p.max_interval = std::nan("");
  s = check(p);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message().find("max_interval"), std::string::npos);
  for (double bad : {-0.001, std::nan(""), 0.051}) {  // negative, NaN, above max_interval (0.05)
    p = {};
    p.min_interval = bad;
    s = check(p);
    ASSERT_FALSE(s.ok()) << bad;
    EXPECT_NE(s.error().message().find("min_interval"), std::string::npos);
  }
  p = {};
  p.min_interval = 0.0;
  EXPECT_TRUE(check(p).ok()) << "0: every interval is used";
}

}  // namespace
