// src/haptics/watchdog.cpp — linear fade to zero on stale snapshots or
// device samples, linear recovery when fresh (sinew/haptics/watchdog.h).
#include "sinew/haptics/watchdog.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace sinew::haptics {

namespace {
Status positive(const char* name, double v) {
  if (!(v > 0.0) || !std::isfinite(v))
    return Error(ErrorCode::bad_parameter,
                 std::string("watchdog.") + name + " must be finite and > 0 [s] (got " + std::to_string(v) + ")");
  return {};
}
}  // namespace

Status check(const WatchdogParams& p) {
  if (auto s = positive("stale_after", p.stale_after); !s) return s;
  if (auto s = positive("device_stale_after", p.device_stale_after); !s) return s;
  if (auto s = positive("fade_time", p.fade_time); !s) return s;
  return positive("recover_time", p.recover_time);
}

double Watchdog::update(double snapshot_age, double device_age, double dt) noexcept {
  // NaN ages compare false: treated as stale.
  const bool fresh = snapshot_age <= p_.stale_after && device_age <= p_.device_stale_after;
  const double step = std::isfinite(dt) && dt > 0.0 ? dt : 0.0;
  if (!fresh && !stale_) ++stalls_;
  stale_ = !fresh;
  gain_ = fresh ? std::min(1.0, gain_ + step / p_.recover_time) : std::max(0.0, gain_ - step / p_.fade_time);
  return gain_;
}

}  // namespace sinew::haptics
