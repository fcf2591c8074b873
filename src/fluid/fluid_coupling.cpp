// fluid_coupling.cpp — sinew/fluid_coupling.h: tissue surfaces carried to
// a fluid's boundary particles, the fluid's impulses carried back to the
// tissue as forces, frame by frame.
#include "sinew/fluid_coupling.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "runtime/simulation_internals.h"

// The class is deprecated for users; its own definitions name it.
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"

namespace sinew {

struct FluidCoupling::Impl {
  Simulation* simulation = nullptr;
  std::unique_ptr<Fluid> fluid;
  std::vector<SurfaceSamples> samples;
  std::vector<std::uint32_t> first_particle;  // per surface
  std::uint32_t fixed = 0, coupled = 0;      // boundary particles: [0, fixed) fixed, then the coupled ones
  int steps = 0;                             // fluid steps per frame
  double frame = 0.0;
  std::vector<std::array<float, 3>> position, velocity, impulse;  // per boundary particle
  std::vector<float> x, v, force;                                 // per simulation particle
  std::array<double, 3> last{}, last_fixed{};
};

FluidCoupling::FluidCoupling(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
FluidCoupling::FluidCoupling(FluidCoupling&&) noexcept = default;
FluidCoupling& FluidCoupling::operator=(FluidCoupling&&) noexcept = default;
FluidCoupling::~FluidCoupling() = default;

Result<FluidCoupling> FluidCoupling::create(Simulation& simulation, FluidDesc desc,
                                            std::span<const CoupledSurface> surfaces) {
  if (surfaces.empty()) return Error(ErrorCode::bad_parameter, "fluid coupling: no surface to couple");
  auto m = std::make_unique<Impl>();
  m->simulation = &simulation;
  m->frame = SimulationInternals::frame_length(simulation);
  const double dt = desc.settings.time_step;
  m->steps = static_cast<int>(std::lround(m->frame / dt));
  if (!(dt > 0.0) || m->steps < 1 || std::abs(m->steps * dt - m->frame) > 1e-9 * m->frame) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "fluid coupling: the tissue's frame %.6g s is not a whole number of fluid steps of %.6g s", m->frame, dt);
    return Error(ErrorCode::bad_parameter, text);
  }
  const std::uint32_t particles = simulation.info().particles;
  m->fixed = static_cast<std::uint32_t>(desc.boundary.size());
  for (std::size_t k = 0; k < surfaces.size(); ++k) {
    const CoupledSurface& c = surfaces[k];
    for (const auto& t : c.surface.triangles)
      for (std::uint32_t v : t)
        if (std::uint64_t{c.first_particle} + v >= particles)
          return Error(ErrorCode::bad_parameter, "fluid coupling: surface " + std::to_string(k) + " vertex " +
                                                     std::to_string(v) + " is beyond the simulation's " +
                                                     std::to_string(particles) + " particles");
    auto samples = sample_surface(c.surface.vertices, c.surface.triangles, desc.settings.spacing);
    if (!samples) return samples.error();
    desc.boundary.insert(desc.boundary.end(), samples->points.begin(), samples->points.end());
    m->samples.push_back(std::move(*samples));
    m->first_particle.push_back(c.first_particle);
  }
  m->coupled = static_cast<std::uint32_t>(desc.boundary.size()) - m->fixed;
  if (m->coupled == 0)
    return Error(ErrorCode::bad_parameter, "fluid coupling: the surfaces gave no boundary particles (no triangles?)");
  // Forces of zero for the next frame: the simulation's error names
  // SceneDesc::external_forces now, before the fluid steps.
  if (Status s = simulation.set_particle_forces(std::vector<float>(3 * std::size_t{particles}, 0.0f)); !s)
    return s.error();
  desc.moving_boundary = true;
  desc.boundary_forces = true;
  auto fluid = Fluid::create(desc);
  if (!fluid) return fluid.error();
  m->fluid = std::make_unique<Fluid>(std::move(*fluid));
  m->position.resize(desc.boundary.size());
  m->velocity.assign(desc.boundary.size(), {0.0f, 0.0f, 0.0f});
  for (std::size_t b = 0; b < m->fixed; ++b)
    m->position[b] = {float(desc.boundary[b][0]), float(desc.boundary[b][1]), float(desc.boundary[b][2])};
  m->force.assign(3 * std::size_t{particles}, 0.0f);
  return FluidCoupling(std::move(m));
}

Status FluidCoupling::step() {
  Impl& m = *impl_;
  // The tissue's surfaces to the boundary particles.
  if (Status s = m.simulation->read_positions(m.x); !s) return s;
  if (Status s = m.simulation->read_velocities(m.v); !s) return s;
  std::vector<std::array<float, 3>> at;
  std::size_t next = m.fixed;
  for (std::size_t k = 0; k < m.samples.size(); ++k) {
    const std::size_t offset = 4 * std::size_t{m.first_particle[k]};
    const std::span<const float> x = std::span<const float>(m.x).subspan(offset);
    const std::span<const float> v = std::span<const float>(m.v).subspan(offset);
    m.samples[k].positions_on(x, 4, at);
    std::copy(at.begin(), at.end(), m.position.begin() + std::ptrdiff_t(next));
    m.samples[k].positions_on(v, 4, at);
    std::copy(at.begin(), at.end(), m.velocity.begin() + std::ptrdiff_t(next));
    next += at.size();
  }
  if (Status s = m.fluid->set_boundary(m.position, m.velocity); !s) return s;
  // The fluid's frame, then its push on the tissue as constant forces over
  // the tissue's frame. An emitter past the capacity still leaves a whole
  // frame (what fits was made): finish it, then report it.
  Status fluid_status = m.fluid->step(m.steps);
  if (!fluid_status && fluid_status.error().code() != ErrorCode::capacity_exceeded) return fluid_status;
  if (Status s = m.fluid->read_boundary_impulses(m.impulse); !s) return s;
  m.last = m.last_fixed = {};
  for (std::size_t b = 0; b < m.impulse.size(); ++b)
    for (int a = 0; a < 3; ++a) (b < m.fixed ? m.last_fixed : m.last)[a] += m.impulse[b][a];
  std::fill(m.force.begin(), m.force.end(), 0.0f);
  std::vector<std::array<float, 3>> per_frame;
  next = m.fixed;
  const float inv_frame = float(1.0 / m.frame);
  for (std::size_t k = 0; k < m.samples.size(); ++k) {
    const std::size_t count = m.samples[k].points.size();
    per_frame.resize(count);
    for (std::size_t i = 0; i < count; ++i)
      for (int a = 0; a < 3; ++a) per_frame[i][a] = m.impulse[next + i][a] * inv_frame;
    m.samples[k].spread_to_vertices(per_frame, std::span<float>(m.force).subspan(3 * std::size_t{m.first_particle[k]}), 3);
    next += count;
  }
  if (Status s = m.simulation->set_particle_forces(m.force); !s) return s;
  if (Status s = m.simulation->step(); !s) return s;
  return fluid_status;
}

Fluid& FluidCoupling::fluid() { return *impl_->fluid; }
const Fluid& FluidCoupling::fluid() const { return *impl_->fluid; }
std::uint32_t FluidCoupling::first_coupled() const { return impl_->fixed; }
std::uint32_t FluidCoupling::coupled_count() const { return impl_->coupled; }
std::array<double, 3> FluidCoupling::last_impulse() const { return impl_->last; }
std::array<double, 3> FluidCoupling::last_fixed_impulse() const { return impl_->last_fixed; }

}  // namespace sinew
