// bind_states.cpp — tools', needles' and graspers' states and the events
// of a frame, as read-only Python objects (vectors as lists of floats,
// particle lists as numpy uint32 arrays).
#include <pybind11/stl.h>

#include "bindings.h"
#include "py_simulation.h"

namespace py = pybind11;

namespace sinew::python {
void bind_states(py::module_& m) {
  py::class_<ToolState>(m, "ToolState", "A tool at the end of the last frame (sinew::ToolState).")
      .def_readonly("position", &ToolState::position, "[m]")
      .def_readonly("rotation", &ToolState::rotation, "unit quaternion (w, x, y, z)")
      .def_readonly("velocity", &ToolState::velocity, "[m/s]")
      .def_readonly("angular_velocity", &ToolState::angular_velocity, "world frame [rad/s]")
      .def_readonly("contact_force", &ToolState::contact_force, "what the tissue pushed the tool with, frame average [N]")
      .def_readonly("contact_torque", &ToolState::contact_torque, "about the tool's centre [N m]")
      .def_readonly("penalty_force", &ToolState::penalty_force, "a level-set tool's penalty [N]")
      .def_readonly("penalty_torque", &ToolState::penalty_torque, "[N m]")
      .def_readonly("penalty_points", &ToolState::penalty_points)
      .def_readonly("penalty_depth", &ToolState::penalty_depth, "[m]")
      .def_readonly("trocar_force", &ToolState::trocar_force, "what its trocar pushed it with, last frame [N]")
      .def_readonly("trocar_torque", &ToolState::trocar_torque, "its moment about the tool's centre [N m]");

  py::class_<Puncture>(m, "Puncture", "A tissue point held on a needle or its thread (sinew::Puncture).")
      .def_property_readonly("body_kind", [](const Puncture& p) { return body_kind_name(p.body_kind); }, "'tet' or 'tri'")
      .def_readonly("body", &Puncture::body, "index among the scene's bodies of that kind")
      .def_readonly("triangle", &Puncture::triangle, "the surface triangle")
      .def_readonly("weights", &Puncture::weights, "barycentric weights of the point on it")
      .def_readonly("exit", &Puncture::exit)
      .def_readonly("on_thread", &Puncture::on_thread)
      .def_readonly("thread_segment", &Puncture::thread_segment)
      .def_readonly("thread_s", &Puncture::thread_s);

  py::class_<NeedleState>(m, "NeedleState", "A needle at the end of the last frame (sinew::NeedleState).")
      .def_readonly("position", &NeedleState::position, "[m]")
      .def_readonly("rotation", &NeedleState::rotation, "unit quaternion (w, x, y, z)")
      .def_readonly("velocity", &NeedleState::velocity, "[m/s]")
      .def_readonly("angular_velocity", &NeedleState::angular_velocity, "[rad/s]")
      .def_readonly("reaction_force", &NeedleState::reaction_force, "the force to render [N]")
      .def_readonly("reaction_torque", &NeedleState::reaction_torque, "[N m]")
      .def_readonly("punctures", &NeedleState::punctures, "list of Puncture, in the order they were made")
      .def_readonly("pushing", &NeedleState::pushing)
      .def_readonly("tip_force", &NeedleState::tip_force, "[N]")
      .def_readonly("refused_degenerate", &NeedleState::refused_degenerate)
      .def_readonly("refused_inverted", &NeedleState::refused_inverted)
      .def_readonly("refused_angle", &NeedleState::refused_angle);

  py::class_<HeldPoint>(m, "HeldPoint", "A surface point a grasper holds: sum weights[k] x[particles[k]].")
      .def_readonly("particles", &HeldPoint::particles)
      .def_readonly("weights", &HeldPoint::weights);

  py::class_<TopologyEvent>(m, "TopologyEvent", "What one topology change did (sinew::TopologyEvent).")
      .def_property_readonly("body_kind", [](const TopologyEvent& e) { return body_kind_name(e.body_kind); })
      .def_readonly("body", &TopologyEvent::body)
      .def_property_readonly("tets_removed", [](const TopologyEvent& e) { return to_numpy(e.tets_removed); })
      .def_property_readonly("triangles_removed", [](const TopologyEvent& e) { return to_numpy(e.triangles_removed); })
      .def_property_readonly("segments_removed", [](const TopologyEvent& e) { return to_numpy(e.segments_removed); })
      .def_property_readonly("vertices_removed", [](const TopologyEvent& e) { return to_numpy(e.vertices_removed); })
      .def_readonly("constraints_removed", &TopologyEvent::constraints_removed)
      .def_readonly("edges_softened", &TopologyEvent::edges_softened)
      .def_readonly("mass_moved", &TopologyEvent::mass_moved, "[kg]")
      .def_readonly("mass_removed", &TopologyEvent::mass_removed, "[kg]")
      .def_readonly("wall_ms", &TopologyEvent::wall_ms, "[ms]")
      .def_readonly("rebuild_ms", &TopologyEvent::rebuild_ms, "[ms]");

  py::class_<CutReport>(m, "CutReport", "What a level-set collider's cut removed.")
      .def_readonly("removed_volume", &CutReport::removed_volume, "[m^3]")
      .def_readonly("changed_voxels", &CutReport::changed_voxels)
      .def_readonly("changed_leaves", &CutReport::changed_leaves);

  py::class_<FrameEvent>(m, "Event",
                         "Something that happened in a frame: a script action, a tear or a new puncture.")
      .def_readonly("frame", &FrameEvent::frame)
      .def_readonly("kind", &FrameEvent::kind,
                    "'close_grasper', 'open_grasper', 'cut', 'cauterize', 'remove', 'cut_collider', 'set_emitter', "
                    "'set_sink', 'tear' or 'puncture'")
      .def_readonly("index", &FrameEvent::index, "the grasper, body, collider, emitter, sink or needle")
      .def_readonly("text", &FrameEvent::text)
      .def_property_readonly("particles", [](const FrameEvent& e) { return to_numpy(e.particles); },
                             "grasps: the particles held or released (uint32)")
      .def_readonly("topology", &FrameEvent::topology, "TopologyEvent of a cut, cautery, removal or tear, else None")
      .def_readonly("collider_cut", &FrameEvent::collider_cut, "CutReport of a collider cut, else None")
      .def_readonly("puncture", &FrameEvent::puncture, "the new Puncture, else None")
      .def("__repr__", [](const FrameEvent& e) { return "<Event " + e.text + ">"; });
}

}  // namespace sinew::python
