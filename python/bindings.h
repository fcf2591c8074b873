// bindings.h — the parts of the `sinew` Python module, one file each
// (module.cpp puts them together).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <mutex>
#include <span>
#include <string>
#include <utility>

#include "sinew/scene.h"

namespace sinew::python {

void bind_stats(pybind11::module_& m);        // FrameStats, StageProfile, SceneInfo (bind_stats.cpp)
void bind_states(pybind11::module_& m);       // ToolState, NeedleState, Puncture, HeldPoint, TopologyEvent, Event
void bind_scene(pybind11::module_& m);        // Scene, load_scene_file, scene_from_dict (bind_scene.cpp)
void bind_simulation(pybind11::module_& m);   // Simulation (bind_simulation.cpp)
void bind_features(pybind11::module_& m);     // Simulation.tools, graspers, needles, topology (bind_features.cpp)

/// "tet", "tri" or "line": how Python names a body kind.
inline const char* body_kind_name(BodyKind kind) {
  return kind == BodyKind::tet ? "tet" : kind == BodyKind::tri ? "tri" : "line";
}

/// A new 1-D numpy uint32 array holding a copy of `values`.
inline pybind11::array_t<std::uint32_t> to_numpy(std::span<const std::uint32_t> values) {
  pybind11::array_t<std::uint32_t> out(static_cast<pybind11::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

/// Runs `f` with the GIL released (a device call that may take long, so
/// other Python threads run meanwhile).
template <class F>
auto without_gil(F&& f) {
  pybind11::gil_scoped_release released;
  return std::forward<F>(f)();
}

/// Runs `f` without the GIL and holding `owner.lock` (a PySimulation's:
/// calls from several Python threads take turns on one Simulation).
template <class Owner, class F>
auto locked(Owner& owner, F&& f) {
  return without_gil([&] {
    std::lock_guard<std::mutex> held(owner.lock);
    return std::forward<F>(f)();
  });
}

}  // namespace sinew::python
