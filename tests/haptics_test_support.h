// haptics_test_support.h — a haptic loop on a virtual clock, ticked by hand,
// with a stand-in physics thread that publishes snapshots at a frame rate.
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "sinew/haptics/clock.h"
#include "sinew/haptics/haptic_loop.h"
#include "sinew/haptics/scripted_device.h"

namespace sinew::test {

using namespace sinew::haptics;

inline constexpr std::int64_t kMs = 1'000'000;

/// A loop at 1 kHz on a virtual clock starting at 0, driving `device`.
/// run(): tick every millisecond; every `frame_ns` (when publishing) a
/// snapshot of `tool` is published first, stamped with the virtual time.
struct VirtualRig {
  VirtualClock clock{0};
  SnapshotChannel snapshots;
  FeedbackChannel feedback;
  std::unique_ptr<HapticLoop> loop;
  HapticSnapshot tool;
  std::int64_t frame_ns = 16'666'667;  // 60 Hz
  std::int64_t next_frame_ns = 0;
  bool publishing = true;

  VirtualRig(HapticDevice& device, const HapticLoopSettings& settings = {}) {
    HapticLoopSettings s = settings;
    s.realtime = false;
    auto made = HapticLoop::create(s, device, snapshots, feedback, clock);
    EXPECT_TRUE(made.ok()) << (made.ok() ? "" : made.error().message());
    if (made.ok()) loop = std::move(*made);
  }
  /// Publishes `tool` now.
  void publish() {
    tool.sequence += 1;
    tool.stamp_ns = clock.now_ns();
    snapshots.publish(tool);
  }
  /// One millisecond: publish if a frame is due, tick, advance.
  TickRecord step() {
    if (publishing && clock.now_ns() >= next_frame_ns) {
      publish();
      next_frame_ns += frame_ns;
    } else if (!publishing) {
      next_frame_ns = clock.now_ns();  // resume with a frame at once
    }
    TickRecord r = loop->tick();
    clock.advance(kMs);
    return r;
  }
  /// `ticks` milliseconds; returns the last record.
  TickRecord run(int ticks) {
    TickRecord r;
    for (int i = 0; i < ticks; ++i) r = step();
    return r;
  }
};

inline double norm3(const Vec3& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

}  // namespace sinew::test
