// Devices: scripted (pose as a function of time), replay (trajectory CSV)
// and null; CSV errors name the file and line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "sinew/haptics/clock.h"
#include "sinew/haptics/replay_device.h"
#include "sinew/haptics/scripted_device.h"

namespace {

using namespace sinew::haptics;
constexpr std::int64_t ms = 1'000'000;

std::filesystem::path tmp(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(SINEW_TEST_TMP_DIR) / "haptics";
  std::filesystem::create_directories(dir);
  return dir / name;
}

void write(const std::filesystem::path& p, const std::string& text) { std::ofstream(p) << text; }

bool says(const sinew::Status& s, const std::string& what) {
  return !s.ok() && s.error().message().find(what) != std::string::npos;
}

TEST(HapticsDevice, ScriptedPoseVelocityAndStamps) {
  const double w = 2.0;  // rad/s about y
  ScriptedDevice d(
      [w](double t) {
        ScriptedPose p;
        p.position = {0.1 * t, 0.02, -0.3 * t};
        p.rotation = {std::cos(w * t / 2), 0.0, std::sin(w * t / 2), 0.0};
        p.buttons = t > 1.0 ? 1u : 0u;
        return p;
      },
      /*origin_ns=*/500 * ms, 1000.0);
  EXPECT_EQ(d.update_rate_hz(), 1000.0);
  DeviceSample s;
  ASSERT_TRUE(d.sample(1500 * ms + 250 * ms, s));  // t = 1.25 s
  EXPECT_EQ(s.sequence, 1u);
  EXPECT_EQ(s.time_ns, 1750 * ms);
  EXPECT_NEAR(s.position[0], 0.125, 1e-15);
  EXPECT_NEAR(s.position[2], -0.375, 1e-15);
  EXPECT_NEAR(s.velocity[0], 0.1, 1e-9);
  EXPECT_NEAR(s.velocity[1], 0.0, 1e-12);
  EXPECT_NEAR(s.velocity[2], -0.3, 1e-9);
  EXPECT_NEAR(s.angular_velocity[1], w, 1e-6);
  EXPECT_EQ(s.buttons, 1u);
  ASSERT_TRUE(d.sample(1751 * ms, s));
  EXPECT_EQ(s.sequence, 2u);
  d.command({1, 2, 3}, {0, 0, 0}, 1751 * ms);
  EXPECT_EQ(d.last_force(), (Vec3{1, 2, 3}));
  EXPECT_EQ(d.commands(), 1u);
}

TEST(HapticsDevice, ScriptedDeviceParametersAreChecked) {
  const ScriptedDevice::Script still = [](double) { return ScriptedPose{}; };
  for (double h : {0.0, -1e-4, std::nan(""), std::numeric_limits<double>::infinity()}) {
    auto made = ScriptedDevice::create(still, 0, 1000.0, h);
    EXPECT_FALSE(made.ok()) << h;
    if (!made.ok()) {
      EXPECT_NE(made.error().message().find("difference_step"), std::string::npos) << made.error().message();
    }
  }
  for (double rate : {0.0, -1000.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    auto made = ScriptedDevice::create(still, 0, rate);
    EXPECT_FALSE(made.ok()) << rate;
    if (!made.ok()) {
      EXPECT_NE(made.error().message().find("rate_hz"), std::string::npos) << made.error().message();
    }
  }
  EXPECT_FALSE(ScriptedDevice::create(ScriptedDevice::Script{}).ok()) << "no script";
  auto good = ScriptedDevice::create(still, 0, 500.0, 1e-3);
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(good->update_rate_hz(), 500.0);
  EXPECT_TRUE(good->start(0).ok());
  // Built by the constructor (unchecked): start() reports the bad parameter.
  ScriptedDevice unchecked(still, 0, 1000.0, 0.0);
  auto st = unchecked.start(0);
  EXPECT_FALSE(st.ok());
  if (!st.ok()) {
    EXPECT_NE(st.error().message().find("difference_step"), std::string::npos);
  }
}

TEST(HapticsDevice, NullDeviceHoldsItsPose) {
  NullDevice d({.position = {1, 2, 3}});
  DeviceSample s;
  ASSERT_TRUE(d.sample(5 * ms, s));
  EXPECT_EQ(s.position, (Vec3{1, 2, 3}));
  EXPECT_EQ(s.velocity, (Vec3{0, 0, 0}));
  EXPECT_EQ(s.time_ns, 5 * ms);
  d.command({1, 0, 0}, {0, 0, 0}, 5 * ms);
  EXPECT_EQ(d.commands(), 1u);
}

std::vector<TrajectorySample> square() {
  const double h = std::sqrt(0.5);
  return {{0.0, {0, 0, 0}, {1, 0, 0, 0}, 0},
          {0.1, {0.01, 0, 0}, {h, 0, 0, h}, 1},
          {0.3, {0.01, 0.02, 0}, {0, 0, 0, 1}, 3}};
}

TEST(HapticsDevice, ReplayInterpolatesHoldsAndLoops) {
  auto d = ReplayDevice::create(square(), /*origin_ns=*/1000 * ms);
  ASSERT_TRUE(d.ok()) << d.error().message();
  EXPECT_NEAR(d->update_rate_hz(), 2 / 0.3, 1e-12);
  DeviceSample s;
  ASSERT_TRUE(d->sample(1050 * ms, s));  // t = 0.05: halfway along the first segment
  EXPECT_NEAR(s.position[0], 0.005, 1e-15);
  EXPECT_NEAR(s.velocity[0], 0.1, 1e-12);
  EXPECT_NEAR(s.rotation[3], std::sin(M_PI / 8), 1e-12) << "45 deg about z";
  EXPECT_NEAR(s.angular_velocity[2], (M_PI / 2) / 0.1, 1e-9);
  EXPECT_EQ(s.buttons, 0u);
  ASSERT_TRUE(d->sample(1250 * ms, s));  // t = 0.25: 3/4 along the second segment
  EXPECT_NEAR(s.position[1], 0.015, 1e-15);
  EXPECT_NEAR(s.velocity[1], 0.1, 1e-12);
  EXPECT_EQ(s.buttons, 1u);
  ASSERT_TRUE(d->sample(900 * ms, s));  // before the start: the first sample
  EXPECT_EQ(s.position, (Vec3{0, 0, 0}));
  ASSERT_TRUE(d->sample(5000 * ms, s));  // after the end: the last, at rest
  EXPECT_EQ(s.position, (Vec3{0.01, 0.02, 0}));
  EXPECT_EQ(s.velocity, (Vec3{0, 0, 0}));
  EXPECT_EQ(s.buttons, 3u);

  auto looped = ReplayDevice::create(square(), 0, /*loop=*/true);
  ASSERT_TRUE(looped.ok());
  ASSERT_TRUE(looped->sample(350 * ms, s));  // 0.35 wraps to 0.05
  EXPECT_NEAR(s.position[0], 0.005, 1e-12);
}

TEST(HapticsDevice, TrajectoryCsvRoundTrips) {
  const auto path = tmp("square.csv");
  ASSERT_TRUE(write_trajectory_csv(path, square()).ok());
  auto back = read_trajectory_csv(path);
  ASSERT_TRUE(back.ok()) << back.error().message();
  const auto orig = square();
  ASSERT_EQ(back->size(), orig.size());
  for (std::size_t i = 0; i < orig.size(); ++i) {
    EXPECT_EQ((*back)[i].time, orig[i].time);
    EXPECT_EQ((*back)[i].position, orig[i].position);
    EXPECT_EQ((*back)[i].buttons, orig[i].buttons);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR((*back)[i].rotation[k], orig[i].rotation[k], 1e-15);
  }
  // Position-only files work too, with comments.
  const auto simple = tmp("simple.csv");
  write(simple, "# recorded by hand\ntime, x, y, z\n0, 0, 0, 0\n\n0.5, 0.01, 0, 0\n");
  auto d = ReplayDevice::load(simple);
  ASSERT_TRUE(d.ok()) << d.error().message();
  EXPECT_EQ(d->samples().size(), 2u);
  EXPECT_NE(d->name().find("simple.csv"), std::string::npos);
}

TEST(HapticsDevice, MalformedTrajectoriesNameFileAndLine) {
  EXPECT_TRUE(says(ReplayDevice::load(tmp("missing.csv")).status(), "missing.csv"));
  const auto bad_header = tmp("bad_header.csv");
  write(bad_header, "# c\ntime,x,y\n0,0,0\n");
  EXPECT_TRUE(says(read_trajectory_csv(bad_header).status(), "bad_header.csv:2: header"));
  const auto wrong_name = tmp("wrong_name.csv");
  write(wrong_name, "t,x,y,z\n");
  EXPECT_TRUE(says(read_trajectory_csv(wrong_name).status(), "wrong_name.csv:1: header column 1 must be 'time'"));
  const auto short_row = tmp("short_row.csv");
  write(short_row, "time,x,y,z\n0,0,0,0\n0.1,0,0\n");
  EXPECT_TRUE(says(read_trajectory_csv(short_row).status(), "short_row.csv:3: expected 4 values, got 3"));
  const auto not_number = tmp("not_number.csv");
  write(not_number, "time,x,y,z\n0,0,abc,0\n");
  EXPECT_TRUE(says(read_trajectory_csv(not_number).status(), "not_number.csv:2: column 3 is not a finite number"));
  const auto nan_value = tmp("nan_value.csv");
  write(nan_value, "time,x,y,z\n0,0,nan,0\n");
  EXPECT_TRUE(says(read_trajectory_csv(nan_value).status(), "nan_value.csv:2: column 3"));
  const auto backwards = tmp("backwards.csv");
  write(backwards, "time,x,y,z\n0,0,0,0\n0.2,0,0,0\n0.1,0,0,0\n");
  EXPECT_TRUE(says(read_trajectory_csv(backwards).status(), "backwards.csv:4: time 0.1 s is not after"));
  const auto zero_q = tmp("zero_q.csv");
  write(zero_q, "time,x,y,z,qw,qx,qy,qz\n0,0,0,0,0,0,0,0\n");
  EXPECT_TRUE(says(read_trajectory_csv(zero_q).status(), "zero_q.csv:2: quaternion is zero"));
  const auto empty = tmp("empty.csv");
  write(empty, "# nothing\n");
  EXPECT_TRUE(says(read_trajectory_csv(empty).status(), "empty.csv: no header"));
  const auto no_rows = tmp("no_rows.csv");
  write(no_rows, "time,x,y,z\n");
  EXPECT_TRUE(says(read_trajectory_csv(no_rows).status(), "no_rows.csv: no samples"));
  EXPECT_TRUE(says(ReplayDevice::create({}).status(), "no samples"));
  EXPECT_TRUE(says(ReplayDevice::create({{0.1, {}, {1, 0, 0, 0}, 0}, {0.1, {}, {1, 0, 0, 0}, 0}}).status(),
                   "sample 1: time"));
  // A bad file is a bad input file; bad samples given in code are a bad parameter.
  EXPECT_EQ(ReplayDevice::load(tmp("missing.csv")).error().code(), sinew::ErrorCode::bad_input_file);
  EXPECT_EQ(read_trajectory_csv(not_number).error().code(), sinew::ErrorCode::bad_input_file);
  EXPECT_EQ(read_trajectory_csv(no_rows).error().code(), sinew::ErrorCode::bad_input_file);
  EXPECT_EQ(ReplayDevice::create({}).error().code(), sinew::ErrorCode::bad_parameter);
}

}  // namespace
