// cpu_sharing_test.cpp — the CPU backend's sharing policies
// (backends/cpu/cpu_sharing.h) fed with made-up timings: the choice between
// the team and one thread follows whichever is faster, tries the other at
// the documented rates and comes back when the machine changes; the
// members' shares cover every item once and converge to equal times.
#include <gtest/gtest.h>

#include <cmath>

#include "backends/cpu/cpu_sharing.h"

namespace sinew {
namespace {

// Runs `runs` programs whose team and alone times are given, and counts how
// many ran on the team.
int team_runs(WidthChoice& w, int runs, double team_ns, double alone_ns) {
  int on_team = 0;
  for (int r = 0; r < runs; ++r) {
    const bool team = w.next_on_team();
    on_team += team;
    w.record(team, team ? team_ns : alone_ns);
  }
  return on_team;
}

TEST(WidthChoice, AFasterTeamRunsEverythingButARecheckEveryKRecheckRuns) {
  WidthChoice w;
  team_runs(w, 1 + WidthChoice::kTrials, 550.0, 1000.0);  // warm-up and trials
  EXPECT_TRUE(w.team);
  const int runs = 32 * WidthChoice::kRecheck;
  const int team = team_runs(w, runs, 550.0, 1000.0);
  EXPECT_EQ(runs - team, runs / int(WidthChoice::kRecheck + 1)) << "one alone run after every kRecheck team runs";
  EXPECT_TRUE(w.team);
}

TEST(WidthChoice, ASlowerTeamIsTriedWithADoublingBackoff) {
  WidthChoice w;
  team_runs(w, 1 + WidthChoice::kTrials, 1500.0, 1000.0);
  EXPECT_FALSE(w.team);
  // A try after 4, 8, 16, 32, then every 64 alone runs.
  const int team = team_runs(w, (4 + 1) + (8 + 1) + (16 + 1) + (32 + 1) + 10 * (64 + 1), 1500.0, 1000.0);
  EXPECT_EQ(team, 4 + 10);
  EXPECT_EQ(w.backoff, WidthChoice::kMaxBackoff);
  EXPECT_FALSE(w.team);
}

TEST(WidthChoice, FollowsTheMachineWhenASecondCoreIsBusyThenFreeAgain) {
  WidthChoice w;
  team_runs(w, 100, 550.0, 1000.0);
  ASSERT_TRUE(w.team);
  // Another process takes a core: the team's runs take three times as long.
  team_runs(w, 30, 3000.0, 1000.0);
  EXPECT_FALSE(w.team) << "30 slow team runs did not move the choice";
  const int during = team_runs(w, 1000, 3000.0, 1000.0);
  EXPECT_LE(during, 1000 / int(WidthChoice::kMaxBackoff) + 5) << "lost tries are at most one run in kMaxBackoff";
  // The core is free again: the next try wins and the team is back.
  team_runs(w, int(WidthChoice::kMaxBackoff) + 2, 550.0, 1000.0);
  EXPECT_TRUE(w.team);
}

TEST(WidthChoice, ATeamOnlyAFewPercentFasterRunsAlone) {
  WidthChoice w;
  const int team = team_runs(w, 1 + WidthChoice::kTrials + 1000, 970.0, 1000.0);
  EXPECT_FALSE(w.team);
  EXPECT_LE(team, 1 + int(WidthChoice::kTrials) / 2 + 1000 / int(WidthChoice::kMaxBackoff) + 5);
}

TEST(WidthChoice, OneSlowTeamRunDoesNotFlipIt) {
  WidthChoice w;
  team_runs(w, 100, 550.0, 1000.0);
  ASSERT_TRUE(w.team);
  ASSERT_TRUE(w.next_on_team());
  w.record(true, 2500.0);  // an interrupt storm
  EXPECT_TRUE(w.team);
}

TEST(Shares, CoverEveryItemOnceForAnyCount) {
  for (unsigned members : {1u, 2u, 3u, 7u}) {
    Shares s(members);
    for (std::uint32_t units : {0u, 1u, 2u, 5u, 1000u, 16'777'216u, 4'000'000'000u}) {
      std::uint32_t next = 0;
      for (unsigned m = 0; m < members; ++m) {
        const auto [b, e] = s.range(units, m);
        EXPECT_EQ(b, next) << members << " members, " << units << " units";
        EXPECT_LE(b, e);
        next = e;
      }
      EXPECT_EQ(next, units) << members << " members";
    }
  }
}

TEST(Shares, ConvergeToEqualTimesOnMembersOfUnequalSpeed) {
  Shares s(2);
  const double speed[2] = {1.0, 0.7};  // member 1 runs at 70% of member 0's speed
  const std::uint32_t units = 1'000'000;
  double busy[2] = {0.0, 0.0};
  for (int run = 0; run < 40; ++run) {
    for (unsigned m = 0; m < 2; ++m) {
      const auto [b, e] = s.range(units, m);
      busy[m] = double(e - b) / speed[m];  // ns: one unit per ns at speed 1
    }
    s.update(busy);
  }
  // Equal times: member 0 takes 1 / (1 + 0.7) of the items.
  const auto [b, e] = s.range(units, 0);
  EXPECT_NEAR(double(e - b) / units, 1.0 / 1.7, 0.01);
  EXPECT_NEAR(busy[0] / busy[1], 1.0, 0.03);
}

TEST(Shares, StayWithinHalfAndOneAndAHalfTimesTheEqualShare) {
  Shares s(2);
  const double busy[2] = {1e6, 1e9};  // member 1 a thousand times slower (descheduled)
  for (int run = 0; run < 50; ++run) s.update(busy);
  const auto [b, e] = s.range(1'000'000, 1);
  EXPECT_NEAR(double(e - b) / 1e6, 0.25, 0.002);
}

TEST(Shares, IgnoreRunsWithTooLittleWorkToTell) {
  Shares s(2);
  const double busy[2] = {1000.0, 5000.0};  // 1 and 5 us: noise
  s.update(busy);
  const auto [b, e] = s.range(1000, 0);
  EXPECT_EQ(e - b, 500u);
}

}  // namespace
}  // namespace sinew
