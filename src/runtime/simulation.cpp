// simulation.cpp — a compiled scene on a device: upload once, run the frame
// program every step, read back on request.
#include "sinew/simulation.h"
#include "runtime/simulation_internals.h"

#include <chrono>
#include <algorithm>
#include <cmath>

#include "compiler/scene_compiler.h"
#include "math/xpbd_math.h"
#include "program/xpbd_program.h"
#include "runtime/simulation_impl.h"

namespace sinew {

// Reads back the residuals, velocities and positions and reduces them in
// double precision, in a fixed order (the same numbers on every backend).
Status Simulation::Impl::measure(FrameStats& out) const {
  double sum = 0.0, largest = 0.0;
  std::size_t count = 0;
  std::vector<float> r;
  for (std::size_t k = 0; k < block_sizes.size(); ++k) {
    r.resize(block_sizes[k]);
    if (r.empty()) continue;
    if (Status s = device->read_buffer(buffers.blocks[k].residual, 0, r.data(), r.size() * sizeof(float)); !s) return s;
    for (float v : r) {
      sum += double(v) * v;
      largest = std::max(largest, double(v));
    }
    count += r.size();
  }
  out.residual_rms = count ? std::sqrt(sum / double(count)) : 0.0;
  out.max_residual = largest;

  std::vector<float> x(std::size_t{info.particles} * 4), v(x.size());
  if (Status s = device->read_buffer(buffers.position, 0, x.data(), x.size() * sizeof(float)); !s) return s;
  if (Status s = device->read_buffer(buffers.velocity, 0, v.data(), v.size() * sizeof(float)); !s) return s;
  double ke = 0.0;
  for (std::size_t p = 0; p < info.particles; ++p) {
    const float w = x[4 * p + 3];
    if (w > 0.0f) ke += 0.5 / w * (double(v[4 * p]) * v[4 * p] + double(v[4 * p + 1]) * v[4 * p + 1] +
                                    double(v[4 * p + 2]) * v[4 * p + 2]);
  }
  out.kinetic_energy = ke;

  double volume = 0.0;
  for (const auto& t : tets) {
    auto at = [&](int k) {
      return kernels::double4{x[4 * t[k]], x[4 * t[k] + 1], x[4 * t[k] + 2], 0.0};
    };
    volume += kernels::tet_volume(at(0), at(1), at(2), at(3));
  }
  out.volume_change = rest_volume > 0.0 ? volume / rest_volume - 1.0 : 0.0;
  return {};
}

Simulation::Simulation(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;
Simulation::~Simulation() = default;

Result<Simulation> Simulation::create(const SceneDesc& scene, const DeviceOptions& device_options) {
  auto compiled = compile_scene(scene);
  if (!compiled) return compiled.error();
  auto device = create_device(device_options);
  if (!device) return device.error();

  auto impl = std::make_unique<Impl>();
  impl->device = std::move(*device);
  auto buffers = upload_scene(*impl->device, *compiled);
  if (!buffers) return buffers.error();
  impl->buffers = *buffers;
  if (Status s = impl->init_contacts(scene, *compiled); !s) return s.error();
  impl->program = build_xpbd_program(*compiled, impl->buffers, scene.solver, scene.gravity);
  auto prepared = impl->device->create_program(impl->program);
  if (!prepared) return prepared.error();
  impl->prepared = *prepared;
  impl->time_step = scene.solver.time_step;
  impl->measure_errors = scene.solver.measure_errors;
  for (const ConstraintBlock& block : compiled->blocks) impl->block_sizes.push_back(block.size());
  for (std::size_t b = 0; b < scene.tet_bodies.size(); ++b) {
    const std::uint32_t first = compiled->tet_body_first_particle[b];
    for (const auto& t : scene.tet_bodies[b].mesh.tets) {
      impl->tets.push_back({first + t[0], first + t[1], first + t[2], first + t[3]});
      const auto at = [&](int k) {
        const Vec3d& p = scene.tet_bodies[b].mesh.vertices[t[k]];
        return kernels::double4{p[0], p[1], p[2], 0.0};
      };
      impl->rest_volume += kernels::tet_volume(at(0), at(1), at(2), at(3));
    }
  }

  SceneInfo& info = impl->info;
  info.particles = static_cast<std::uint32_t>(compiled->positions.size());
  for (const ConstraintBlock& block : compiled->blocks) {
    if (block.kernel == Kernel::xpbd_solve_distance) {
      info.distance_constraints += block.size();
      info.distance_colors += block.colors();
    } else if (block.kernel == Kernel::xpbd_solve_volume) {
      info.volume_constraints += block.size();
      info.volume_colors += block.colors();
    } else {
      info.other_constraints += block.size();
    }
    info.colors += block.colors();
  }
  info.dispatches_per_frame = static_cast<std::uint32_t>(impl->program.dispatch_count());
  info.barriers_per_frame = static_cast<std::uint32_t>(impl->program.barrier_count());
  info.tet_body_first_particle = compiled->tet_body_first_particle;
  info.tri_body_first_particle = compiled->tri_body_first_particle;
  info.line_body_first_particle = compiled->line_body_first_particle;
  return Simulation(std::move(impl));
}

Status Simulation::step() {
  const auto start = std::chrono::steady_clock::now();
  if (Status s = impl_->before_frame(); !s) return s;
  if (Status s = impl_->device->run_program(impl_->prepared); !s) return s;
  if (Status s = impl_->device->last_run_times(impl_->stats.device); !s) return s;
  if (Status s = impl_->after_frame(); !s) return s;
  const auto end = std::chrono::steady_clock::now();
  impl_->stats.frame += 1;
  impl_->stats.time = static_cast<double>(impl_->stats.frame) * impl_->time_step;
  impl_->stats.wall_ms = std::chrono::duration<double, std::milli>(end - start).count();
  if (impl_->measure_errors) {
    if (Status s = impl_->measure(impl_->stats); !s) return s;
    impl_->stats.measure_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - end).count();
  }
  return {};
}

Status Simulation::read_positions(std::vector<float>& xyzw) const {
  xyzw.resize(std::size_t{impl_->info.particles} * 4);
  return impl_->device->read_buffer(impl_->buffers.position, 0, xyzw.data(), xyzw.size() * sizeof(float));
}

Status Simulation::read_velocities(std::vector<float>& xyzw) const {
  xyzw.resize(std::size_t{impl_->info.particles} * 4);
  return impl_->device->read_buffer(impl_->buffers.velocity, 0, xyzw.data(), xyzw.size() * sizeof(float));
}

const SceneInfo& Simulation::info() const { return impl_->info; }
const FrameStats& Simulation::last_frame() const { return impl_->stats; }
std::string Simulation::backend_name() const { return impl_->device->backend_name(); }
std::string Simulation::device_name() const { return impl_->device->device_name(); }

const Device& SimulationInternals::device(const Simulation& sim) { return *sim.impl_->device; }
const FrameProgram& SimulationInternals::program(const Simulation& sim) { return sim.impl_->program; }

}  // namespace sinew
