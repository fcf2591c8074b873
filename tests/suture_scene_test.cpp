// The reference scene S3 (examples/common/suture_scene.h), shortened: the
// pad at 2 mm cells (13 x 5 x 8 cells, 3,012 tets instead of 20,064), the
// same 200-segment thread and the whole script (both stitches, the pull to
// the knot, the hold). Every frame: every position finite; the continuous
// collision forced no crossing (FrameStats::ccd_forced: a thread segment
// through another or through the tissue that CCD could not prevent); no two
// non-adjacent thread segments touch (closer than 1 um: crossed). At the
// end: the needle punctured both lips at both stitches (entering and
// leaving each), every puncture holds the thread, the knot holds at the
// first, and the slit at the stitches is narrower than before the pull.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>

#include "suture_scene.h"

namespace {

sinew::examples::SutureSettings short_settings() {
  sinew::examples::SutureSettings s;
  s.cell = 2e-3;
  s.nx = 13, s.ny = 5, s.nz = 8;
  s.threads = 2;
  return s;
}

TEST(SutureScene, StitchedThreadClosesTheSlitWithoutCrossing) {
  auto made = sinew::examples::SutureScene::create(short_settings());
  ASSERT_TRUE(made) << made.error().message();
  auto& scene = *made;
  auto before = scene.gap();
  ASSERT_TRUE(before) << before.error().message();
  EXPECT_NEAR(*before, 2e-3, 1e-9) << "the slit starts 2 mm wide";
  std::uint64_t forced = 0, touches = 0;
  double least = INFINITY;  // the least distance between non-adjacent thread segments, its frame and pair
  int least_frame = -1;
  std::array<int, 2> pair{};
  sinew::examples::SutureCheck c;
  while (!scene.done()) {
    ASSERT_TRUE(scene.frame()) << "frame " << scene.frames();
    ASSERT_LT(scene.frames(), 2000) << "the script never ended";
    forced += scene.sim().last_frame().ccd_forced;
    touches += scene.sim().last_frame().ccd_hits;
    auto checked = scene.check();
    ASSERT_TRUE(checked) << checked.error().message();
    c = *checked;
    ASSERT_TRUE(c.finite) << "frame " << scene.frames();
    if (c.thread_min_distance < least) least = c.thread_min_distance, least_frame = scene.frames(), pair = c.thread_closest;
    ASSERT_GT(c.thread_min_distance, 1e-6) << "frame " << scene.frames() << ": the thread crossed itself";
  }
  EXPECT_EQ(forced, 0u) << "a crossing continuous collision could not prevent";
  EXPECT_EQ(c.punctures, 8u) << "two stitches: in and out of each lip";
  EXPECT_EQ(c.left_lip, 4u);
  EXPECT_EQ(c.right_lip, 4u);
  EXPECT_EQ(c.on_thread, c.punctures) << "every puncture holds the thread";
  EXPECT_TRUE(c.knot_holds);
  EXPECT_LT(c.gap, *before - 1e-4) << "the stitches must close the slit by more than 0.1 mm";
  std::printf("%d frames, knot at frame %d; slit %.3f -> %.3f mm; least thread distance %.4f mm (frame %d, segments "
              "%d and %d); %llu CCD touches, %llu forced\n",
              scene.frames(), scene.knot_frame(), 1e3 * *before, 1e3 * c.gap, 1e3 * least, least_frame, pair[0], pair[1],
              static_cast<unsigned long long>(touches), static_cast<unsigned long long>(forced));
}

// Bad settings are named, not clamped.
TEST(SutureScene, BadSettingsAreNamed) {
  auto s = short_settings();
  s.cell = 1.5e-3;  // the 2 mm slit is not a whole number of cells
  auto made = sinew::examples::SutureScene::create(s);
  ASSERT_FALSE(made);
  EXPECT_NE(made.error().message().find("whole number of cells"), std::string::npos) << made.error().message();
  s = short_settings();
  s.nx = 6;  // the lips too narrow for the needle's entry points
  made = sinew::examples::SutureScene::create(s);
  ASSERT_FALSE(made);
  EXPECT_NE(made.error().message().find("9 mm either side"), std::string::npos) << made.error().message();
  s = short_settings();
  s.thread_segments = 1;
  made = sinew::examples::SutureScene::create(s);
  ASSERT_FALSE(made);
  EXPECT_NE(made.error().message().find("thread_segments"), std::string::npos) << made.error().message();
}

}  // namespace
