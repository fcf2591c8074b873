// bind_features.cpp — a Simulation's tools, graspers, needles and topology
// for Python: `sim.tools.state(0)`, `sim.graspers.close(0, ...)`. Objects
// are named by their index in the scene (the C++ typed ids are looked up
// from it); each handle keeps its Simulation alive.
#include <pybind11/stl.h>

#include <array>
#include <string>

#include "bindings.h"
#include "errors.h"
#include "py_simulation.h"

namespace py = pybind11;

namespace sinew::python {
namespace {

using Vec3 = std::array<double, 3>;
using Quat = std::array<double, 4>;
constexpr Vec3 kZero{0.0, 0.0, 0.0};
constexpr Quat kIdentity{1.0, 0.0, 0.0, 0.0};

// The handles: a view of one PySimulation.
struct ToolsHandle { PySimulation* s; };
struct GraspersHandle { PySimulation* s; };
struct NeedlesHandle { PySimulation* s; };
struct TopologyHandle { PySimulation* s; };

// `call(id)` on the object `lookup()` finds (its Result<Id>), holding the
// Simulation's lock: call's Status or Result, or the lookup's error.
template <class Lookup, class Call>
auto with_id(PySimulation& s, Lookup lookup, Call call) {
  return locked(s, [&] {
    auto id = lookup();
    using Returned = decltype(call(*id));
    if (!id) return Returned(id.error());
    return call(*id);
  });
}

// tet or tri body `body`'s topology change `change`, by kind.
template <class TetChange, class TriChange>
TopologyEvent on_body(PySimulation& s, const std::string& kind, std::size_t body, TetChange tet, TriChange tri) {
  if (kind != "tet" && kind != "tri") raise_bad_parameter("kind must be 'tet' or 'tri' (got '" + kind + "')");
  return take(locked(s, [&]() -> Result<TopologyEvent> {
    Topology t = s.sim.topology();
    if (kind == "tet") {
      auto id = t.tet_body(body);
      if (!id) return id.error();
      return tet(t, *id);
    }
    auto id = t.tri_body(body);
    if (!id) return id.error();
    return tri(t, *id);
  }));
}

}  // namespace

void bind_features(py::module_& m) {
  py::class_<ToolsHandle>(m, "Tools", "A Simulation's tools, colliders and kinematic targets, by scene index.")
      .def_property_readonly("count", [](const ToolsHandle& h) { return h.s->scene.tools.size(); }, "the scene's tools")
      .def_property_readonly("collider_count", [](const ToolsHandle& h) { return h.s->scene.colliders.size(); })
      .def_property_readonly("target_count", [](const ToolsHandle& h) { return h.s->scene.targets.size(); })
      .def(
          "state",
          [](const ToolsHandle& h, std::size_t tool) {
            return take(with_id(*h.s, [&] { return h.s->sim.tools().tool(tool); },
                [&](auto id) { return h.s->sim.tools().state(id); }));
          },
          py::arg("tool"), "Tool `tool`'s ToolState: pose, velocities, contact force and torque of the last frame.")
      .def(
          "apply_force",
          [](const ToolsHandle& h, std::size_t tool, const Vec3& force, const Vec3& torque) {
            check(with_id(*h.s, [&] { return h.s->sim.tools().tool(tool); },
                [&](auto id) { return h.s->sim.tools().apply_force(id, force, torque); }));
          },
          py::arg("tool"), py::arg("force"), py::arg("torque") = kZero,
          "Force [N] and torque [N m] (world frame) on tool `tool` during the next frame; calls add up.")
      .def(
          "set_pose",
          [](const ToolsHandle& h, std::size_t collider, const Vec3& position, const Quat& rotation) {
            check(with_id(*h.s, [&] { return h.s->sim.tools().collider(collider); },
                [&](auto id) { return h.s->sim.tools().set_pose(id, position, rotation); }));
          },
          py::arg("collider"), py::arg("position"), py::arg("rotation") = kIdentity,
          "Moves collider `collider` to this pose [m, quaternion (w, x, y, z)] by the end of the next frame.")
      .def(
          "set_target",
          [](const ToolsHandle& h, std::size_t target, const Vec3& position) {
            check(with_id(*h.s, [&] { return h.s->sim.tools().target(target); },
                [&](auto id) { return h.s->sim.tools().set_position(id, position); }));
          },
          py::arg("target"), py::arg("position"), "Moves kinematic target `target` to `position` [m] by the next frame's end.");

  py::class_<GraspersHandle>(m, "Graspers", "A Simulation's graspers, by scene index.")
      .def_property_readonly("count", [](const GraspersHandle& h) { return h.s->sim.graspers().count(); })
      .def(
          "close",
          [](const GraspersHandle& h, std::size_t grasper, const Vec3& position, const Vec3& half_extents, const Quat& rotation) {
            const auto held = take(with_id(*h.s, [&] { return h.s->sim.graspers().grasper(grasper); },
                [&](auto id) { return h.s->sim.graspers().close(id, Pose{position, rotation}, half_extents); }));
            return to_numpy(held);
          },
          py::arg("grasper"), py::arg("position"), py::arg("half_extents"), py::arg("rotation") = kIdentity,
          "Closes the jaws (a box of half_extents [m] at the pose) on the tissue inside; returns the held particles.")
      .def(
          "move",
          [](const GraspersHandle& h, std::size_t grasper, const Vec3& position, const Quat& rotation) {
            check(with_id(*h.s, [&] { return h.s->sim.graspers().grasper(grasper); },
                [&](auto id) { return h.s->sim.graspers().move(id, Pose{position, rotation}); }));
          },
          py::arg("grasper"), py::arg("position"), py::arg("rotation") = kIdentity,
          "Moves a closed grasper to this pose by the end of the next frame.")
      .def(
          "open",
          [](const GraspersHandle& h, std::size_t grasper) {
            const auto released = take(with_id(*h.s, [&] { return h.s->sim.graspers().grasper(grasper); },
                [&](auto id) { return h.s->sim.graspers().open(id); }));
            return to_numpy(released);
          },
          py::arg("grasper"), "Opens the grasper; returns the released particles.")
      .def(
          "held_points",
          [](const GraspersHandle& h, std::size_t grasper) {
            return take(with_id(*h.s, [&] { return h.s->sim.graspers().grasper(grasper); },
                [&](auto id) { return h.s->sim.graspers().held_points(id); }));
          },
          py::arg("grasper"), "The surface points the grasper holds (list of HeldPoint; none while open).");

  py::class_<NeedlesHandle>(m, "Needles", "A Simulation's needles, by scene index.")
      .def_property_readonly("count", [](const NeedlesHandle& h) { return h.s->sim.needles().count(); })
      .def(
          "state",
          [](const NeedlesHandle& h, std::size_t needle) {
            return take(with_id(*h.s, [&] { return h.s->sim.needles().needle(needle); },
                [&](auto id) { return h.s->sim.needles().state(id); }));
          },
          py::arg("needle"), "The needle's NeedleState: pose, reaction force, punctures.")
      .def(
          "set_pose",
          [](const NeedlesHandle& h, std::size_t needle, const Vec3& position, const Quat& rotation) {
            check(with_id(*h.s, [&] { return h.s->sim.needles().needle(needle); },
                [&](auto id) { return h.s->sim.needles().set_pose(id, position, rotation); }));
          },
          py::arg("needle"), py::arg("position"), py::arg("rotation") = kIdentity,
          "Moves a kinematic needle to this pose by the end of the next frame.")
      .def(
          "apply_force",
          [](const NeedlesHandle& h, std::size_t needle, const Vec3& force, const Vec3& torque) {
            check(with_id(*h.s, [&] { return h.s->sim.needles().needle(needle); },
                [&](auto id) { return h.s->sim.needles().apply_force(id, force, torque); }));
          },
          py::arg("needle"), py::arg("force"), py::arg("torque") = kZero,
          "Force [N] and torque [N m] on a force-driven needle during the next frame.");

  py::class_<TopologyHandle>(m, "Topology", "A Simulation's topology changes (scenes with topology_changes).")
      .def(
          "cut",
          [](const TopologyHandle& h, std::size_t body, const Vec3& a_from, const Vec3& b_from, const Vec3& a_to,
             const Vec3& b_to, const std::string& kind) {
            const Blade from{a_from, b_from}, to{a_to, b_to};
            return on_body(
                *h.s, kind, body, [&](Topology& t, TetBodyId id) { return t.cut(id, from, to); },
                [&](Topology& t, TriBodyId id) { return t.cut(id, from, to); });
          },
          py::arg("body"), py::arg("a_from"), py::arg("b_from"), py::arg("a_to"), py::arg("b_to"), py::arg("kind") = "tet",
          "Cuts the body with a blade (a to b [m]) swept from its `from` ends to its `to` ends; a TopologyEvent.")
      .def(
          "cauterize",
          [](const TopologyHandle& h, std::size_t body, const Vec3& centre, double radius, double seconds,
             double dwell_time, const std::string& kind) {
            return on_body(
                *h.s, kind, body,
                [&](Topology& t, TetBodyId id) { return t.cauterize(id, centre, radius, seconds, dwell_time); },
                [&](Topology& t, TriBodyId id) { return t.cauterize(id, centre, radius, seconds, dwell_time); });
          },
          py::arg("body"), py::arg("centre"), py::arg("radius"), py::arg("seconds"), py::arg("dwell_time"),
          py::arg("kind") = "tet", "A heated tip (ball of radius [m] at centre [m]) touching the body for `seconds`.")
      .def(
          "remove",
          [](const TopologyHandle& h, std::size_t body, const std::vector<std::uint32_t>& elements, const std::string& kind) {
            return on_body(
                *h.s, kind, body, [&](Topology& t, TetBodyId id) { return t.remove_tets(id, elements); },
                [&](Topology& t, TriBodyId id) { return t.remove_triangles(id, elements); });
          },
          py::arg("body"), py::arg("elements"), py::arg("kind") = "tet",
          "Removes tets (kind 'tet') or triangles ('tri') of the body by index; a TopologyEvent.");

  // The handles as attributes of Simulation (each keeps the Simulation alive).
  auto simulation = py::reinterpret_borrow<py::class_<PySimulation>>(m.attr("Simulation"));
  simulation.def_property_readonly("tools", py::cpp_function([](PySimulation& s) { return ToolsHandle{&s}; }, py::keep_alive<0, 1>()))
      .def_property_readonly("graspers", py::cpp_function([](PySimulation& s) { return GraspersHandle{&s}; }, py::keep_alive<0, 1>()))
      .def_property_readonly("needles", py::cpp_function([](PySimulation& s) { return NeedlesHandle{&s}; }, py::keep_alive<0, 1>()))
      .def_property_readonly("topology", py::cpp_function([](PySimulation& s) { return TopologyHandle{&s}; }, py::keep_alive<0, 1>()));
}

}  // namespace sinew::python
