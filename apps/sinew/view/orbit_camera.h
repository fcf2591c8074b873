// orbit_camera.h — the viewer's camera (docs/viewer.md): it orbits a
// target point (drag to turn, wheel to come closer), pans, and turns
// mouse motion in pixels into world motion in the view plane or along
// the view direction, for the virtual haptic device's handle.
#pragma once

#include <algorithm>
#include <cmath>

#include "view/view_math.h"

namespace sinew::view {

/// A y-up camera orbiting `target` at `distance`, `yaw` about y and `pitch` above the horizon.
class OrbitCamera {
 public:
  V3 target{0, 0, 0};     ///< the point orbited [m]
  float distance = 0.3f;  ///< from the target [m], > 0
  float yaw = 0.35f;       ///< [rad]
  float pitch = 0.35f;    ///< [rad], within +-1.5
  float fov_y = 0.8f;     ///< vertical field of view [rad]

  /// Frames a box [in] lo, hi [m]: the target at its centre, the distance to see it whole.
  void frame_box(V3 lo, V3 hi) {
    target = (lo + hi) * 0.5f;
    distance = std::max(1.8f * length(hi - lo) / (2 * std::tan(fov_y / 2)), 1e-3f);
  }
  [[nodiscard]] V3 eye() const {
    return target + V3{std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw)} * distance;
  }
  [[nodiscard]] V3 forward() const { return normalize(target - eye()); }
  [[nodiscard]] V3 right() const { return normalize(cross(forward(), V3{0, 1, 0})); }
  [[nodiscard]] V3 up() const { return cross(right(), forward()); }
  [[nodiscard]] M4 view() const { return look_at(eye(), target, V3{0, 1, 0}); }
  /// [in] aspect: width / height of the viewport.
  [[nodiscard]] M4 projection(float aspect) const {
    return perspective(fov_y, aspect, distance * 0.01f, distance * 100.0f);
  }

  /// Turns by a mouse drag of [in] dx, dy pixels.
  void orbit(float dx, float dy) {
    yaw -= dx * 0.008f;
    pitch = std::clamp(pitch + dy * 0.008f, -1.5f, 1.5f);
  }
  /// Comes closer by `steps` wheel clicks (negative: further away).
  void zoom(float steps) { distance = std::max(distance * std::pow(0.88f, steps), 1e-4f); }
  /// Moves the target with a drag of [in] dx, dy pixels in a viewport `height` pixels high.
  void pan(float dx, float dy, float height) { target = target + drag_in_plane(target, dx, dy, height) * -1.0f; }

  /// The world motion [m] of a point at `at` that follows a drag of dx, dy
  /// pixels (x right, y down) in the plane through it facing the camera.
  [[nodiscard]] V3 drag_in_plane(V3 at, float dx, float dy, float height) const {
    const float scale = metres_per_pixel(at, height);
    return right() * (dx * scale) + up() * (-dy * scale);
  }
  /// The world motion [m] along the view direction for a vertical drag of
  /// dy pixels (down: towards the camera, as pulling the handle back).
  [[nodiscard]] V3 drag_in_depth(V3 at, float dy, float height) const {
    return forward() * (-dy * metres_per_pixel(at, height));
  }

 private:
  [[nodiscard]] float metres_per_pixel(V3 at, float height) const {
    const float depth = std::max(dot(at - eye(), forward()), distance * 0.01f);
    return 2 * depth * std::tan(fov_y / 2) / std::max(height, 1.0f);
  }
};

}  // namespace sinew::view
