// bind_simulation.cpp — sinew.Simulation: made from a Scene on a backend,
// stepped with the GIL released, its particles read into numpy arrays.
//
// Positions and velocities live on the device (or in the CPU backend's own
// buffers), so reading them is always a copy: the library copies them into
// a staging vector kept by the Simulation (no allocation after the first
// read), and that is copied into the numpy array, a new one or the `out`
// array the caller passes to reuse its memory. No view without a copy is
// possible.
#include <pybind11/stl.h>

#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "bindings.h"
#include "errors.h"
#include "py_simulation.h"
#include "sinew/mesh.h"

namespace py = pybind11;

namespace sinew::python {
namespace {

using Reader = Status (Simulation::*)(std::vector<float>&) const;

// An N x 4 float32 array: `out` when given (checked: float32, C-contiguous,
// writeable, N x 4), else a new one. `what` names the call in errors.
py::array_t<float> read_xyzw(PySimulation& s, Reader read, const py::object& out, const char* what) {
  const auto n = static_cast<py::ssize_t>(s.sim.info().particles);
  py::array_t<float> array;
  if (out.is_none()) {
    array = py::array_t<float>({n, py::ssize_t{4}});
  } else {
    if (!py::isinstance<py::array>(out)) raise_bad_parameter(std::string(what) + ": out must be a numpy array");
    py::array a = py::reinterpret_borrow<py::array>(out);
    if (!a.dtype().is(py::dtype::of<float>()))
      raise_bad_parameter(std::string(what) + ": out must have dtype float32 (got " + py::str(a.dtype()).cast<std::string>() + ")");
    if (a.ndim() != 2 || a.shape(0) != n || a.shape(1) != 4)
      raise_bad_parameter(std::string(what) + ": out must have shape (" + std::to_string(n) + ", 4), one row per particle");
    if (!(a.flags() & py::array::c_style)) raise_bad_parameter(std::string(what) + ": out must be C-contiguous");
    if (!a.writeable()) raise_bad_parameter(std::string(what) + ": out is read-only");
    array = py::reinterpret_borrow<py::array_t<float>>(a);
  }
  float* dst = array.mutable_data();
  check(locked(s, [&] {
    if (Status st = (s.sim.*read)(s.staging); !st) return st;
    std::memcpy(dst, s.staging.data(), s.staging.size() * sizeof(float));
    return Status{};
  }));
  return array;
}

void set_forces(PySimulation& s, const py::array_t<float, py::array::c_style | py::array::forcecast>& forces) {
  const std::size_t n = s.sim.info().particles;
  const bool rows = forces.ndim() == 2 && forces.shape(1) == 3 && static_cast<std::size_t>(forces.shape(0)) == n;
  const bool flat = forces.ndim() == 1 && static_cast<std::size_t>(forces.shape(0)) == 3 * n;
  if (!rows && !flat)
    raise_bad_parameter("set_particle_forces: forces must have shape (" + std::to_string(n) + ", 3) or (" +
                        std::to_string(3 * n) + ",), one x y z force [N] per particle");
  const std::span<const float> xyz(forces.data(), 3 * n);
  check(locked(s, [&] { return s.sim.set_particle_forces(xyz); }));
}

// The surface of body `body` of `kind` as triangles (M x 3 uint32): a tet
// body's boundary faces (of its live tets after topology changes), a tri
// body's (live) triangles; with global_indices the vertices as particle
// indices (rows of read_positions), else as the body's own vertex indices.
py::array_t<std::uint32_t> surface_triangles(PySimulation& s, std::size_t body, const std::string& kind, bool global_indices) {
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::uint32_t first = 0;
  if (kind == "tet") {
    if (body >= s.scene.tet_bodies.size())
      raise_bad_parameter("surface_triangles: tet body " + std::to_string(body) + " does not exist (the scene has " +
                          std::to_string(s.scene.tet_bodies.size()) + ")");
    TetMesh live;
    live.vertices = s.scene.tet_bodies[body].mesh.vertices;
    if (s.scene.topology_changes) {
      std::lock_guard<std::mutex> held(s.lock);
      live.tets = take(s.sim.topology().current_tets(take(s.sim.topology().tet_body(body))));
    } else {
      live.tets = s.scene.tet_bodies[body].mesh.tets;
    }
    triangles = extract_boundary_surface(live).triangles;
    first = s.sim.info().tet_body_first_particle[body];
  } else if (kind == "tri") {
    if (body >= s.scene.tri_bodies.size())
      raise_bad_parameter("surface_triangles: tri body " + std::to_string(body) + " does not exist (the scene has " +
                          std::to_string(s.scene.tri_bodies.size()) + ")");
    if (s.scene.topology_changes) {
      std::lock_guard<std::mutex> held(s.lock);
      triangles = take(s.sim.topology().current_triangles(take(s.sim.topology().tri_body(body))));
    } else {
      triangles = s.scene.tri_bodies[body].mesh.triangles;
    }
    first = s.sim.info().tri_body_first_particle[body];
  } else {
    raise_bad_parameter("surface_triangles: kind must be 'tet' or 'tri' (got '" + kind + "')");
  }
  if (!global_indices) first = 0;
  py::array_t<std::uint32_t> out({static_cast<py::ssize_t>(triangles.size()), py::ssize_t{3}});
  std::uint32_t* dst = out.mutable_data();
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) dst[3 * t + c] = triangles[t][c] + first;
  return out;
}

}  // namespace

