// fluid.cpp — sinew/fluid.h: a device and an SphSolver (sph_solver.h)
// behind the public API.
#include "sinew/fluid.h"

#include "backends/backend.h"
#include "fluid/sph_solver.h"

namespace sinew {

struct Fluid::Impl {
  std::unique_ptr<Device> device;
  std::unique_ptr<SphSolver> solver;
};

Fluid::Fluid(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Fluid::Fluid(Fluid&&) noexcept = default;
Fluid& Fluid::operator=(Fluid&&) noexcept = default;
Fluid::~Fluid() {
  if (impl_) impl_->solver.reset();  // before its device
}

Result<Fluid> Fluid::create(const FluidDesc& desc) {
  auto device = create_device(desc.device);
  if (!device) return device.error();
  auto impl = std::make_unique<Impl>();
  impl->device = std::move(*device);
  auto solver = SphSolver::create(*impl->device, desc);
  if (!solver) return solver.error();
  impl->solver = std::move(*solver);
  return Fluid(std::move(impl));
}

Status Fluid::step(int steps) { return impl_->solver->step(steps); }
Status Fluid::read(std::vector<FluidParticle>& particles) const { return impl_->solver->read(particles); }
const FluidStats& Fluid::stats() const { return impl_->solver->stats(); }
Status Fluid::set_emitter(std::size_t index, const FluidEmitter& emitter) {
  return impl_->solver->set_emitter(index, emitter);
}
Status Fluid::set_sink(std::size_t index, const FluidSink& sink) { return impl_->solver->set_sink(index, sink); }
Status Fluid::set_boundary(std::span<const std::array<float, 3>> positions,
                           std::span<const std::array<float, 3>> velocities) {
  return impl_->solver->set_boundary(positions, velocities);
}
Status Fluid::read_boundary_impulses(std::vector<std::array<float, 3>>& impulses) {
  return impl_->solver->read_boundary_impulses(impulses);
}
std::string Fluid::device_name() const { return impl_->device->device_name(); }
std::uint32_t Fluid::boundary_count() const { return impl_->solver->boundary_count(); }
std::uint32_t Fluid::capacity() const { return impl_->solver->capacity(); }
double Fluid::particle_mass() const { return impl_->solver->particle_mass(); }

}  // namespace sinew
