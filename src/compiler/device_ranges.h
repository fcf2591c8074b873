// device_ranges.h — what the device computes from a scene's parameters,
// checked in the precision it computes in (float32), and the work a scene
// may ask for per frame (issue 39). A value finite in double can be
// infinite in float (1e300), or round to 0 (1e-300, an inverse mass of
// 1e-300): both give NaN or a frozen body after a frame, so each is a
// named bad_parameter error instead.
#pragma once

#include <string>
#include <vector>

#include "sinew/result.h"
#include "sinew/scene.h"

namespace sinew {

/// `check(item, "name[i]")` on each item of `items`; the first error.
template <class T, class Check>
Status check_all(const std::vector<T>& items, const std::string& name, Check&& check) {
  for (std::size_t i = 0; i < items.size(); ++i)
    if (Status s = check(items[i], name + "[" + std::to_string(i) + "]"); !s) return s;
  return {};
}

/// `v` as the scene checks' messages print it (scene_checks.cpp).
std::string number_text(double v);

/// The caps on a frame's work (documented with SolverSettings, scene.h).
constexpr int kMaxSubsteps = 10000;
constexpr int kMaxIterations = 10000;           ///< iterations per substep
constexpr int kMaxResidualIterations = 100000;  ///< max_iterations per substep (residual mode)
constexpr double kMaxSweepsPerFrame = 1000000;  ///< substeps x ((max_)iterations + contact_sweeps)

/// The most a constant acceleration (gravity, a particle's force over its
/// mass) may move a particle in one frame, a dt^2 [m]: the constraint math
/// squares and cubes lengths in float (a tet's volume overflows beyond
/// about 7e12 m), so a frame's move must stay far below that.
constexpr double kMaxFrameMove = 1e12;

/// The substep h = time_step / substeps as the device's float, and its
/// 1/h and 1/h^2, checked finite and h a normal float.
struct DeviceStep {
  float h = 0.0f;
  float inv_h2 = 0.0f;
};
Result<DeviceStep> device_step(const SolverSettings& solver);

/// Solver caps, h, gravity (g, h g and h^2 g) and every compliance of the
/// scene (alpha and alpha / h^2) in float; called by check_scene.
Status check_device_ranges(const SceneDesc& scene);

/// [in] owner, field: the parameter, for the message (e.g. "tet_bodies[0]",
/// ".distance_compliance"; joined only on an error: this runs per
/// constraint); alpha: the compliance the device stores (after any scaling
/// by the element's size, e.g. c L^2 / V). Errors (bad_parameter, naming
/// the field): float(alpha) or float(alpha) / h^2 not finite.
Status check_device_compliance(const std::string& owner, const char* field, double alpha, const DeviceStep& step);

}  // namespace sinew
