// src/haptics/snapshot_interpolator.cpp — the tool state rendered between
// (or just past) the two newest snapshots; formulas in
// sinew/haptics/snapshot_interpolator.h (interpolation buffer one
// publication interval deep; Bernier, GDC 2001).
#include "sinew/haptics/snapshot_interpolator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "math/vec3.h"
#include "sinew/haptics/clock.h"

namespace sinew::haptics {

Status check(const InterpolationParams& p) {
  if (!(p.extrapolation_horizon >= 0.0) || !std::isfinite(p.extrapolation_horizon))
    return Error(ErrorCode::bad_parameter,
                 "interpolation.extrapolation_horizon must be finite and >= 0 [s] (got " +
                 std::to_string(p.extrapolation_horizon) + ")");
  if (!(p.max_interval > 0.0) || !std::isfinite(p.max_interval))
    return Error(ErrorCode::bad_parameter,
                 "interpolation.max_interval must be finite and > 0 [s] (got " + std::to_string(p.max_interval) + ")");
  if (!(p.min_interval >= 0.0) || !(p.min_interval <= p.max_interval))
    return Error(ErrorCode::bad_parameter,
                 "interpolation.min_interval must be >= 0 and <= max_interval [s] (got " +
                 std::to_string(p.min_interval) + ")");
  return {};
}

void SnapshotHistory::push(const HapticSnapshot& snapshot) noexcept {
  if (count_ > 0) older_ = newest_;
  newest_ = snapshot;
  count_ = std::min(count_ + 1, 2);
}

namespace {

void fill_single(const HapticSnapshot& s, RenderedTool& r) {
  r.position = s.position;
  r.rotation = s.rotation;
  r.velocity = s.velocity;
  r.angular_velocity = s.angular_velocity;
  r.contact_force = s.contact_force;
}

}  // namespace

RenderedTool SnapshotHistory::render(std::int64_t now_ns, const InterpolationParams& params) const noexcept {
  RenderedTool r;
  if (count_ == 0) {
    r.snapshot_age = r.render_age = std::numeric_limits<double>::infinity();
    return r;
  }
  const HapticSnapshot& b = newest_;
  r.snapshot_age = ns_to_seconds(now_ns - b.stamp_ns);
  r.contact_normal = b.contact_normal;
  r.in_contact = b.in_contact != 0;
  const double interval = count_ == 2 ? ns_to_seconds(b.stamp_ns - older_.stamp_ns) : 0.0;
  if (count_ == 1 || !(interval > 0.0) || interval > params.max_interval || interval < params.min_interval) {
    // One snapshot, two stamped alike or closer than min_interval (their
    // spacing is no measure of the tool's speed), or a stall between them: hold the newest.
    r.mode = RenderMode::single;
    fill_single(b, r);
    r.u = 1.0;
    r.render_age = r.snapshot_age;
    return r;
  }
  const HapticSnapshot& a = older_;
  const double u_raw = r.snapshot_age / interval;
  const double u_max = 1.0 + params.extrapolation_horizon / interval;
  double u = std::max(u_raw, 0.0);
  if (u <= 1.0) {
    r.mode = RenderMode::interpolated;
  } else if (u <= u_max) {
    r.mode = RenderMode::extrapolated;
  } else {
    r.mode = RenderMode::held;
    u = u_max;
  }
  r.u = u;
  r.position = math::lerp(a.position, b.position, u);
  r.velocity = math::lerp(a.velocity, b.velocity, u);
  r.angular_velocity = math::lerp(a.angular_velocity, b.angular_velocity, u);
  r.contact_force = math::lerp(a.contact_force, b.contact_force, u);
  r.rotation = math::nlerp(a.rotation, b.rotation, u);
  // The rendered state stands for the time a + u D on the loop clock.
  r.render_age = ns_to_seconds(now_ns - a.stamp_ns) - u * interval;
  return r;
}

}  // namespace sinew::haptics
