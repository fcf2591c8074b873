// src/haptics/force_safety.cpp — non-finite filter, magnitude clamp (keeping
// the direction), watchdog gain and per-tick slew limit; the order and why
// in sinew/haptics/force_safety.h.
#include "sinew/haptics/force_safety.h"

#include <algorithm>
#include <cmath>

#include "math/vec3.h"

namespace sinew::haptics {

Vec3 SafetyFilter::apply(const Vec3& raw, double gain, std::uint32_t& flags) noexcept {
  // 1. NaN/Inf: zero at once (the safe direction), slew bypassed.
  if (!math::finite(raw)) {
    flags |= kNonFinite;
    last_ = {0.0, 0.0, 0.0};
    return last_;
  }
  // 2. Clamp the magnitude, keeping the direction.
  Vec3 v = raw;
  const double m = math::norm(v);
  if (m > max_) {
    v = math::mul(v, max_ / m);
    flags |= kClamped;
  }
  // 3. Watchdog gain.
  const double g = std::isfinite(gain) ? std::clamp(gain, 0.0, 1.0) : 0.0;
  v = math::mul(v, g);
  // 4. Per-tick change limit.
  const Vec3 d = math::sub(v, last_);
  const double dm = math::norm(d);
  if (dm > max_change_) {
    v = math::add(last_, math::mul(d, max_change_ / dm));
    flags |= kSlewLimited;
  }
  last_ = v;
  return v;
}

}  // namespace sinew::haptics
