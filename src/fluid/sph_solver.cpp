// sph_solver.cpp — see sph_solver.h.
#include "fluid/sph_solver.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <numeric>
#include <string>

#include "fluid/sph_density.h"
#include "program/primitives.h"
#include "sph_flow_params.h"
#include "pbf_params.h"
#include "sph_tension_params.h"

namespace sinew {
namespace {

std::string str(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

Status positive(const std::string& name, double v) {
  if (v > 0.0 && std::isfinite(v)) return {};
  return Error(ErrorCode::bad_parameter, "sph: " + name + " must be finite and > 0 (got " + str(v) + ")");
}

Status finite3(const std::string& name, const std::array<double, 3>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return Error(ErrorCode::bad_parameter, "sph: " + name + " must be finite");
  return {};
}

// What the device computes from the settings (Fluid::create's parameter
// blocks, sph_params), each checked in float32, the device's precision: a
// setting finite in double can give an infinite kernel constant (a spacing
// of 1e-30 m: 1 / (pi l^3) = 1e90) or one that rounds to 0 (a divisor), and
// then NaN after a step. `scale` values must be finite; `divisor` ones
// finite and a normal float (not 0, not denormal).
Status check_device_floats(const FluidSettings& settings) {
  const double h = settings.support * settings.spacing, l = 0.5 * h, c = settings.speed_of_sound;
  const double rho0 = settings.rest_density, dt = settings.time_step;
  struct Derived {
    const char* what;  // the quantity and its formula
    double value;
    bool divisor;
  };
  std::vector<Derived> derived = {
      {"the kernels' support squared h^2 [m^2]", h * h, true},
      {"the kernels' 1 / l (l = h / 2) [1/m]", 1.0 / l, false},
      {"the kernels' 1 / (pi l^3) [1/m^3]", 1.0 / (std::numbers::pi * l * l * l), false},
      {"the kernels' 1 / (pi l^4) [1/m^4]", 1.0 / (std::numbers::pi * l * l * l * l), false},
      {"the viscosity's 0.01 h^2 [m^2]", 0.01 * h * h, true},
      {"a particle's mass rho0 spacing^3 [kg]", rho0 * std::pow(settings.spacing, 3), true},
      {"rest_density [kg/m^3]", rho0, true},
      {"the pressure stiffness rho0 c0^2 / 7 [Pa]", rho0 * c * c / 7.0, true},
      {"the pressure's acceleration scale c0^2 / h [m/s^2]", c * c / h, false},
      {"its change of velocity per step c0^2 dt / h [m/s]", c * c * dt / h, false},
      {"the viscosity's alpha c0 h [m^2/s]", settings.viscosity * c * h, false},
      {"the boundary viscosity's alpha c0 h [m^2/s]", settings.boundary_viscosity * c * h, false},
      {"time_step [s]", dt, true}};
  for (int k = 0; k < 3; ++k) {
    derived.push_back({"gravity [m/s^2]", settings.gravity[k], false});
    derived.push_back({"gravity's change of velocity per step g dt [m/s]", settings.gravity[k] * dt, false});
  }
  if (settings.surface_tension > 0.0) {
    derived.push_back({"surface tension's cohesion 32 / (pi h^9) [1/m^9]", 32.0 / (std::numbers::pi * std::pow(h, 9)), false});
    derived.push_back({"surface tension's h^6 / 64 [m^6]", std::pow(h, 6) / 64.0, true});
    derived.push_back({"surface tension's dt^2 [s^2]", dt * dt, true});
    derived.push_back({"surface_tension", settings.surface_tension, false});
  }
  if (settings.method == FluidMethod::pbf) {
    derived.push_back({"PBF's 1 / rho0 [m^3/kg]", 1.0 / rho0, true});
    derived.push_back({"PBF's 1 / dt [1/s]", 1.0 / dt, false});
  }
  for (const Derived& d : derived) {
    const float f = static_cast<float>(d.value);
    const bool ok = std::isfinite(f) && (!d.divisor || std::isnormal(f));
    if (ok) continue;
    return Error(ErrorCode::bad_parameter,
                 "sph: these settings (spacing " + str(settings.spacing) + " m, support " + str(settings.support) +
                     ", rest_density " + str(rho0) + ", speed_of_sound " + str(c) + ", time_step " + str(dt) +
                     ") give " + d.what + " = " + str(d.value) + ", which in float32, the device's precision, is " +
                     (std::isfinite(f) ? "0 or denormal" : "not finite"));
  }
  return {};
}

Status check_settings(const FluidSettings& settings) {
  for (const auto& [name, value] : {std::pair{"spacing", settings.spacing}, {"rest_density", settings.rest_density},
                                    {"speed_of_sound", settings.speed_of_sound}, {"time_step", settings.time_step}})
    if (Status s = positive(name, value); !s) return s;
  for (const auto& [name, value] : {std::pair{"viscosity", settings.viscosity}, {"boundary_viscosity", settings.boundary_viscosity}})
    if (!(value >= 0.0) || !std::isfinite(value))
      return Error(ErrorCode::bad_parameter, std::string("sph: ") + name + " must be finite and >= 0 (got " + str(value) + ")");
  if (Status s = finite3("gravity", settings.gravity); !s) return s;
  if (!(settings.support >= 1.0) || !std::isfinite(settings.support))
    return Error(ErrorCode::bad_parameter, "sph: support must be finite and >= 1 spacing (got " + str(settings.support) + ")");
  if (!(settings.surface_tension >= 0.0) || !std::isfinite(settings.surface_tension))
    return Error(ErrorCode::bad_parameter, "sph: surface_tension must be finite and >= 0 (got " +
                                               str(settings.surface_tension) + ")");
  if (settings.method == FluidMethod::pbf && settings.surface_tension > 0.0)
    return Error(ErrorCode::bad_parameter, "sph: surface_tension needs method wcsph (PBF's is not built)");
  if (settings.method == FluidMethod::pbf) {
    if (settings.pbf_iterations < 1)
      return Error(ErrorCode::bad_parameter, "sph: pbf_iterations must be >= 1 (got " + std::to_string(settings.pbf_iterations) + ")");
    return positive("pbf_relaxation", settings.pbf_relaxation);
  }
  if (Status s = check_device_floats(settings); !s) return s;
  // The CFL condition for the speed of sound (Monaghan 2005): reported, never clamped.
  const double h = settings.support * settings.spacing;
  const double cfl = 0.4 * h / settings.speed_of_sound;
  if (settings.time_step > cfl)
    return Error(ErrorCode::bad_parameter, "sph: time_step " + str(settings.time_step) +
                                               " s is beyond the CFL bound 0.4 h / c0 = " + str(cfl) +
                                               " s (h = " + str(h) + " m, c0 = " + str(settings.speed_of_sound) +
                                               " m/s): shorten it or lower the speed of sound");
  return {};
}

// An emitter's square lattice of `spacing` within its disc: (u, v) [m].
std::vector<std::array<double, 2>> emitter_lattice(double radius, double spacing) {
  std::vector<std::array<double, 2>> points;
  const int k = int(std::floor(radius / spacing));
  for (int j = -k; j <= k; ++j)
    for (int i = -k; i <= k; ++i) {
      const double u = i * spacing, v = j * spacing;
      if (u * u + v * v <= radius * radius * (1.0 + 1e-12)) points.push_back({u, v});
    }
  return points;
}

// Unit tangents t1, t2 with d: an orthonormal frame (d normalised).
void frame_of(const std::array<double, 3>& d, std::array<double, 3>& t1, std::array<double, 3>& t2) {
  const std::array<double, 3> axis = std::fabs(d[0]) < 0.6 ? std::array<double, 3>{1, 0, 0} : std::array<double, 3>{0, 1, 0};
  t1 = {axis[1] * d[2] - axis[2] * d[1], axis[2] * d[0] - axis[0] * d[2], axis[0] * d[1] - axis[1] * d[0]};
  const double l = std::sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
  for (double& x : t1) x /= l;
  t2 = {d[1] * t1[2] - d[2] * t1[1], d[2] * t1[0] - d[0] * t1[2], d[0] * t1[1] - d[1] * t1[0]};
}

// The fields every fluid kernel shares with the WCSPH parameters: the
// count's word, the capacity, the grid's buckets and the spline's radii.
template <class Params>
Params grid_fields(const kernels::SphParams& p) {
  Params q{};
  q.count_word = p.count_word;
  q.capacity = p.capacity;
  q.table_mask = p.table_mask;
  q.h2 = p.h2;
  q.inv_l = p.inv_l;
  q.grad_sigma = p.grad_sigma;
  return q;
}

}  // namespace

void SphSolver::state_buffers(std::vector<std::pair<BufferHandle, std::size_t>>& out) const {
  for (const auto& b : sized_)
    if (b.second > 0) out.push_back(b);
  grid_->state_buffers(out);
}

SphSolver::~SphSolver() {
  if (have_program_) (void)device_.destroy_program(program_);
  if (have_rest_program_) (void)device_.destroy_program(rest_program_);
  for (BufferHandle h : {velocity_, sorted_velocity_, density_, pressure_, speed2_, scratch_, state_, emitters_,
                         emit_flags_, previous_, lambda_, moved_, normals_, pattern_, sinks_, flags_, kept_, compact_scratch_, boundary_position_, boundary_velocity_,
                         impulse_, near_})
    if (h.valid()) (void)device_.destroy_buffer(h);
  grid_.reset();
}

Result<std::unique_ptr<SphSolver>> SphSolver::create(Device& device, const SphSettings& settings,
                                                     std::span<const std::array<double, 3>> fluid,
                                                     std::span<const std::array<double, 3>> boundary) {
  FluidDesc desc;
  desc.settings = settings;
  desc.particles.assign(fluid.begin(), fluid.end());
  desc.boundary.assign(boundary.begin(), boundary.end());
  return create(device, desc);
}

Status SphSolver::check_emitter(std::size_t index, const FluidEmitter& e) const {
  const std::string name = "emitter " + std::to_string(index);
  if (Status s = finite3(name + " centre", e.centre); !s) return s;
  if (Status s = finite3(name + " direction", e.direction); !s) return s;
  const double length = std::hypot(e.direction[0], e.direction[1], e.direction[2]);
  if (!(length > 0.0)) return Error(ErrorCode::bad_parameter, "sph: " + name + " direction must not be zero");
  if (!(e.radius >= 0.5 * spacing_) || !std::isfinite(e.radius))
    return Error(ErrorCode::bad_parameter, "sph: " + name + " radius " + str(e.radius) +
                                               " m must be finite and >= half the spacing (" + str(0.5 * spacing_) + " m)");
  if (e.radius / spacing_ > 36.0)  // pi 36^2 is about 4,000 lattice points (the limit is 4,096 in all)
    return Error(ErrorCode::bad_parameter, "sph: " + name + " radius " + str(e.radius) + " m holds about " +
                                               str(3.14159 * (e.radius / spacing_) * (e.radius / spacing_)) +
                                               " lattice points, more than 4096");
  if (!(e.flow_rate >= 0.0) || !std::isfinite(e.flow_rate))
    return Error(ErrorCode::bad_parameter, "sph: " + name + " flow_rate must be finite and >= 0 (got " + str(e.flow_rate) + ")");
  const double points = double(emitter_lattice(e.radius, spacing_).size());
  const double speed = e.flow_rate / (points * spacing_ * spacing_);
  if (speed * time_step_ > spacing_)
    return Error(ErrorCode::bad_parameter, "sph: " + name + " flow_rate " + str(e.flow_rate) + " m^3/s leaves at " +
                                               str(speed) + " m/s, more than a spacing per step (" +
                                               str(spacing_ / time_step_) + " m/s): widen it or shorten the step");
  const double bound = 0.4 * h_ / (speed_of_sound_ + speed);
  if (time_step_ > bound)
    return Error(ErrorCode::bad_parameter, "sph: " + name + " leaves at " + str(speed) +
                                               " m/s: time_step is beyond the CFL bound 0.4 h / (c0 + v) = " + str(bound) + " s");
  // A source inside a collider: its lattice within half a spacing of a boundary particle.
  std::array<double, 3> d = e.direction, t1, t2;
  for (double& x : d) x /= length;
  frame_of(d, t1, t2);
  const double near2 = 0.25 * spacing_ * spacing_;
  for (const auto& [u, v] : emitter_lattice(e.radius, spacing_)) {
    std::array<double, 3> x;
    for (int a = 0; a < 3; ++a) x[a] = e.centre[a] + u * t1[a] + v * t2[a];
    for (std::size_t b = 0; b < boundary_at_.size(); ++b) {
      const double dx = x[0] - boundary_at_[b][0], dy = x[1] - boundary_at_[b][1], dz = x[2] - boundary_at_[b][2];
      if (dx * dx + dy * dy + dz * dz < near2)
        return Error(ErrorCode::bad_parameter, "sph: " + name + " lies inside the boundary: its particle at (" +
                                                   str(x[0]) + ", " + str(x[1]) + ", " + str(x[2]) +
                                                   ") m is within half a spacing of boundary particle " + std::to_string(b));
    }
  }
  return {};
}

Status SphSolver::write_emitter(std::size_t index, const FluidEmitter& e, std::vector<float>* pattern) {
  const double length = std::hypot(e.direction[0], e.direction[1], e.direction[2]);
  std::array<double, 3> d = e.direction, t1, t2;
  for (double& x : d) x /= length;
  frame_of(d, t1, t2);
  const auto lattice = emitter_lattice(e.radius, spacing_);
  const double speed = e.flow_rate / (double(lattice.size()) * spacing_ * spacing_);
  std::uint32_t first = 0;
  for (std::size_t k = 0; k < index; ++k) first += emitter_points_[k];
  float record[SINEW_SPH_EMITTER_FLOATS];
  for (int a = 0; a < 3; ++a) {
    record[a] = float(e.centre[a]);
    record[4 + a] = float(d[a]);
    record[8 + a] = float(t1[a]);
    record[12 + a] = float(t2[a]);
  }
  record[3] = float(speed * time_step_ / spacing_);
  record[7] = float(speed);
  record[11] = std::bit_cast<float>(first);
  record[15] = std::bit_cast<float>(std::uint32_t(lattice.size()));
  if (pattern)
    for (const auto& [u, v] : lattice) pattern->insert(pattern->end(), {float(u), float(v), std::bit_cast<float>(std::uint32_t(index)), 0.0f});
  return device_.write_buffer(emitters_, 4 * SINEW_SPH_EMITTER_FLOATS * index, record, sizeof record);
}

Result<std::unique_ptr<SphSolver>> SphSolver::create(Device& device, const FluidDesc& desc) {
  const FluidSettings& settings = desc.settings;
  if (Status s = check_settings(settings); !s) return s.error();
  if (desc.particles.empty() && desc.emitters.empty())
    return Error(ErrorCode::bad_parameter, "sph: no fluid particles and no emitter");
  for (const auto& [what, points] : {std::pair{"fluid", std::span(desc.particles)}, {"boundary", std::span(desc.boundary)}})
    for (std::size_t i = 0; i < points.size(); ++i)
      for (double x : points[i])
        if (!std::isfinite(x))
          return Error(ErrorCode::bad_parameter, std::string("sph: ") + what + " particle " + std::to_string(i) +
                                                     " has coordinate " + str(x) + ": it must be finite");
  if (!desc.velocities.empty() && desc.velocities.size() != desc.particles.size())
    return Error(ErrorCode::bad_parameter, "sph: " + std::to_string(desc.velocities.size()) + " velocities for " +
                                               std::to_string(desc.particles.size()) + " particles");
  for (std::size_t i = 0; i < desc.velocities.size(); ++i)
    if (Status s = finite3("velocity " + std::to_string(i), desc.velocities[i]); !s) return s.error();
  const std::size_t capacity = desc.capacity > 0 ? desc.capacity : desc.particles.size();
  if (!desc.emitters.empty() && capacity <= desc.particles.size())
    return Error(ErrorCode::bad_parameter, "sph: FluidDesc::capacity " + std::to_string(capacity) +
                                               " leaves emitters no room: it must be more than the " +
                                               std::to_string(desc.particles.size()) + " initial particles");
  if (!desc.emitters.empty() && !(settings.support >= 1.25))
    return Error(ErrorCode::bad_parameter, "sph: emitters need support >= 1.25 spacings (got " + str(settings.support) +
                                               "): their search for room reaches 0.75 spacing + a step's motion");
  if (desc.particles.size() > capacity)
    return Error(ErrorCode::bad_parameter, "sph: " + std::to_string(desc.particles.size()) +
                                               " particles, more than the capacity " + std::to_string(capacity));
  const std::size_t total = capacity + desc.boundary.size();
  if (total > (1u << 24))
    return Error(ErrorCode::bad_parameter, "sph: capacity " + std::to_string(capacity) + " and " +
                                               std::to_string(desc.boundary.size()) + " boundary particles, more than 2^24");
  const double h = settings.support * settings.spacing;
  std::unique_ptr<SphSolver> solver(new SphSolver(device));
  SphSolver& m = *solver;
  m.boundary_ = static_cast<std::uint32_t>(desc.boundary.size());
  m.capacity_ = static_cast<std::uint32_t>(capacity);
  m.slots_ = static_cast<std::uint32_t>(total);
  m.pbf_ = settings.method == FluidMethod::pbf;
  m.speed_of_sound_ = m.pbf_ ? 0.0 : settings.speed_of_sound;  // PBF's steps are bound by the particles' speed alone
  m.iterations_ = settings.pbf_iterations;
  if (m.pbf_ && desc.boundary_forces)
    return Error(ErrorCode::bad_parameter, "sph: boundary_forces (and coupling with tissue) need method wcsph: "
                                           "PBF's reaction on the boundary is not built");
  m.h_ = h;
  m.spacing_ = settings.spacing;
  m.time_step_ = settings.time_step;
  m.mass_ = settings.rest_density * std::pow(settings.spacing, 3);
  m.boundary_at_ = desc.boundary;
  for (std::size_t e = 0; e < desc.emitters.size(); ++e)
    if (Status s = m.check_emitter(e, desc.emitters[e]); !s) return s.error();
  for (std::size_t k = 0; k < desc.sinks.size(); ++k) {
    if (Status s = finite3("sink " + std::to_string(k) + " centre", desc.sinks[k].centre); !s) return s.error();
    if (Status s = positive("sink " + std::to_string(k) + " radius", desc.sinks[k].radius); !s) return s.error();
  }

  const std::uint32_t n = m.slots_;
  auto grid = NeighbourGrid::create(device, n, h, 1);  // the solver visits the cells itself: no lists
  if (!grid) return grid.error();
  m.grid_ = std::move(*grid);
  NeighbourGrid& g = *m.grid_;
  struct Made {
    BufferHandle* handle;
    std::size_t bytes;
    const char* label;
  };
  std::vector<Made> made{{&m.velocity_, 16 * std::size_t{n}, "sph velocities"},
                         {&m.sorted_velocity_, 16 * std::size_t{n}, "sph sorted velocities"},
                         {&m.density_, 4 * std::size_t{n}, "sph densities"},
                         {&m.pressure_, 4 * std::size_t{n}, "sph pressures"},
                         {&m.speed2_, 4 * std::size_t{n}, "sph speeds"},
                         {&m.scratch_, 4 * std::size_t{reduce_scratch_words(n)}, "sph scratch"},
                         {&m.state_, 4 * (SINEW_SPH_STATE_PHASES + desc.emitters.size()), "sph state"}};
  std::uint32_t lattice_points = 0;
  for (const FluidEmitter& e : desc.emitters) lattice_points += std::uint32_t(emitter_lattice(e.radius, m.spacing_).size());
  m.lattice_points_ = lattice_points;
  m.next_id_ = static_cast<std::uint32_t>(desc.particles.size());
  if (lattice_points > 4096)  // sph_emit counts the points before each one in a loop
    return Error(ErrorCode::bad_parameter, "sph: the emitters' discs hold " + std::to_string(lattice_points) +
                                               " lattice points, more than 4096: make them smaller or fewer");
  if (!desc.emitters.empty()) {
    made.push_back({&m.emitters_, 4 * SINEW_SPH_EMITTER_FLOATS * desc.emitters.size(), "sph emitters"});
    made.push_back({&m.emit_flags_, 4 * std::size_t{lattice_points}, "sph emitter flags"});
  }
  if (!desc.sinks.empty()) {
    made.push_back({&m.sinks_, 16 * desc.sinks.size(), "sph sinks"});
    made.push_back({&m.flags_, 4 * std::size_t{n}, "sph sink flags"});
    made.push_back({&m.kept_, 4 * std::size_t{n}, "sph kept"});
    made.push_back({&m.compact_scratch_, 4 * std::size_t{compact_scratch_words(n)}, "sph compaction scratch"});
  }
  if (desc.moving_boundary && m.boundary_ > 0) {
    made.push_back({&m.boundary_position_, 16 * std::size_t{m.boundary_}, "sph boundary positions"});
    made.push_back({&m.boundary_velocity_, 16 * std::size_t{m.boundary_}, "sph boundary velocities"});
  }
  if (desc.boundary_forces && m.boundary_ > 0) made.push_back({&m.impulse_, 16 * std::size_t{m.boundary_}, "sph boundary impulses"});
  m.tension_ = settings.surface_tension > 0.0;
  if (m.tension_) made.push_back({&m.normals_, 16 * std::size_t{n}, "sph surface normals"});
  if (m.pbf_) {
    made.push_back({&m.previous_, 16 * std::size_t{n}, "pbf previous positions"});
    made.push_back({&m.lambda_, 4 * std::size_t{n}, "pbf lambdas"});
    made.push_back({&m.moved_, 16 * std::size_t{n}, "pbf moved positions"});
  }
  for (const Made& b : made) {
    auto buffer = device.create_buffer(std::max<std::size_t>(b.bytes, 16), b.label);
    if (!buffer) return buffer.error();
    *b.handle = *buffer;
    m.sized_.emplace_back(*buffer, b.bytes);  // what a saved state holds (state_buffers)
  }
  if (desc.boundary_forces && m.boundary_ > 0) {
    // Rebuilt every step (sph_fluid_cells), so no part of a saved state.
    auto near = device.create_buffer(4 * std::size_t{g.buckets()}, "sph buckets near the fluid");
    if (!near) return near.error();
    m.near_ = *near;
  }
  kernels::SphParams p = sph_params(g, h);
  p.rho0 = float(settings.rest_density);
  p.stiffness = float(settings.rest_density * settings.speed_of_sound * settings.speed_of_sound / 7.0);
  p.viscosity = float(settings.viscosity * settings.speed_of_sound * h);
  p.boundary_viscosity = float(settings.boundary_viscosity * settings.speed_of_sound * h);
  p.eta2 = float(0.01 * h * h);
  p.gx = float(settings.gravity[0]);
  p.gy = float(settings.gravity[1]);
  p.gz = float(settings.gravity[2]);
  p.dt = float(settings.time_step);
  m.params_ = p;
  if (m.tension_) {
    kernels::TensionParams t = grid_fields<kernels::TensionParams>(p);
    t.h = float(h);
    t.gamma = float(settings.surface_tension);
    t.cohesion = float(32.0 / (std::numbers::pi * std::pow(h, 9)));
    t.h6_64 = float(std::pow(h, 6) / 64.0);
    t.rho0 = p.rho0;
    t.dt = p.dt;
    t.dt2 = float(settings.time_step * settings.time_step);
    m.tension_params_ = t;
  }
  if (m.pbf_) {
    kernels::PbfParams q = grid_fields<kernels::PbfParams>(p);
    q.sigma = p.sigma;
    q.rho0 = p.rho0;
    q.inv_rho0 = float(1.0 / settings.rest_density);
    q.dt = p.dt;
    q.inv_dt = float(1.0 / settings.time_step);
    q.gx = p.gx;
    q.gy = p.gy;
    q.gz = p.gz;
    // epsilon: a fraction of sum_j |grad_j C_i|^2 / m_j inside a fluid at rest
    // (a cubic lattice of the spacing), the constraint's stiffness there.
    const double l = 0.5 * h, mass = settings.rest_density * std::pow(settings.spacing, 3);
    double stiffness = 0.0;
    const int reach = int(std::ceil(h / settings.spacing));
    for (int i = -reach; i <= reach; ++i)
      for (int j = -reach; j <= reach; ++j)
        for (int k = -reach; k <= reach; ++k) {
          const double r = settings.spacing * std::sqrt(double(i * i + j * j + k * k)), q2 = r / l;
          if (r == 0.0 || r >= h) continue;
          const double slope = q2 < 1.0 ? 2.25 * q2 * q2 - 3.0 * q2 : -0.75 * (2.0 - q2) * (2.0 - q2);
          const double gradient = mass / settings.rest_density * slope / (std::numbers::pi * l * l * l * l);
          stiffness += gradient * gradient / mass;
        }
    q.epsilon = float(settings.pbf_relaxation * stiffness);
    if (!std::isnormal(q.epsilon))
      return Error(ErrorCode::bad_parameter, "sph: pbf_relaxation " + str(settings.pbf_relaxation) +
                                                 " gives PBF's relaxation epsilon = " +
                                                 str(settings.pbf_relaxation * stiffness) +
                                                 ", which in float32, the device's precision, is not a normal number");
    m.pbf_params_ = q;
  }

  // The boundary's volumes: its density with mass 1 each (as if fluid) is sum_k W_bk.
  const auto& boundary = desc.boundary;
  std::vector<float> xyzw;
  xyzw.reserve(4 * total);
  for (const auto& b : boundary) xyzw.insert(xyzw.end(), {float(b[0]), float(b[1]), float(b[2]), 1.0f});
  std::vector<float> psi(boundary.size());
  if (!boundary.empty()) {
    if (Status s = g.upload(xyzw.data(), m.boundary_); !s) return s.error();
    FrameProgram volumes;
    g.append_grid(volumes);
    append_sph_density(volumes, g, p, m.density_);
    auto program = device.create_program(volumes);
    if (!program) return program.error();
    Status ran = device.run_program(*program);
    std::vector<float> sum(boundary.size());
    std::vector<std::uint32_t> order(boundary.size());
    if (ran) ran = device.read_buffer(m.density_, 0, sum.data(), 4 * boundary.size());
    if (ran) ran = device.read_buffer(g.buffers().order, 0, order.data(), 4 * boundary.size());
    (void)device.destroy_program(*program);
    if (!ran) return ran.error();
    for (std::size_t s = 0; s < boundary.size(); ++s) psi[order[s]] = float(settings.rest_density / double(sum[s]));
  }
  // Fluid first (ids 0 ..), then the boundary (w = -psi, ids with bit 31).
  const float mass = float(m.mass_);
  xyzw.clear();
  std::vector<float> velocity;
  velocity.reserve(4 * total);
  for (std::size_t i = 0; i < desc.particles.size(); ++i) {
    const auto& x = desc.particles[i];
    xyzw.insert(xyzw.end(), {float(x[0]), float(x[1]), float(x[2]), mass});
    const std::array<double, 3> v = desc.velocities.empty() ? std::array<double, 3>{} : desc.velocities[i];
    velocity.insert(velocity.end(), {float(v[0]), float(v[1]), float(v[2]), std::bit_cast<float>(std::uint32_t(i))});
  }
  for (std::size_t b = 0; b < boundary.size(); ++b) {
    xyzw.insert(xyzw.end(), {float(boundary[b][0]), float(boundary[b][1]), float(boundary[b][2]), -psi[b]});
    velocity.insert(velocity.end(), {0.0f, 0.0f, 0.0f, std::bit_cast<float>(SINEW_SPH_BOUNDARY_ID | std::uint32_t(b))});
  }
  const auto initial = static_cast<std::uint32_t>(desc.particles.size() + boundary.size());
  if (Status s = g.upload(xyzw.data(), initial); !s) return s.error();
  if (Status s = device.write_buffer(m.velocity_, 0, velocity.data(), 4 * velocity.size()); !s) return s.error();
  std::vector<std::uint32_t> state(SINEW_SPH_STATE_PHASES + desc.emitters.size(), 0u);  // phases 0.0f
  state[0] = static_cast<std::uint32_t>(desc.particles.size());
  state[3] = initial;
  if (Status s = device.write_buffer(m.state_, 0, state.data(), 4 * state.size()); !s) return s.error();

  m.emitters_desc_ = desc.emitters;
  std::vector<float> pattern;
  for (const FluidEmitter& e : desc.emitters) m.emitter_points_.push_back(std::uint32_t(emitter_lattice(e.radius, m.spacing_).size()));
  for (std::size_t e = 0; e < desc.emitters.size(); ++e)
    if (Status s = m.write_emitter(e, desc.emitters[e], &pattern); !s) return s.error();
  if (!pattern.empty()) {
    auto buffer = device.create_buffer(4 * pattern.size(), "sph emitter lattice");
    if (!buffer) return buffer.error();
    m.pattern_ = *buffer;
    if (Status s = device.write_buffer(m.pattern_, 0, pattern.data(), 4 * pattern.size()); !s) return s.error();
  }
  m.sinks_count_ = desc.sinks.size();
  for (std::size_t k = 0; k < desc.sinks.size(); ++k)
    if (Status s = m.set_sink(k, desc.sinks[k]); !s) return s.error();
  // No grid yet: the emitters' first search must find no particle (sph_emit_flags).
  const std::vector<std::uint32_t> empty(3 * std::size_t{g.buckets()}, 0u);
  if (Status s = device.write_buffer(g.buffers().ranges, 0, empty.data(), 4 * empty.size()); !s) return s.error();
  if (m.boundary_position_.valid()) {
    std::vector<std::array<float, 3>> x(boundary.size()), v(boundary.size(), {0.0f, 0.0f, 0.0f});
    for (std::size_t b = 0; b < boundary.size(); ++b) x[b] = {float(boundary[b][0]), float(boundary[b][1]), float(boundary[b][2])};
    if (Status s = m.set_boundary(x, v); !s) return s.error();
  }
  if (Status s = m.build_program(!desc.sinks.empty(), !desc.emitters.empty(), m.boundary_position_.valid(),
                                 m.impulse_.valid());
      !s)
    return s.error();
  m.stats_.particles = static_cast<std::uint32_t>(desc.particles.size());
  m.stats_.mass = double(m.stats_.particles) * m.mass_;
  return solver;
}

Status SphSolver::build_program(bool have_sinks, bool have_emitters, bool moving, bool forces) {
  const NeighbourGrid& g = *grid_;
  const NeighbourGridBuffers& b = g.buffers();
  const std::uint32_t n = slots_;
  kernels::SphFlowParams flow{};
  flow.count_word = 0;
  flow.kept_word = 1;  // the grid's pair word: free, as a solver runs only the grid's part
  flow.capacity = n;
  flow.emitters = static_cast<std::uint32_t>(emitters_desc_.size());
  flow.pattern = std::accumulate(emitter_points_.begin(), emitter_points_.end(), 0u);
  flow.sinks = static_cast<std::uint32_t>(sinks_count_);
  flow.spacing = float(spacing_);
  flow.rest_mass = float(mass_);
  flow.inv_cell = g.inv_cell();
  flow.table_mask = g.buckets() - 1;
  flow.clear2 = float(0.75 * spacing_) * float(0.75 * spacing_);

  // Two programs when the boundary moves: the first step of a step() call
  // moves it to the host's (or the tissue's) latest pose; the others need
  // not, as nothing changes that pose within a call and sph_step copies
  // boundary particles unchanged (the same floats, one kernel over every
  // particle less per step).
  auto make = [&](bool move) -> Result<ProgramHandle> {
    FrameProgram step;
    // The particle-wise kernels run over the live particles (counts[0]), not the slots.
    const std::uint32_t live = g.live_points(step);
    if (move) {
      step.dispatch_indirect(Kernel::sph_boundary_move, live, {b.counts, b.points, velocity_, boundary_position_, boundary_velocity_}, flow);
      step.barrier();
    }
    if (have_emitters) {
      // Before the sinks: the points are still in the last grid's order, which
      // sph_emit_flags searches for room.
      step.dispatch(Kernel::sph_emit_flags, std::max(flow.pattern, 1u),
                    {b.counts, b.points, b.sorted_cells, b.ranges, emitters_, pattern_, state_, emit_flags_}, flow);
      step.barrier();
      step.dispatch(Kernel::sph_emit, std::max(flow.pattern, 1u),
                    {b.counts, b.points, velocity_, emitters_, pattern_, state_, emit_flags_}, flow);
      step.barrier();
      step.dispatch(Kernel::sph_emit_commit, 1, {b.counts, emitters_, state_, emit_flags_}, flow);
      step.barrier();
      step.counter("sph particles (fluid capacity + boundary particles)", state_, 3, n);
    }
    if (have_sinks) {
      // Flags, their compaction into the kept indices (count in counts[1]),
      // the kept particles packed into the sorted arrays (free until the
      // grid's gather), copied back with their count.
      step.dispatch_indirect(Kernel::sph_sink_flags, live, {b.counts, b.points, sinks_, flags_}, flow);
      step.barrier();
      append_compact(step, {b.counts, 0, n}, flags_, BufferHandle{}, kept_, {b.counts, 1, n}, "sph particles kept",
                     compact_scratch_);
      step.dispatch(Kernel::sph_pack, n, {b.counts, kept_, b.points, velocity_, b.sorted_points, sorted_velocity_, state_}, flow);
      step.barrier();
      step.copy(b.sorted_points, 0, b.points, 0, 4 * n);
      step.copy(sorted_velocity_, 0, velocity_, 0, 4 * n);
      step.copy(b.counts, 1, b.counts, 0, 1);
      step.barrier();
    }
    if (pbf_) {
      append_pbf(step);
    } else {
      append_wcsph(step, forces);
    }
    // The fastest particle, for the speed check after the steps.
    max_word_ = append_reduce(step, {b.counts, 0, n}, ReduceOp::max_f32, {speed2_, 0}, 1, {scratch_, 0});
    return device_.create_program(step);
  };
  auto program = make(moving);
  if (!program) return program.error();
  program_ = *program;
  have_program_ = true;
  if (moving) {
    auto rest = make(false);
    if (!rest) return rest.error();
    rest_program_ = *rest;
    have_rest_program_ = true;
  }
  return {};
}

void SphSolver::append_pbf(FrameProgram& step) const {
  // Predict, sort the predicted positions along the grid, project the
  // density constraints (Jacobi: lambdas, then moves, copied back), then
  // the velocities from the motion (pbf_params.h).
  const NeighbourGrid& g = *grid_;
  const NeighbourGridBuffers& b = g.buffers();
  const std::uint32_t n = slots_;
  const std::uint32_t live = g.live_points(step);
  step.dispatch_indirect(Kernel::pbf_predict, live, {b.counts, b.points, velocity_, previous_}, pbf_params_);
  step.barrier();
  g.append_grid(step);
  step.dispatch_indirect(Kernel::sph_gather, live, {b.counts, b.order, velocity_, sorted_velocity_}, params_);
  step.barrier();
  for (int it = 0; it < iterations_; ++it) {
    step.dispatch_indirect(Kernel::pbf_lambda, live, {b.counts, b.sorted_points, b.sorted_cells, b.ranges, density_, lambda_},
                  pbf_params_);
    step.barrier();
    step.dispatch_indirect(Kernel::pbf_delta, live, {b.counts, b.sorted_points, b.sorted_cells, b.ranges, lambda_, moved_},
                  pbf_params_);
    step.barrier();
    step.copy(moved_, 0, b.sorted_points, 0, 4 * n);
    step.barrier();
  }
  step.dispatch_indirect(Kernel::pbf_finish, live,
                {b.counts, b.sorted_points, b.order, previous_, sorted_velocity_, b.points, velocity_, speed2_,
                 pressure_},
                pbf_params_);
  step.barrier();
}

void SphSolver::append_wcsph(FrameProgram& step, bool forces) const {
  const NeighbourGrid& g = *grid_;
  const NeighbourGridBuffers& b = g.buffers();
  const std::uint32_t live = g.live_points(step);
  // The grid, the density, the velocities in the grid's order, the forces and the motion.
  if (forces) step.fill(near_, 0, g.buckets(), 0u);  // before the grid's closing barrier
  g.append_grid(step);
  if (forces)  // the buckets near the fluid, beside the density (sph_params.h: sph_fluid_cells)
    step.dispatch_indirect(Kernel::sph_fluid_cells, live, {b.counts, b.sorted_points, b.sorted_cells, near_}, params_);
  append_sph_density(step, g, params_, density_);
  step.dispatch_indirect(Kernel::sph_gather, live, {b.counts, b.order, velocity_, sorted_velocity_}, params_);
  if (tension_)  // reads the densities and sorted points, as the gather does not write them
    step.dispatch_indirect(Kernel::sph_normals, live, {b.counts, b.sorted_points, b.sorted_cells, b.ranges, density_, normals_},
                  tension_params_);
  step.barrier();
  step.dispatch_indirect(Kernel::sph_step, live,
                {b.counts, b.sorted_points, b.sorted_cells, b.ranges, density_, sorted_velocity_, b.points, velocity_,
                 pressure_, speed2_},
                params_);
  if (forces)  // reads what sph_step reads, writes only the impulses: no barrier between them
    step.dispatch_indirect(Kernel::sph_boundary_force, live,
                  {b.counts, b.sorted_points, b.sorted_cells, b.ranges, density_, sorted_velocity_, impulse_, near_},
                           params_);
  step.barrier();
  if (tension_) {  // a further acceleration over the step, added to sph_step's results
    step.dispatch_indirect(Kernel::sph_tension, live,
                  {b.counts, b.sorted_points, b.sorted_cells, b.ranges, density_, normals_, b.points, velocity_},
                  tension_params_);
    step.barrier();
  }
}

Status SphSolver::read_counts() {
  std::uint32_t count = 0, state[5] = {};
  if (Status s = device_.read_buffer(grid_->buffers().counts, 0, &count, 4); !s) return s;
  if (Status s = device_.read_buffer(state_, 0, state, sizeof state); !s) return s;
  stats_.particles = std::min(count, slots_) - boundary_;
  stats_.emitted = state[1];
  stats_.removed = state[2];
  stats_.blocked = state[4];
  next_id_ = state[0];
  stats_.mass = double(stats_.particles) * mass_;
  return {};
}

Status SphSolver::step(int steps) {
  // Fluid ids are 31 bits (bit 31 marks the boundary's): a step must not
  // make one past that. The counts read after the last step bound it.
  if (std::uint64_t{next_id_} + std::uint64_t{lattice_points_} * std::uint64_t(std::max(steps, 0)) >= 0x80000000ull)
    return Error(ErrorCode::capacity_exceeded, "sph: fluid ids would pass 2^31 in these steps (" +
                                                   std::to_string(next_id_) + " made since create)");
  Status ran;
  for (int k = 0; k < steps; ++k) {
    Status one = device_.run_program(k > 0 && have_rest_program_ ? rest_program_ : program_);
    // A capacity error leaves a consistent step (what fits was made): count
    // it, go on with the steps asked for, and report it after them.
    const bool overflow = !one && one.error().code() == ErrorCode::capacity_exceeded;
    if (!one && !overflow) {
      ran = one;
      break;
    }
    ++stats_.steps;
    stats_.time += time_step_;
    if (overflow && ran) ran = one;
  }
  if (steps <= 0) return {};
  if (Status s = read_counts(); !s) return s;
  float v2 = 0.0f;
  if (Status s = device_.read_buffer(scratch_, 4 * std::size_t{max_word_}, &v2, 4); !s) return s;
  // No particle at all leaves the reduction's identity: speed 0.
  stats_.max_speed = v2 > 0.0f && std::isfinite(v2) ? std::sqrt(double(v2)) : 0.0;
  if (!ran) return ran;
  const double bound = 0.4 * h_ / (speed_of_sound_ + stats_.max_speed);
  if (pbf_ && !(time_step_ <= bound))
    return Error(ErrorCode::bad_parameter, "sph: time_step " + str(time_step_) + " s moves the fastest particle (" +
                                               str(stats_.max_speed) + " m/s) more than 0.4 h per step (bound " +
                                               str(bound) + " s): shorten it");
  if (!(time_step_ <= bound))
    return Error(ErrorCode::bad_parameter, "sph: time_step " + str(time_step_) + " s is beyond the CFL bound 0.4 h / (c0 + "
                                               "v_max) = " + str(bound) + " s with a particle at " + str(stats_.max_speed) +
                                               " m/s (c0 = " + str(speed_of_sound_) + " m/s)");
  return {};
}

Status SphSolver::read(std::vector<SphParticle>& fluid) {
  std::uint32_t count = 0;
  if (Status s = device_.read_buffer(grid_->buffers().counts, 0, &count, 4); !s) return s;
  const std::uint32_t n = std::min(count, slots_);
  std::vector<float> x(4 * std::size_t{n}), v(4 * std::size_t{n}), rho(n), pressure(n);
  // After a step, points and velocity hold the grid's sorted order of that
  // step, as do density and pressure.
  if (n > 0) {
    if (Status s = device_.read_buffer(grid_->buffers().points, 0, x.data(), 4 * x.size()); !s) return s;
    if (Status s = device_.read_buffer(velocity_, 0, v.data(), 4 * v.size()); !s) return s;
    if (Status s = device_.read_buffer(density_, 0, rho.data(), 4 * rho.size()); !s) return s;
    if (Status s = device_.read_buffer(pressure_, 0, pressure.data(), 4 * pressure.size()); !s) return s;
  }
  fluid.clear();
  for (std::uint32_t s = 0; s < n; ++s) {
    const std::uint32_t id = std::bit_cast<std::uint32_t>(v[4 * std::size_t{s} + 3]);
    if (id & SINEW_SPH_BOUNDARY_ID) continue;
    SphParticle q;
    q.id = id;
    q.position = {x[4 * std::size_t{s}], x[4 * std::size_t{s} + 1], x[4 * std::size_t{s} + 2]};
    q.velocity = {v[4 * std::size_t{s}], v[4 * std::size_t{s} + 1], v[4 * std::size_t{s} + 2]};
    q.density = rho[s];
    q.pressure = pressure[s];
    fluid.push_back(q);
  }
  std::sort(fluid.begin(), fluid.end(), [](const SphParticle& a, const SphParticle& b) { return a.id < b.id; });
  return {};
}

Status SphSolver::set_emitter(std::size_t index, const FluidEmitter& emitter) {
  if (index >= emitters_desc_.size())
    return Error(ErrorCode::bad_parameter, "sph: no emitter " + std::to_string(index) + " (the fluid has " +
                                               std::to_string(emitters_desc_.size()) + ")");
  if (emitter.radius != emitters_desc_[index].radius)
    return Error(ErrorCode::bad_parameter, "sph: emitter " + std::to_string(index) + " radius must stay " +
                                               str(emitters_desc_[index].radius) + " m (its lattice is fixed at create)");
  if (Status s = check_emitter(index, emitter); !s) return s;
  emitters_desc_[index] = emitter;
  return write_emitter(index, emitter, nullptr);
}

Status SphSolver::set_sink(std::size_t index, const FluidSink& sink) {
  if (index >= sinks_count_)
    return Error(ErrorCode::bad_parameter, "sph: no sink " + std::to_string(index) + " (the fluid has " +
                                               std::to_string(sinks_count_) + ")");
  const std::string name = "sink " + std::to_string(index);
  if (Status s = finite3(name + " centre", sink.centre); !s) return s;
  if (Status s = positive(name + " radius", sink.radius); !s) return s;
  const float record[4] = {float(sink.centre[0]), float(sink.centre[1]), float(sink.centre[2]),
                           float(sink.radius * sink.radius)};
  return device_.write_buffer(sinks_, 16 * index, record, sizeof record);
}

Status SphSolver::set_boundary(std::span<const std::array<float, 3>> positions,
                               std::span<const std::array<float, 3>> velocities) {
  if (!boundary_position_.valid())
    return Error(ErrorCode::bad_parameter, "sph: set_boundary needs FluidDesc::moving_boundary (and a boundary)");
  if (positions.size() != boundary_ || velocities.size() != boundary_)
    return Error(ErrorCode::bad_parameter, "sph: set_boundary takes " + std::to_string(boundary_) +
                                               " positions and velocities (got " + std::to_string(positions.size()) +
                                               " and " + std::to_string(velocities.size()) + ")");
  std::vector<float> x(4 * std::size_t{boundary_}), v(4 * std::size_t{boundary_});
  for (std::size_t b = 0; b < boundary_; ++b)
    for (int a = 0; a < 3; ++a) {
      if (!std::isfinite(positions[b][a]) || !std::isfinite(velocities[b][a]))
        return Error(ErrorCode::bad_parameter, "sph: set_boundary: boundary particle " + std::to_string(b) +
                                                   " has a coordinate that is not finite");
      x[4 * b + a] = positions[b][a];
      v[4 * b + a] = velocities[b][a];
    }
  for (std::size_t b = 0; b < boundary_; ++b) boundary_at_[b] = {positions[b][0], positions[b][1], positions[b][2]};
  if (Status s = device_.write_buffer(boundary_position_, 0, x.data(), 4 * x.size()); !s) return s;
  return device_.write_buffer(boundary_velocity_, 0, v.data(), 4 * v.size());
}

Status SphSolver::read_boundary_impulses(std::vector<std::array<float, 3>>& impulses) {
  if (!impulse_.valid())
    return Error(ErrorCode::bad_parameter, "sph: read_boundary_impulses needs FluidDesc::boundary_forces (and a boundary)");
  std::vector<float> words(4 * std::size_t{boundary_});
  if (Status s = device_.read_buffer(impulse_, 0, words.data(), 4 * words.size()); !s) return s;
  impulses.resize(boundary_);
  for (std::size_t b = 0; b < boundary_; ++b) impulses[b] = {words[4 * b], words[4 * b + 1], words[4 * b + 2]};
  std::fill(words.begin(), words.end(), 0.0f);
  return device_.write_buffer(impulse_, 0, words.data(), 4 * words.size());
}

}  // namespace sinew
