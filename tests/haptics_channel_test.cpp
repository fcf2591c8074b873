// The seqlock channel on one thread: nothing before the first publication,
// the newest value wins, versions count publications, payloads of any
// 8-byte-word struct round-trip bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "sinew/haptics/snapshot_channel.h"

namespace {

using namespace sinew::haptics;

TEST(HapticsChannel, EmptyUntilPublished) {
  SnapshotChannel c;
  HapticSnapshot s;
  s.sequence = 42;
  EXPECT_FALSE(c.try_read(s));
  EXPECT_EQ(s.sequence, 42u) << "a failed read leaves the output alone";
  EXPECT_EQ(c.published(), 0u);
}

TEST(HapticsChannel, NewestWinsAndVersionsCount) {
  SnapshotChannel c;
  for (std::uint64_t k = 1; k <= 5; ++k) {
    HapticSnapshot s;
    s.sequence = 100 + k;
    s.position = {double(k), 0, 0};
    c.publish(s);
    HapticSnapshot r;
    std::uint64_t version = 0;
    ASSERT_TRUE(c.try_read(r, 1, &version));
    EXPECT_EQ(r.sequence, 100 + k);
    EXPECT_EQ(version, k);
    EXPECT_EQ(c.published(), k);
  }
}

TEST(HapticsChannel, PayloadRoundTripsBitForBit) {
  FeedbackChannel c;
  CouplingFeedback f;
  f.ticks = 7;
  f.time_ns = -3;
  f.impulse = {1e-300, -0.0, std::numeric_limits<double>::infinity()};
  f.force = {std::nan(""), 1.5, -2.25};
  f.device_rotation = {0.5, 0.5, 0.5, 0.5};
  f.gain = 0.125;
  f.flags = 0xffffffffffffffffull;
  c.publish(f);
  CouplingFeedback g;
  ASSERT_TRUE(c.try_read(g));
  EXPECT_EQ(std::memcmp(&f, &g, sizeof f), 0);
  EXPECT_TRUE(std::signbit(g.impulse[1]));
  EXPECT_TRUE(std::isnan(g.force[0]));
}

}  // namespace
