// device_bvh_support.h — a device BVH built and refitted over given boxes
// (collision/device_bvh.h), for the tests that traverse it
// (tests/device_bvh_test.cpp, tests/device_narrow_phase_test.cpp).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include "backends/backend.h"
#include "collision/aabb.h"
#include "collision/device_bvh.h"

namespace sinew::test {

/// Six floats per box (lo xyz, hi xyz): DeviceBvh::boxes' layout.
inline std::vector<float> flat(const std::vector<collision::Aabb>& boxes) {
  std::vector<float> f;
  f.reserve(6 * boxes.size());
  for (const collision::Aabb& b : boxes) f.insert(f.end(), {b.lo[0], b.lo[1], b.lo[2], b.hi[0], b.hi[1], b.hi[2]});
  return f;
}

/// The boxes' bounds (the build's lo, hi).
inline std::pair<std::array<float, 3>, std::array<float, 3>> bounds_of(const std::vector<collision::Aabb>& boxes) {
  std::array<float, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (const collision::Aabb& b : boxes)
    for (std::size_t k = 0; k < 3; ++k) lo[k] = std::min(lo[k], b.lo[k]), hi[k] = std::max(hi[k], b.hi[k]);
  return {lo, hi};
}

/// A device BVH over `boxes` (>= 2), built and refitted in one program that
/// has run; nullopt (with a test failure) when any step fails.
inline std::optional<collision::DeviceBvh> built_device_bvh(Device& device, const std::vector<collision::Aabb>& boxes) {
  const auto n = std::uint32_t(boxes.size());
  auto bvh = collision::make_device_bvh(device, n);
  EXPECT_TRUE(bvh.ok());
  if (!bvh.ok()) return std::nullopt;
  const std::vector<float> f = flat(boxes);
  EXPECT_TRUE(device.write_buffer(bvh->boxes, 0, f.data(), f.size() * 4).ok());
  const auto [lo, hi] = bounds_of(boxes);
  FrameProgram build;
  EXPECT_TRUE(collision::append_device_bvh_build(build, *bvh, n, lo, hi).ok());
  EXPECT_TRUE(collision::append_device_bvh_refit(build, *bvh, n).ok());
  auto built = device.create_program(build);
  EXPECT_TRUE(built.ok()) << (built.ok() ? "" : built.error().message());
  if (!built.ok()) return std::nullopt;
  const Status ran = device.run_program(*built);
  EXPECT_TRUE(ran.ok()) << (ran.ok() ? "" : ran.error().message());
  if (!ran.ok()) return std::nullopt;
  return *bvh;
}

}  // namespace sinew::test
