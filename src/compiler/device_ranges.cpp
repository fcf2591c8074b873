// device_ranges.cpp — scene parameters and what the device derives from
// them, checked in float32 (device_ranges.h; issue 39). The device computes
// h = time_step / substeps, 1/h, 1/h^2, alpha~ = alpha / h^2 and the
// gravity impulse h g in float (src/program/xpbd_program.cpp): each is
// checked here as that float, so that a finite input either runs with
// finite numbers or is an error naming its field.
#include "compiler/device_ranges.h"

#include <cmath>
#include <limits>

namespace sinew {
namespace {

std::string str(double v) { return number_text(v); }

bool finite_float(double v) { return std::isfinite(static_cast<float>(v)); }

Status check_work(const SolverSettings& solver) {
  if (solver.substeps > kMaxSubsteps)
    return Error(ErrorCode::bad_parameter, "solver.substeps must be <= " + std::to_string(kMaxSubsteps) + " (got " +
                                               std::to_string(solver.substeps) + ")");
  if (solver.iterations > kMaxIterations)
    return Error(ErrorCode::bad_parameter, "solver.iterations must be <= " + std::to_string(kMaxIterations) +
                                               " (got " + std::to_string(solver.iterations) + ")");
  if (solver.contact_sweeps > kMaxIterations)
    return Error(ErrorCode::bad_parameter, "solver.contact_sweeps must be <= " + std::to_string(kMaxIterations) +
                                               " (got " + std::to_string(solver.contact_sweeps) + ")");
  const bool residual_mode = solver.residual_tolerance > 0.0;
  if (residual_mode && solver.max_iterations > kMaxResidualIterations)
    return Error(ErrorCode::bad_parameter, "solver.max_iterations must be <= " + std::to_string(kMaxResidualIterations) +
                                               " (got " + std::to_string(solver.max_iterations) + ")");
  const double sweeps =
      double(solver.substeps) * ((residual_mode ? solver.max_iterations : solver.iterations) + solver.contact_sweeps);
  if (sweeps > kMaxSweepsPerFrame)
    return Error(ErrorCode::bad_parameter,
                 std::string("solver.substeps x (solver.") + (residual_mode ? "max_iterations" : "iterations") +
                     " + solver.contact_sweeps) = " +
                     str(sweeps) + " sweeps per frame, more than " + str(kMaxSweepsPerFrame));
  return {};
}

}  // namespace

Result<DeviceStep> device_step(const SolverSettings& solver) {
  const double h = solver.time_step / solver.substeps;
  DeviceStep step;
  step.h = static_cast<float>(h);
  step.inv_h2 = static_cast<float>(1.0 / (h * h));
  // A normal float h with finite 1/h and 1/h^2: otherwise alpha~, the
  // velocity update (x - x_prev) / h or h g overflow or vanish.
  if (!(step.h >= std::numeric_limits<float>::min()) || !std::isfinite(step.h) ||
      !std::isfinite(static_cast<float>(1.0 / h)) || !std::isfinite(step.inv_h2))
    return Error(ErrorCode::bad_parameter,
                 "solver.time_step: the substep h = time_step / substeps = " + str(h) +
                     " s and 1/h^2 must be finite, non-zero floats (the device's precision; got time_step " +
                     str(solver.time_step) + ", substeps " + std::to_string(solver.substeps) + ")");
  return step;
}

Status check_device_compliance(const std::string& owner, const char* field, double alpha, const DeviceStep& step) {
  const float a = static_cast<float>(alpha);
  if (!std::isfinite(a) || !std::isfinite(a * step.inv_h2))
    return Error(ErrorCode::bad_parameter,
                 owner + field + ": the compliance the device stores (" + str(alpha) + ") and it over h^2 (h = " +
                     str(step.h) + " s) must be finite in float32, the device's precision");
  return {};
}

Status check_device_ranges(const SceneDesc& scene) {
  if (Status s = check_work(scene.solver); !s) return s;
  const Result<DeviceStep> step = device_step(scene.solver);
  if (!step) return step.error();
  for (int k = 0; k < 3; ++k) {
    const float g = static_cast<float>(scene.gravity[k]), dt = static_cast<float>(scene.solver.time_step);
    // The impulse h g of a substep, and the move over a frame, dt^2 g.
    if (!std::isfinite(g) || !std::isfinite(step->h * g) || !(std::abs(dt * (dt * g)) <= kMaxFrameMove))
      return Error(ErrorCode::bad_parameter, "gravity[" + std::to_string(k) + "] = " + str(scene.gravity[k]) +
                                                 ": it and h g (h = " + str(step->h) +
                                                 " s) must be finite in float32, the device's precision, and the "
                                                 "move over a frame, time_step^2 g, at most " + str(kMaxFrameMove) +
                                                 " m");
  }
  // Constraint damping: the device's gamma = tau / h (xpbd_program.cpp).
  const auto damping = [&](const auto& body, const std::string& owner) -> Status {
    const double tau = body.stiffness_damping;
    if (std::isfinite(static_cast<float>(tau / scene.solver.time_step * scene.solver.substeps))) return {};
    return Error(ErrorCode::bad_parameter, owner + ".stiffness_damping = " + str(tau) +
                                               ": over the substep h (" + str(step->h) +
                                               " s) it must be finite in float32, the device's precision");
  };
  if (Status s = check_all(scene.tet_bodies, "tet_bodies", damping); !s) return s;
  if (Status s = check_all(scene.tri_bodies, "tri_bodies", damping); !s) return s;
  if (Status s = check_all(scene.line_bodies, "line_bodies", damping); !s) return s;
  // The compliances stored as they are (scaled ones: at compile time).
  const auto each = [&](const std::string& owner, double alpha, const char* field = ".compliance") {
    return check_device_compliance(owner, field, alpha, *step);
  };
  const auto line = [&](const LineBodyDesc& b, const std::string& name) -> Status {
    if (Status s = each(name, b.compliance); !s) return s;
    if (b.bending_compliance >= 0.0)
      if (Status s = each(name, b.bending_compliance, ".bending_compliance"); !s) return s;
    for (std::size_t v = 0; v < b.masses.size(); ++v)
      if (!finite_float(1.0 / b.masses[v]) || !(static_cast<float>(1.0 / b.masses[v]) > 0.0f))
        return Error(ErrorCode::bad_parameter, name + ".masses[" + std::to_string(v) + "] = " + str(b.masses[v]) +
                                                   " kg: its inverse must be a finite, non-zero float32");
    return {};
  };
  if (Status s = check_all(scene.line_bodies, "line_bodies", line); !s) return s;
  const auto bending = [&](const TriBodyDesc& b, const std::string& name) {
    return b.bending_compliance >= 0.0 ? each(name, b.bending_compliance, ".bending_compliance") : Status();
  };
  if (Status s = check_all(scene.tri_bodies, "tri_bodies", bending); !s) return s;
  const auto compliance = [&](const auto& item, const std::string& name) { return each(name, item.compliance); };
  if (Status s = check_all(scene.colliders, "colliders", compliance); !s) return s;
  if (Status s = check_all(scene.tools, "tools", compliance); !s) return s;
  if (Status s = check_all(scene.needles, "needles", compliance); !s) return s;
  if (Status s = check_all(scene.attachments, "attachments", compliance); !s) return s;
  if (Status s = check_all(scene.body_attachments, "body_attachments", compliance); !s) return s;
  if (Status s = check_all(scene.graspers, "graspers", compliance); !s) return s;
  if (scene.mesh_collision.enabled)
    if (Status s = each("mesh_collision", scene.mesh_collision.compliance); !s) return s;
  // Rigid tools and needles: their mass and moments divide their forces
  // into moves of a float32 pose; each, and its inverse, a normal float.
  const auto rigid = [](const auto& item, const std::string& name) -> Status {
    const auto normal = [&](const std::string& field, double v, const char* unit) -> Status {
      if (std::isnormal(static_cast<float>(v)) && std::isnormal(static_cast<float>(1.0 / v))) return {};
      return Error(ErrorCode::bad_parameter, name + field + " = " + str(v) + " " + unit +
                                                 ": it and its inverse must be normal float32 numbers (about 1e-38 "
                                                 "to 3e38), the device's precision");
    };
    if (Status s = normal(".mass", item.mass, "kg"); !s) return s;
    for (int k = 0; k < 3; ++k)
      if (Status s = normal(".inertia[" + std::to_string(k) + "]", item.inertia[k], "kg m^2"); !s) return s;
    return {};
  };
  if (Status s = check_all(scene.tools, "tools", rigid); !s) return s;
  // A kinematic needle is posed, never pushed: it has no mass to check.
  const auto pushed_needle = [&](const NeedleDesc& n, const std::string& name) {
    return n.drive == NeedleDrive::force ? rigid(n, name) : Status();
  };
  if (Status s = check_all(scene.needles, "needles", pushed_needle); !s) return s;
  return {};
}

}  // namespace sinew
