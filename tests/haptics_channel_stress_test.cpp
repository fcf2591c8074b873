// Torn-read stress of the seqlock snapshot channel (real threads): a writer
// publishes as fast as it can while a reader takes at least 10^6 snapshots;
// every snapshot must be internally consistent (every field a function of
// its sequence number, so a mix of two publications shows) and sequences
// must never go back. Built twice: into test_haptics, and alone with
// -fsanitize=thread into test_haptics_tsan (header-only: no libsinew, no TBB).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <thread>

#include "sinew/haptics/snapshot_channel.h"

namespace {

using sinew::haptics::HapticSnapshot;
using sinew::haptics::SnapshotChannel;

// Publication k: every field derived from k (exact in double below 2^53).
HapticSnapshot make(std::uint64_t k) {
  HapticSnapshot s;
  const double d = static_cast<double>(k);
  s.sequence = k;
  s.stamp_ns = static_cast<std::int64_t>(7 * k);
  s.sim_time = d * 0.5;
  s.frame = k ^ 0x5a5a5a5aull;
  s.position = {d, d + 1, d + 2};
  s.rotation = {d + 3, d + 4, d + 5, d + 6};
  s.velocity = {-d, -d - 1, -d - 2};
  s.angular_velocity = {2 * d, 2 * d + 1, 2 * d + 2};
  s.contact_force = {3 * d, 3 * d + 1, 3 * d + 2};
  s.contact_torque = {4 * d, 4 * d + 1, 4 * d + 2};
  s.contact_normal = {5 * d, 5 * d + 1, 5 * d + 2};
  s.in_contact = ~k;
  return s;
}

bool consistent(const HapticSnapshot& s) {
  const HapticSnapshot e = make(s.sequence);
  return s.stamp_ns == e.stamp_ns && s.sim_time == e.sim_time && s.frame == e.frame && s.position == e.position &&
         s.rotation == e.rotation && s.velocity == e.velocity && s.angular_velocity == e.angular_velocity &&
         s.contact_force == e.contact_force && s.contact_torque == e.contact_torque &&
         s.contact_normal == e.contact_normal && s.in_contact == e.in_contact;
}

TEST(HapticsChannelStress, NoTornReadsAgainstAConcurrentWriter) {
  constexpr std::uint64_t kReads = 1'000'000;
  SnapshotChannel channel;
  std::atomic<bool> done{false};
  std::atomic<std::uint64_t> writes{0};
  std::thread writer([&] {
    std::uint64_t k = 0;
    while (!done.load(std::memory_order_relaxed)) channel.publish(make(++k));
    writes.store(k, std::memory_order_relaxed);
  });
  while (channel.published() == 0) std::this_thread::yield();

  std::uint64_t reads = 0, torn = 0, backwards = 0, gave_up = 0, distinct = 0, last = 0, version_mismatch = 0;
  HapticSnapshot s;
  while (reads < kReads) {
    std::uint64_t version = 0;
    if (!channel.try_read(s, 8, &version)) {  // every attempt overlapped two publications
      ++gave_up;
      continue;
    }
    ++reads;
    if (!consistent(s)) ++torn;
    if (s.sequence != version) ++version_mismatch;
    if (s.sequence < last) ++backwards;
    if (s.sequence != last) ++distinct;
    last = s.sequence;
  }
  done.store(true, std::memory_order_relaxed);
  writer.join();
  EXPECT_EQ(torn, 0u) << "a snapshot mixed two publications";
  EXPECT_EQ(version_mismatch, 0u);
  EXPECT_EQ(backwards, 0u) << "a newer read returned an older snapshot";
  EXPECT_GT(distinct, 1u) << "the reader saw the writer progress";
  std::printf("[ measured ] %llu reads (%llu distinct snapshots) against %llu writes; %llu bounded reads gave up\n",
              static_cast<unsigned long long>(reads), static_cast<unsigned long long>(distinct),
              static_cast<unsigned long long>(writes.load()), static_cast<unsigned long long>(gave_up));
}

TEST(HapticsChannelStress, TwoReadersAndAWriterAtPhysicsRate) {
  // Several readers are allowed; with the writer publishing at a modest
  // pace, readers practically never retry.
  SnapshotChannel channel;
  std::atomic<bool> done{false};
  std::atomic<std::uint64_t> bad{0};
  auto reader = [&](std::uint64_t& good) {  // [out] good: successful reads
    HapticSnapshot s;
    std::uint64_t last = 0;
    for (int i = 0; i < 200'000; ++i)
      if (channel.try_read(s, 64)) {
        ++good;
        if (!consistent(s) || s.sequence < last) bad.fetch_add(1);
        last = s.sequence;
      }
  };
  std::thread writer([&] {
    std::uint64_t k = 0;
    while (!done.load(std::memory_order_relaxed)) {
      channel.publish(make(++k));
      std::this_thread::yield();
    }
  });
  while (channel.published() == 0) std::this_thread::yield();  // every read after this one has a value
  std::uint64_t good1 = 0, good2 = 0;
  std::thread r1(reader, std::ref(good1)), r2(reader, std::ref(good2));
  r1.join();
  r2.join();
  done.store(true);
  writer.join();
  EXPECT_EQ(bad.load(), 0u);
  // Without these the test passes with no read at all.
  EXPECT_GT(good1, 0u) << "reader 1 read nothing";
  EXPECT_GT(good2, 0u) << "reader 2 read nothing";
}

}  // namespace