void bind_simulation(py::module_& m) {
  py::class_<PySimulation>(m, "Simulation",
                           "A scene compiled onto a device. step() plays the scene's script for the frame (as "
                           "`sinew run` does) and advances one frame.")
      .def(py::init([](const SceneFile& scene, std::optional<std::string> backend, std::string device, int threads,
                       bool play_script, bool cpu_adaptive_team) {
             if (threads < 0) raise_bad_parameter("threads must be >= 0 (0: all hardware threads), got " + std::to_string(threads));
             DeviceOptions options{.backend = backend.value_or(scene.run.backend), .device = std::move(device),
                                   .threads = threads, .cpu_adaptive_team = cpu_adaptive_team, .quiet = true};
             return without_gil([&] { return std::make_unique<PySimulation>(scene, options, play_script); });
           }),
           py::arg("scene"), py::arg("backend") = py::none(), py::arg("device") = "", py::arg("threads") = 0,
           py::arg("play_script") = true, py::arg("cpu_adaptive_team") = true,
           "Makes the Simulation of `scene` on `backend` ('cpu', 'opencl', 'vulkan', 'auto'; default: the "
           "scene's run.backend), device (index or name substring), CPU worker `threads` (0: all). With "
           "play_script, each step() first plays the scene's script and scripted hands for its frame.")
      .def(
          "step",
          [](PySimulation& s) {
            FrameStats stats;
            check(without_gil([&] { return s.step(&stats); }));
            return stats;
          },
          "Plays the script's next frame (poses, forces, actions), advances one frame without holding the GIL, "
          "and returns its FrameStats. Raises sinew.Error (e.g. code 'diverged').")
      .def(
          "run",
          [](PySimulation& s, int frames) {
            if (frames < 1) raise_bad_parameter("run: frames must be >= 1, got " + std::to_string(frames));
            FrameStats stats;
            check(without_gil([&] {
              for (int f = 0; f < frames; ++f)
                if (Status st = s.step(f + 1 == frames ? &stats : nullptr); !st) return st;
              return Status{};
            }));
            return stats;
          },
          py::arg("frames"), "step() `frames` times; returns the last FrameStats (events: the last frame's).")
      .def_property_readonly("frame", [](const PySimulation& s) { return s.frame.load(); }, "frames stepped")
      .def_property_readonly("particles", [](const PySimulation& s) { return s.sim.info().particles; })
      .def(
          "read_positions",
          [](PySimulation& s, const py::object& out) { return read_xyzw(s, &Simulation::read_positions, out, "read_positions"); },
          py::arg("out") = py::none(),
          "Positions [m] and inverse mass [1/kg] per particle, an N x 4 float32 array (x, y, z, w): a copy "
          "from the device, into `out` when given (float32, C-contiguous, N x 4) to avoid allocating.")
      .def(
          "read_velocities",
          [](PySimulation& s, const py::object& out) { return read_xyzw(s, &Simulation::read_velocities, out, "read_velocities"); },
          py::arg("out") = py::none(), "Velocities [m/s] per particle (w unused), N x 4 float32; `out` as read_positions.")
      .def("set_particle_forces", &set_forces, py::arg("forces"),
           "Forces [N] on the particles during the next frame, N x 3 (or 3N); converted to float32. Needs the "
           "scene's external_forces.")
      .def("surface_triangles", &surface_triangles, py::arg("body") = 0, py::arg("kind") = "tet",
           py::arg("global_indices") = true,
           "The body's current surface triangles, M x 3 uint32 (a tet body's boundary faces, a tri body's "
           "triangles); global_indices: as particle indices (rows of read_positions), else the body's vertices.")
      .def_property_readonly("info", [](const PySimulation& s) { return s.sim.info(); }, "SceneInfo")
      .def_property_readonly("last_frame", [](PySimulation& s) { return locked(s, [&] { return s.sim.last_frame(); }); },
                             "the last step()'s FrameStats")
      .def_property_readonly("events", [](PySimulation& s) { return locked(s, [&] { return s.events; }); },
                             "what happened in the last step(): list of Event")
      .def_property_readonly("backend_name", [](const PySimulation& s) { return s.sim.backend_name(); })
      .def_property_readonly("device_name", [](const PySimulation& s) { return s.sim.device_name(); });
}

}  // namespace sinew::python
