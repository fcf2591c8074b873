// bind_stats.cpp — what a frame did and cost (FrameStats with its stages)
// and what a compiled scene holds (SceneInfo), as read-only Python objects.
#include <pybind11/stl.h>

#include "bindings.h"
#include "sinew/simulation.h"

namespace py = pybind11;

namespace sinew::python {
namespace {

const char* stop_name(SolveStop stop) {
  switch (stop) {
    case SolveStop::fixed: return "fixed";
    case SolveStop::converged: return "converged";
    case SolveStop::iteration_cap: return "iteration_cap";
    case SolveStop::time_budget: return "time_budget";
  }
  return "unknown";
}

// The stage's counters as a dict, in the order they were first set.
py::dict counters(const StageProfile& s) {
  py::dict d;
  for (const StageProfile::Counter& c : s.counters) d[py::str(c.name)] = c.value;
  return d;
}

// Device time per kernel that ran [ms], by kernel name (empty where the backend records none).
py::dict kernel_ms(const FrameStats& st) {
  py::dict d;
  if (!st.device.timed) return d;
  const auto names = kernel_names();
  for (std::size_t k = 0; k < names.size() && k < DeviceTimes::max_kernels; ++k)
    if (st.device.dispatches[k] > 0) d[py::str(std::string(names[k]))] = st.device.kernel_ms[k];
  return d;
}

}  // namespace

void bind_stats(py::module_& m) {
  py::class_<StageProfile>(m, "StageProfile", "One stage of the frame: its name, wall time and counters.")
      .def_readonly("name", &StageProfile::name, "the stage's name, e.g. 'solve' or 'mesh collision'")
      .def_readonly("ms", &StageProfile::ms, "wall time of the stage's work in the last step() [ms]")
      .def_property_readonly("counters", &counters, "the stage's figures of the last step(), {name: value}")
      .def("__repr__", [](const StageProfile& s) { return "<StageProfile " + s.name + " " + std::to_string(s.ms) + " ms>"; });

  py::class_<FrameStats>(m, "FrameStats", "What the last frame did and cost (sinew::FrameStats).")
      .def_readonly("frame", &FrameStats::frame, "frames done")
      .def_readonly("time", &FrameStats::time, "simulated time [s]")
      .def_readonly("wall_ms", &FrameStats::wall_ms, "wall time of the last step() [ms]")
      .def_readonly("measure_ms", &FrameStats::measure_ms, "of which reading back and combining the statistics [ms]")
      .def_readonly("residual_rms", &FrameStats::residual_rms,
                    "RMS normalised constraint residual at the start of the frame's last sweep (0: solved exactly)")
      .def_readonly("max_residual", &FrameStats::max_residual, "the largest normalised residual")
      .def_readonly("kinetic_energy", &FrameStats::kinetic_energy, "sum of m |v|^2 / 2 over movable particles [J]")
      .def_readonly("volume_change", &FrameStats::volume_change, "total tet volume / rest total - 1")
      .def_readonly("inverted_tets", &FrameStats::inverted_tets, "tets turned inside out at the frame's end")
      .def_readonly("sweeps", &FrameStats::sweeps, "Gauss-Seidel sweeps run in the frame, over all its substeps")
      .def_property_readonly("stop", [](const FrameStats& s) { return stop_name(s.stop); },
                             "how the sweeps ended: 'fixed', 'converged', 'iteration_cap' or 'time_budget'")
      .def_readonly("checked_residual", &FrameStats::checked_residual, "residual mode: the last checked residual")
      .def_readonly("residual_checks", &FrameStats::residual_checks, "residual mode: checks in the frame")
      .def_readonly("position_reads", &FrameStats::position_reads, "read-backs of all positions by the frame's stages")
      .def_readonly("read_back_bytes", &FrameStats::read_back_bytes, "bytes read from the device in the frame")
      .def_readonly("host_reads", &FrameStats::host_reads, "read-backs (round trips) in the frame")
      .def_readonly("host_waits", &FrameStats::host_waits, "times the frame blocked on the device")
      .def_property_readonly("device_timed", [](const FrameStats& s) { return s.device.timed; },
                             "whether the backend recorded device timestamps (Vulkan on GPUs)")
      .def_property_readonly("device_ms", [](const FrameStats& s) { return s.device.span_ms; },
                             "the frame program's time on the device [ms] (0 when not timed)")
      .def_property_readonly("kernel_ms", &kernel_ms, "device time per kernel [ms], {kernel: ms} (empty when not timed)")
      .def_readonly("stages", &FrameStats::stages, "the frame's stages in the order they run (list of StageProfile)")
      .def("stage_ms", &FrameStats::stage_ms, py::arg("name"), "wall time of stage `name` [ms] (0 when absent)")
      .def("counter", &FrameStats::counter, py::arg("stage"), py::arg("counter"),
           "counter `counter` of stage `stage` (0 when absent)")
      .def("__repr__", [](const FrameStats& s) {
        return "<FrameStats frame " + std::to_string(s.frame) + " t=" + std::to_string(s.time) + " s, " +
               std::to_string(s.wall_ms) + " ms, residual_rms " + std::to_string(s.residual_rms) + ">";
      });

  py::class_<SceneInfo>(m, "SceneInfo", "What a compiled scene holds (fixed for the Simulation's life).")
      .def_readonly("particles", &SceneInfo::particles)
      .def_readonly("distance_constraints", &SceneInfo::distance_constraints)
      .def_readonly("volume_constraints", &SceneInfo::volume_constraints)
      .def_readonly("other_constraints", &SceneInfo::other_constraints)
      .def_property_readonly("constraints", &SceneInfo::constraints, "distance + volume + other")
      .def_readonly("distance_colors", &SceneInfo::distance_colors)
      .def_readonly("volume_colors", &SceneInfo::volume_colors)
      .def_readonly("colors", &SceneInfo::colors, "dependent sweeps per iteration")
      .def_readonly("dispatches_per_frame", &SceneInfo::dispatches_per_frame)
      .def_readonly("barriers_per_frame", &SceneInfo::barriers_per_frame)
      .def_readonly("tet_body_first_particle", &SceneInfo::tet_body_first_particle)
      .def_readonly("tri_body_first_particle", &SceneInfo::tri_body_first_particle)
      .def_readonly("line_body_first_particle", &SceneInfo::line_body_first_particle)
      .def_readonly("rest_close_triangle_pairs", &SceneInfo::rest_close_triangle_pairs)
      .def("__repr__", [](const SceneInfo& i) {
        return "<SceneInfo " + std::to_string(i.particles) + " particles, " + std::to_string(i.constraints()) +
               " constraints, " + std::to_string(i.colors) + " colours>";
      });
}

}  // namespace sinew::python
