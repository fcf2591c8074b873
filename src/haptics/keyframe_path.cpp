// keyframe_path.cpp — a scripted hand's pose between keyframes
// (sinew/haptics/keyframe_path.h).
#include "sinew/haptics/keyframe_path.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "math/vec3.h"

namespace sinew::haptics {
namespace {

bool finite(const Vec3& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

Result<KeyframePath> KeyframePath::create(std::vector<PathKey> keys, PathInterpolation interpolation) {
  if (keys.empty()) return Error(ErrorCode::bad_parameter, "keys: a path needs at least one key");
  for (std::size_t i = 0; i < keys.size(); ++i) {
    PathKey& k = keys[i];
    const std::string name = "keys[" + std::to_string(i) + "]";
    if (!std::isfinite(k.time) || k.time < 0.0)
      return Error(ErrorCode::bad_parameter, name + ".time: must be finite and >= 0 (got " + number(k.time) + ")");
    if (i > 0 && !(k.time > keys[i - 1].time))
      return Error(ErrorCode::bad_parameter, name + ".time: must be greater than the previous key's (got " +
                                                 number(k.time) + " after " + number(keys[i - 1].time) + ")");
    if (!finite(k.position)) return Error(ErrorCode::bad_parameter, name + ".position: must be finite");
    const Quat& q = k.rotation;
    const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!std::isfinite(n) || n < 1e-12)
      return Error(ErrorCode::bad_parameter, name + ".rotation: must be a finite, non-zero quaternion");
    for (double& c : k.rotation) c /= n;
  }
  return KeyframePath(std::move(keys), interpolation);
}

ScriptedPose KeyframePath::at(double t) const noexcept {
  ScriptedPose p;
  // Before the first key (or NaN): the first pose; after the last: the last.
  const PathKey* hold = !(t > keys_.front().time) ? &keys_.front() : t >= keys_.back().time ? &keys_.back() : nullptr;
  if (hold) {
    p.position = hold->position;
    p.rotation = hold->rotation;
    return p;
  }
  // The first key after t (there is one before it).
  const auto after = std::upper_bound(keys_.begin(), keys_.end(), t,
                                      [](double time, const PathKey& k) { return time < k.time; });
  const PathKey& a = *(after - 1);
  const PathKey& b = *after;
  const double s = (t - a.time) / (b.time - a.time);
  const double w = interpolation_ == PathInterpolation::smooth ? 0.5 - 0.5 * std::cos(M_PI * s) : s;
  for (int i = 0; i < 3; ++i) p.position[i] = a.position[i] + (b.position[i] - a.position[i]) * w;
  // Along the shorter arc (q and -q are the same rotation), normalised.
  p.rotation = math::nlerp(a.rotation, b.rotation, w);
  return p;
}

ScriptedDevice::Script KeyframePath::script() const {
  return [path = *this](double t) { return path.at(t); };
}

}  // namespace sinew::haptics
