// cpu_sharing.h — how the CPU backend shares a program among its team
// (cpu_team.h): whether a program runs on the team at all (WidthChoice),
// and each member's part of a shared dispatch (Shares). Both learn from
// wall times measured as the programs run; neither changes a result,
// because a dispatch's items are independent and every split of them
// computes the same values.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>

namespace sinew {

// Whether a program runs on the team or on the calling thread alone,
// chosen by timing both. On a quiet machine the team wins wherever the
// work is big enough; when another process keeps a core busy, the members
// take turns on the other core and the team loses; a body of a few hundred
// constraints is faster alone at any time. The team must be faster by
// kMargin to be chosen: a team that saves a few percent on average loses
// as much in its slow frames, and one thread never pays for the other's
// interruptions. The first kTrials runs after a
// warm-up alternate the two; from then on the program runs on the faster,
// and tries the other now and then: one alone run in kRecheck while on the
// team (keeps the alone time current), one team run after a backoff that
// doubles from kFirstBackoff to kMaxBackoff while the team keeps losing (so
// a lost try costs at most one run in kMaxBackoff).
struct WidthChoice {
  static constexpr std::uint32_t kTrials = 8, kRecheck = 32, kFirstBackoff = 4, kMaxBackoff = 64;
  static constexpr double kMargin = 0.95;  // the team runs if its time < kMargin x the alone time
  double team_ns = 0.0, alone_ns = 0.0;  // recent wall times of a run [ns]
  std::uint32_t runs = 0;
  std::uint32_t since = 0;  // runs on the chosen width since the last try of the other
  std::uint32_t backoff = kFirstBackoff;
  bool team = true;

  [[nodiscard]] bool next_on_team() const {
    if (runs <= kTrials) return runs % 2 == 0;  // run 0 (warm-up) on the team, then alone, team, ...
    return team ? since < kRecheck : since >= backoff;
  }
  void record(bool on_team, double ns) {
    const std::uint32_t run = runs++;
    if (run == 0) return;
    if (run <= kTrials) {
      double& e = on_team ? team_ns : alone_ns;
      e = e == 0.0 ? ns : e + (ns - e) / 2;
      if (run == kTrials) team = team_ns < kMargin * alone_ns;
      return;
    }
    if (on_team == team) {
      // A run on the chosen width. One slow run (an interrupt storm) moves
      // the team's time by an eighth, so it alone does not flip the choice.
      double& e = on_team ? team_ns : alone_ns;
      e += (ns - e) / (on_team ? 8 : 4);
      ++since;
      if (team && team_ns >= kMargin * alone_ns) {
        team = false;
        since = 0;
      }
      return;
    }
    since = 0;  // a try of the other width
    if (on_team) {
      team_ns = ns;
      if (ns < kMargin * alone_ns) {
        team = true;
        backoff = kFirstBackoff;
      } else {
        backoff = std::min(2 * backoff, kMaxBackoff);
      }
    } else {
      alone_ns = ns;
      if (team_ns >= kMargin * ns) team = false;
    }
  }
};

// Each member's share of a shared dispatch, as boundaries in 1/65536 of its
// items, weighted by the members' measured speeds. Why: the two vCPUs of
// this project's VMs ran at speeds 20-27% apart for seconds at a time
// (measured: one member's half of every colour took that much longer), and
// with equal halves the faster waited at every barrier. Each member times
// its shares of a run; between runs the shares move a quarter of the way
// towards the split that would have made those times equal. A member keeps
// its share from run to run (only the boundary moves), so its part of each
// colour, and the particles it touches, stay in its cache.
class Shares {
 public:
  static constexpr std::uint32_t kOne = 1u << 16;
  explicit Shares(unsigned members) : members_(members) {
    for (unsigned m = 0; m <= members; ++m) bound_[m] = static_cast<std::uint32_t>(std::uint64_t{kOne} * m / members);
  }
  // Member m's items of a dispatch of `units`.
  [[nodiscard]] std::pair<std::uint32_t, std::uint32_t> range(std::uint32_t units, unsigned m) const {
    return {static_cast<std::uint32_t>((std::uint64_t{units} * bound_[m]) >> 16),
            static_cast<std::uint32_t>((std::uint64_t{units} * bound_[m + 1]) >> 16)};
  }
  // [in] busy_ns: each member's time in its shares during the last run.
  void update(const double* busy_ns) {
    double speed[kMaxMembers], total = 0.0;
    for (unsigned m = 0; m < members_; ++m) {
      if (busy_ns[m] < kMinBusyNs) return;  // too little work to tell
      speed[m] = double(bound_[m + 1] - bound_[m]) / busy_ns[m];
      total += speed[m];
    }
    // A quarter of the way to equal times, each share kept within half and
    // one and a half times the equal one.
    double cumulative = 0.0;
    std::uint32_t next[kMaxMembers + 1] = {0};
    for (unsigned m = 0; m < members_; ++m) {
      const double current = double(bound_[m + 1] - bound_[m]) / kOne;
      const double fair = 1.0 / members_;
      const double share = std::clamp(current + 0.25 * (speed[m] / total - current), 0.5 * fair, 1.5 * fair);
      cumulative += share;
      next[m + 1] = static_cast<std::uint32_t>(cumulative * kOne);
    }
    // Rescale so the last boundary is exactly the whole.
    for (unsigned m = 1; m < members_; ++m)
      bound_[m] = static_cast<std::uint32_t>(double(next[m]) / double(next[members_]) * kOne);
    bound_[members_] = kOne;
  }
  static constexpr unsigned kMaxMembers = 256;

 private:
  static constexpr double kMinBusyNs = 100'000.0;
  unsigned members_;
  std::array<std::uint32_t, kMaxMembers + 1> bound_{};
};

}  // namespace sinew
