// simulation.cpp — a compiled scene on a device: upload once, run the frame
// program every step, read back on request.
#include "sinew/simulation.h"

#include <chrono>

#include "scene/scene_compiler.h"
#include "xpbd/xpbd_program.h"

namespace sinew {

struct Simulation::Impl {
  std::unique_ptr<Device> device;
  XpbdBuffers buffers;
  FrameProgram program;
  ProgramHandle prepared;
  SceneInfo info;
  FrameStats stats;
  double time_step = 0.0;
};

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
  impl->program = build_xpbd_program(*compiled, impl->buffers, scene.solver, scene.gravity);
  auto prepared = impl->device->create_program(impl->program);
  if (!prepared) return prepared.error();
  impl->prepared = *prepared;
  impl->time_step = scene.solver.time_step;

  SceneInfo& info = impl->info;
  info.particles = static_cast<std::uint32_t>(compiled->positions.size());
  for (const ConstraintBlock& block : compiled->blocks) {
    if (block.kernel == Kernel::xpbd_solve_distance) {
      info.distance_constraints += block.size();
      info.distance_colors += block.colors();
    } else if (block.kernel == Kernel::xpbd_solve_volume) {
      info.volume_constraints += block.size();
      info.volume_colors += block.colors();
    }
    info.colors += block.colors();
  }
  info.dispatches_per_frame = static_cast<std::uint32_t>(impl->program.dispatch_count());
  info.barriers_per_frame = static_cast<std::uint32_t>(impl->program.barrier_count());
  info.tet_body_first_particle = compiled->tet_body_first_particle;
  info.line_body_first_particle = compiled->line_body_first_particle;
  return Simulation(std::move(impl));
}

Status Simulation::step() {
  const auto start = std::chrono::steady_clock::now();
  if (Status s = impl_->device->run_program(impl_->prepared); !s) return s;
  const auto end = std::chrono::steady_clock::now();
  impl_->stats.frame += 1;
  impl_->stats.time = static_cast<double>(impl_->stats.frame) * impl_->time_step;
  impl_->stats.wall_ms = std::chrono::duration<double, std::milli>(end - start).count();
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
const Device& Simulation::device() const { return *impl_->device; }
const FrameProgram& Simulation::program() const { return impl_->program; }

}  // namespace sinew
